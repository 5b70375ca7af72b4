#pragma once
/// @file The probe and its contact with the object (seed Fig. 5): sphere-sphere tests between the probe
/// and the point spheres, push and grab, and the local linear contact model the haptic thread renders.
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/geometry/spatial_grid.hpp>

#include <Eigen/Geometry>

#include <vector>

namespace pointhaptics {

/// PUSH_GRAB: pushes while the button is up and grabs while it is held (a viewer's mouse probe).
/// CUT: the tool is a blade, its capsule axis the cutting edge: while the button is held it passes through the
/// object and cuts where its edge sweeps (mechanics/cut.hpp), and the hand feels the cutting resistance; while
/// it is up it pushes.
/// PUSH: the probe pushes; GRAB: holds the points under it while button 1 is down; PUSH_GRAB: pushes, and grabs
/// while the button is down; CUT: a blade that cuts while the button is down; GRASP: a grasper, two capsule jaws
/// that close while the button is down (ProbeParams::opening, grip) and hold what they squeeze by friction.
enum class ProbeMode { PUSH, GRAB, PUSH_GRAB, CUT, GRASP };

struct ProbeParams {
  double radius = 0.005;  ///< probe sphere, m
  ProbeMode mode = ProbeMode::PUSH;
  double point_radius = 0;  ///< point spheres, m (0: half the model's spacing)
  double stiffness = 0;     ///< contact / grab spring per point, N/m (0: E x spacing, the object's own scale)
  double friction = 0;      ///< Coulomb's coefficient on the surface (the point spheres are frictionless)
  /// On the surface: > 0 makes the tool a capsule, its axis segment this long (m) along the tool's local z,
  /// posed by `orientation` turned by the device's own (a device that reports none keeps `orientation`).
  double length = 0;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// On the surface: the local model's stiffness is the object's as the tool sees it (ProbeTool::
  /// compliance_stiffness), not the contact's own. Off by default: its solves cost a tangent product per CG
  /// iteration on the simulated model, which doubled the step of the level-of-detail half-sphere (1.98
  /// against 0.97 ms) and took it out of real time, for a local model that strays 1.5 mN from the next
  /// update where the contact's own strays 2.6 mN (docs/haptics.md).
  bool object_stiffness = false;
  /// On the surface: the contact's map without its negative weights (SurfaceContactParams::non_negative_weights).
  bool non_negative_surface_map = false;
  /// On the surface: the contact's samples along the surface's edges at most this far apart, m
  /// (SurfaceContactParams::sample_spacing; 0: default_sample_spacing, 1.2, times the tool's radius).
  double sample_spacing = 0;
  /// CUT: the work of cutting per unit of new cut area, J/m^2 (N/m): the hand feels it as a force against the
  /// edge's motion, this times the new area over the distance moved (0: the blade cuts freely)
  double cut_resistance = 0;
  /// GRASP: the gap between the jaws' surfaces with the button up (opening) and held (grip), m, and the time the
  /// jaws take from one to the other, s (they move at a constant speed)
  double opening = 0, grip = 0, grip_time = 0.2;
};

/// The force the object exerts on the probe near p0, linearised: F(p) = f0 + K (p - p0).
/// K is symmetric negative semi-definite (the object pushes back), so the haptic side's coupling solve
/// (k I - K) p = ... is always well posed.
struct ContactModel {
  double time = 0;         ///< simulation time it was made at, s
  Vec3 p0 = Vec3::Zero();  ///< probe position it was made at, m
  Vec3 f0 = Vec3::Zero();  ///< force on the probe at p0, N
  Mat3 K = Mat3::Zero();   ///< dF/dp, N/m
  int contacts = 0;        ///< touched or grabbed points
  bool grabbing = false;
  Vec3 torque = Vec3::Zero();  ///< torque on the tool about p0, N m (held between updates)
};

/// Contact between the probe and the object, for the simulation thread. Push: every point sphere that
/// overlaps the probe is pushed out along the line of centres by a spring (stiffness x overlap), and the
/// probe feels the opposite. Grab: while the button is held, the points under the probe when it was
/// pressed follow the probe by springs (the seed's dragged point); on release they are let go.
class ProbeContact {
 public:
  ProbeContact(const Model& model, const ProbeParams& params);
  /// Adds the contact forces on the points (N) into `forces` (3 x n) for the probe at `probe` (m) and the
  /// current displacement u, and returns the local contact model. A non-finite probe position is ignored
  /// (no contact). No allocation after the first calls. `same_u`: u is the one of the last call, so the
  /// current positions and their grid are reused (the probe solve tries several probe positions at once).
  ContactModel apply(const Model& model, const Points& u, const Vec3& probe, bool button, double time, Points& forces,
                     bool same_u = false);
  /// The stiffness -df_i/du_i of the contact springs of the last apply() per point (push: k n n^T,
  /// grab: k I), added into `springs` (9 x n, column-major 3x3).
  void add_stiffness(Eigen::Matrix<double, 9, Eigen::Dynamic>& springs) const;
  /// The model's points were renumbered (a level-of-detail re-selection): grabbed points follow their
  /// new index new_index[old] (a point without one, -1, is let go) and the touched set is forgotten.
  /// Allocates; not for every step.
  void remap(const Model& model, const std::vector<index_t>& new_index);
  const ProbeParams& params() const { return params_; }
  const std::vector<index_t>& grabbed() const { return grabbed_; }
  /// The points the last apply() pushed.
  const std::vector<index_t>& touched() const { return touched_; }

 private:
  ProbeParams params_;
  SpatialGrid grid_;
  Points x_;  // current positions
  std::vector<index_t> grabbed_;
  std::vector<Vec3> offsets_;     // grabbed point minus probe at the press
  std::vector<index_t> touched_;  // points pushed by the last apply(), with their normals
  std::vector<Vec3> normals_;
  bool was_pressed_ = false;
  bool grabbing_ = false;         // the last apply() grabbed (or held nothing, in grab mode)
  bool positions_valid_ = false;  // x_ and grid_ hold the positions of the last apply()
};

}  // namespace pointhaptics
