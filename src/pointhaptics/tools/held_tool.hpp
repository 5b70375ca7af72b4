#pragma once
/// @file A tool held at a prescribed pose against the object's surface: a static indentation (`[probe]
/// position` with solver.kind = "static"), or a tool posed by the program in dynamics. Its contact is a
/// term of the energy for the Newton solvers (static, implicit) and forces at every explicit sub-step; the
/// static solver meets its constraint (augmented Lagrangian), dynamics leaves the penalty's give.
#include <pointhaptics/haptics/surface_contact.hpp>
#include <pointhaptics/solvers/solver.hpp>

#include <limits>

namespace pointhaptics {

class HeldTool final : public DynamicForces {
 public:
  explicit HeldTool(SurfaceContact contact) : contact_(std::move(contact)) {}

  void set_pose(const ToolPose& pose) { contact_.set_pose(pose); }
  const ToolPose& pose() const { return contact_.pose(); }
  const ToolShape& shape() const { return contact_.shape(); }

  void add(const Model& model, const State& state, Points& f) override { contact_.add_forces(model, state.u, f); }
  /// In dynamics (update_after_step(true)): Uzawa's update spread over the steps, `multiplier_rate` of it a
  /// step, and the friction's anchors with it, as a device's probe has (ProbeTool::after_step). Without it a held
  /// tool or obstacle in dynamics was a frictionless penalty: two tools pinching a body could not lift it. Off in
  /// static solves, whose solver meets the constraint itself (update_multipliers()).
  void after_step(const Model& model, const State& state, Workspace&) override {
    if (!update_after_step_) return;
    contact_.load(model, state.u);
    contact_.advance_multipliers(multiplier_rate, std::numeric_limits<double>::infinity());
  }
  void update_after_step(bool on) { update_after_step_ = on; }
  static constexpr double multiplier_rate = 0.2;
  double max_point_stiffness() const override { return contact_.max_point_stiffness(); }
  EnergyTerm* energy_term() override { return &contact_; }

  /// What the object does to the tool at u.
  ToolLoad load(const Model& model, const Points& u) { return contact_.load(model, u); }
  SurfaceContact& contact() { return contact_; }

 private:
  SurfaceContact contact_;
  bool update_after_step_ = false;
};

}  // namespace pointhaptics
