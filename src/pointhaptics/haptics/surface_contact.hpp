#pragma once
/// @file A tool against the object's surface (issue 16): the surface's vertices, carried by the points
/// (y = Y + W u), may not enter the tool. The constraint is met by an augmented Lagrangian: each vertex
/// carries a multiplier lambda_v (its contact force, N) and a penalty k_v, and the energy
///   E(u) = sum_v (<lambda_v + k_v g_v>^2 - lambda_v^2) / (2 k_v),  g_v = radius - |y_v - core(y_v)|,
/// (<x> = max(x, 0)) is minimised with the material's; between minimisations lambda_v <- <lambda_v + k_v g_v>
/// (Uzawa), until no vertex is inside the tool by more than the tolerance. A penalty alone would need a
/// stiffness that makes the tangent ill conditioned to reach the 1% of the depth; the multipliers
/// reach any tolerance with a penalty of the object's own stiffness. Forces on the vertices reach the points
/// by W^T (virtual work), and the tool feels their opposite.
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/geometry/triangle_mesh.hpp>
#include <pointhaptics/haptics/tool_shape.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>
#include <pointhaptics/solvers/newton.hpp>

#include <vector>

namespace pointhaptics {

struct SurfaceContactParams {
  /// Penalty per unit of the vertex's area, N/m^3 (0: 1000 E / spacing). The multipliers meet the constraint
  /// whatever it is; a stiffer one needs fewer updates (measured on the contact experiment's block: 10 E /
  /// spacing took 51+ updates, 100 E / spacing 13, 1000 E / spacing 5) and CG's iterations did not grow.
  double penalty = 0;
  /// Largest penetration of a vertex into the tool at which the constraint counts as met, m (0: 1e-4 of
  /// the tool's radius).
  double tolerance = 0;
  /// If > 0, N/m: the penalty is lowered so that no point's contact stiffness (sum_v k_v w_vj^2) exceeds it
  /// (explicit dynamics, whose stable sub-step it would otherwise shorten).
  double max_point_stiffness = 0;
};

/// What the object does to the tool.
struct ToolLoad {
  Vec3 force = Vec3::Zero();   ///< N, on the tool, scene axes
  Vec3 torque = Vec3::Zero();  ///< N m, about the tool's position
  int contacts = 0;            ///< vertices pressing on it
  double penetration = 0;      ///< deepest vertex inside the tool, m (0: none)
  /// d force / d tool position with the object held still, N/m: -sum_v k_v n_v n_v^T over the pressing
  /// vertices (negative semi-definite; the tool's curvature term, which would make it indefinite, left out)
  Mat3 stiffness = Mat3::Zero();
};

class SurfaceContact final : public EnergyTerm {
 public:
  /// `mesh`: the surface's reference triangles (its vertices Y), `map` carries them with `model`'s points.
  SurfaceContact(const Model& model, const TriangleMesh& mesh, SurfaceMap map, const ToolShape& shape,
                 const SurfaceContactParams& params = {});

  void set_pose(const ToolPose& pose) { pose_ = pose; }
  const ToolPose& pose() const { return pose_; }
  const ToolShape& shape() const { return shape_; }
  double tolerance() const { return tolerance_; }

  double energy(const Model& model, const Points& u) override;
  void add_forces(const Model& model, const Points& u, Points& f) override;
  void linearise(const Model& model, const Points& u, TangentMode mode) override;
  void add_tangent_product(const Points& dx, Points& out) const override;
  void add_diagonal_blocks(Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks) const override;
  /// Uzawa's update at u: true (multipliers kept) when no vertex is deeper in the tool than the tolerance.
  bool update_multipliers(const Model& model, const Points& u) override;

  /// The load on the tool at u (its multipliers and penalty as they are); same_u: u is the last evaluation's,
  /// whose carried surface is reused (the probe's placement tries several positions on one state).
  ToolLoad load(const Model& model, const Points& u, bool same_u = false);
  /// The load of the last add_forces(), which computes it on the way.
  const ToolLoad& last_load() const { return last_load_; }
  /// Forget the multipliers (the tool lifted off, or moved far).
  void reset_multipliers();
  /// Upper bound of the contact's stiffness on one point, N/m (explicit stable step): max_j sum_v k_v w_vj^2.
  double max_point_stiffness() const { return max_point_stiffness_; }
  /// The deformed vertices of the last evaluation.
  const Points& vertices() const { return y_; }
  const SurfaceMap& map() const { return map_; }

 private:
  struct Active {
    index_t vertex;
    Vec3 normal;
    double pressure;  // <lambda + k g>, N
    Mat3 hessian;     // d2E/dy2 at the vertex
  };
  /// y = Y + W u, the vertices that can touch the tool, and their contact values.
  void evaluate(const Points& u);
  /// The load of the vertices pressing on the tool at y_, calling pressing(v, distance, pressure) for each.
  template <class Pressing>
  ToolLoad for_each_pressing(const Pressing& pressing) const;

  Points Y_, y_;
  SurfaceMap map_;
  ToolShape shape_;
  ToolPose pose_;
  std::vector<double> penalty_, lambda_;  // per vertex
  std::vector<Active> active_;            // at the last linearise()
  ToolLoad last_load_;
  double tolerance_ = 0, max_point_stiffness_ = 0;
};

}  // namespace pointhaptics
