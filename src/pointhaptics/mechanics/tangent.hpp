#pragma once
/// @file The tangent stiffness K = d^2 W / du^2 (Hessian of the elastic, volume and hourglass energy),
/// applied matrix-free (physics.md, "Tangent"), and its 3x3 diagonal blocks for block-Jacobi.
#include <pointhaptics/core/workspace.hpp>

#include <vector>

namespace pointhaptics {

enum class TangentMode {
  EXACT,      ///< the exact Hessian; indefinite under compression (the geometric term dF S)
  PROJECTED,  ///< positive semi-definite per point: the material's projection (SVK: the positive part of S in
              ///< the geometric term) and the volume term without its (J - 1) d(cof F) part (Gauss-Newton)
};

/// The linearisation of the internal forces at one configuration u: K du = -(d f_int / du) du.
/// linearise() records F_i and S_i per point; apply() then costs about one force evaluation.
class Tangent {
 public:
  /// Linearise at displacement u (parallel: on ws's threads when given, else on all of TBB's; allocates
  /// only the first time for a model size).
  void linearise(const Model& model, const Points& u, TangentMode mode, Workspace* ws = nullptr);
  /// out = K du, on ws's threads (uses ws.chunk_forces as scratch), no allocation.
  void apply(const Model& model, const Points& du, Workspace& ws, Points& out) const;
  /// The 3x3 diagonal blocks K_jj (column-major, 9 x n), for a block-Jacobi preconditioner (parallel as
  /// linearise; allocates only the first time for a model size; not for two threads at once). The
  /// hourglass part is the model's precomputed hg_diagonal, which also counts the pairs of passive points'
  /// stencils: with passive points those blocks are approximate (fine for a preconditioner).
  void diagonal_blocks(const Model& model, Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks,
                       Workspace* ws = nullptr) const;
  /// The moduli v_i dP_i/dG_i of every stencil i at the last linearise() (9 x 9 on column-major vec(dG),
  /// 81 doubles per point, column-major; the added terms included), for the assembled tangent
  /// (tangent_matrix.hpp). Parallel as linearise(); allocates only the first time for a model size.
  void moduli(const Model& model, std::vector<double>& out, Workspace* ws = nullptr) const;
  TangentMode mode() const { return mode_; }

 private:
  TangentMode mode_ = TangentMode::EXACT;
  /// the material's Linearisation per point (mechanics/energies/), as plain doubles: the tangent is one
  /// class whatever the material
  std::vector<double> linearisation_;
};

}  // namespace pointhaptics
