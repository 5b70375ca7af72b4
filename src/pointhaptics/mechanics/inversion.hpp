#pragma once
/// @file Inverted neighbourhoods: where the deformation gradient's determinant is not positive, the point's
/// material has turned inside out (or flattened) and the state is not a physical result, whatever a solver's
/// residual says (issue 17: St. Venant-Kirchhoff "converged" on a collapsed block).
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/core/workspace.hpp>

namespace pointhaptics {

/// The stencils i < model.stencil_end() with det(I + G_i) <= 0, for the gradients of the last force
/// evaluation (ws.gradients: compute_internal_forces fills them), on ws's threads, without allocation.
index_t count_inverted(const Model& model, Workspace& ws);

/// The same for the gradients of displacement `u`, computed here (a stencil pass, without storing them): for a
/// solver that evaluates no forces point by point (a reduced model's polynomial).
index_t count_inverted(const Model& model, const Points& u, Workspace& ws);

}  // namespace pointhaptics
