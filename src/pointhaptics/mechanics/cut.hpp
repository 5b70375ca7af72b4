#pragma once
/// @file Cutting without a mesh (issue 18): a blade's swept surface severs the neighbour pairs whose segment it
/// crosses (the visibility criterion of Pauly et al. 2005, as Mueller et al. 2004 cut point-based objects), and
/// only the stencils that lost pairs are refitted.
///
/// A severed pair stays in the neighbour lists with w_ij = 0, hence d_ij = 0 and k_ij = 0: it carries no force
/// and no stiffness, every sparsity pattern built on the lists (the tangent, its factorisation's analysis)
/// stays valid, and the forces remain the exact gradient of the cut object's energy. A cut removes no
/// material: volumes and masses stay.
#include <pointhaptics/core/model.hpp>

#include <array>
#include <limits>
#include <span>
#include <vector>

namespace pointhaptics {

/// A blade's cutting edge, the segment a0-b0, moved to a1-b1: it sweeps the triangles (a0, b0, b1) and
/// (a0, b1, a1).
struct BladeSweep {
  Vec3 a0 = Vec3::Zero(), b0 = Vec3::Zero(), a1 = Vec3::Zero(), b1 = Vec3::Zero();
  /// Only crossings within this distance of the edge's last pose a1-b1 cut, m (infinity: anywhere on the
  /// sweep). A blade cuts at its edge: with a trail swept over many steps, material that later moves across
  /// the trail far behind the edge (where the blade's body would stand in its way) is not cut.
  double edge_reach = std::numeric_limits<double>::infinity();
  /// Only this body's pairs are cut (Model::body_start; -1: every body the sweep crosses): a scripted blade drawn
  /// through two layers cuts the one it names.
  index_t body = -1;
};

/// The pairs e = (i, j), i < j, not yet severed, whose segment between the points' positions `x` (3 x n: the
/// current positions, X + u) crosses the swept surface. A point exactly on it counts as on the side its normal
/// points to, so a blade through a lattice plane severs each pair once.
std::vector<index_t> pairs_crossing(const Model& model, const Points& x, const BladeSweep& sweep);

/// The pairs e = (i, j), i < j, not yet severed, whose segment between the positions `x` crosses one of the
/// `triangles` (each as three corners): with x = model.X and a cut's sheets in the reference configuration
/// (cut_surface.hpp), the pairs those cuts part, in any model over the same object (levels of detail carry a
/// cut of the active set to the object, and the object's cuts to the next active set, by them).
std::vector<index_t> pairs_crossing_triangles(const Model& model, const Points& x,
                                              std::span<const std::array<Vec3, 3>> triangles);

/// The area a number of severed pairs stands for, m^2: in a body of uniform point density rho = 1 / spacing^3
/// and support h, a plane of area A is crossed by rho^2 A pi h^4 / 4 pairs (a point at distance z from it has
/// rho pi (h - z)^2 (2h + z) / 3 neighbours beyond it; integrated over z in [0, h]). Counted from the pairs,
/// the area steps by one pair's share (4 spacing^6 / (pi h^4)), fine against the blade's.
double cut_area(const Model& model, index_t severed_pairs);

/// What one cut changed.
struct CutReport {
  index_t severed_pairs = 0;                    ///< pairs newly severed (a pair and its reverse count once)
  index_t refitted_stencils = 0;                ///< stencils that lost pairs and were refitted
  index_t regularised = 0;                      ///< of those, the ones left one-sided or too thin, hence regularised
  std::vector<index_t> cut_points;              ///< the ends of the newly severed pairs, each once
  std::vector<std::array<index_t, 2>> severed;  ///< the newly severed pairs (i, j), i < j
};

/// Sever the pairs `pairs` (each given in either direction; severed ones are skipped) and refit what depends
/// on them: the stencils that lost pairs (M_i, d_ij, d_ii), the hourglass coefficients of their pairs and of
/// the pairs' reverses, the hourglass diagonal's terms of those pairs, and the diagnostics
/// (regularised_neighbourhoods, isolated_points, severed_pairs). Cost: the affected rows, not the model.
/// Throws Error for a pair that does not exist. On a level-of-detail active set the passive points' stencils
/// are refitted too (they carry no energy; their pairs' hourglass terms do). With `keep_hourglass_diagonal`
/// false the hourglass diagonal is dropped instead (Model::hg_diagonal empty): only Newton's block-Jacobi
/// preconditioner reads it, and keeping it exact was a third of a blade step's update in explicit dynamics.
CutReport sever_pairs(Model& model, const std::vector<index_t>& pairs, bool keep_hourglass_diagonal = true);

/// sever_pairs() of the pairs_crossing() of every sweep (a blade step's strips), all at the positions x: the
/// stencils they touch are refitted once.
CutReport cut(Model& model, const Points& x, std::span<const BladeSweep> sweeps, bool keep_hourglass_diagonal = true);
inline CutReport cut(Model& model, const Points& x, const BladeSweep& sweep, bool keep_hourglass_diagonal = true) {
  return cut(model, x, std::span<const BladeSweep>(&sweep, 1), keep_hourglass_diagonal);
}

/// The object's connected pieces over its unsevered pairs: piece_of[i] in [0, count), numbered in the order of
/// their lowest point. Returns count. A cut all the way through makes more than one.
index_t connected_pieces(const Model& model, std::vector<index_t>& piece_of);

/// connected_pieces(), and the number of points in each piece.
std::vector<index_t> piece_sizes(const Model& model, std::vector<index_t>& piece_of);

}  // namespace pointhaptics
