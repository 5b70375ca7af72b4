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
///
/// Coulomb friction (friction > 0) is met the same way (Simo and Laursen's augmented Lagrangian): a pressing
/// vertex sticks to an anchor on the tool (kept in the tool's frame, so it follows the tool), and adds
///   E_t = sum_v (|tau_v + k_v s_v|^2 - |tau_v|^2) / (2 k_v),  s_v = P_v (y_v - anchor_v),
/// with P_v the projection off the normal frozen at the last update, while the trial force t = tau_v + k_v s_v
/// lies in the cone |t| <= friction x lambda_v (stick), and linear in |t| beyond it (slip: the force stays on
/// the cone, so a slide is one minimisation). Between minimisations tau_v takes the trial force (put on the
/// cone, the anchor then moving to the vertex); the solve is done when no sticking vertex strays from its
/// anchor, and no sliding one's force changes, by more than the tolerance's worth of penalty.
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/geometry/mesh_distance.hpp>
#include <pointhaptics/geometry/triangle_mesh.hpp>
#include <pointhaptics/haptics/contact_samples.hpp>
#include <pointhaptics/haptics/tool_shape.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>
#include <pointhaptics/solvers/newton.hpp>

#include <array>
#include <memory>
#include <optional>
#include <span>
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
  /// Coulomb's coefficient (0: frictionless). The static solver meets it by Uzawa's updates, dynamics by
  /// one update a step (advance_multipliers).
  double friction = 0;
  /// The friction's penalty over the normal one. For the static solver a hundredth: the full penalty puts
  /// the stick-slip kink within c / k of the anchor (1e-7 m on the contact experiment's block) and Newton's
  /// iterations ran out on the first drag; the multipliers meet the stick exactly whatever it is. In
  /// dynamics, with one multiplier update a step, that small a share left a vertex that starts to touch
  /// sticking for tens of steps while its force grew to the cone (friction 5% short of mu x pressure on a
  /// slide); a device's probe uses a tenth.
  double tangential_share = 0.01;
  /// With levels of detail: each object point's contact stiffness with the whole surface (N/m,
  /// SurfaceContact::point_stiffness()), and `penalty` the whole surface's. A part of the surface an active set
  /// carries (probe_surface_contact()) then presses as the whole one does, lowered only at the vertices of a
  /// point that would press stiffer than it does on the whole surface (limit_point_stiffness()).
  std::shared_ptr<const std::vector<double>> object_point_stiffness;
  /// The contact's map without its negative weights (without_negative_weights()) instead of the surface's
  /// exact one. The surface lies half a spacing beyond the outer points, so the exact map extrapolates to it:
  /// a vertex moves by about 1.4 of its outer points' displacement less 0.4 of the next layer's (the negative
  /// weights sum to -0.35 on average at the 100k half-sphere's pole), and a force pushing a vertex out of the
  /// tool pulls that layer into it. With the multipliers pressing as hard as the material, a probe 3.6
  /// spacings wide squeezed the layers under it until they were crushed (scenes/half_sphere_100k_lod.toml
  /// diverged at 2.2 s of its deterministic run; with this map it is calm). Not the default: on the coarse
  /// soft dome (a probe 1.5 spacings wide) its real-time soak diverged in 2 of 3 runs (docs/haptics.md).
  bool non_negative_weights = false;
  /// Largest distance between the contact's samples along the surface's edges, m (0: default_sample_spacing
  /// times the tool's radius). Longer edges get samples at their midpoints (haptics/contact_samples.hpp), so
  /// that the tool cannot pass between the surface's vertices. Negative: the vertices only.
  double sample_spacing = 0;
  /// Carry only the vertices that can touch the tool: those within its reach of it by a bound on how far the
  /// displacement moved them (or, for a plane, not above it by that bound), and those whose multiplier or
  /// friction is in force; the others are put far outside it, where every evaluation skips them. For obstacles
  /// and posed tools, which read no vertex but those: carrying every vertex of every body at every explicit
  /// sub-step was a seventh of a three-body run. A device's probe culls too, with a margin (cull_margin) that covers
  /// the moves its god-object tries within a step (enters(), side_of(): they read the triangles whose vertices are
  /// all carried).
  bool cull_far_vertices = false;
  /// With cull_far_vertices: how much farther than the tool's reach a vertex is still carried, m (a probe's
  /// placement tries positions up to two radii from where the step found it).
  double cull_margin = 0;
};

/// A sphere fits through a triangle whose circumradius exceeds its radius, touching none of its vertices. At
/// edges of at most 1.2 radii a triangle's circumradius is at most 0.6 radius (half its longest edge when
/// right-angled, 0.69 radius when equilateral), so the tool dips at most 0.2-0.28 of its radius below a face
/// before a sample touches it, and the lattice's right triangles under a tool wider than their diagonal get
/// none: samples under such a tool (scenes/beam_probe.toml, 10.6 mm diagonals under a 10 mm probe, split once
/// at a spacing of one radius) let its rolling probe through the beam at 1.3 s, where without them it rolls on
/// top.
inline constexpr double default_sample_spacing = 1.2;

/// What the object does to the tool.
struct ToolLoad {
  Vec3 force = Vec3::Zero();     ///< N, on the tool, scene axes
  Vec3 friction = Vec3::Zero();  ///< N: the part of `force` friction makes (the rest is the normal pressure's)
  Vec3 torque = Vec3::Zero();    ///< N m, about the tool's position
  int contacts = 0;              ///< vertices (and samples, SurfaceContactParams::sample_spacing) pressing on it
  double penetration = 0;        ///< deepest vertex inside the tool, m (0: none)
  /// d force / d tool position with the object held still, N/m: -sum_v k_v n_v n_v^T over the pressing
  /// vertices (negative semi-definite; the tool's curvature term, which would make it indefinite, left out)
  Mat3 stiffness = Mat3::Zero();
};

class SurfaceContact final : public EnergyTerm {
 public:
  /// `mesh`: the surface's reference triangles (its vertices Y), `map` carries them with `model`'s points.
  SurfaceContact(const Model& model, const TriangleMesh& mesh, SurfaceMap map, const ToolShape& shape,
                 const SurfaceContactParams& params = {});

  /// Moves the tool; the pose it leaves is kept for friction (a vertex touching during the move is anchored
  /// as if it had touched before it, so it slides at once as the tool moves on it).
  void set_pose(const ToolPose& pose) {
    previous_pose_ = posed_ ? pose_ : pose;
    pose_ = pose;
    posed_ = true;
  }
  const ToolPose& pose() const { return pose_; }
  const ToolShape& shape() const { return shape_; }
  double tolerance() const { return tolerance_; }

  double energy(const Model& model, const Points& u) override;
  void add_forces(const Model& model, const Points& u, Points& f) override;
  void linearise(const Model& model, const Points& u, TangentMode mode) override;
  void add_tangent_product(const Points& dx, Points& out) const override;
  void add_diagonal_blocks(Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks) const override;
  /// Each pressing vertex's positive part P coupled over the points that carry it, w_j w_k P: the Cholesky
  /// preconditioner's factor then holds the contact's stiffness as it is (at a sample its parents' rows, each
  /// weighted by b_k, a bound of the sample's own row in the same way as its squared weights).
  bool add_to_matrix(TangentMatrix& K) const override;
  /// The tool's coupling to the points, at the last linearise(): b += W^T sum_v H_v e, the load on the points
  /// when the tool moves by e with them held (H_v the vertex's positive stiffness, k_v n_v n_v^T pressing, the
  /// friction's sticking); returns sum_v H_v, the tool's stiffness against the held object.
  Mat3 add_tool_load(const Vec3& e, Points& b) const;
  /// The other side of that coupling: sum_v H_v W_v x, the force the vertices' stiffness makes on the tool when
  /// the points move by x (so B^T x, with B's columns add_tool_load() of the axes).
  Vec3 tool_response(const Points& x) const;
  /// Uzawa's update at u: true (multipliers kept) when no vertex is deeper in the tool than the tolerance.
  bool update_multipliers(const Model& model, const Points& u) override;
  /// Before a static solve's first minimisation, which has no multiplier yet:
  /// - with friction, anchor every vertex pressing into the tool at u that has no anchor yet, sticking without a
  ///   bound until the next update_multipliers() (which puts it on its cone). It then holds a body that only this
  ///   tool's friction holds (two tools pinching it under gravity), where a cone of friction x 0 would let it fall
  ///   without end (the body contact's fresh pairs alike);
  /// - the next linearise() counts the vertices touching the tool as pressing (kink_tangent_).
  void begin_static_solve(const Points& u);

  /// The load on the tool at u (its multipliers and penalty as they are); same_u: u is the last evaluation's,
  /// whose carried surface is reused (the probe's placement tries several positions on one state).
  ToolLoad load(const Model& model, const Points& u, bool same_u = false);
  /// The load of the last add_forces(), which computes it on the way.
  const ToolLoad& last_load() const { return last_load_; }
  /// The point that carries most of each vertex pressing on the tool at the last evaluation (out is cleared).
  void pressing_points(std::vector<index_t>& out) const;
  /// The object surface's vertex each of the surface's vertices given to the constructor is (a part of the
  /// surface, with levels of detail; by default the whole surface, in its order): the samples' keys follow.
  void set_vertex_ids(const std::vector<index_t>& ids);
  /// The multipliers and anchors of `other` (the same tool on another part of the same object surface, or
  /// the same part over other points) for the vertices both have: a new active set keeps the proxy's force.
  void take_multipliers(const SurfaceContact& other);
  /// Forget the multipliers and the friction's anchors (the tool lifted off, or moved far).
  void reset_multipliers();
  /// Uzawa's update spread over time (a tool in dynamics, once a step, at the state and pose of the last
  /// load()): lambda_v <- <lambda_v + rate k_v g_v>, then all scaled down if they press on the tool with more
  /// than `max_force` together; the friction's anchors as update_multipliers() moves them. Returns the load on
  /// the tool then.
  ToolLoad advance_multipliers(double rate, double max_force);
  double friction() const { return friction_; }
  /// The contact's stiffness on one point, N/m (explicit stable step): max_j sum_v k_v w_vj^2, the largest
  /// diagonal of its stiffness on the points (an estimate, not a strict bound: the largest eigenvalue is above
  /// it where a vertex is carried by several points).
  double max_point_stiffness() const { return max_point_stiffness_; }
  /// N/m^3: the penalty per unit area the vertices took (params.penalty or its default, lowered to the cap).
  double per_area_penalty() const { return per_area_penalty_; }
  /// Each point's contact stiffness sum_v k_v w_vj^2 (N/m, per point of a model of n_points).
  std::vector<double> point_stiffness(index_t n_points) const;
  /// Lowers each vertex's penalty by the largest excess of its points' stiffness over `limit` (N/m per point
  /// of the model), but never below the uniform scale that brings the stiffest point to `cap`: every point then
  /// presses at most max(limit_j, cap), and no vertex softer than a uniform lowering would make it (cap <= 0:
  /// no cap, and nothing is lowered).
  void limit_point_stiffness(std::span<const double> limit, double cap);
  /// The deformed vertices of the last evaluation: the surface's, then the samples.
  const Points& vertices() const { return y_; }
  /// How many of them are the surface's own vertices (the rest are samples on its triangles).
  index_t surface_vertices() const { return n_surface_; }
  /// How many times the surface's triangles were split for the samples (0: none).
  int sample_levels() const { return sample_levels_; }
  /// Whether the segment from-to enters the surface as the last evaluation carried it: crosses a triangle
  /// from its outer side to its inner one. The tool's core may not (the god-object's rule): a tool that has
  /// pushed a coarse surface's vertices aside can hold none inside it, and so pass through unseen.
  bool enters(const Vec3& from, const Vec3& to) const;
  /// Where p is seen from the surface as the last evaluation carried it (nearest_surface_within()).
  std::optional<SurfaceSide> side_of(const Vec3& p, double radius) const {
    return nearest_surface_within(p, y_, cull_ ? near_triangles_ : triangles_, radius);
  }
  /// The contact's map of the surface's vertices: the surface's, or without its negative weights
  /// (SurfaceContactParams::non_negative_weights). The samples are carried through it by their vertices.
  const SurfaceMap& map() const { return map_; }

 private:
  struct Active {
    index_t vertex;
    Vec3 normal;
    double pressure;      // <lambda + k g>, N
    Mat3 hessian;         // d2E/dy2 at the vertex
    Mat3 preconditioner;  // its positive part
  };
  /// A vertex stuck to the tool (friction): where, in the tool's frame, the projection off the normal frozen
  /// at the last update, and the tangential multiplier.
  struct Anchor {
    Vec3 local = Vec3::Zero();
    Mat3 tangent = Mat3::Zero();
    Vec3 tau = Vec3::Zero();
    bool held = false;
    bool fresh = false;  ///< begin_static_solve()'s, before its first update: its cone has no bound
  };
  /// The friction's trial force on the tool from an anchored vertex v at y_: tau + k s.
  Vec3 friction_trial(index_t v) const;
  /// The friction's penalty: tangential_share of the normal one.
  double tangential_penalty(index_t v) const;
  /// Its cone's radius: friction x the vertex's normal multiplier.
  double friction_cone(index_t v) const;
  /// The force itself: the trial force put on the cone when beyond it.
  Vec3 friction_force(index_t v) const;
  /// Its derivative by the vertex's position (minus its derivative by the tool's).
  Mat3 friction_hessian(index_t v) const;
  /// Uzawa's update of vertex v's anchor and tangential multiplier (at distance d from the tool), on its
  /// normal multiplier as it now is: freed when that is 0, anchored when it starts to press, its force put on
  /// the cone (the anchor following the vertex) when beyond it.
  void advance_anchor(index_t v, const ToolDistance& d);
  /// y = Y + W u, the vertices that can touch the tool, and their contact values.
  void evaluate(const Points& u);
  /// evaluate() of the vertices that can touch the tool (SurfaceContactParams::cull_far_vertices): the candidates
  /// select_candidates() chose, chosen again when the tool or the displacement's bound has moved past their skin
  void evaluate_near(const Points& u);
  /// The vertices and samples within the tool's reach, the margin and the skin by the displacement's bound `largest`
  /// (and those with a multiplier or friction in force), the triangles among them; the rest put far outside.
  void select_candidates(double largest);
  /// Each vertex or sample a loop over the contact must visit: the candidates when culling (the rest are far
  /// outside, with no multiplier or friction), else all.
  template <class Fn>
  void for_each_candidate(const Fn& fn) const {
    if (cull_)
      for (const index_t v : candidates_) fn(v);
    else
      for (index_t v = 0; v < y_.cols(); ++v) fn(v);
  }
  /// The load of the vertices pressing on the tool at y_, calling pressing(v, distance, pressure) for each.
  template <class Pressing>
  ToolLoad for_each_pressing(const Pressing& pressing, bool touching = false) const;

  SurfaceContact(const Model& model, const TriangleMesh& surface, SurfaceMap map, ContactSamples samples,
                 const ToolShape& shape, const SurfaceContactParams& params);
  /// fn(vertex, b) for the surface's vertices that make vertex or sample v: v itself with b = 1, or the
  /// sample's vertices with their weights.
  template <class Fn>
  void for_each_surface_vertex(index_t v, const Fn& fn) const;
  /// fn(point, weight) for every point that carries vertex or sample v: a sample's vertices' rows times its
  /// weights (a point can come more than once).
  template <class Fn>
  void for_each_weight(index_t v, const Fn& fn) const;
  /// fn(point, bound of weight^2): a vertex's own squares; a sample's, sum_k b_k w_kj^2, which is at least
  /// (sum_k b_k w_kj)^2 (the b_k are >= 0 and sum to 1): the stiffness caps and the preconditioner's blocks
  /// are then upper bounds at the samples, and no merged row is made.
  template <class Fn>
  void for_each_squared_weight(index_t v, const Fn& fn) const;

  Points Y_, y_;                                   // the surface's vertices, then the samples
  std::vector<std::array<index_t, 3>> triangles_;  // the surface's, counter-clockwise seen from outside
  std::vector<ContactSample> samples_;             // each a combination of the surface's vertices
  std::vector<std::array<index_t, 2>> parents_;    // each sample's two ends (ContactSamples::parents)
  std::vector<std::uint64_t> keys_;                // each vertex's and sample's name on the whole surface
  index_t n_surface_ = 0;
  bool cull_ = false;  ///< SurfaceContactParams::cull_far_vertices
  /// The next linearise() counts a vertex touching with no multiplier (at the kink) as pressing: the first of a
  /// static solve (begin_static_solve()), where a body resting exactly on an obstacle has no stiffness under it
  /// otherwise (two blocks stacked on a table: the first iteration's CG diverged). Only the first: at every
  /// linearisation it made the shipped block on a table stall at 0.91 of its load
  bool kink_tangent_ = false;
  double cull_margin_ = 0;  ///< SurfaceContactParams::cull_margin
  /// culling: the vertices and samples carried (select_candidates()), in order, and the triangles whose vertices are
  /// all among them (the rest reach far outside); where the tool was and the displacement's bound when they were
  /// chosen, their skin, and the largest sum |w| of a vertex
  std::vector<index_t> candidates_;
  std::vector<std::array<index_t, 3>> near_triangles_;
  Vec3 candidate_position_ = Vec3::Constant(NAN);
  double candidate_largest_ = 0, candidate_skin_ = 0, max_weight_l1_ = 0;
  std::vector<double> weight_l1_;  ///< per vertex and sample, sum |w| of its map's row (samples: their parents')
  std::vector<char> carried_;      ///< evaluate()'s scratch: which vertices and samples it carries
  /// the points the candidates' maps read (each once; point_marked_ flags them), and their u when the candidates
  /// were last carried (candidate_u_current_): the vertices stand while those have not moved
  std::vector<index_t> candidate_points_;
  std::vector<char> point_marked_;
  Points candidate_u_;
  bool candidate_u_current_ = false;
  int sample_levels_ = 0;
  SurfaceMap map_;
  ToolShape shape_;
  ToolPose pose_, previous_pose_;
  std::vector<double> penalty_, lambda_;  // per vertex
  std::vector<Anchor> anchors_;           // per vertex, with friction
  std::vector<Active> active_;            // at the last linearise()
  ToolLoad last_load_;
  double tolerance_ = 0, max_point_stiffness_ = 0, per_area_penalty_ = 0, friction_ = 0, tangential_share_ = 0.01;
  bool posed_ = false;
};

}  // namespace pointhaptics
