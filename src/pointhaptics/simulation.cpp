#include <pointhaptics/simulation.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/kd_tree.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>
#include <pointhaptics/solvers/reactions.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <future>
#include <limits>

namespace pointhaptics {

// A selection and its active model, ready to take over (built on a worker thread or in place).
struct LodBuild {
  Selection selection;
  ActiveSet active;
  Vec3 centre;
  double stable_dt = 0;
  double ms = 0;  // selection, active model and its stable step
};

LodBuild build_lod(const Model& full, const LodParams& params, const Vec3& centre, SolverKind solver) {
  const auto start = std::chrono::steady_clock::now();
  LodBuild b;
  std::mt19937_64 rng(params.seed);  // a fresh generator: every point keeps its draw across selections
  b.selection = select_points(full, centre, params, rng);
  b.active = build_active_set(full, b.selection, params);
  b.centre = centre;
  if (solver == SolverKind::EXPLICIT) b.stable_dt = stable_time_step(b.active.model, 0.8, 20);
  b.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return b;
}

// Levels of detail: the object, its state, and the active set simulated in its place.
struct Simulation::Lod {
  Model full;
  State full_state;
  std::unique_ptr<KdTree> tree;  // over full.X, for snapping contact points
  LodParams params;
  ActiveSet active;
  Selection selection;
  Vec3 centre = Vec3::Constant(NAN);   // of the selection: the object's point nearest the contact
  Vec3 contact = Vec3::Constant(NAN);  // the contact point the selection was made for
  bool full_state_current = true;
  long long selections = 0;
  double last_build_ms = 0, max_reselect_ms = 0;
  std::future<LodBuild> pending;  // an asynchronous re-selection in flight
  double last_selection_time = -std::numeric_limits<double>::infinity();  // of the last take-over, s

  Vec3 snap(const Vec3& c) const {
    index_t nearest = 0;
    double d2 = 0;
    tree->index().knnSearch(c.data(), 1, &nearest, &d2);
    return full.X.col(nearest);
  }
};

Simulation::Simulation(Model model, const SolverSpec& solver, int n_threads)
    : model_(std::move(model)), solver_(solver), state_(State::at_rest(model_)), ws_(model_, n_threads), n_threads_(n_threads) {
  prepare_solver();
  hold_points(model_, 0.0, state_.u);  // held points start at their prescribed displacement at t = 0
}

Simulation::~Simulation() {
  if (lod_ && lod_->pending.valid()) lod_->pending.wait();  // the worker reads lod_->full
}
Simulation::Simulation(Simulation&&) noexcept = default;

void Simulation::prepare_solver(double stable_dt) {
  stable_dt_ = stable_dt > 0 ? stable_dt : stable_time_step(model_);  // reported for every kind; explicit steps below it
  solver_impl_ = make_solver(model_, solver_, stable_dt_);
}

void Simulation::enable_lod(const LodParams& params, const Vec3& contact) {
  validate(params);
  if (!contact.allFinite()) throw Error("lod: the contact point is not finite");
  if (lod_) throw Error("lod: levels of detail are already on");
  auto lod = std::make_unique<Lod>();
  lod->params = params;
  lod->full = std::move(model_);
  lod->full_state = state_;
  lod->tree = std::make_unique<KdTree>(lod->full.X);
  lod_ = std::move(lod);
  lod_->contact = contact;
  take_over(build_lod(lod_->full, params, lod_->snap(contact), solver_.kind), true);
}

void Simulation::set_state(const State& state) {
  if (state.u.cols() != model_.n_points || state.velocity.cols() != model_.n_points)
    throw Error("simulation: the state is for another model");
  state_ = state;
  if (lod_) lod_->full_state_current = false;
}

const Model& Simulation::full_model() const { return lod_ ? lod_->full : model_; }
const ActiveSet* Simulation::active_set() const { return lod_ ? &lod_->active : nullptr; }

const Selection* Simulation::lod_selection() const { return lod_ ? &lod_->selection : nullptr; }

long long Simulation::lod_selections() const { return lod_ ? lod_->selections : 0; }

const State& Simulation::full_state() {
  if (!lod_) return state_;
  if (!lod_->full_state_current) {
    lod_->active.prolong_state(state_, lod_->full_state);
    lod_->full_state_current = true;
  }
  return lod_->full_state;
}

Vec3 Simulation::lod_contact_of_probe(const Vec3& probe, const std::vector<index_t>& grabbed,
                                      const std::vector<index_t>& touched) const {
  // grabbing: where the grabbed points are in the object, however far they were dragged
  if (!grabbed.empty()) {
    Vec3 sum = Vec3::Zero();
    for (index_t i : grabbed) sum += model_.X.col(i);
    return sum / static_cast<double>(grabbed.size());
  }
  // pushing: the probe carried back by the mean displacement of the touched points, so that pressing in
  // does not move the contact point (the touched material stays where it is in the object). The mean of
  // many points moves smoothly as the probe slides, unlike the nearest point
  if (!touched.empty()) {
    Vec3 sum = Vec3::Zero();
    for (index_t i : touched) sum += state_.u.col(i);
    return probe - sum / static_cast<double>(touched.size());
  }
  return probe;
}

std::vector<index_t> Simulation::update_lod(const Vec3& contact, bool onset, bool asynchronous) {
  if (!lod_) throw Error("lod: levels of detail are off");
  Lod& l = *lod_;
  if (l.pending.valid()) {
    // a re-selection in flight: take it over once it is built (waiting for it unless asynchronous)
    if (asynchronous && l.pending.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return {};
    return take_over(l.pending.get(), false);
  }
  if (!contact.allFinite()) return {};
  // the distance is the contact point's own, not its snapped point's: a probe that trembles between two
  // points of the lattice must not re-select at every step
  const double moved = (contact - l.contact).norm();
  if (onset ? moved < 0.25 * l.params.reselect * l.full.h : moved <= l.params.reselect * l.full.h) return {};
  if (!onset && state_.time - l.last_selection_time < l.params.reselect_interval) return {};
  l.contact = contact;
  if (!asynchronous) return take_over(build_lod(l.full, l.params, l.snap(contact), solver_.kind), true);
  // the worker only reads the object's model, which nothing writes while levels of detail are on
  l.pending = std::async(std::launch::async, build_lod, std::cref(l.full), l.params, l.snap(contact), solver_.kind);
  return {};
}

namespace {

// A re-selection must not add energy. The new active set sees the same displacement field through other
// points, volumes and stencils, and measured on a probe sliding over the half-sphere its strain energy came
// out 30-100% above the old set's, its kinetic energy about 10% (mass moves between points, absorbed points
// follow by extrapolation). Re-selecting every few tens of milliseconds, as a slow real-time session does,
// pumped the object up until it diverged (issue 21). What the new state holds beyond the old one is taken
// out of its kinetic energy (down to rest, at most): the take-over is passive.
void remove_added_energy(const Model& model, double energy_before, State& state) {
  const double kinetic = kinetic_energy(model, state.velocity);
  const double added = strain_energy(model, state.u).total() + kinetic - energy_before;
  if (!(added > 0) || !(kinetic > 0)) return;
  state.velocity *= std::sqrt(std::max(0.0, kinetic - added) / kinetic);
}

}  // namespace

std::vector<index_t> Simulation::take_over(LodBuild build, bool built_here) {
  Lod& l = *lod_;
  const auto start = std::chrono::steady_clock::now();
  const State& carried = full_state();  // the active state so far, back on the object
  ActiveSet& active = build.active;
  std::vector<index_t> new_index(model_.n_points, -1);
  if (l.selections > 0)
    for (index_t k = 0; k < l.active.n_selected; ++k) {
      const index_t now = active.active_of[l.active.full_of[k]];
      new_index[k] = now < active.n_selected ? now : -1;
    }
  const double time = carried.time;
  const double energy_before =
      l.selections > 0 ? strain_energy(model_, state_.u).total() + kinetic_energy(model_, state_.velocity) : 0.0;
  state_ = active.restrict_state(carried);
  state_.time = time;
  if (l.selections > 0) remove_added_energy(active.model, energy_before, state_);
  l.active = std::move(active);
  l.selection = std::move(build.selection);
  l.centre = build.centre;
  model_ = l.active.model;
  ws_ = Workspace(model_, n_threads_);
  prepare_solver(build.stable_dt);
  if (probe_) probe_->remap(model_, new_index);  // grabbed points follow their new numbers
  l.full_state_current = false;
  const bool first = l.selections == 0;  // made by enable_lod(), before any step: set-up, not a stall
  if (!first) l.last_selection_time = time;
  ++l.selections;
  const double stall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  l.last_build_ms = build.ms - l.selection.milliseconds;
  // the time this thread was held: the swap, and the build too when it was made here
  if (!first) l.max_reselect_ms = std::max(l.max_reselect_ms, stall + (built_here ? build.ms : 0.0));
  return new_index;
}

void Simulation::attach_probe(const ProbeParams& params, double coupling_stiffness, double max_force, bool asynchronous_lod) {
  if (solver_.kind == SolverKind::STATIC) throw Error("probe: needs a dynamic solver (explicit or implicit)");
  probe_.emplace(model_, params, coupling_stiffness, max_force);
  asynchronous_lod_ = asynchronous_lod;
  inputs_ = StepInputs{};
}

void Simulation::detach_probe() {
  probe_.reset();
  inputs_ = StepInputs{};
}

// ---- the step pipeline: each stage is one function below, in the order step() calls them ----------------

const StepReport& Simulation::step() {
  if (diagnostics_.failed)
    throw Error(fmt::format("simulation: no step after a failed one (t = {:.6g} s: {})", state_.time, diagnostics_.failure));
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  // 1. the inputs (inputs_) were filled by the caller; 2. the active set follows the last step's contact
  follow_contact();
  const auto selected = clock::now();
  // 3. the tools take their place for this step
  place_tools();
  const auto placed = clock::now();
  // 4. the solver: internal, external and tool forces, time integration or equilibrium, held points
  report_ = solver_impl_->step(model_, state_, ws_, probe_ ? &*probe_ : nullptr);
  const auto solved = clock::now();
  // 5. a state that is not finite is not a result, whatever the solver said
  check_finite(report_);
  // 6. the outputs: diagnostics, and the object's state is stale until asked for
  const auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  diagnostics_.active_set_seconds += seconds(start, selected);
  diagnostics_.tools_seconds += seconds(selected, placed);
  diagnostics_.solve_seconds += seconds(placed, solved);
  record(report_, seconds(start, clock::now()));
  if (lod_) lod_->full_state_current = false;
  return report_;
}

void Simulation::follow_contact() {
  // levels of detail follow the probe's contact point: at contact onset and when it moved far enough (as
  // the last step left it; the haptic side keeps rendering the local model published meanwhile)
  if (!lod_ || !probe_ || diagnostics_.steps == 0) return;
  const ProbeTool& p = *probe_;
  const bool onset = p.contacts_before_step() == 0 && p.contact_model().contacts > 0;
  update_lod(lod_contact_of_probe(p.probe(), p.contact().grabbed(), p.contact().touched()), onset, asynchronous_lod_);
}

void Simulation::place_tools() {
  if (probe_) probe_->place(model_, state_, inputs_.device, inputs_.button);
}

void Simulation::check_finite(StepReport& report) const {
  if (report.status == StepStatus::FAILED || state_.u.allFinite()) return;
  report.status = StepStatus::FAILED;
  report.failure = fmt::format("the state is not finite at t = {:.6g} s", state_.time);
}

void Simulation::record(const StepReport& report, double seconds) {
  StepDiagnostics& d = diagnostics_;
  ++d.steps;
  d.substeps += report.substeps;
  d.iterations += report.iterations;
  d.cg_iterations += report.cg_iterations;
  if (solver_.kind != SolverKind::EXPLICIT) d.residual = report.residual;
  if (report.status == StepStatus::AT_BUDGET) ++d.budget_steps;
  d.status = report.status;
  if (report.status == StepStatus::FAILED) {
    d.failed = true;
    d.failure = report.failure;
  }
  d.step_seconds += seconds;
}

void Simulation::run(double duration, const std::function<bool(long long, long long)>& after_step) {
  const long long n_steps =
      solver_.kind == SolverKind::STATIC ? 1 : std::max<long long>(0, std::llround(std::ceil(duration / solver_.dt - 1e-9)));
  for (long long k = 1; k <= n_steps; ++k) {
    if (step().status == StepStatus::FAILED) return;
    if (after_step && !after_step(k, n_steps)) return;
  }
}

RunSummary Simulation::summary() {
  RunSummary s;
  s.solver_kind = std::string(to_string(solver_.kind));
  const StepDiagnostics& d = diagnostics_;
  s.converged = state_.u.allFinite() && !d.failed;
  s.failure = d.failure;
  s.steps = d.steps;
  s.substeps = d.substeps;
  s.iterations = d.iterations;
  s.cg_iterations = d.cg_iterations;
  s.budget_steps = d.budget_steps;
  s.stable_dt = stable_dt_;
  compute_internal_forces(model_, state_.u, ws_);
  s.reactions = support_reactions(model_, ws_.f_int);
  // dynamics is out of balance by the inertia; its Newton residual includes it
  s.residual = solver_.kind == SolverKind::IMPLICIT ? d.residual : relative_residual(model_, ws_.f_int);
  s.strain_energy = strain_energy(model_, state_.u).total();
  s.kinetic_energy = kinetic_energy(model_, state_.velocity);
  s.wall_s = d.step_seconds;
  s.step_ms_mean = d.steps > 0 ? 1e3 * d.step_seconds / static_cast<double>(d.steps) : 0;
  s.steps_per_s = d.step_seconds > 0 ? static_cast<double>(d.steps) / d.step_seconds : 0;
  if (lod_) {
    const Lod& l = *lod_;
    LodSummary& o = s.lod;
    o.enabled = true;
    o.selected = l.active.n_selected;
    o.frozen = l.active.model.n_points - l.active.n_selected;
    o.widened = l.active.widened;
    o.band_count = l.selection.band_count;
    o.band_selected = l.selection.band_selected;
    o.active.assign(l.full.n_points, 0);
    for (index_t k = 0; k < l.active.n_selected; ++k) o.active[l.active.full_of[k]] = 1;
    o.selections = l.selections;
    o.selection_ms = l.selection.milliseconds;
    o.build_ms = l.last_build_ms;
    o.max_reselect_ms = l.max_reselect_ms;
  }
  return s;
}

}  // namespace pointhaptics
