#pragma once
/// @file The active set of levels of detail: the selected points as a computational model of their own,
/// and the maps between its state and the full object's.
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/lod/selection.hpp>
#include <pointhaptics/mechanics/cut.hpp>

#include <vector>

namespace pointhaptics {

/// The model over the selected points (design.md's reading of seed §3):
/// - each unselected point inside the selection bands gives its volume, mass and external load to its
///   nearest selected point (so the active set keeps the region's mass and load), and follows the nearest
///   few: u_j = sum_i w_ji (u_i + G_i (X_j - X_i)), first-order MLS from each, blended by weights that fall to
///   zero at the last of them (so that neighbouring followers move together);
/// - unselected points beyond the last band that a selected point's support reaches, and their own
///   neighbours, form a frozen ring, held at their current displacement (or their prescribed one), so the
///   active set is supported by the rest of the object as it is, not left floating; held points that the
///   seed selects beyond the bands join that ring where it reaches them; the rest is not simulated;
/// - a selected point whose neighbourhood became sparse gets a wider support (per-point h_i, up to
///   max_widening h), symmetric neighbourhoods by max(h_i, h_j); the dense core keeps h.
struct ActiveSet {
  Model model;                          ///< active points first (selected), then the frozen ring
  index_t n_selected = 0;               ///< simulated points: the selected ones inside the bands
  std::vector<index_t> full_of;         ///< active index -> full index
  std::vector<index_t> active_of;       ///< full index -> active index, or -1
  Csr followed;                         ///< full index -> the selected points an absorbed point follows (empty: none)
  std::vector<double> followed_weight;  ///< per entry of followed: its weight (a row sums to 1)
  std::vector<Vec3> followed_offset;    ///< per entry of followed: X_j - X_followed
  index_t widened = 0;                  ///< selected points whose support was widened
  Vec3 centre = Vec3::Zero();           ///< the selection's contact point (reference configuration, m)
  double core_radius = 0;               ///< the selection's T_r2, m
  double build_ms = 0;

  /// The active state from the full one (selected and frozen points copy theirs).
  State restrict_state(const State& full) const;
  /// Write the active state back: active points (selected and ring) copy, absorbed points follow by
  /// blended first-order MLS, unsimulated points keep their displacement and are at rest (zero velocity). No allocation after the first call; not for two
  /// threads at once (it keeps the selected points' gradients in a buffer).
  void prolong_state(const State& active, State& full) const;

 private:
  mutable std::vector<Mat3> gradient_cache_;
};

/// Throws Error if nothing is selected.
ActiveSet build_active_set(const Model& full, const Selection& selection, const LodParams& params = {});

/// The object's cuts in an active set built from it: its pairs severed where the object's same pair is, and
/// where their segment crosses one of the cuts' `sheets` (reference configuration): a pair the object does not
/// have (a widened support's) or one between points the object's cut left apart but that were not both
/// simulated when it was cut. Returns what it severed (mechanics/cut.hpp).
CutReport cut_as_object(ActiveSet& active, const Model& full, std::span<const std::array<Vec3, 3>> sheets,
                        bool keep_hourglass_diagonal = true);

}  // namespace pointhaptics
