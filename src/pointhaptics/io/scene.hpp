#pragma once
/// @file The scene: a plain description of an experiment, as read from a scene file (design.md's TOML schema).
#include <pointhaptics/core/parameters.hpp>
#include <pointhaptics/core/types.hpp>

#include <array>
#include <optional>
#include <cmath>
#include <string>
#include <vector>

namespace pointhaptics {

struct Aabb {
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();
  bool contains(const Vec3& p) const { return (p.array() >= min.array()).all() && (p.array() <= max.array()).all(); }
};

enum class ShapeKind { BOX, SPHERE, HALF_SPHERE, FILE };
template <>
struct EnumNames<ShapeKind> {
  static constexpr std::array<std::pair<ShapeKind, std::string_view>, 4> table{{{ShapeKind::BOX, "box"},
                                                                                {ShapeKind::SPHERE, "sphere"},
                                                                                {ShapeKind::HALF_SPHERE, "half_sphere"},
                                                                                {ShapeKind::FILE, "file"}}};
};

struct ObjectSpec {
  ShapeKind shape = ShapeKind::BOX;
  Vec3 size = Vec3(0.15, 0.03, 0.03);                ///< box edge lengths, m
  Vec3 origin = Vec3::Zero();                        ///< box: min corner; sphere, half_sphere: centre, m
  double radius = 0.05;                              ///< sphere, half_sphere, m
  double spacing = 0.0075;                           ///< sample spacing, m
  double surface_edge = 0;                           ///< the surface's edge length, m (0: half the spacing)
  std::string file;                                  ///< shape = file: path, resolved against the scene file's folder
  double threshold_low = NAN, threshold_high = NAN;  ///< volume images: the intensity window sampled
  /// volume images: [intensity, young (Pa)] rows, intensities increasing; each point's Young's modulus is
  /// interpolated linearly at its voxel's intensity (held at the end values beyond them); empty: none
  std::vector<std::array<double, 2>> stiffness_map;
  int line = 0;  ///< of the [object] table, for messages
};

/// A ball of points: |X - centre| <= radius.
struct SphereRegion {
  Vec3 centre = Vec3::Zero();
  double radius = 0;  ///< m
};
/// A solid cylinder of points: |a| <= half_length and |d - a axis| <= radius, d = X - centre, a = d . axis.
struct CylinderRegion {
  Vec3 centre = Vec3::Zero();
  Vec3 axis = Vec3::UnitY();           ///< unit
  double radius = 0, half_length = 0;  ///< m
};

/// Which points a [[fixed]] or [[region]] table selects (faces included): those in `box`, or in `sphere` or
/// `cylinder` when one is given (a scene gives exactly one of the three).
struct PointSelector {
  Aabb box;
  std::optional<SphereRegion> sphere;
  std::optional<CylinderRegion> cylinder;

  /// The scene key that selects: "box", "sphere" or "cylinder".
  const char* key() const { return sphere ? "sphere" : cylinder ? "cylinder" : "box"; }
  /// Whether x lies in the region grown by tol (m).
  bool contains(const Vec3& x, double tol) const {
    if (sphere) return (x - sphere->centre).norm() <= sphere->radius + tol;
    if (cylinder) {
      const Vec3 d = x - cylinder->centre;
      const double along = d.dot(cylinder->axis);
      return std::abs(along) <= cylinder->half_length + tol &&
             (d - along * cylinder->axis).norm() <= cylinder->radius + tol;
    }
    return (x.array() >= box.min.array() - tol).all() && (x.array() <= box.max.array() + tol).all();
  }
  /// The region's bounding box.
  Aabb bounds() const {
    if (sphere) return {sphere->centre.array() - sphere->radius, sphere->centre.array() + sphere->radius};
    if (cylinder) {
      const Vec3 reach = (cylinder->half_length * cylinder->axis).cwiseAbs().array() + cylinder->radius;
      return {cylinder->centre - reach, cylinder->centre + reach};
    }
    return box;
  }
};

struct FixedSpec : PointSelector {
  Vec3 displacement = Vec3::Zero();  ///< prescribed displacement, m
  double ramp = 0;                   ///< ramp-in time, s
  std::string object;                ///< the [[object]] it holds, by name (empty: the scene's only object)
  int line = 0;                      ///< line of the [[fixed]] table, for messages
};

/// [[region]]: a part of the object with its own material (a stiff nodule in soft tissue); the keys it
/// omits are the object's [material]'s. Later tables win where regions overlap.
struct RegionSpec : PointSelector {
  std::string object;  ///< the [[object]] it belongs to, by name (empty: the scene's only object)
  std::optional<MaterialModel> model;
  std::optional<double> young, poisson, density;  ///< Pa, -, kg/m^3
  int line = 0;
};

/// A [[refine]] table: the object's points in the region resampled at a finer spacing (resolution where a tool
/// presses; geometry/refine_sampling.hpp).
struct RefineSpec : PointSelector {
  std::string object;  ///< the [[object]] it resamples, by name (empty: the scene's only object)
  double spacing = 0;  ///< m, finer than the object's
  int line = 0;
};

enum class LoadKind { TRACTION, GRAVITY, POINT };
template <>
struct EnumNames<LoadKind> {
  static constexpr std::array<std::pair<LoadKind, std::string_view>, 3> table{
      {{LoadKind::TRACTION, "traction"}, {LoadKind::GRAVITY, "gravity"}, {LoadKind::POINT, "point"}}};
};

struct LoadSpec {
  LoadKind kind = LoadKind::TRACTION;
  Aabb box;                    ///< traction: the loaded points
  Vec3 total = Vec3::Zero();   ///< traction: total force, N
  Vec3 g = Vec3(0, -9.81, 0);  ///< gravity, m/s^2
  long long point = 0;         ///< point load: point index (within its object)
  Vec3 force = Vec3::Zero();   ///< point load: force, N
  /// the [[object]] it loads, by name (empty: the scene's only object; gravity: every object)
  std::string object;
  int line = 0;
};

/// [probe]: a spherical probe driven by a device (design.md, "Haptics").
struct ProbeSpec {
  bool present = false;
  double radius = 0.005;                         ///< m
  bool grab = false;                             ///< mode = "grab" (else push)
  bool cut = false;                              ///< mode = "cut": a blade, its capsule axis the edge (ProbeMode::CUT)
  double cut_resistance = 0;                     ///< J/m^2: the work of cutting per unit of new cut area
  std::string trajectory;                        ///< virtual device: CSV of t, x, y, z[, button] (resolved path)
  std::vector<std::array<double, 5>> keyframes;  ///< or keyframes t, x, y, z, button
  Vec3 origin = Vec3::Constant(NAN);  ///< scene position of the device origin, m (NaN: above the object's centre)
  double scale = 1.0;                 ///< scene metres per device metre
  double stiffness = 0;               ///< contact spring per point, N/m (0: E x spacing)
  /// A tool held there, m (scene axes; NaN: driven by the device). With solver.kind = "static" the
  /// equilibrium with the tool there; its contact is on the object's surface (issue 16).
  Vec3 position = Vec3::Constant(NAN);
  /// A held tool: the unit direction it presses in (`pointhaptics fit` moves it along it from `position`, the
  /// tool at zero depth, and reads the force against it)
  Vec3 direction = -Vec3::UnitY();
  std::array<double, 4> orientation{1, 0, 0, 0};  ///< unit quaternion w, x, y, z: tool to scene axes
  bool capsule = false;                           ///< shape = "capsule" (else "sphere")
  /// shape = "grasper" ([[tool]] posed by the scene): two capsule jaws (radius, length) either side of the tool's
  /// position along its local x, their axes along its local z, `opening` apart (the gap between their surfaces)
  bool grasper = false;
  /// A grasper driven by a device: its jaws' gap with the button up (opening) and held (grip), m, and the time they
  /// take from one to the other, s
  double opening = 0, grip = 0, grip_time = 0.2;
  double length = 0;              ///< capsule: its axis segment, m, along the tool's local z
  double friction = 0;            ///< Coulomb's coefficient on the surface
  bool object_stiffness = false;  ///< local_stiffness = "object" (else "contact"): ProbeParams::object_stiffness
  bool non_negative_surface_map =
      false;                  ///< surface_map = "non_negative" (else "exact"): ProbeParams::non_negative_surface_map
  double sample_spacing = 0;  ///< m (0: 1.2 x the tool's radius): ProbeParams::sample_spacing
  int line = 0;
  bool held() const { return present && position.allFinite(); }
};

/// [device]: which device drives the probe.
struct DeviceSpec {
  std::string kind = "virtual";  ///< virtual | replay | openhaptics | haply
  std::string specs = "touch";   ///< touch | omni | falcon | custom
  double max_force = 0, max_stiffness = 0, max_damping = 0, workspace_radius = 0;  ///< custom specs
  double max_torque = 0;             ///< custom specs: the largest torque it renders, N m (0: none)
  std::string log;                   ///< replay: a recorded session (resolved path)
  std::string library = "libHD.so";  ///< openhaptics: the HD library to load
  /// openhaptics: the device's configuration name in OpenHaptics' set-up ("Left Device"; empty: the default
  /// device), so that two Touch devices drive two tools
  std::string hd_device;
  /// haply: the Inverse Service's simulation channel (ws://host:port) and the Inverse3 to drive (empty: the first)
  std::string host = "127.0.0.1";
  int port = 10001;
  std::string device_id;
  bool passivity_control = true;  ///< ForceRules::passivity_control
};

/// [[tool]] (issue 47): a named tool. Held at a `position`, or moved along `keyframes` by the scene (both in scene
/// axes: a posed tool), or driven by the [[device]] it names (then it takes every [probe] key, its keyframes being
/// the virtual device's script as [probe]'s are).
struct ToolSpec {
  std::string name;
  ProbeSpec probe;  ///< its shape and contact's settings, and a held tool's position, as [probe]'s
  /// A posed tool moved by the scene: keyframes (t, x, y, z), where it is (scene axes, m), linear in between and
  /// held after the last (empty: held at probe.position, or driven by a device)
  std::vector<std::array<double, 4>> path;
  /// A grasper: the gap between its jaws' surfaces, m: one value held at `position`, or one per keyframe (the 5th
  /// value of [t, x, y, z, opening]), linear in between
  std::vector<double> opening;
  std::string device;  ///< the [[device]] that drives it (empty: posed by the scene)
  int line = 0;
};

/// A second or later device-driven [[tool]] (issue 47: two hands): its keys and its [[device]]'s.
struct SceneHand {
  std::string name;
  ProbeSpec probe;
  DeviceSpec device;
};

/// [[device]] (issue 47): a named device, with [device]'s keys, that a [[tool]] names.
struct DeviceTable {
  std::string name;
  DeviceSpec spec;
  int line = 0;
};

/// [lod]: levels of detail around the contact point (design.md, "Levels of detail").
struct LodSpec {
  bool present = false;
  LodParams params;
  Vec3 contact = Vec3::Constant(NAN);  ///< reference position of the contact, m (NaN: the probe, else the point load)
  int line = 0;
};

/// [[cut]]: a scripted blade (issue 18). Its cutting edge, the segment edge[0]-edge[1] at `start`, moves
/// linearly to to[0]-to[1] over `duration`, and cuts the object where it passes (mechanics/cut.hpp).
struct CutSpec {
  std::array<Vec3, 2> edge{Vec3::Zero(), Vec3::Zero()};  ///< m, scene axes
  std::array<Vec3, 2> to{Vec3::Zero(), Vec3::Zero()};    ///< m, scene axes
  double start = 0;                                      ///< s
  double duration = 0;                                   ///< s (0: the whole sweep at once, at `start`)
  /// The [[object]] it cuts (required with several: a blade drawn through two layers cuts only the one named;
  /// empty with one object)
  std::string object;
  int line = 0;
};

/// [[obstacle]]: a static rigid body the object rests on or is pressed against (issue 47): a plane (the
/// half-space below it, a table), a box, a sphere or a capsule. Its contact is on the object's surface, met as
/// a held tool's is (an augmented Lagrangian in static solves, a penalty in dynamics), with Coulomb friction.
enum class ObstacleShape { PLANE, BOX, SPHERE, CAPSULE };
struct ObstacleSpec {
  std::string name;
  ObstacleShape shape = ObstacleShape::PLANE;
  Vec3 point = Vec3::Zero();                             ///< plane: a point on it, m
  Vec3 normal = Vec3::UnitY();                           ///< plane: unit, out of the obstacle
  Aabb box;                                              ///< box: its corners, m (scene axes)
  Vec3 centre = Vec3::Zero();                            ///< sphere
  std::array<Vec3, 2> ends{Vec3::Zero(), Vec3::Zero()};  ///< capsule: its axis segment's ends, m
  double radius = 0;                                     ///< sphere, capsule, m
  double friction = 0;                                   ///< Coulomb's coefficient with the object
  /// Moved along keyframes (t, dx, dy, dz): its translation from where the shape puts it, m, linear in between
  /// and held after the last (empty: static)
  std::vector<std::array<double, 4>> keyframes;
  int line = 0;
};

/// [[object]]: one of several deformable bodies (issue 47). Its keys are [object]'s, with a `name` and an optional
/// `material` table (the keys it omits are the scene's [material]'s).
struct BodySpec {
  std::string name;
  ObjectSpec object;
  MaterialParams material;
};

/// [contact]: the contact between the bodies of several [[object]] tables (issue 47).
struct ContactSpec {
  double friction = 0;  ///< Coulomb's coefficient between any two bodies
  struct Pair {
    std::array<std::string, 2> bodies;
    double friction = 0;
  };
  std::vector<Pair> pairs;  ///< per pair of bodies, over `friction`
  int line = 0;
};

struct Scene {
  std::string path;  ///< the scene file ("<string>" when parsed from text), for messages
  /// With [[object]] tables, every body (`object` and `material` are then the first's); empty with one [object].
  std::vector<BodySpec> bodies;
  ObjectSpec object;
  MaterialParams material;
  KernelParams kernel;
  std::vector<FixedSpec> fixed;
  std::vector<RegionSpec> regions;
  std::vector<RefineSpec> refine;
  std::vector<LoadSpec> loads;
  std::vector<CutSpec> cuts;
  std::vector<ObstacleSpec> obstacles;
  /// [[tool]] tables: the posed ones (position or keyframes); the first driven by a device is `probe` and
  /// `device`, the others other_hands
  std::vector<ToolSpec> tools;
  std::vector<DeviceTable> devices;  ///< [[device]] tables
  ContactSpec contact;
  SolverSpec solver;
  ProbeSpec probe;
  std::string probe_name;  ///< the [[tool]] the probe was given as (empty: [probe])
  DeviceSpec device;
  /// The device-driven [[tool]]s after the first (which is `probe` and `device`), in the file's order
  std::vector<SceneHand> other_hands;
  LodSpec lod;
};

}  // namespace pointhaptics
