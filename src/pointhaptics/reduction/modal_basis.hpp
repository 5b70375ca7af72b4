#pragma once
/// @file The reduced model's basis (issue 49, `[reduction] basis = "modal"`): the object's lowest vibration modes
/// about rest, their modal derivatives (Barbic & James 2005, "Real-time subspace integration for St.
/// Venant-Kirchhoff deformable models"), and the static responses to the scene's dead loads, made mass-orthonormal
/// and truncated to r vectors by mass-weighted principal components. Every vector is zero at the held points, so
/// the reduced model honours them exactly whatever its coordinates.
#include <pointhaptics/core/workspace.hpp>

#include <vector>

namespace pointhaptics {

struct ModalBasisSettings {
  int size = 20;  ///< r, the basis vectors kept
  /// m, the linear modes whose derivatives are taken; 0: the fewest with m + m (m + 1) / 2 >= 1.3 r
  int linear_modes = 0;
  /// dead loads (gravity, tractions: 3 x n forces, N) whose static responses K^-1 f join the basis: the reduced
  /// model then holds the small-load static answer exactly
  std::vector<Points> loads;
};

struct ModalBasis {
  /// 3n x r, column k the k-th basis vector in Points' layout (x0, y0, z0, x1, ...): mass-orthonormal
  /// (U^T M U = I with the lumped masses), zero at held points
  Eigen::MatrixXd U;
  Eigen::VectorXd eigenvalues;  ///< the linear modes' omega^2 about rest, (rad/s)^2, ascending
  int linear_modes = 0, derivatives = 0, load_vectors = 0;
  double factorise_s = 0, modes_s = 0, derivatives_s = 0, total_s = 0;  ///< where the set-up went, s
  double factor_bytes = 0;                                              ///< the rest tangent's Cholesky factor
};

/// Builds the basis of `model` about rest. The rest tangent is assembled and factorised once (CHOLMOD; its
/// hourglass part is the assembled bound, close to the exact one: a basis needs to span well, not to be exact);
/// the modes come from a shift-invert Lanczos solve at zero (Spectra), each derivative from one solve with the
/// same factor, K Psi_ij = -d^2 f / du^2 [phi_i, phi_j], the directional derivative taken by central differences
/// of the exact tangent (exact for St. Venant-Kirchhoff, whose tangent is quadratic in u). Throws Error when the
/// model has fewer free degrees of freedom than r + 2, nothing held (the rest tangent is singular), or the
/// eigen-solver does not converge; Interrupted on a stop request.
/// (A change to how the basis is made must change basis_cache.cpp's magic: files kept by older code are then not read.)
ModalBasis build_modal_basis(const Model& model, const ModalBasisSettings& settings, Workspace& ws);

/// A coarser sampling of `model`'s object for its basis (`[reduction] basis_spacing`): the points binned in boxes of
/// about `spacing` (a whole number across the points' extent on each axis) centred on a lattice from their lowest
/// corner, one point per cube (the one nearest its
/// centre, so a lattice sampled at a divisor of `spacing` keeps a sub-lattice), standing for the cube's volume, held
/// if it is held in `model`, carrying the cube's constant loads; the material and kernel are `model`'s (the
/// kernel's support scaled with the spacing). Throws Error when `spacing` is not coarser than the model's.
Model coarse_model(const Model& model, double spacing);

/// A basis made on `coarse`, a coarser sampling of the same object held alike (`[reduction] basis_spacing`), carried
/// to `model`'s points by the moving least squares interpolant of `coarse`'s points (mechanics/surface_map.hpp),
/// zeroed at `model`'s held points and made mass-orthonormal with `model`'s masses. The modes and derivatives
/// then cost a factor of the coarse tangent (tens of times smaller): the basis is a little less than optimal,
/// but the reduced model stays the exact projection of `model`'s energy on it. Throws Error when a point of
/// `model` lies beyond `coarse`'s points or the carried vectors are not independent.
ModalBasis carry_basis(const ModalBasis& basis, const Model& coarse, const Model& model);

/// u = U q, the displacement of reduced coordinates q (3 x n).
Points displacement_of(const Eigen::MatrixXd& U, const Eigen::VectorXd& q, index_t n_points);

}  // namespace pointhaptics
