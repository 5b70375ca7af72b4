#pragma once
/// @file Contact between deformable bodies (issue 47): the carried surface of each body may not enter another's.
/// Each surface vertex v near another body is paired with that body's nearest triangle t (its outward unit normal
/// n, the nearest point's barycentric coordinates beta), and its gap
///   g_v = n . (y_v - sum_b beta_b y_tb),  y = Y + W u,
/// is positive outside. The pairing (t, n, beta) is frozen between refreshes (each step, each multiplier update),
/// so g_v is linear in u and the energy below is exactly the one the forces and the tangent come from. As a
/// tool's surface contact (haptics/surface_contact.hpp), the constraint g_v >= 0 is met by an augmented Lagrangian,
///   E(u) = sum_v (<lambda_v - k_v g_v>^2 - lambda_v^2) / (2 k_v),
/// with Uzawa's update lambda_v <- <lambda_v - k_v g_v> until no vertex is inside by more than the tolerance
/// (static solves), or once a step (dynamics). Both directions are paired (a vertex of A on B's faces and one of B
/// on A's), so neither body's mesh decides alone. The force on v is F_v n and the triangle's vertices carry
/// -F_v beta_b n: equal and opposite, so the bodies' momentum is conserved exactly, and both reach the points
/// by W^T.
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/geometry/spatial_grid.hpp>
#include <pointhaptics/geometry/triangle_mesh.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>
#include <pointhaptics/solvers/newton.hpp>
#include <pointhaptics/solvers/solver.hpp>

#include <array>
#include <vector>

namespace pointhaptics {

struct BodyContactParams {
  /// Penalty per unit of a vertex's area, N/m^3 (0: 1000 E / spacing, E the softer body's; as a tool's contact).
  double penalty = 0;
  /// Largest penetration at which the constraint counts as met, m (0: a thousandth of the finest spacing).
  double tolerance = 0;
  /// If > 0, N/m: the penalty is lowered so that no point's contact stiffness exceeds it (explicit dynamics).
  double max_point_stiffness = 0;
  /// How far from another body a vertex is paired with it, m (0: the finest spacing): a pair is kept a whole
  /// step, so a vertex closer than this at its start is watched through it.
  double reach = 0;
  /// Dynamics: the share of the penetration's penalty force the multipliers take each step (their Uzawa update
  /// spread over time), so that a body at rest on another sinks into it by the tolerance, not by its weight
  /// over the penalty.
  double multiplier_rate = 0.2;
};

/// What the contact does to each body, N (scene axes): the sum of the forces the others exert on it.
struct BodyLoads {
  std::vector<Vec3> force;  ///< per body
  int contacts = 0;         ///< pressing vertices
  double penetration = 0;   ///< deepest vertex inside another body, m (0: none)
};

class BodyContact final : public DynamicForces, public EnergyTerm {
 public:
  /// `mesh`: every body's reference surface, body k's vertices [vertex_start[k], vertex_start[k + 1]) and
  /// triangles [face_start[k], face_start[k + 1]); `map` carries them with `model`'s points.
  BodyContact(const Model& model, TriangleMesh mesh, SurfaceMap map, std::vector<index_t> vertex_start,
              std::vector<index_t> face_start, const BodyContactParams& params = {});

  /// Pair the vertices with the other bodies' nearest triangles at u (and keep the multipliers of the vertices
  /// that stay paired).
  void refresh(const Model& model, const Points& u);
  /// The loads on the bodies at u, with the pairs and multipliers as they are.
  BodyLoads loads(const Model& model, const Points& u) const;
  double tolerance() const { return tolerance_; }
  index_t pairs() const { return static_cast<index_t>(pairs_.size()); }

  // DynamicForces: explicit steps evaluate the term at each sub-step; the pairs are refreshed after each step
  void add(const Model& model, const State& state, Points& f) override;
  double max_point_stiffness() const override { return max_point_stiffness_; }
  EnergyTerm* energy_term() override { return this; }
  void after_step(const Model& model, const State& state, Workspace& ws) override;

  // EnergyTerm
  double energy(const Model& model, const Points& u) override;
  void add_forces(const Model& model, const Points& u, Points& f) override;
  void linearise(const Model& model, const Points& u, TangentMode mode) override;
  void add_tangent_product(const Points& dx, Points& out) const override;
  void add_diagonal_blocks(Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks) const override;
  /// Each pressing pair's k (c c^T) (x) n n^T over its points, for the Cholesky preconditioner: the two bodies'
  /// points are not neighbours, so the coupling across them is lumped on the diagonal (add_coupling()), a bound.
  bool add_to_matrix(TangentMatrix& K) const override;
  bool update_multipliers(const Model& model, const Points& u) override;

 private:
  /// A vertex paired with another body's triangle: g = gap0 + n . sum_j c_j u_j over its points j.
  struct Pair {
    index_t vertex = 0, triangle = 0;
    Vec3 normal = Vec3::Zero();
    double gap0 = 0;              ///< the gap at u = 0 with this pairing, m
    double stiffness = 0;         ///< k_v, N/m
    double multiplier = 0;        ///< lambda_v, N
    index_t first = 0, last = 0;  ///< its coefficients: coefficient_[first, last)
  };
  double gap(const Pair& p, const Points& u) const;
  /// The pair's pressing force F = <lambda - k g> at gap g, N.
  static double pressing(const Pair& p, double g) { return std::max(0.0, p.multiplier - p.stiffness * g); }
  index_t body_of_vertex(index_t v) const;
  index_t body_of_face(index_t t) const;

  TriangleMesh mesh_;
  SurfaceMap map_;
  std::vector<index_t> vertex_start_, face_start_;
  std::vector<double> vertex_stiffness_;  ///< k_v, N/m
  double tolerance_ = 0, reach_ = 0, rate_ = 0.2, max_point_stiffness_ = 0, max_circumradius_ = 0;
  bool refreshed_ = false;

  std::vector<Pair> pairs_;
  std::vector<std::pair<index_t, double>> coefficient_;  ///< (point j, c_j) of every pair
  // refresh's scratch
  Points y_, centroid_;
  Points vertex_normal_;
  SpatialGrid grid_;
  std::vector<double> previous_multiplier_;  ///< per vertex, across a refresh
  std::vector<char> pressing_;               ///< per pair, at the last linearise()
};

}  // namespace pointhaptics
