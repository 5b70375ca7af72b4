#pragma once
/// @file The coarse level of the two-level preconditioner (`[solver] preconditioner = "two_level"`, issue 19):
/// CG's slow modes on a long or stiff object are its smooth, global deformations (a cantilever's bending),
/// which a point-local preconditioner (block-Jacobi) reaches only one stencil per iteration. A coarser point
/// set carries them: about 64 of the object's points (a cell of coarsening() spacings keeps its point nearest
/// the cell's low corner: every n-th lattice point, or a thinned cloud), rebuilt as a model of its own with
/// that spacing and support (the levels of detail's idea of coarser point sets), its tangent assembled and
/// factorised (CHOLMOD), and joined to the fine points by P, the coarse model's first-order MLS map at the fine
/// points (mechanics/surface_map.hpp: it carries every affine field exactly). The preconditioner is additive:
///   z = D^-1 r + P K_c^-1 P^T r,
/// block-Jacobi for the rough part, the coarse solve for the smooth part; symmetric positive definite, so CG
/// keeps its guarantees. K_c is the coarse model's own tangent (re-discretised, not P^T K P: that needs the
/// fine tangent assembled, which costs more than the solve it would save at these sizes).
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/mechanics/tangent_matrix.hpp>
#include <pointhaptics/solvers/sparse_cholesky.hpp>

#include <memory>
#include <vector>

namespace pointhaptics {

class CoarseCorrection {
 public:
  /// About this many coarse points: the coarse tangent couples every point to its neighbours' neighbours,
  /// so its factor is nearly dense and costs (3 n_c)^3 / 3; at 64 points (192 unknowns) that is well under a
  /// millisecond (measured on the 1,519-point cantilever: 256 coarse points took 14 ms to factorise and 17 ms
  /// to build, 32 took 0.15 and 4 ms, for 56 and 88 CG iterations against block-Jacobi's 348).
  static constexpr double target_coarse_points = 64;
  /// The coarse spacing over the fine one: cbrt(n / target_coarse_points), at least 2.
  static double coarsening(const Model& fine);
  /// The coarse points of `fine` (indices into it): per cell of coarsening() spacings, the point nearest the
  /// cell's low corner.
  static std::vector<index_t> coarse_points(const Model& fine);

  /// Made for `fine` (its address, points and pairs), else false.
  bool built_for(const Model& fine) const;
  /// Build the coarse model and P for `fine`; false (and no coarse level) when the object is too small for
  /// one (fewer than 8 coarse points) or the coarse model cannot be built (a coarse point without
  /// neighbours): the preconditioner is then block-Jacobi alone.
  bool build(const Model& fine);
  /// Linearise the coarse tangent at the fine displacement u (its coarse points' values), add the inertia
  /// k m_i, and factorise; false when it is not positive definite (no coarse correction until the next call).
  bool factorise(const Model& fine, const Points& u, double inertia);
  bool ready() const { return ready_; }
  /// z += P K_c^-1 P^T r over the free fine points (held points: untouched). No allocation.
  void add_correction(const Model& fine, const Points& r, Points& z);

  index_t n_coarse() const { return coarse_ ? coarse_->n_points : 0; }
  const CholeskyStats& cholesky_stats() const { return cholesky_.stats(); }

 private:
  const Model* fine_ = nullptr;
  index_t fine_points_ = -1, fine_pairs_ = -1;
  std::vector<index_t> selected_;
  std::unique_ptr<Model> coarse_;
  std::unique_ptr<Workspace> coarse_ws_;
  Tangent tangent_;
  TangentMatrix matrix_;
  SparseCholesky cholesky_;
  SurfaceMap prolongation_;  ///< P: rows the fine points, entries the coarse points carrying them
  Points coarse_u_, coarse_r_, coarse_z_, fine_zero_, fine_dz_;
  bool ready_ = false;
};

}  // namespace pointhaptics
