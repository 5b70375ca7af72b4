#pragma once
/// @file The tangent K assembled as a sparse matrix of 3x3 blocks, for a factorised preconditioner
/// (solvers/sparse_cholesky.hpp). Point j's force depends on every point of every stencil that contains j,
/// so row j has a block for each point k sharing a stencil with j (the neighbours' neighbours).
#include <pointhaptics/mechanics/tangent.hpp>

#include <vector>

namespace pointhaptics {

struct TangentMatrix {
  /// row j: the points k with a block K_jk (sharing a stencil with j), sorted, j itself included
  Csr pattern;
  std::vector<index_t> diagonal;            ///< the entry of the block K_jj in row j  (n)
  std::vector<double> values;               ///< K_jk per entry, 9 doubles, column-major 3x3, N/m
  std::vector<std::vector<index_t>> slots;  ///< assembly scratch: a row's entry per point, per thread (-1: none)
  std::vector<double> moduli;               ///< assembly scratch: the stencils' moduli (Tangent::moduli)
  index_t model_pairs = -1;                 ///< the neighbour pairs of the model the pattern was built for
  index_t n_blocks() const { return pattern.n_entries(); }
};

/// The block pattern of the model's tangent (once per model; the values are assemble_tangent()'s).
void build_tangent_pattern(const Model& model, TangentMatrix& K);

/// K's values from the tangent as last linearised, through the stencils' moduli C_i = v_i dP_i/dG_i
/// (Tangent::moduli()); builds the pattern first when K has none for a model of this size (points and pairs):
/// K_jk = sum_i (d_ij (x) I)^T C_i (d_ik (x) I) over the stencils i that contain j and k (d_ii = d_self),
/// the matrix of what Tangent::apply() computes without assembling. The hourglass energy, whose exact tangent
/// couples points three stencils apart, enters as an upper bound that stays in this pattern (tangent_matrix.cpp,
/// add_hourglass_bound): a preconditioner needs to be close, not exact. On ws's threads when given (no allocation after the first call for a model size).
void assemble_tangent(const Model& model, const Tangent& tangent, TangentMatrix& K, Workspace* ws = nullptr);

/// K_jk += a S and K_kj += a S (S symmetric, 3x3; j == k: once), the coupling of a term whose tangent is
/// w w^T (x) S over a few points (a contact vertex carried by its points). A pair outside K's pattern is lumped
/// onto the two diagonal blocks as |a| S each: with S positive semi-definite the result stays at or above the
/// exact sum, so a preconditioner made from it stays positive definite.
void add_coupling(TangentMatrix& K, index_t j, index_t k, double a, const Mat3& S);

/// y = K x over all points (checks and tests: the solvers use K through its factor).
void multiply(const TangentMatrix& K, const Points& x, Points& y);

}  // namespace pointhaptics
