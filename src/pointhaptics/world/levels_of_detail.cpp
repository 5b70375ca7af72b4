#include <pointhaptics/world/levels_of_detail.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <span>

namespace pointhaptics {
namespace {

// `sheets`: the cuts' so far (a copy: a worker builds while the simulation cuts on); object_cuts: the count of
// the object's cuts they stand for
LodBuild build_lod(const Model& full, const LodParams& params, const Vec3& centre, SolverKind solver,
                   std::vector<std::array<Vec3, 3>> sheets, long long object_cuts) {
  const auto start = std::chrono::steady_clock::now();
  LodBuild b;
  std::mt19937_64 rng(params.seed);  // a fresh generator: every point keeps its draw across selections
  b.selection = select_points(full, centre, params, rng);
  b.active = build_active_set(full, b.selection, params);
  cut_as_object(b.active, full, sheets,
                solver != SolverKind::EXPLICIT);  // before its stable step: a cut stencil can be stiffer
  b.object_cuts = object_cuts;
  b.centre = centre;
  if (solver == SolverKind::EXPLICIT) b.stable_dt = stable_time_step(b.active.model, 0.8, 20);
  b.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return b;
}

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

LevelsOfDetail::LevelsOfDetail(ModelSimulation&& object, const LodParams& params, const Vec3& contact)
    : solver_(object.solver()), n_threads_(object.n_threads()), params_(params), contact_(contact) {
  validate(params);
  if (!contact.allFinite()) throw Error("lod: the contact point is not finite");
  full_state_ = object.state();
  full_ = object.take_model();
  tree_ = std::make_unique<KdTree>(full_.X);
  // the object's simulation, its model taken, hands its diagnostics, inputs and probe to the first active
  // set like any re-selection; built here, before any step (set-up, not a stall)
  active_ = std::make_unique<ModelSimulation>(std::move(object));
  // the object's own cuts so far are in its model (and its sheets): the active sets are built with them
  sheets_carried_ = active_->cut_sheets().triangles.size();
  sheet_revision_carried_ = active_->cut_sheets().revision;
  take_over(build_lod(full_, params_, snap(contact), solver_.kind, active_->cut_sheets().triangles, object_cuts_made_),
            true);
}

void LevelsOfDetail::carry_cuts() {
  ModelSimulation& sim = *active_;
  // the pairs the active model lost, where the object has them
  const Csr& object = full_.neighbours;
  for (const auto& [k, l] : sim.severed()) {
    const index_t i = active_set_.full_of[k], j = active_set_.full_of[l];
    for (index_t e = object.begin(i); e < object.end(i); ++e)
      if (object.index[e] == j) {
        object_cuts_.push_back(e);
        break;
      }
  }
  sim.clear_severed();
  // the object's pairs across the new sheets: those between points that are not both simulated too (the
  // last strip's two triangles again, as a straight cut extends them)
  const CutSheets& sheets = sim.cut_sheets();
  if (sheets.revision != sheet_revision_carried_) {
    const std::size_t from = std::min(sheets_carried_ >= 2 ? sheets_carried_ - 2 : 0, sheets.triangles.size());
    const std::vector<index_t> crossing =
        pairs_crossing_triangles(full_, full_.X, std::span(sheets.triangles).subspan(from));
    object_cuts_.insert(object_cuts_.end(), crossing.begin(), crossing.end());
    sheets_carried_ = sheets.triangles.size();
    sheet_revision_carried_ = sheets.revision;
  }
  // a re-selection in flight reads the object's model: the cut waits for it (take_over())
  if (!pending_.valid()) apply_object_cuts();
}

void LevelsOfDetail::apply_object_cuts() {
  if (object_cuts_.empty()) return;
  if (sever_pairs(full_, object_cuts_, solver_.kind != SolverKind::EXPLICIT).severed_pairs > 0) ++object_cuts_made_;
  object_cuts_.clear();
}

const Model& LevelsOfDetail::settled_object_model() {
  if (pending_.valid()) pending_.wait();
  apply_object_cuts();
  return full_;
}

LevelsOfDetail::~LevelsOfDetail() {
  if (pending_.valid()) pending_.wait();  // the worker reads full_
}

Vec3 LevelsOfDetail::snap(const Vec3& c) const {
  index_t nearest = 0;
  double d2 = 0;
  tree_->index().knnSearch(c.data(), 1, &nearest, &d2);
  return full_.X.col(nearest);
}

const State& LevelsOfDetail::object_state() const {
  if (!object_state_current_) {
    active_set_.prolong_state(active_->state(), full_state_);
    object_state_current_ = true;
  }
  return full_state_;
}

void LevelsOfDetail::set_object_state(const State& state) {
  if (state.u.cols() != full_.n_points || state.velocity.cols() != full_.n_points)
    throw Error("simulation: the state is for another model");
  full_state_.u = state.u;
  full_state_.velocity = state.velocity;
  full_state_.time = state.time;
  if (state.viscous.rows() == full_state_.viscous.rows() && state.viscous.cols() == full_state_.viscous.cols())
    full_state_.viscous = state.viscous;
  State active = active_set_.restrict_state(full_state_);
  active.time = state.time;
  active_->set_state(active);
  object_state_current_ = false;  // unsimulated points' values are the object's own; selected ones come back
}

Vec3 LevelsOfDetail::contact_of_probe(const Vec3& probe, const std::vector<index_t>& grabbed,
                                      const std::vector<index_t>& touched) const {
  const Model& model = active_->model();
  // grabbing: where the grabbed points are in the object, however far they were dragged
  if (!grabbed.empty()) {
    Vec3 sum = Vec3::Zero();
    for (index_t i : grabbed) sum += model.X.col(i);
    return sum / static_cast<double>(grabbed.size());
  }
  // pushing: the probe carried back by the mean displacement of the touched points, so that pressing in
  // does not move the contact point (the touched material stays where it is in the object). The mean of
  // many points moves smoothly as the probe slides, unlike the nearest point
  if (!touched.empty()) {
    Vec3 sum = Vec3::Zero();
    for (index_t i : touched) sum += active_->state().u.col(i);
    return probe - sum / static_cast<double>(touched.size());
  }
  return probe;
}

void LevelsOfDetail::follow_probe() {
  const ProbeAttachment* attached = active_->probe();
  if (!attached || active_->diagnostics().steps == 0) return;
  const ProbeTool& p = attached->tool;
  const bool onset = p.contacts_before_step() == 0 && p.contact_model().contacts > 0;
  update(contact_of_probe(p.probe(), p.contact().grabbed(), p.touched()), onset, attached->asynchronous_lod);
}

std::vector<index_t> LevelsOfDetail::update(const Vec3& contact, bool onset, bool asynchronous) {
  if (pending_.valid()) {
    // a re-selection in flight: take it over once it is built (waiting for it unless asynchronous)
    if (asynchronous && pending_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return {};
    return take_over(pending_.get(), false);
  }
  if (!contact.allFinite()) return {};
  // the distance is the contact point's own, not its snapped point's: a probe that trembles between two
  // points of the lattice must not re-select at every step
  const double moved = (contact - contact_).norm();
  if (onset ? moved < 0.25 * params_.reselect * full_.h : moved <= params_.reselect * full_.h) return {};
  if (!onset && active_->state().time - last_selection_time_ < params_.reselect_interval) return {};
  contact_ = contact;
  apply_object_cuts();
  if (!asynchronous)
    return take_over(
        build_lod(full_, params_, snap(contact), solver_.kind, active_->cut_sheets().triangles, object_cuts_made_),
        true);
  // the worker only reads the object's model: a cut meanwhile reaches it once the build is done (carry_cuts())
  // and, with a probe on the surface, the part of it the new active set carries
  const ProbeAttachment* probe = active_->probe();
  std::shared_ptr<const ObjectSurface> surface =
      probe && probe->surface ? (probe->split ? probe->split : probe->surface) : nullptr;
  const double reach = probe ? tool_reach(probe_shape(probe->tool.contact().params())) : 0.0;
  pending_ = std::async(std::launch::async,
                        [&full = full_, params = params_, at = snap(contact), kind = solver_.kind,
                         sheets = active_->cut_sheets().triangles, cuts = object_cuts_made_, surface, reach] {
                          LodBuild build = build_lod(full, params, at, kind, sheets, cuts);
                          if (surface) {
                            build.part = restrict_surface(surface->mesh, surface->map, build.active, reach);
                            build.part_of = surface;
                          }
                          return build;
                        });
  return {};
}

std::vector<index_t> LevelsOfDetail::take_over(LodBuild build, bool built_here) {
  const auto start = std::chrono::steady_clock::now();
  const bool first = selections_ == 0;  // the constructor's, before any step: set-up, not a stall
  ActiveSet& next = build.active;
  // the cuts made while it was built: on the object now (nothing reads it), and on the new set
  carry_cuts();
  if (build.object_cuts != object_cuts_made_) {
    const CutReport late =
        cut_as_object(next, full_, active_->cut_sheets().triangles, solver_.kind != SolverKind::EXPLICIT);
    if (late.severed_pairs > 0 && build.stable_dt > 0)
      build.stable_dt = std::min(
          build.stable_dt, local_stable_time_step(next.model, late.cut_points, ModelSimulation::cut_patch_rings, 0.8,
                                                  ModelSimulation::cut_lanczos_steps));
  }
  std::vector<index_t> new_index(first ? 0 : static_cast<std::size_t>(active_->model().n_points), -1);
  double energy_before = 0;
  State carried = full_state_;
  if (!first) {
    for (index_t k = 0; k < active_set_.n_selected; ++k) {
      const index_t now = next.active_of[active_set_.full_of[k]];
      new_index[k] = now < next.n_selected ? now : -1;
    }
    const ModelSimulation& old = *active_;
    energy_before =
        strain_energy(old.model(), old.state().u).total() + kinetic_energy(old.model(), old.state().velocity);
    carried = object_state();  // the active state so far, back on the object
  }
  const double time = carried.time;
  State state = next.restrict_state(carried);
  state.time = time;
  if (!first) remove_added_energy(next.model, energy_before, state);
  // a new simulation of the new active model; what the pipeline carries (diagnostics, inputs, the probe,
  // renumbered: grabbed points follow their new numbers, none at the first selection) moves over
  auto sim = std::make_unique<ModelSimulation>(next.model, solver_, n_threads_, build.stable_dt);
  sim->continue_from(std::move(*active_));
  active_ = std::move(sim);
  if (active_->probe()) {
    ProbeAttachment& probe = *active_->probe();
    probe.object_model = &full_;
    probe.active_set = &active_set_;  // (next, once moved there below)
    std::optional<SurfaceContact> surface;
    const std::shared_ptr<const ObjectSurface>& current = probe.split ? probe.split : probe.surface;
    const ToolShape shape = probe_shape(probe.tool.contact().params());
    if (current && build.part && build.part_of == current)  // made by the worker (a cut split none since)
      surface.emplace(probe_surface_contact(std::move(*build.part), probe.contact, shape, active_->model(), next));
    else if (current) surface.emplace(probe_surface_contact(*current, probe.contact, shape, active_->model(), &next));
    probe.tool.remap(active_->model(), new_index, std::move(surface));
  }
  active_->set_state(state);
  active_set_ = std::move(next);
  selection_ = std::move(build.selection);
  centre_ = build.centre;
  object_state_current_ = false;
  if (!first) last_selection_time_ = time;
  ++selections_;
  const double stall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  last_build_ms_ = build.ms - selection_.milliseconds;
  // the time the simulation's thread was held: the swap, and the build too when it was made there
  if (!first) max_reselect_ms_ = std::max(max_reselect_ms_, stall + (built_here ? build.ms : 0.0));
  return first ? std::vector<index_t>{} : new_index;
}

void LevelsOfDetail::fill(LodSummary& o) const {
  o.enabled = true;
  o.selected = active_set_.n_selected;
  o.frozen = active_set_.model.n_points - active_set_.n_selected;
  o.widened = active_set_.widened;
  o.band_count = selection_.band_count;
  o.band_selected = selection_.band_selected;
  o.active.assign(static_cast<std::size_t>(full_.n_points), 0);
  for (index_t k = 0; k < active_set_.n_selected; ++k) o.active[active_set_.full_of[k]] = 1;
  o.selections = selections_;
  o.selection_ms = selection_.milliseconds;
  o.build_ms = last_build_ms_;
  o.max_reselect_ms = max_reselect_ms_;
}

}  // namespace pointhaptics
