#pragma once
/// @file One point's stencil: its pairs' kernel weights, its moment matrix M_i (seed Eq. 11) with the
/// conditioning check, and its d_ij, d_ii (Eq. 10). The model build fits every stencil with it; a cut refits
/// only the stencils that lost pairs (mechanics/cut.hpp).
#include <pointhaptics/core/model.hpp>

namespace pointhaptics {

/// Condition number of M_i above which the neighbourhood is regularised (M + eps tr(M) I).
inline constexpr double max_moment_condition = 1e6;

/// The kernel weight w_ij of pair e = (i, j) at the reference distance, with i's own support when the points'
/// supports differ; zero for a pair a cut severed (the pair stays in the lists, so every sparsity pattern
/// built on them stays valid, but it carries nothing).
double pair_weight(const Model& model, index_t i, index_t e);

/// What fitting one stencil found.
struct StencilFit {
  double condition = 0;      ///< cond(M_i) before regularisation (infinite when singular or empty)
  double weight_sum = 0;     ///< sum_j w_ij
  bool regularised = false;  ///< M_i was regularised, or the stencil is empty (then G_i = 0)
};

/// Stencil i's moment matrix M_i (seed Eq. 11) from its pairs' weights `w_row` (row i's, in order) and what it
/// says: condition, weight sum, and whether fit_stencil() regularises it. Writes nothing.
StencilFit assess_stencil(const Model& model, index_t i, const double* w_row, Mat3* moment = nullptr);

/// Fit stencil i from its pairs' weights `w_row` (row i's, in order): M_i (seed Eq. 11), regularised to cond
/// near 1e3 above max_moment_condition, then model.d (Eq. 10) for its pairs and model.d_self. Writes only
/// row i's entries, so stencils can be fitted in parallel.
StencilFit fit_stencil(Model& model, index_t i, const double* w_row);

}  // namespace pointhaptics
