#pragma once
/// @file Several deformable bodies in one model (issue 47): each body built alone (its own sampling, spacing,
/// material, supports, held points and loads), then joined. No neighbour list crosses from one body to another,
/// so their mechanics stay apart and the solvers need nothing new; what couples them is contact
/// (contact/body_contact.hpp).
#include <pointhaptics/core/model.hpp>

#include <string>
#include <vector>

namespace pointhaptics {

/// The bodies as one model, in the order given: body k's points are [body_start[k], body_start[k + 1]). Their
/// materials, stiffness scales and supports are kept per point; the joined `material` is the first body's, `h`
/// the largest support, `spacing` the finest. Throws Error for a body with passive points (a level of detail's
/// frozen ring) or more than 256 materials in all.
Model join_models(std::vector<Model> bodies, std::vector<std::string> names);

}  // namespace pointhaptics
