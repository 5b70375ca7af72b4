#pragma once
/// @file A patch of a model: the points around some of its points as a model of their own, their stencils as
/// they are (d_ij, k_ij, severed pairs kept), for questions asked near a place at the cost of the place, not
/// of the object: the explicit stable step after a cut (solvers/explicit_solver.hpp).
#include <pointhaptics/core/model.hpp>

#include <vector>

namespace pointhaptics {

struct ModelPatch {
  Model model;                   ///< the patch: `free` points first, then the rings around them (held; the
                                 ///< outer one passive, Model::n_passive)
  std::vector<index_t> full_of;  ///< patch index -> the model's
  index_t n_free = 0;            ///< the first n_free points: the free ones
  /// per held ring, the end of its points (ring k is [ring_end[k-1], ring_end[k]), ring 0 starting at n_free)
  std::vector<index_t> ring_end;
};

/// The points `free` (each once; the model's held ones stay held) and, held, `held_rings` rings of neighbours
/// around them (at least two; the outermost passive): the stencils that reach a free point, and their hourglass
/// pairs, are whole in the patch where it matters (a neighbour left out is held at zero), so the patch's tangent
/// with the rings held is the model's tangent restricted to the free points (its principal submatrix: the
/// eigenvalues interlace). The patch's energy changes with the free points as the model's does only from three
/// rings: a pair's hourglass energy reads both ends' gradients, and with two the outer ring's (whose stencils are
/// not whole) meets the inner ring's, which the free points move (reduction/contact_patch.hpp). Pairs to points
/// outside the patch are left out; d_self, masses, volumes and materials are the model's. Throws Error for an
/// index out of range.
ModelPatch model_patch(const Model& model, const std::vector<index_t>& free, int held_rings = 2);

/// The points within `rings` neighbour steps of `seeds` (the seeds included), each once, in increasing order.
std::vector<index_t> neighbourhood(const Model& model, const std::vector<index_t>& seeds, int rings);

}  // namespace pointhaptics
