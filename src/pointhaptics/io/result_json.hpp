#pragma once
/// @file The result JSON of `pointhaptics run --json` (design.md's contract).
#include <pointhaptics/core/state.hpp>

#include <string>
#include <vector>

namespace pointhaptics {

/// Levels of detail in a run (all zero and empty without).
struct LodSummary {
  bool enabled = false;
  index_t selected = 0;                ///< points simulated at the end
  index_t frozen = 0;                  ///< points held around them (the frozen ring)
  index_t widened = 0;                 ///< selected points with a widened support
  std::vector<index_t> band_count;     ///< points per band (T_r1, T_r2, levels), selected or not
  std::vector<index_t> band_selected;  ///< selected points per band
  std::vector<char> active;            ///< per point of the object: simulated at the end
  long long selections = 0;            ///< selections made (the first and the re-selections)
  double selection_ms = 0;             ///< the last selection, ms
  double build_ms = 0;                 ///< the last active model's build (neighbours, M_i, stable step), ms
  double max_reselect_ms = 0;          ///< the longest a re-selection held the simulation thread, ms (the whole
                                       ///< build when made in place, the take-over when built on a worker)
};

/// Cuts in a run (issue 18): absent without.
struct CutSummary {
  bool present = false;
  long long sweeps = 0;               ///< cut updates: the steps a blade cut in (a step's strips are one)
  long long cut_pairs = 0;            ///< neighbour pairs severed in all
  double max_update_ms = 0;           ///< the longest update (refits, stable step, solver), ms
  double mean_update_ms = 0;          ///< the updates' mean, ms
  std::vector<index_t> piece_points;  ///< points per connected piece, in the order of their lowest point
  long long sheet_triangles = 0;      ///< the cuts' sheets (reference configuration) the surface splits along
  long long surface_splits = 0;  ///< a probe's or the bodies' contact surface split along them (once per stroke or cut)
  double max_split_ms = 0;       ///< the longest split, ms (on a worker in real time)
};

/// What a run reports besides the points: solver outcome, energies, timing, support reactions.
/// A run's tool (issue 16): what the object does to it at the end.
struct ToolSummary {
  bool present = false;
  std::string kind;              ///< "sphere" or "capsule"
  Vec3 position = Vec3::Zero();  ///< m, scene axes
  Vec3 force = Vec3::Zero();     ///< N, the force the object exerts on the tool
  Vec3 torque = Vec3::Zero();    ///< N m, about its position
  int contacts = 0;              ///< surface vertices (probe on points: points) pressing on it
  double penetration = 0;        ///< deepest surface vertex inside the tool, m (held tools)
  Vec3 friction = Vec3::Zero();  ///< N, the part of `force` friction makes (held tools with friction)
  /// A device-driven tool (a hand): its own haptic loop's ticks, p99 period error (us) and largest force (N)
  /// (the first hand's are also the top-level `haptic` block); 0 ticks: not driven by a device
  long long haptic_ticks = 0;
  double haptic_period_p99_us = 0, haptic_max_force_n = 0;
};

/// How far the haptic side's local model F(p) = f0 + K (p - p0) strays from the next update's force f0' at
/// its p0' (issue 16, item 4): |f0 + K (p0' - p0) - f0'| over the updates made in contact, N, for the K
/// rendered, for none (the force held between updates) and for the held object's (the contact's own stiffness).
struct LocalModelSummary {
  long long updates = 0;    ///< updates compared (both in contact)
  double force_mean_n = 0;  ///< mean |f0'|, N
  double rendered_mean_n = 0, rendered_max_n = 0;
  double hold_mean_n = 0, hold_max_n = 0;
  double held_object_mean_n = 0, held_object_max_n = 0;
};

/// One of several bodies (issue 47): the `bodies` block of the result, keyed by its name.
struct BodySummary {
  std::string name;
  long long points = 0;
  double mass = 0;                        ///< kg
  Vec3 mean_displacement = Vec3::Zero();  ///< of its centre of mass, m
  double max_displacement = 0;            ///< m
  Vec3 contact_force = Vec3::Zero();      ///< what the other bodies exert on it, N
  std::vector<int> constraints;           ///< its [[fixed]] groups (indices into `constraints`)
  bool asleep = false;                    ///< at the end (explicit steps: a body at rest that nothing touches)
  long long slept_steps = 0;              ///< the steps it slept
};
/// The contact between the bodies, and between the pieces cuts made of one (the JSON's `body_contact`, with several
/// bodies or once a cut has parted one).
struct BodyContactSummary {
  bool present = false;
  long long pairs = 0, contacts = 0;
  double penetration = 0;  ///< m
};

/// A reduced model's set-up (`[reduction]`, docs/reduction.md): its basis and polynomial, and where the time went.
struct ReductionSummary {
  int modes = 0;  ///< r (0: no reduction)
  int linear_modes = 0, derivatives = 0, load_vectors = 0;
  double basis_spacing = 0;  ///< m (0: the basis made on the points)
  double setup_s = 0, factorise_s = 0, modes_s = 0, derivatives_s = 0, polynomial_s = 0;
  double factor_bytes = 0, tables_bytes = 0;
  double first_frequency_hz = 0;  ///< the reduced model's lowest natural frequency about rest
  std::string cache_file;         ///< where the basis was read from or kept (empty: not kept)
  bool from_cache = false;  ///< the basis was read from cache_file (the set-up's factor, modes and derivatives skipped)
  std::string cache_note;   ///< what went wrong with the cache file, when something did
  /// a tool's contact region in full resolution (reduction/contact_patch.hpp): the most points it had free, the
  /// times it was chosen anew, and the Hessians made for it (each a Cholesky factor of its tangent)
  long long contact_points = 0, contact_patches = 0, contact_hessians = 0;
};

struct RunSummary {
  std::string solver_kind;
  bool converged = false;
  long long iterations = 0;  ///< Newton iterations (static, implicit) or force evaluations (explicit)
  double residual = 0;       ///< relative out-of-balance force of the free points at the end
  long long steps = 0;       ///< solver steps of dt
  double strain_energy = 0, kinetic_energy = 0;  ///< J
  double wall_s = 0, step_ms_mean = 0, steps_per_s = 0;
  double step_ms_max = 0;  ///< the longest step, ms
  /// wall time in the step pipeline's stages, s: following the contact (levels of detail), placing the
  /// tools, the solver
  double active_set_s = 0, tools_s = 0, solve_s = 0;
  double contact_s = 0;                     ///< the part of solve_s the contacts took (tools, obstacles, bodies)
  double stable_dt = 0;                     ///< explicit: the stable sub-step, s
  long long substeps = 0;                   ///< explicit: sub-steps taken in all; static: load increments
  long long cg_iterations = 0;              ///< static, implicit: conjugate-gradient iterations in all
  std::string preconditioner;               ///< static, implicit: "block_jacobi", "cholesky" or "two_level"
  long long factorisations = 0;             ///< cholesky: numeric factorisations of the tangent
  long long background_factorisations = 0;  ///< ... of them, made on a worker thread
  double factor_bytes = 0;      ///< cholesky: the largest factor's size (with the worker's copy when it refactorised
                                ///< in the background), bytes; two_level: the coarse factor's
  long long coarse_points = 0;  ///< two_level: the coarse level's points
  long long budget_steps = 0;   ///< implicit with an iteration budget: steps it ended above the tolerance
  std::string failure;          ///< static: why it did not converge (empty when it did)
  bool interrupted = false;     ///< the run was stopped (SIGINT, SIGTERM) before its end: the state reached
  std::vector<Vec3> reactions;  ///< per fixed group, N
  /// not a physical result, whatever the residual: neighbourhoods inverted (det F <= 0) at the end, and held
  /// groups whose support force opposes their prescribed motion (the body pulls a plate that pushes it: a
  /// collapse); either makes `converged` false. Steps that ended with inverted neighbourhoods are counted
  /// (a warning: a dynamic run can recover from them)
  long long inverted = 0, inverted_steps = 0;
  std::vector<std::string> collapsed;  ///< the groups' names
  // haptic loop (runs with a probe)
  long long haptic_ticks = 0;
  double haptic_rate_hz = 0, haptic_period_p99_us = 0, haptic_max_force_n = 0;
  /// the passivity observer's minimum and what the passivity controller dissipated, J, and on how many ticks
  double haptic_min_observed_energy = 0, haptic_passivity_dissipated = 0;
  long long haptic_passivity_ticks = 0;
  LocalModelSummary local_model;
  LodSummary lod;
  ReductionSummary reduction;
  ToolSummary tool;
  /// The obstacles by name: what the object does to each (`kind` its shape, `position` its pose's origin).
  std::vector<std::pair<std::string, ToolSummary>> obstacles;
  /// The posed tools ([[tool]] with a position or keyframes) by name, as `tool`. The JSON's `tools` has them and
  /// the probe or held tool (`tool`) under tool_name.
  std::vector<std::pair<std::string, ToolSummary>> tools;
  std::string tool_name = "probe";
  /// With several bodies, each one's block, in the model's order (empty with one body).
  std::vector<BodySummary> bodies;
  BodyContactSummary body_contact;
  CutSummary cut;
};

/// The result document as a string (indented JSON).
std::string result_json(const Model& model, const State& state, const RunSummary& summary);

/// Write result_json() to `path`; throws Error naming the path when it cannot be written.
void write_result_json(const std::string& path, const Model& model, const State& state, const RunSummary& summary);

}  // namespace pointhaptics
