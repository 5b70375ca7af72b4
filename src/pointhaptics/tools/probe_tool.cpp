#include <pointhaptics/tools/probe_tool.hpp>

#include <pointhaptics/haptics/coupling.hpp>

#include <algorithm>
#include <optional>

namespace pointhaptics {

ProbeTool::ProbeTool(const Model& model, const ProbeParams& params, double coupling_stiffness, double max_force,
                     std::optional<SurfaceContact> surface)
    : contact_(model, params),
      surface_(std::move(surface)),
      k_(coupling_stiffness),
      max_force_(max_force),
      scratch_(Points::Zero(3, model.n_points)),
      compliance_solver_(model) {
  trail_.reserve(blade_trail_steps);
  gap_ = params.opening;
}

void ProbeTool::set_grasp_load(const ToolLoad& load, double time) {
  grasp_load_ = load;
  last_ = ContactModel{time, probe_, load.force, Mat3::Zero(), load.contacts, false, load.torque};
  held_K_ = load.stiffness;
}

bool ProbeTool::pushing_surface() const {
  const ProbeMode mode = contact_.params().mode;
  return surface_ &&
         (mode == ProbeMode::PUSH || ((mode == ProbeMode::PUSH_GRAB || mode == ProbeMode::CUT) && !button_));
}

std::array<Vec3, 2> ProbeTool::blade_edge() const {
  const Vec3 half = orientation_ * Vec3(0, 0, 0.5 * contact_.params().length);
  return {probe_ - half, probe_ + half};
}

void ProbeTool::resist_cut(const Model& model, const CutReport& report, double dt) {
  const std::array<Vec3, 2> edge = blade_edge();
  Vec3 target = Vec3::Zero();
  if (!trail_.empty()) {
    const std::array<Vec3, 2>& last = trail_.back();
    const Vec3 move = 0.5 * ((edge[0] - last[0]) + (edge[1] - last[1]));
    // the new area per distance over the last spacing of travel (the oldest step dropped once the rest cover it)
    // a blade held still adds nothing, and the history keeps at most cut_history_steps (bounded memory)
    if (move.norm() > 1e-12 || report.severed_pairs > 0)
      cut_history_.push_back({move.norm(), cut_area(model, report.severed_pairs)});
    if (cut_history_.size() > cut_history_steps) cut_history_.erase(cut_history_.begin());
    double travel = 0, area = 0;
    for (const auto& [d, a] : cut_history_) {
      travel += d;
      area += a;
    }
    while (cut_history_.size() > 1 && travel - cut_history_.front()[0] >= model.spacing) {
      travel -= cut_history_.front()[0];
      area -= cut_history_.front()[1];
      cut_history_.erase(cut_history_.begin());
    }
    // the work G dA done over the move: a force G dA / ds against it; over at least a spacing, so that as the
    // blade enters, the force builds over its first spacing (a first plane of pairs over a shorter travel
    // asked for 8 N where 1.2 N was due, which the per-tick bound then had to cut)
    if (move.norm() > 1e-12)
      target = -contact_.params().cut_resistance * area / std::max(travel, model.spacing) * move.normalized();
  }
  cut_force_ += std::min(1.0, dt / cut_smoothing) * (target - cut_force_);
  if (!report.cut_points.empty()) cut_points_ = report.cut_points;
  if (trail_.size() == blade_trail_steps) trail_.erase(trail_.begin());
  trail_.push_back(edge);
}

double ProbeTool::max_point_stiffness() const {
  return std::max(contact_.params().stiffness, surface_ ? surface_->max_point_stiffness() : 0.0);
}

namespace {

// the haptic side's local model of a surface contact's load on the probe at p
ContactModel contact_model_of(const ToolLoad& load, double time, const Vec3& p) {
  return ContactModel{time, p, load.force, load.stiffness, load.contacts, false, load.torque};
}

}  // namespace

ContactModel ProbeTool::surface_model(const Model& model, const State& state, const Vec3& p, bool same_u) {
  surface_->set_pose(ToolPose{p, surface_->pose().orientation});
  return contact_model_of(surface_->load(model, state.u, same_u), state.time, p);
}

ToolLoad ProbeTool::load_at(const Model& model, const State& state, const Vec3& p) {
  surface_->set_pose(ToolPose{p, surface_->pose().orientation});
  return surface_->load(model, state.u, true);
}

Vec3 ProbeTool::stop_at_surface(const Model& model, const State& state, const Vec3& from, const Vec3& to) {
  // on the surface the probe moves at most a quarter radius per iteration (2 radii a step, far above a
  // hand's speed): its local model knows only the vertices it touches where it is, and a longer jump could
  // pass the surface and push it out from within
  const double longest = 0.25 * contact_.params().radius;
  const auto limited = [&](const Vec3& move) {
    return move.norm() > longest ? Vec3(move * (longest / move.norm())) : move;
  };
  // load_at() carries the surface to the state: enters() sees it as the step found it
  const ToolLoad here = load_at(model, state, from);
  const double allowed = std::max(allowed_penetration * contact_.params().radius, here.penetration);
  const auto refused = [&](const Vec3& p) {
    return load_at(model, state, p).penetration > allowed || surface_->enters(from, p);
  };
  // each try once (a try costs a pass over the surface's vertices and one over its triangles)
  const auto furthest = [&](const Vec3& move) -> std::optional<Vec3> {
    Vec3 target = from + limited(move);
    for (int halving = 0; halving <= 6; ++halving, target = from + 0.5 * (target - from))
      if (!refused(target)) return target;
    return std::nullopt;
  };
  if (const std::optional<Vec3> moved = furthest(to - from)) return *moved;
  // refused all the way: the move's part along the contact, as a god-object slides on its constraint. With a
  // vertex deeper than allowed (a surface coarser than the probe: the soft dome's 4 mm points under a 6 mm
  // probe leave one 1.6-1.9 mm inside), every move with a part into the surface deepens it, and the probe was
  // held where it stood while the hand went 18 mm aside. The plane is the contact force's, not the deepest
  // vertex's: sliding on that one let the probe dig in, a vertex 4-5 mm inside (of 6) as it slid.
  if (!(here.force.norm() > 0)) return from;
  const Vec3 normal = here.force.normalized();  // the force on the tool, out of the object
  const Vec3 along = (to - from) - (to - from).dot(normal) * normal;
  // only a hand going mostly along the surface: pressed straight into it, the force's plane tilts as the
  // surface rings, and sliding on it let the probe wander (1.9 mm off the soft dome's apex in 0.6 s with
  // levels of detail, where it stays on it without the slide)
  if (!(along.norm() > 0.5 * (to - from).norm())) return from;
  return furthest(along).value_or(from);
}

Vec3 ProbeTool::back_on_surface(const Vec3& p) const {
  const ToolShape& shape = surface_->shape();
  const std::optional<SurfaceSide> side = surface_->side_of(p, 2 * shape.radius + shape.length);
  if (!side || side->distance >= 0 || !side->sure) return p;
  // just outside (on the surface itself a move along it could count as entering)
  return side->point + (side->point - p) * (1e-3 * shape.radius / -side->distance);
}

void ProbeTool::place(const Model& model, const State& state, const Vec3& device, bool button,
                      const Eigen::Quaterniond& orientation) {
  device_ = device;
  button_ = button;
  step_start_ = state.time;
  orientation_ = (orientation * contact_.params().orientation).normalized();
  if (surface_) surface_->set_pose(ToolPose{surface_->pose().position, orientation_});
  contacts_before_ = last_.contacts;
  if (!cutting()) {
    // a cut ends when the button is let go: the next one sweeps from where it starts
    trail_.clear();
    cut_history_.clear();
    cut_force_.setZero();
    cut_points_.clear();
  }
  if (grasper()) {
    // the jaws close while the button is held and open when it is let go, at a constant speed; a device that is
    // lost lets go
    const ProbeParams& p = contact_.params();
    const bool closing = device.allFinite() && button;
    const double dt = std::max(0.0, state.time - grasp_time_);
    const double speed = (p.opening - p.grip) / std::max(p.grip_time, 1e-9);
    gap_ = closing ? std::max(p.grip, gap_ - speed * dt) : std::min(p.opening, gap_ + speed * dt);
    grasp_time_ = state.time;
    if (device.allFinite()) probe_ = device;
    return;
  }
  if (!device.allFinite() || (contact_.params().mode == ProbeMode::CUT && button)) {
    // a blade cutting goes where the hand takes it (the resistance is what it feels)
    probe_ = device;
    return;
  }
  Vec3 p = probe_.allFinite() ? probe_ : device;
  if (pushing_surface()) {
    surface_->load(model, state.u);  // the surface carried to the step's start, for every placement below
    if (probe_.allFinite()) p = back_on_surface(p);
  }
  for (int it = 0; it < 8; ++it) {
    scratch_.setZero();
    // the state is the same at every iteration: the positions (and their grid) are made once
    const ContactModel local = pushing_surface()
                                   ? surface_model(model, state, p, true)
                                   : contact_.apply(model, state.u, p, button, state.time, scratch_, it > 0);
    Vec3 next = coupled_probe(local, device, k_, max_force_);
    if (pushing_surface()) next = stop_at_surface(model, state, p, next);
    const bool settled = (next - p).norm() < 1e-9 + 1e-6 * contact_.params().radius;
    p = next;
    if (settled) break;
  }
  probe_ = p;
  if (surface_) surface_->set_pose(ToolPose{p, surface_->pose().orientation});
}

void ProbeTool::add(const Model& model, const State& state, Points& f) {
  if (grasper()) return;  // its jaws push (posed tools of the simulation's); last_ is set_grasp_load()'s
  if (cutting()) {
    // the blade pushes the points it parts along its move as hard as they resist it
    for (const index_t p : cut_points_) f.col(p) -= cut_force_ / static_cast<double>(cut_points_.size());
    last_ = ContactModel{state.time, probe_, cut_force_, Mat3::Zero(), static_cast<int>(cut_points_.size()), false};
    held_K_.setZero();
    return;
  }
  if (!pushing_surface() || !probe_.allFinite()) {
    last_ = contact_.apply(model, state.u, probe_, button_, state.time, f);
    held_K_ = last_.K;
    return;
  }
  surface_->add_forces(model, state.u, f);
  last_ = contact_model_of(surface_->last_load(), state.time, probe_);
}

void ProbeTool::after_step(const Model& model, const State& state, Workspace& ws) {
  if (grasper()) return;
  if (!pushing_surface() || !probe_.allFinite()) {
    if (surface_) surface_->reset_multipliers();
    surface_touched_.clear();
    return;
  }
  surface_->load(model, state.u);  // the surface carried to the step's end
  // the proxy: the multipliers take the penetration left at the step's end (Uzawa's update spread over
  // steps), so that over a few steps the surface comes to touch the probe and the force is the material's;
  // never pressing harder together than the coupling does (the probe's balance at the step's start)
  const double pressing = std::min(max_force_, k_ * (device_ - probe_).norm());
  const double step = state.time - step_start_;
  const double rate = step > 0 ? multiplier_rate * std::min(1.0, step / multiplier_rate_step) : multiplier_rate;
  last_ = contact_model_of(surface_->advance_multipliers(rate, pressing), state.time, probe_);
  surface_->pressing_points(surface_touched_);
  held_K_ = last_.K;
  if (!contact_.params().object_stiffness) return;
  // made before the first touch: a step that allocates it (and linearises the material) as the probe arrives
  // let the hand run ahead of a slow simulation (under a sanitizer) and the probe through the surface
  if (!compliance_ws_) compliance_ws_ = std::make_unique<Workspace>(model, ws.n_threads());
  if (last_.contacts > 0 && compliance_contacts_ > 0) {
    last_.K = compliance_stiffness(model, state, last_.K);
  } else if (last_.contacts > 0) {
    // a new contact: the held object's stiffness this step, the compliance's solves from the next one on,
    // the material linearised first (the last solutions are of another contact)
    for (Points& x : compliance_) x.setZero();
    compliance_turn_ = 0;
  }
  compliance_contacts_ = last_.contacts;
}

Mat3 ProbeTool::compliance_stiffness(const Model& model, const State& state, const Mat3& held) {
  // the static tangent of the object with the contact: an object held nowhere has none (it gives way as a
  // whole), and keeps the held object's stiffness
  if (std::find(model.fixed.begin(), model.fixed.end(), 1) == model.fixed.end()) return held;
  const Points no_load;
  NewtonProblem problem;
  problem.load = &no_load;
  problem.term = &*surface_;
  // the contact's tangent every step; the material's every few (a 9x9 eigen decomposition per point made it
  // cost twice the step of a 2.6k-point block), and after every new contact
  const bool material = compliance_turn_ % compliance_relinearise == 0;
  compliance_solver_.linearise(model, problem, state.u, *compliance_ws_, material);
  if (compliance_load_.cols() != model.n_points) {
    compliance_load_ = Points::Zero(3, model.n_points);
    for (Points& x : compliance_) x = Points::Zero(3, model.n_points);
  }
  // one direction's solve per step, in turn (the other two keep their last solutions, warm starts of their
  // next turn): the compliance changes slowly at a hand's speed, and three solves a step tripled its cost
  const int turn = static_cast<int>(compliance_turn_++ % 3);
  compliance_load_.setZero();
  const Mat3 sum = surface_->add_tool_load(Vec3::Unit(turn), compliance_load_);
  const int iterations = compliance_solver_.solve_linearised(model, problem, compliance_load_, compliance_[turn],
                                                             compliance_tolerance, compliance_budget, *compliance_ws_);
  if (iterations < 0 || !compliance_[turn].allFinite()) {
    for (Points& x : compliance_) x.setZero();
    return held;
  }
  Mat3 coupling;
  for (int a = 0; a < 3; ++a) coupling.col(a) = surface_->tool_response(compliance_[a]);  // B^T H^-1 B e_a
  // symmetric (it is, but for the solves' tolerance) and negative semi-definite: the haptic side's coupling
  // solve needs K <= 0, and a partial solve keeps it there but for round-off
  const Mat3 K = 0.5 * (coupling + coupling.transpose()) - sum;
  Eigen::SelfAdjointEigenSolver<Mat3> eigen(K);
  if (eigen.info() != Eigen::Success || !K.allFinite()) return held;
  return eigen.eigenvectors() * eigen.eigenvalues().cwiseMin(0.0).asDiagonal() * eigen.eigenvectors().transpose();
}

// Implicit steps take the contact's forces at the step's start and its normal stiffness, per point, as springs
// (linearly implicit, as the point spheres' springs): the full contact term in Newton (as the static solver
// has it) failed its line search when a probe started deep in the object (a new session under a held mouse),
// where vertices cross the probe's centre and their normals flip.
bool ProbeTool::add_stiffness(const Model& model, const State& state,
                              Eigen::Matrix<double, 9, Eigen::Dynamic>& springs) {
  if (grasper()) return false;
  if (pushing_surface() && probe_.allFinite()) {
    surface_->linearise(model, state.u, TangentMode::PROJECTED);
    surface_->add_diagonal_blocks(springs);
    return last_.contacts > 0;
  }
  contact_.add_stiffness(springs);
  return last_.contacts > 0;
}

void ProbeTool::remap(const Model& model, const std::vector<index_t>& new_index,
                      std::optional<SurfaceContact> surface) {
  contact_.remap(model, new_index);
  // the proxy's multipliers carry over to the vertices the new contact has (without them the probe would sink
  // by the penalty's give at every re-selection)
  if (surface && surface_) surface->take_multipliers(*surface_);
  surface_ = std::move(surface);
  if (surface_ && probe_.allFinite()) surface_->set_pose(ToolPose{probe_, surface_->pose().orientation});
  scratch_ = Points::Zero(3, model.n_points);
  compliance_solver_ = NewtonSolver(model);
  compliance_ws_.reset();
  compliance_load_.resize(3, 0);
  compliance_contacts_ = 0;
}

void ProbeTool::blade_sweeps(std::vector<BladeSweep>& out) const {
  out.clear();
  const std::array<Vec3, 2> edge = blade_edge();
  for (std::size_t k = 0; k < trail_.size(); ++k) {
    const std::array<Vec3, 2>& to = k + 1 < trail_.size() ? trail_[k + 1] : edge;
    out.push_back(BladeSweep{trail_[k][0], trail_[k][1], to[0], to[1]});
  }
}

}  // namespace pointhaptics
