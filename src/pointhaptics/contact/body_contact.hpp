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
///
/// Coulomb friction (Simo and Laursen's augmented Lagrangian, as a tool's): a pressing vertex is anchored to a
/// point of the other body's surface (a triangle and barycentric coordinates, so the anchor moves with that
/// body), its slip s_v = P_v (y_v - anchor) with P_v = I - n n^T, and
///   E_t = sum_v (|tau_v + k_t s_v|^2 - |tau_v|^2) / (2 k_t)
/// while the trial force t = tau_v + k_t s_v lies in the cone |t| <= mu lambda_v (stick), linear in |t| beyond
/// it (slip: the force stays on the cone). Between minimisations tau_v takes the trial force (put on the cone,
/// and a sliding vertex's anchor moves to where it is); a static solve is done when no sticking vertex strays
/// from its anchor by more than the tolerance, and no sliding one's force changes by more than its worth.
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/geometry/spatial_grid.hpp>
#include <pointhaptics/geometry/triangle_mesh.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>
#include <pointhaptics/solvers/newton.hpp>
#include <pointhaptics/solvers/solver.hpp>

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace pointhaptics {

/// The multipliers' rates in explicit steps (BodyContactParams::multiplier_rate, friction_rate).
inline constexpr double explicit_contact_rate = 0.02;

struct BodyContactParams {
  /// Penalty per unit of a vertex's area, N/m^3 (0: 1000 E / spacing, E the vertex's body's; as a tool's contact).
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
  /// Dynamics: the share of the way to its trial force a sticking vertex's friction multiplier takes each step (a
  /// slide still goes onto the cone at once). Explicit steps lower both rates to 0.02: a rate that takes much of
  /// the way each step pumped energy into the contact's ringing (a block settling on another pressed on it with
  /// 0.13 to 2.3 times its weight, for good, and on a slope of 0.2 with friction 0.5 crept 7-10 mm/s; at 0.02 it
  /// settles to its weight within 0.2% and holds: Bodies.ABlockOnASlopeSettlesAndHoldsInExplicitSteps).
  double friction_rate = 1.0;
  /// Dynamics: the multipliers and the pairs are updated after each step. A static solve's equilibrium is met
  /// by its own updates (update_multipliers()), and one after it would move what it converged to.
  bool update_after_step = true;
  /// Coulomb's coefficient between any two bodies, and per pair of bodies (row-major, bodies x bodies,
  /// symmetric; empty: `friction` for all).
  double friction = 0;
  std::vector<double> pair_friction;
  /// The friction's penalty over the normal one (as a tool's contact: the multipliers meet the stick whatever it
  /// is, and a small one keeps the stick-slip kink out of Newton's way).
  double tangential_share = 0.01;
};

/// What the contact does to each body, N (scene axes): the sum of the forces the others exert on it.
struct BodyLoads {
  std::vector<Vec3> force;     ///< per body
  std::vector<Vec3> friction;  ///< per body: the part of `force` friction makes
  int contacts = 0;            ///< pressing vertices
  double penetration = 0;      ///< deepest vertex inside another body, m (0: none)
};

class BodyContact final : public DynamicForces, public EnergyTerm {
 public:
  /// `mesh`: every body's reference surface, body k's vertices [vertex_start[k], vertex_start[k + 1]) and
  /// triangles [face_start[k], face_start[k + 1]); `map` carries them with `model`'s points. A vertex touches the
  /// faces of every other piece of material (mechanics/cut.hpp's connected_pieces() of `model`: the other bodies,
  /// and the pieces cuts made of its own body, whose surface is then split along the cuts, cut_surface.hpp), so
  /// one body, cut in pieces, is enough.
  BodyContact(const Model& model, TriangleMesh mesh, SurfaceMap map, std::vector<index_t> vertex_start,
              std::vector<index_t> face_start, const BodyContactParams& params = {});

  /// Pair the vertices with the other bodies' nearest triangles at u (keeping the multipliers, and the anchors
  /// of the vertices whose friction is in force).
  void refresh(const Model& model, const Points& u);
  /// The loads on the bodies at u, with the pairs and multipliers as they are.
  BodyLoads loads(const Model& model, const Points& u) const;
  double tolerance() const { return tolerance_; }
  /// Body k's vertices are [vertex_start()[k], vertex_start()[k + 1]).
  const std::vector<index_t>& vertex_start() const { return vertex_start_; }
  /// Before the first refresh: take `from`'s multipliers, vertex v's from its vertex from_vertex[v] (-1: none),
  /// so that a contact rebuilt over a changed surface (split along a cut) goes on pressing as the last did.
  void carry_multipliers(const BodyContact& from, std::span<const index_t> from_vertex);
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
  /// Each pressing pair's blocks over its points, for the Cholesky preconditioner: the two bodies' points are
  /// not neighbours, so the coupling across them is lumped on the diagonal (add_coupling()), a bound.
  bool add_to_matrix(TangentMatrix& K) const override;
  bool update_multipliers(const Model& model, const Points& u) override;

 private:
  /// A vertex paired with another body's triangle: its gap g = gap0 + n . sum_j c_j u_j over its points j, and
  /// its slip from its anchor s = P (slip0 + sum_j d_j u_j).
  struct Pair {
    index_t vertex = 0, triangle = 0;
    Vec3 normal = Vec3::Zero();
    double gap0 = 0;                        ///< the gap at u = 0 with this pairing, m
    double stiffness = 0;                   ///< k_v, N/m
    double multiplier = 0;                  ///< lambda_v, N
    double friction = 0;                    ///< mu between its two bodies
    index_t first = 0, last = 0;            ///< its gap's coefficients c: coefficient_[first, last)
    Vec3 slip0 = Vec3::Zero();              ///< the vertex less its anchor at u = 0, m
    index_t slip_first = 0, slip_last = 0;  ///< its slip's coefficients d: coefficient_[slip_first, slip_last)
    bool pressing = false;                  ///< at the last linearise()
    Mat3 friction_hessian = Mat3::Zero();   ///< at the last linearise(), in the slip's space (P H P)
  };
  /// A vertex's friction: FRESH just paired while touching (it sticks until the first update: a static solve's
  /// first minimisation holds a body resting on another by these springs, where without them it could slide off
  /// under any sideways load), HELD in force (the cone mu lambda), FREE not pressing (none).
  enum class Friction : std::uint8_t { FREE, FRESH, HELD };
  /// Where a vertex's friction holds it: a point of another body's triangle, and the friction's multiplier.
  struct Anchor {
    index_t triangle = -1;  ///< -1: none
    std::array<double, 3> beta{0, 0, 0};
    Vec3 tau = Vec3::Zero();  ///< N, in the tangent plane
    Friction state = Friction::FREE;
    bool afresh = false;  ///< anchored afresh where the vertex is at the next refresh (a slide, a new pressure)
  };
  double gap(const Pair& p, const Points& u) const;
  Vec3 slip(const Pair& p, const Points& u) const;
  /// The pair's pressing force F = <lambda - k g> at gap g, N.
  static double pressing(const Pair& p, double g) { return std::max(0.0, p.multiplier - p.stiffness * g); }
  double tangential_stiffness(const Pair& p) const { return tangential_share_ * p.stiffness; }
  /// The friction cone's radius, N: mu lambda in force, unbounded while FRESH (a stick), 0 when FREE.
  double cone(const Pair& p) const {
    if (p.friction <= 0) return 0;
    switch (anchors_[static_cast<std::size_t>(p.vertex)].state) {
      case Friction::HELD: return p.friction * p.multiplier;
      case Friction::FRESH: return std::numeric_limits<double>::infinity();
      default: return 0;
    }
  }
  /// The trial force tau + k_t s at slip s, N.
  Vec3 trial(const Pair& p, const Vec3& s) const;
  /// The friction's force at slip s: the trial force put on the cone, N (on the vertex, against the slip).
  Vec3 friction_force(const Pair& p, const Vec3& s) const;
  /// visit(first, last, H) for each block of the tangent fixed by the last linearise(): a pressing pair's k n n^T
  /// over its gap's coefficients, a pair in friction's P H P over its slip's; the tangent is sum c c^T (x) H
  template <class Visit>
  void for_each_block(const Visit& visit) const;
  /// f_j += x_j along for the coefficients [first, last); and sum_j x_j y_j
  void spread(index_t first, index_t last, const Vec3& along, Points& f) const;
  Vec3 gather(index_t first, index_t last, const Points& y) const;
  /// Whether the stick and the slide are met at u; Coulomb's update at u (the multipliers and anchors).
  bool friction_met(const Points& u) const;
  void update_friction(const Points& u, double rate);
  index_t body_of_vertex(index_t v) const;
  index_t body_of_face(index_t t) const;
  /// The piece of material a vertex moves with (its first carrying point's; -1: carried by none) and a face's (its
  /// first corner's): a vertex is paired with the faces of the other pieces only.
  std::vector<index_t> vertex_piece_, face_piece_;
  /// the coefficients of y_v - sum_b beta_b y_{t_b} over the points (appended to coefficient_), and its value at u = 0
  Vec3 append_difference(index_t v, index_t triangle, const std::array<double, 3>& beta);

  TriangleMesh mesh_;
  SurfaceMap map_;
  std::vector<index_t> vertex_start_, face_start_;
  std::vector<double> vertex_stiffness_;  ///< k_v, N/m
  double tolerance_ = 0, reach_ = 0, rate_ = 0.2, friction_rate_ = 1.0, max_point_stiffness_ = 0, max_circumradius_ = 0;
  double tangential_share_ = 0.01;
  bool update_after_step_ = true;
  std::vector<double> pair_friction_;  ///< bodies x bodies
  bool refreshed_ = false;

  std::vector<Pair> pairs_;
  std::vector<std::pair<index_t, double>> coefficient_;  ///< (point j, c_j) of every pair
  std::vector<Anchor> anchors_;                          ///< per vertex
  // refresh's scratch
  Points y_, centroid_;
  Points vertex_normal_;
  Points face_normal_;                          ///< unit, deformed
  std::vector<Eigen::AlignedBox3d> piece_box_;  ///< each piece's deformed faces' box
  SpatialGrid grid_;
  std::vector<double> previous_multiplier_;  ///< per vertex, across a refresh
  /// per vertex, across a refresh: the triangle it was paired with (-1: none), kept while it still covers it
  std::vector<index_t> previous_triangle_;
};

}  // namespace pointhaptics
