#pragma once
/// @file Forces that the supports exert on held points.
#include <pointhaptics/core/model.hpp>

#include <vector>

namespace pointhaptics {

/// Per fixed group, the total force the support exerts on its points so that they stay where they are
/// held: -sum_i (f_int_i + f_ext_i) over the group's points (inertia of a ramping support neglected). N.
std::vector<Vec3> support_reactions(const Model& model, const Points& f_int);

/// Out-of-balance force of the free points, relative: |f_int + f_ext|_free / max(|f_ext|, |f_int|, force_floor).
double relative_residual(const Model& model, const Points& f_int);

/// The floor of a residual's force scale, N: the elastic force of a strain of 1e-9 across the object, E L^2
/// (L its largest extent). Forces below it are below anything the model resolves; with nothing else pushing
/// (no load, a tool only touching) a residual measured against its own round-off would never fall.
double force_floor(const Model& model);

}  // namespace pointhaptics
