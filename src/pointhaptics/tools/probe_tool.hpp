#pragma once
/// @file The probe as a tool of the simulation: placed on its coupling spring once per step, then its
/// contact forces act on the points at every (sub-)step the solver takes.
#include <pointhaptics/haptics/contact.hpp>
#include <pointhaptics/haptics/surface_contact.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/solvers/solver.hpp>

#include <array>
#include <memory>
#include <optional>
#include <vector>

namespace pointhaptics {

/// The probe's shape on the surface: a sphere, or a capsule when params.length > 0.
inline ToolShape probe_shape(const ProbeParams& params) {
  return ToolShape{params.length > 0 ? ToolKind::CAPSULE : ToolKind::SPHERE, params.radius, params.length};
}

class ProbeTool final : public DynamicForces {
 public:
  /// coupling_stiffness: the spring between the device point and the probe, N/m; max_force: the device's
  /// largest force, N (the hand cannot push harder than it can feel).
  /// `surface`: the probe pushes on the object's surface (issue 16) instead of the point spheres; grabbing
  /// still holds the points under it.
  ProbeTool(const Model& model, const ProbeParams& params, double coupling_stiffness, double max_force,
            std::optional<SurfaceContact> surface = std::nullopt);

  /// Once per step: the probe is where the coupling spring toward `device` (its force capped at max_force)
  /// balances the contact forces at the step's start; a few Newton steps on the local model from the last
  /// position. Within the step the probe stays there (re-solving it at every sub-step let the contact set
  /// chatter and excite the lattice). A non-finite device point lifts the probe off.
  /// `orientation`: the device's, which turns the tool from the params' orientation (a capsule).
  void place(const Model& model, const State& state, const Vec3& device, bool button,
             const Eigen::Quaterniond& orientation = Eigen::Quaterniond::Identity());
  void add(const Model& model, const State& state, Points& f) override;
  bool add_stiffness(const Model&, const State&, Eigen::Matrix<double, 9, Eigen::Dynamic>& springs) override;
  double max_point_stiffness() const override;
  /// Pushing on the surface: the local contact model at the step's end state, for the haptic side, its
  /// stiffness through the object's compliance (compliance_stiffness()).
  void after_step(const Model& model, const State& state, Workspace& ws) override;

  /// A blade (ProbeMode::CUT).
  bool blade() const { return contact_.params().mode == ProbeMode::CUT; }
  /// A grasper (ProbeMode::GRASP): the tool is two capsule jaws that the simulation poses either side of the
  /// probe along the tool's local x, jaw_gap() apart (ModelSimulation), each a posed tool's contact; the probe
  /// goes where the device is (the jaws are the hand's, as a real grasper's are), and the hand feels what the
  /// bodies exert on the jaws (set_grasp_load()). The tool itself touches nothing.
  bool grasper() const { return contact_.params().mode == ProbeMode::GRASP; }
  /// A grasper: the gap between its jaws' surfaces at this step, m: from the opening it closes toward the grip
  /// while the button is held, and opens again when it is let go, at (opening - grip) / grip_time m/s.
  double jaw_gap() const { return gap_; }
  /// The tool's orientation at the last placement: the params' turned by the device's.
  const Eigen::Quaterniond& orientation() const { return orientation_; }
  /// A grasper, at the step's end: the bodies' load on its jaws (summed; the torque about the probe) is the hand's
  /// local model, held between updates without a stiffness (the jaws' contact, stuck to a body it carries, is
  /// stiffer than anything a hand moves against, and a model with it would hold the hand still).
  void set_grasp_load(const ToolLoad& load, double time);
  /// A grasper: the load set_grasp_load() was given last.
  const ToolLoad& grasp_load() const { return grasp_load_; }
  /// A blade with the button held: this step it cuts instead of touching.
  bool cutting() const { return blade() && button_ && probe_.allFinite(); }
  /// The blade's edge at the probe's pose (its capsule axis).
  std::array<Vec3, 2> blade_edge() const;
  /// Where the edge was at the last blade_trail_steps steps of this cut, oldest first (empty on its first
  /// step). The step cuts the strips between them and blade_edge(): the material moves between steps, and a
  /// pair that moved back over a strip the edge had passed would escape a blade that cut only its last strip
  /// (a device's blade through the cantilever missed 6 of 169 pairs and left it whole).
  const std::vector<std::array<Vec3, 2>>& blade_trail() const { return trail_; }
  /// The strips a cutting blade sweeps this step: from each edge of its trail to the next, the last to blade_edge()
  /// (none on the step a cut starts). `out` is cleared first; it allocates only to grow.
  void blade_sweeps(std::vector<BladeSweep>& out) const;
  /// Steps in the cutting resistance's history, at most cut_history_steps (a second at 1 kHz: a blade crawling
  /// slower than a spacing a second feels the area over its last second).
  std::size_t cut_history_size() const { return cut_history_.size(); }
  static constexpr std::size_t cut_history_steps = 1000;
  static constexpr std::size_t blade_trail_steps = 8;
  /// This step's cut (ModelSimulation::place_tools): the hand feels cut_resistance times the new area
  /// (cut_area()) per distance the edge moved, against its move. The area comes in whole pairs, a plane of
  /// them at a time as the edge passes a plane of points, so it is taken over the last spacing of the edge's
  /// travel (divided by a spacing at least), and the force low-passed over cut_smoothing seconds. The points
  /// of the severed pairs take the opposite force. Remembers the edge.
  void resist_cut(const Model& model, const CutReport& report, double dt);

  /// Whether the probe touches the object's surface (else the point spheres).
  bool on_surface() const { return surface_.has_value(); }
  const SurfaceContact* surface_contact() const { return surface_ ? &*surface_ : nullptr; }
  /// The model's points were renumbered (a level-of-detail re-selection): new_index[old], -1 if dropped;
  /// `surface`: the contact with the part of the surface the new model carries (none: the point spheres).
  void remap(const Model& model, const std::vector<index_t>& new_index, std::optional<SurfaceContact> surface);

  const Vec3& probe() const { return probe_; }
  /// Where the device put the hand at the last placement (the probe's goal), m.
  const Vec3& device() const { return device_; }
  /// The local contact model of the last force evaluation, for the haptic side.
  const ContactModel& contact_model() const { return last_; }
  /// Its stiffness against the held object (the contact's own, before the object's compliance is taken in).
  const Mat3& held_stiffness() const { return held_K_; }
  /// Points in contact when the step began (before place()): contact onset is 0 before, > 0 after.
  int contacts_before_step() const { return contacts_before_; }
  const ProbeContact& contact() const { return contact_; }
  /// The points the probe touches: on the surface those that carry most of each vertex pressing on it at the
  /// last step's end, else the point spheres it pushed (the contact's).
  const std::vector<index_t>& touched() const { return surface_ ? surface_touched_ : contact_.touched(); }

 private:
  bool pushing_surface() const;
  /// The surface contact's load on the probe at p (its deepest vertex inside, its force), the surface as the
  /// step found it (evaluated already).
  ToolLoad load_at(const Model& model, const State& state, const Vec3& p);
  /// The god-object's rule: the probe's move from `from` toward `to` (at most a quarter radius), halved until
  /// no surface vertex is deeper inside it than allowed_penetration x radius (or than at `from`, if deeper
  /// there) and its centre's path does not enter the surface (SurfaceContact::enters()); if every halving is
  /// refused and the move goes mostly along the surface, the same with its part across the contact's force
  /// (a slide along the surface); else no move.
  Vec3 stop_at_surface(const Model& model, const State& state, const Vec3& from, const Vec3& to);
  /// p, or the nearest point of the surface (as the step found it) if p is inside it: a soft, coarse object
  /// pressed hard can flow over the probe's centre within a step, its vertices passing the probe's sides and a
  /// triangle its centre, and a probe left inside sank through the object (scenes/half_sphere_lod.toml
  /// without [lod]). Put back, the god-object is outside again and its moves are kept there.
  Vec3 back_on_surface(const Vec3& p) const;
  /// The local model of the surface contact at the probe position p (u as in the last evaluation when same_u).
  ContactModel surface_model(const Model& model, const State& state, const Vec3& p, bool same_u);
  /// The stiffness the tool feels with the object free to give (issue 16, item 4): K = B^T H^-1 B - sum_v H_v,
  /// the Schur complement of the points in the tangent of the object and the contact (H: the static tangent,
  /// B = W^T sum_v H_v: the points' load per unit of tool motion), by three warm-started CG solves, one a
  /// step in turn within a budget of iterations (a partial solve from zero gives a K between the held
  /// object's and the true one). Falls back to the held object's -sum_v H_v when a solve fails.
  Mat3 compliance_stiffness(const Model& model, const State& state, const Mat3& held);

  /// On the surface the probe is a proxy kept on it: the contact's multipliers advance by this share of
  /// Uzawa's update at every step's end. The penalty alone (capped at E x spacing per point, for the explicit
  /// stable step) let the probe sink by its give and the hand feel 0.78 of the material's force on a slow
  /// press; the full update (1) made a probe pushed fast to half a soft block's depth diverge
  /// (tests/deep_compression_test.cpp), a half keeps it stable and on a slow press leaves 0.16% of the
  /// depth inside the surface and the force at 0.999 of the material's (tests/probe_surface_test.cpp).
  static constexpr double multiplier_rate = 0.5;
  /// The step multiplier_rate is for, s: a shorter step takes a proportional share, so that the multipliers
  /// build at the same rate per second whatever the step (an update is an integral action on the penetration:
  /// at the same share per step, the 100k half-sphere's 0.1 ms steps built them ten times faster than 1 ms
  /// steps, and its explicit run diverged at 0.47 s; at the share per millisecond at 2.2 s, docs/haptics.md).
  static constexpr double multiplier_rate_step = 1e-3;
  /// How deep a surface vertex may be inside the probe when it is placed, over its radius. Without a bound, a
  /// hand pushing fast into a soft, coarse dome (scenes/half_sphere_lod.toml: E = 1e4 Pa, spacing 4 mm, a 6 mm
  /// probe) took the probe past the surface's vertices faster than the multipliers could build (their
  /// penalty is E x spacing per point), and through; held back, the probe presses with the multipliers,
  /// which catch up with the coupling's force over the next steps.
  static constexpr double allowed_penetration = 0.1;
  /// The time constant of the cutting resistance's low-pass, s (ten haptic ticks).
  static constexpr double cut_smoothing = 0.01;
  ProbeContact contact_;
  std::optional<SurfaceContact> surface_;
  Eigen::Quaterniond orientation_ = Eigen::Quaterniond::Identity();  ///< the tool's, the device's turn included
  std::vector<std::array<Vec3, 2>> trail_;                           ///< blade_trail()
  Vec3 cut_force_ = Vec3::Zero();                                    ///< on the blade, N
  std::vector<index_t> cut_points_;                                  ///< the points that take its opposite
  std::vector<std::array<double, 2>>
      cut_history_;  ///< per step of this cut: the edge's travel, m, and the new area, m^2
  double k_, max_force_;
  Vec3 device_ = Vec3::Constant(NAN);
  double step_start_ = 0;  // the time at which the step being taken began (place())
  Vec3 probe_ = Vec3::Constant(NAN);
  bool button_ = false;
  double gap_ = 0;         ///< a grasper's jaw gap, m (jaw_gap())
  double grasp_time_ = 0;  ///< the time its gap was last moved to, s
  ToolLoad grasp_load_;    ///< grasp_load()
  int contacts_before_ = 0;
  ContactModel last_;
  Mat3 held_K_ = Mat3::Zero();
  Points scratch_;
  std::vector<index_t> surface_touched_;
  /// the compliance solves: relative tolerance and CG iterations of a direction's turn (warm-started, the rest
  /// of the convergence comes over the next turns)
  static constexpr double compliance_tolerance = 1e-2;
  static constexpr int compliance_budget = 3;
  /// steps between linearisations of the material's tangent (in between it lags; the contact's is made anew)
  static constexpr int compliance_relinearise = 48;
  NewtonSolver compliance_solver_;
  std::unique_ptr<Workspace> compliance_ws_;  // its own: the step's keeps what the solver carries to the next step
  Points compliance_load_;                    // B e, one direction at a time
  std::array<Points, 3> compliance_;          // H^-1 B e_a: the warm starts of the next step
  int compliance_contacts_ = 0;               // contacts at the last step (0: the next contact is new)
  long long compliance_turn_ = 0;
};

}  // namespace pointhaptics
