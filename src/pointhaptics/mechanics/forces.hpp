#pragma once
/// @file Internal elastic forces: the exact negative gradient of strain_energy().
#include <pointhaptics/core/workspace.hpp>

namespace pointhaptics {

/// Internal forces f = -dW/du into ws.f_int (3 x n), with W the material's, the volume term's and the
/// hourglass penalty's energy (mechanics/energies/, which has each one's formulas). For each stencil i, with
/// P_i the first Piola stress of the point's energy and the hourglass terms of energies/hourglass.hpp
/// (k_ij r_ij per pair, Q_i = sum_j k_ij r_ij X_ij^T):
///   f_j -= (v_i P_i - Q_i) d_ij + k_ij r_ij,   f_i -= (v_i P_i - Q_i) d_ii - sum_j k_ij r_ij.
/// \note The seed's Eq. 14 carries a factor 2 (f = -2 v J sigma d) that belongs to Mueller's strain without
///       the 1/2; with the Green strain of Eq. 2 the exact gradient has none (physics.md).
/// Runs on ws's threads, one contiguous chunk of stencils each, scattering into per-chunk buffers; no allocation.
void compute_internal_forces(const Model& model, const Points& u, Workspace& ws);

}  // namespace pointhaptics
