#include <pointhaptics/haptics/probe_tool.hpp>

#include <pointhaptics/haptics/coupling.hpp>

#include <algorithm>

namespace pointhaptics {

ProbeTool::ProbeTool(const Model& model, const ProbeParams& params, double coupling_stiffness, double max_force,
                     std::optional<SurfaceContact> surface)
    : contact_(model, params), surface_(std::move(surface)), k_(coupling_stiffness), max_force_(max_force),
      scratch_(Points::Zero(3, model.n_points)) {}

bool ProbeTool::pushing_surface() const {
  const ProbeMode mode = contact_.params().mode;
  return surface_ && (mode == ProbeMode::PUSH || (mode == ProbeMode::PUSH_GRAB && !button_));
}

double ProbeTool::max_point_stiffness() const {
  return std::max(contact_.params().stiffness, surface_ ? surface_->max_point_stiffness() : 0.0);
}

namespace {

// the haptic side's local model of a surface contact's load on the probe at p
ContactModel contact_model_of(const ToolLoad& load, double time, const Vec3& p) {
  return ContactModel{time, p, load.force, load.stiffness, load.contacts, false};
}

}  // namespace

ContactModel ProbeTool::surface_model(const Model& model, const State& state, const Vec3& p, bool same_u) {
  surface_->set_pose(ToolPose{p, surface_->pose().orientation});
  return contact_model_of(surface_->load(model, state.u, same_u), state.time, p);
}

void ProbeTool::place(const Model& model, const State& state, const Vec3& device, bool button) {
  device_ = device;
  button_ = button;
  contacts_before_ = last_.contacts;
  if (!device.allFinite()) {
    probe_ = device;
    return;
  }
  Vec3 p = probe_.allFinite() ? probe_ : device;
  for (int it = 0; it < 8; ++it) {
    scratch_.setZero();
    // the state is the same at every iteration: the positions (and their grid) are made once
    const ContactModel local = pushing_surface() ? surface_model(model, state, p, it > 0)
                                                 : contact_.apply(model, state.u, p, button, state.time, scratch_, it > 0);
    Vec3 next = coupled_probe(local, device, k_, max_force_);
    // on the surface the probe moves at most a quarter radius per iteration (2 radii a step, far above a
    // hand's speed): its local model knows only the vertices it touches where it is, and a longer jump could
    // pass the surface and push it out from within
    const double longest = 0.25 * contact_.params().radius;
    if (pushing_surface() && (next - p).norm() > longest) next = p + (next - p) * (longest / (next - p).norm());
    const bool settled = (next - p).norm() < 1e-9 + 1e-6 * contact_.params().radius;
    p = next;
    if (settled) break;
  }
  probe_ = p;
  if (surface_) surface_->set_pose(ToolPose{p, surface_->pose().orientation});
}

void ProbeTool::add(const Model& model, const State& state, Points& f) {
  if (!pushing_surface() || !probe_.allFinite()) {
    last_ = contact_.apply(model, state.u, probe_, button_, state.time, f);
    return;
  }
  surface_->add_forces(model, state.u, f);
  last_ = contact_model_of(surface_->last_load(), state.time, probe_);
}

void ProbeTool::after_step(const Model& model, const State& state) {
  if (pushing_surface() && probe_.allFinite()) last_ = surface_model(model, state, probe_, false);
}

// Implicit steps take the contact's forces at the step's start and its normal stiffness, per point, as springs
// (linearly implicit, as the point spheres' springs): the full contact term in Newton (as the static solver
// has it) failed its line search when a probe started deep in the object (a new session under a held mouse),
// where vertices cross the probe's centre and their normals flip.
bool ProbeTool::add_stiffness(const Model& model, const State& state, Eigen::Matrix<double, 9, Eigen::Dynamic>& springs) {
  if (pushing_surface() && probe_.allFinite()) {
    surface_->linearise(model, state.u, TangentMode::PROJECTED);
    surface_->add_diagonal_blocks(springs);
    return last_.contacts > 0;
  }
  contact_.add_stiffness(springs);
  return last_.contacts > 0;
}

void ProbeTool::remap(const Model& model, const std::vector<index_t>& new_index) {
  contact_.remap(model, new_index);
  surface_.reset();  // its map is over the points it was built for: the point spheres from now on
  scratch_ = Points::Zero(3, model.n_points);
}

}  // namespace pointhaptics
