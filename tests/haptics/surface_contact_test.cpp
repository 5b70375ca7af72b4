// Tests for haptics/surface_contact: the contact energy's forces are its gradient and its tangent the forces'
// derivative (finite differences, sphere and capsule, with and without multipliers); the load on the tool
// balances what the points get, and with the map without negative weights a pressing tool pushes every point
// that carries the surface away from it (the exact map pulls some into it); a capsule's off-centre contact
// has the torque of its forces; a tool held at a position in a static solve leaves no vertex inside it beyond
// the tolerance and pushes the object with the force the supports resist; with Coulomb friction the forces
// stay the energy's gradient, a small move of the pressed tool sticks (a tangential force inside the cone)
// and a longer one slides with mu times the normal force.
#include <pointhaptics/geometry/sampling.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>
#include <pointhaptics/haptics/surface_contact.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/mechanics/tangent_matrix.hpp>
#include <pointhaptics/world/simulation.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace pointhaptics {
namespace {

const double spacing = 0.005;
const Vec3 size(0.04, 0.02, 0.04);

struct Block {
  Model model;
  TriangleMesh surface;
};

Block block(bool hold_bottom = false) {
  PointCloud cloud = sample_box(Vec3::Zero(), size, spacing);
  Block b{build_model(cloud, MaterialParams{}, KernelParams{}), box_surface(Vec3::Zero(), size, spacing / 2)};
  if (hold_bottom) {
    FixedGroup bottom;
    bottom.name = "bottom";
    for (index_t i = 0; i < b.model.n_points; ++i)
      if (b.model.X(1, i) < 1e-9) {
        b.model.fixed[i] = 1;
        bottom.points.push_back(i);
      }
    b.model.fixed_groups.push_back(bottom);
  }
  return b;
}

Points random_field(index_t n, double scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, scale);
  Points u(3, n);
  for (Eigen::Index k = 0; k < u.size(); ++k) u.data()[k] = noise(rng);
  return u;
}

double dot(const Points& a, const Points& b) { return (a.array() * b.array()).sum(); }

struct ToolCase {
  const char* name;
  ToolShape shape;
  ToolPose pose;
};

std::vector<ToolCase> tools() {
  ToolShape sphere{ToolKind::SPHERE, 0.01, 0};
  ToolShape capsule{ToolKind::CAPSULE, 0.006, 0.02};
  // the capsule lies across the top face, tilted, its axis off the block's centre
  const Eigen::Quaterniond tilted(Eigen::AngleAxisd(1.3, Vec3(0.2, 0.1, 1).normalized()));
  // a rounded box turned so that an edge and a corner press into the top face 1.5 mm deep (obstacles)
  ToolShape box{ToolKind::BOX, 0.002, 0, Vec3(0.006, 0.004, 0.005)};
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(0.3, Vec3(1, 0, 0.5).normalized()));
  const Eigen::Matrix3d R = turned.toRotationMatrix();
  const double box_below = box.radius + R.row(1).cwiseAbs().dot(box.half_core);
  // a plane tilted over the top face, its normal down: the half-space above holds part of the face
  ToolShape plane{ToolKind::PLANE, 0.01, 0};
  const Eigen::Quaterniond facing_down =
      Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), Vec3(0.1, -1, 0.05).normalized());
  return {{"sphere", sphere, {Vec3(0.02, 0.02 + 0.01 - 0.0015, 0.02), Eigen::Quaterniond::Identity()}},
          {"capsule", capsule, {Vec3(0.018, 0.02 + 0.006 - 0.001, 0.021), tilted}},
          {"box", box, {Vec3(0.021, 0.02 + box_below - 0.0015, 0.019), turned}},
          {"plane", plane, {Vec3(0.02, 0.0195, 0.02), facing_down}}};
}

// The obstacles' shapes: a plane's penetration is the depth below it; a box's, out through its nearest face
// inside, and from its rounded edges and corners outside, with the normal the penetration's gradient.
TEST(ToolDistance, PlanesAndBoxesGiveTheirDepthAndOutwardNormal) {
  const ToolShape plane{ToolKind::PLANE, 0.01, 0};
  const ToolPose table{Vec3(0, 0.1, 0), Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), Vec3::UnitY())};
  ToolDistance d = tool_distance(plane, table, Vec3(3, 0.097, -2));
  EXPECT_NEAR(d.penetration, 0.003, 1e-12);
  EXPECT_LT((d.normal - Vec3::UnitY()).norm(), 1e-12);
  EXPECT_LT((d.core - Vec3(3, 0.1, -2)).norm(), 1e-12);
  EXPECT_EQ(d.curvature, 0);
  EXPECT_NEAR(tool_distance(plane, table, Vec3(0, 0.25, 0)).penetration, -0.15, 1e-12);

  const ToolShape box{ToolKind::BOX, 0.001, 0, Vec3(0.02, 0.01, 0.03)};
  const ToolPose at{Vec3(1, 2, 3), Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vec3(1, 2, 0.5).normalized()))};
  const auto world = [&](const Vec3& local) { return Vec3(at.position + at.orientation * local); };
  // inside the core, nearest the +y face: 4 mm to it, plus the rounding
  d = tool_distance(box, at, world(Vec3(0.005, 0.006, -0.01)));
  EXPECT_NEAR(d.penetration, 0.004 + 0.001, 1e-12);
  EXPECT_LT((d.normal - at.orientation * Vec3::UnitY()).norm(), 1e-12);
  // outside a face, an edge and a corner
  d = tool_distance(box, at, world(Vec3(0.0, 0.0105, 0.0)));
  EXPECT_NEAR(d.penetration, 0.0005, 1e-12);
  EXPECT_EQ(d.curvature, 0);
  d = tool_distance(box, at, world(Vec3(0.0203, 0.0104, 0.0)));
  EXPECT_NEAR(d.penetration, 0.001 - 0.0005, 1e-12);
  EXPECT_NEAR(d.curvature, 1 / 0.0005, 1e-6);
  EXPECT_LT((d.axis.cwiseAbs() - (at.orientation * Vec3::UnitZ()).cwiseAbs()).norm(), 1e-12);
  d = tool_distance(box, at, world(Vec3(-0.0206, -0.0108, 0.0300)));
  EXPECT_NEAR(d.penetration, 0.001 - 0.001, 1e-12);
  EXPECT_EQ(d.axis.norm(), 0);
  // the normal is the penetration's gradient (central differences), wherever the point is
  for (const Vec3& local : {Vec3(0.005, 0.006, -0.01), Vec3(0.0203, 0.0104, 0.0), Vec3(0.01, -0.0104, 0.0302)}) {
    const Vec3 p = world(local);
    const ToolDistance at_p = tool_distance(box, at, p);
    Vec3 gradient;
    for (int a = 0; a < 3; ++a) {
      const Vec3 e = 1e-7 * Vec3::Unit(a);
      gradient[a] = (tool_distance(box, at, p - e).penetration - tool_distance(box, at, p + e).penetration) / 2e-7;
    }
    EXPECT_LT((gradient - at_p.normal).norm(), 1e-6) << local.transpose();
  }
}

// Forces are the energy's gradient (central differences of the energy) and the exact tangent their
// derivative (central differences of the forces), at u along a random direction.
void expect_forces_are_the_gradient_and_the_tangent_their_derivative(SurfaceContact& contact, const Model& model,
                                                                     const Points& u, const Points& f) {
  const Points du = random_field(model.n_points, 1e-4, 5);
  const double eps = 1e-4;
  const double dE = (contact.energy(model, u + eps * du) - contact.energy(model, u - eps * du)) / (2 * eps);
  EXPECT_NEAR(dE, -dot(f, du), 1e-6 * std::abs(dot(f, du)));
  contact.linearise(model, u, TangentMode::EXACT);
  Points Hdu = Points::Zero(3, model.n_points);
  contact.add_tangent_product(du, Hdu);
  Points f_plus = Points::Zero(3, model.n_points), f_minus = Points::Zero(3, model.n_points);
  contact.add_forces(model, u + eps * du, f_plus);
  contact.add_forces(model, u - eps * du, f_minus);
  const Points fd = -(f_plus - f_minus) / (2 * eps);
  EXPECT_LT((Hdu - fd).norm(), 1e-5 * fd.norm());
}

TEST(SurfaceContact, ForcesAreTheEnergyGradientAndTheTangentTheirDerivative) {
  const Block b = block();
  for (const ToolCase& t : tools()) {
    for (const bool with_multipliers : {false, true}) {
      SCOPED_TRACE(std::string(t.name) + (with_multipliers ? " with multipliers" : ""));
      SurfaceContact contact(b.model, b.surface, build_surface_map(b.model, b.surface.V), t.shape);
      contact.set_pose(t.pose);
      const Points u = random_field(b.model.n_points, 1e-4, 3);
      if (with_multipliers) {
        ASSERT_FALSE(contact.update_multipliers(b.model, u));  // the tool is inside: multipliers grow
      }
      Points f = Points::Zero(3, b.model.n_points);
      contact.add_forces(b.model, u, f);
      ASSERT_GT(f.norm(), 0);
      expect_forces_are_the_gradient_and_the_tangent_their_derivative(contact, b.model, u, f);
      const Points du = random_field(b.model.n_points, 1e-4, 5);
      // the projected tangent keeps the normal stiffness only: positive semi-definite
      contact.linearise(b.model, u, TangentMode::PROJECTED);
      Points Pdu = Points::Zero(3, b.model.n_points);
      contact.add_tangent_product(du, Pdu);
      EXPECT_GE(dot(du, Pdu), 0);
      // the tool feels the opposite of what the points get
      const ToolLoad load = contact.load(b.model, u);
      EXPECT_LT((load.force + f.rowwise().sum()).norm(), 1e-9 * load.force.norm());
      EXPECT_GT(load.contacts, 0);
    }
  }
}

// An obstacle's or posed tool's contact carries only the vertices that can touch it
// (SurfaceContactParams::cull_far_vertices): its energy, forces, tangent, load and multipliers are those of the
// contact that carries every vertex, for every shape, with friction, over displacements large and small
TEST(SurfaceContact, CarryingOnlyTheVerticesThatCanTouchChangesNothing) {
  const Block b = block();
  for (const ToolCase& t : tools()) {
    for (const double scale : {1e-4, 3e-3}) {
      SCOPED_TRACE(std::string(t.name) + " at " + std::to_string(scale) + " m");
      SurfaceContactParams all, near;
      all.friction = near.friction = 0.3;
      near.cull_far_vertices = true;
      SurfaceContact every(b.model, b.surface, build_surface_map(b.model, b.surface.V), t.shape, all);
      SurfaceContact culled(b.model, b.surface, build_surface_map(b.model, b.surface.V), t.shape, near);
      every.set_pose(t.pose);
      culled.set_pose(t.pose);
      const Points u = random_field(b.model.n_points, scale, 11);
      every.begin_static_solve(u);
      culled.begin_static_solve(u);
      EXPECT_EQ(every.update_multipliers(b.model, u), culled.update_multipliers(b.model, u));
      const Points v = random_field(b.model.n_points, scale, 13);
      EXPECT_NEAR(every.energy(b.model, v), culled.energy(b.model, v), 1e-12 * std::abs(every.energy(b.model, v)));
      Points f_every = Points::Zero(3, b.model.n_points), f_culled = f_every;
      every.add_forces(b.model, v, f_every);
      culled.add_forces(b.model, v, f_culled);
      ASSERT_GT(f_every.norm(), 0);
      EXPECT_LT((f_every - f_culled).norm(), 1e-12 * f_every.norm());
      every.linearise(b.model, v, TangentMode::EXACT);
      culled.linearise(b.model, v, TangentMode::EXACT);
      const Points du = random_field(b.model.n_points, 1e-4, 17);
      Points k_every = Points::Zero(3, b.model.n_points), k_culled = k_every;
      every.add_tangent_product(du, k_every);
      culled.add_tangent_product(du, k_culled);
      EXPECT_LT((k_every - k_culled).norm(), 1e-12 * k_every.norm());
      const ToolLoad a = every.load(b.model, v), c = culled.load(b.model, v);
      EXPECT_EQ(a.contacts, c.contacts);
      EXPECT_LT((a.force - c.force).norm(), 1e-12 * a.force.norm());
      EXPECT_NEAR(a.penetration, c.penetration, 1e-15);
    }
  }
}

// What the Cholesky preconditioner's factor takes of the contact (EnergyTerm::add_to_matrix): the projected
// tangent with its coupling between the points that carry a vertex. Where a pair of them lies outside the
// material tangent's pattern it is lumped onto their diagonal blocks, which keeps the matrix at or above the
// contact's tangent: x^T K x >= x^T H x for every x, and equal where no pair was lumped.
TEST(SurfaceContact, ItsTangentEntersTheAssembledMatrixWithItsCoupling) {
  const Block b = block();
  for (const ToolCase& t : tools()) {
    SCOPED_TRACE(t.name);
    SurfaceContact contact(b.model, b.surface, build_surface_map(b.model, b.surface.V), t.shape);
    contact.set_pose(t.pose);
    const Points u = random_field(b.model.n_points, 1e-4, 3);
    contact.linearise(b.model, u, TangentMode::PROJECTED);
    TangentMatrix K;
    build_tangent_pattern(b.model, K);
    K.values.assign(9 * static_cast<std::size_t>(K.n_blocks()), 0.0);
    ASSERT_TRUE(contact.add_to_matrix(K));
    double worst = 0, scale = 0, coupled = 0;
    for (unsigned seed = 10; seed < 20; ++seed) {
      const Points x = random_field(b.model.n_points, 1.0, seed);
      Points Hx = Points::Zero(3, b.model.n_points), Kx;
      contact.add_tangent_product(x, Hx);
      multiply(K, x, Kx);
      const double exact = dot(x, Hx), assembled = dot(x, Kx);
      ASSERT_GT(exact, 0);
      EXPECT_GE(assembled, exact * (1 - 1e-12)) << "the lumped matrix is a bound of the contact's tangent";
      worst = std::max(worst, (Kx - Hx).norm());
      scale = std::max(scale, Hx.norm());
    }
    // the coupling is there: K's off-diagonal blocks carry most of the contact (a diagonal alone would be far off)
    for (index_t j = 0; j < b.model.n_points; ++j)
      for (index_t e = K.pattern.begin(j); e < K.pattern.end(j); ++e)
        if (K.pattern.index[e] != j)
          coupled += Eigen::Map<const Mat3>(K.values.data() + 9 * static_cast<std::size_t>(e)).norm();
    EXPECT_GT(coupled, 0);
    EXPECT_LT(worst, 0.5 * scale) << "close to the contact's own tangent";
  }
}

// The block held at its bottom in a static solve, a sphere of `radius` held `depth` into its top face above
// (x, z).
struct Press {
  Simulation sim;
  TriangleMesh surface;
};

Press pressed_block(double radius, double depth, double x, double z, const SurfaceContactParams& params = {}) {
  Block b = block(true);
  TriangleMesh surface = b.surface;
  SolverSpec spec;
  spec.kind = SolverKind::STATIC;
  Simulation sim(std::move(b.model), spec, 2);
  sim.hold_tool(ToolShape{ToolKind::SPHERE, radius, 0},
                ToolPose{Vec3(x, 0.02 + radius - depth, z), Eigen::Quaterniond::Identity()}, surface,
                build_surface_map(sim.model(), surface.V), params);
  return {std::move(sim), std::move(surface)};
}

// A tool narrower than the surface's triangles (a 1 mm sphere over 2.5 mm edges, 3.5 mm diagonals: a sphere
// fits through a triangle whose circumradius exceeds its radius): centred over a diagonal's midpoint, 1.77 mm
// from the nearest vertices, it touches none of them. The contact's samples on the triangles (two splits, to
// edges of at most its radius) carry the surface there, and the forces stay the energy's gradient.
TEST(SurfaceContact, ASphereNarrowerThanTheTrianglesPressesOnTheirSamples) {
  const Block b = block();
  const SurfaceMap map = build_surface_map(b.model, b.surface.V);
  const ToolShape thin{ToolKind::SPHERE, 0.001, 0};
  const ToolPose pressed{Vec3(0.02 + 0.00125, 0.02 + 0.001 - 0.0002, 0.02 + 0.00125), Eigen::Quaterniond::Identity()};
  const Points u = random_field(b.model.n_points, 1e-6, 3);
  SurfaceContactParams vertices_only;
  vertices_only.sample_spacing = -1;
  SurfaceContact without(b.model, b.surface, map, thin, vertices_only);
  without.set_pose(pressed);
  EXPECT_EQ(without.sample_levels(), 0);
  EXPECT_EQ(without.load(b.model, u).contacts, 0);  // it sinks 0.2 mm into the face unfelt
  SurfaceContact contact(b.model, b.surface, map, thin);
  contact.set_pose(pressed);
  EXPECT_EQ(contact.sample_levels(), 2);
  EXPECT_EQ(contact.surface_vertices(), b.surface.V.cols());
  const ToolLoad load = contact.load(b.model, u);
  EXPECT_GT(load.contacts, 0);
  EXPECT_NEAR(load.penetration, 0.0002, 2e-5);  // the sample under it is on the face
  EXPECT_GT(load.force.y(), 0);
  ASSERT_FALSE(contact.update_multipliers(b.model, u));
  Points f = Points::Zero(3, b.model.n_points);
  contact.add_forces(b.model, u, f);
  EXPECT_LT((contact.last_load().force + f.rowwise().sum()).norm(), 1e-9 * contact.last_load().force.norm());
  expect_forces_are_the_gradient_and_the_tangent_their_derivative(contact, b.model, u, f);
}

// Held in a static solve, the thin sphere pushes the face down by its depth and no sample ends inside it
// beyond the tolerance; the same sphere over the vertices only is not held at all.
TEST(SurfaceContact, StaticIndentationByASphereNarrowerThanTheTrianglesMeetsTheConstraint) {
  for (const bool samples : {true, false}) {
    SCOPED_TRACE(samples ? "with samples" : "vertices only");
    const double radius = 0.001, depth = 0.0002;
    SurfaceContactParams params;
    if (!samples) params.sample_spacing = -1;
    Press press = pressed_block(radius, depth, 0.02 + 0.00125, 0.02 + 0.00125, params);
    Simulation& sim = press.sim;
    ASSERT_EQ(sim.step().status, StepStatus::CONVERGED);
    const RunSummary s = sim.summary();
    ASSERT_TRUE(s.tool.present);
    if (!samples) {
      EXPECT_EQ(s.tool.force.norm(), 0.0);
      continue;
    }
    EXPECT_GT(s.tool.force.y(), 0);
    EXPECT_NEAR(s.reactions[0].y(), s.tool.force.y(), 1e-4 * s.tool.force.y());
    EXPECT_LT(s.tool.penetration, 0.01 * depth);
    // the sample under the sphere went down by the depth: the face follows the tool between its vertices
    const SurfaceContact& contact = sim.held_tool()->contact();
    double under = NAN;
    for (index_t v = contact.surface_vertices(); v < contact.vertices().cols(); ++v)
      if (std::hypot(contact.vertices()(0, v) - 0.02125, contact.vertices()(2, v) - 0.02125) < 1e-5 &&
          contact.vertices()(1, v) > 0.01)
        under = contact.vertices()(1, v);
    EXPECT_NEAR(under, 0.02 - depth, 0.01 * depth);
  }
}

// limit_point_stiffness (a level of detail's part of the surface pressing as the whole one does): every point
// ends at most at max(its limit, the cap), no point softer than the uniform lowering to the cap left it, and a
// vertex whose points are all within their limits keeps its penalty.
TEST(SurfaceContact, PointStiffnessLimitsLowerOnlyTheVerticesOfPointsBeyondThem) {
  const Block b = block();
  const SurfaceMap map = build_surface_map(b.model, b.surface.V);
  SurfaceContact contact(b.model, b.surface, map, tools()[0].shape, SurfaceContactParams{});
  const std::vector<double> before = contact.point_stiffness(b.model.n_points);
  const double stiffest = *std::max_element(before.begin(), before.end());
  ASSERT_GT(stiffest, 0);
  // every third point limited to a fifth of its stiffness, the others not at all
  std::vector<double> limit(before.size());
  for (std::size_t j = 0; j < limit.size(); ++j) limit[j] = j % 3 == 0 ? before[j] / 5 : 10 * stiffest;
  const double cap = stiffest / 2, uniform = cap / stiffest;
  contact.limit_point_stiffness(limit, cap);
  const std::vector<double> after = contact.point_stiffness(b.model.n_points);
  int lowered = 0, kept = 0;
  for (std::size_t j = 0; j < after.size(); ++j) {
    EXPECT_LE(after[j], std::max(limit[j], cap) * (1 + 1e-12)) << j;
    EXPECT_GE(after[j], uniform * before[j] * (1 - 1e-12)) << j;
    if (after[j] < before[j] * (1 - 1e-9)) ++lowered;
  }
  // a point none of whose vertices has a limited point keeps its stiffness
  for (index_t j = 0; j < b.model.n_points; ++j) {
    bool free = before[static_cast<std::size_t>(j)] > 0;
    for (index_t v = 0; v < map.n_vertices() && free; ++v) {
      bool carries_j = false, carries_limited = false;
      for (index_t e = map.points.begin(v); e < map.points.end(v); ++e) {
        carries_j = carries_j || (map.points.index[e] == j && map.weight[e] != 0);
        carries_limited = carries_limited || (map.points.index[e] % 3 == 0 && map.weight[e] != 0);
      }
      free = !(carries_j && carries_limited);
    }
    if (!free) continue;
    ++kept;
    EXPECT_DOUBLE_EQ(after[static_cast<std::size_t>(j)], before[static_cast<std::size_t>(j)]) << j;
  }
  EXPECT_GT(lowered, 0);
  EXPECT_GT(kept, 0);
  EXPECT_LE(contact.max_point_stiffness(), *std::max_element(after.begin(), after.end()) * (1 + 1e-12));
}

TEST(SurfaceContact, CapsuleTorqueIsTheMomentOfItsForces) {
  const Block b = block();
  const ToolCase t = tools()[1];
  SurfaceContact contact(b.model, b.surface, build_surface_map(b.model, b.surface.V), t.shape);
  contact.set_pose(t.pose);
  const Points u = Points::Zero(3, b.model.n_points);
  Points f = Points::Zero(3, b.model.n_points);
  contact.add_forces(b.model, u, f);
  const ToolLoad load = contact.load(b.model, u);
  // the forces on the points, moved to the vertices' lines of action: recomputed independently from the
  // deformed vertices, each vertex's force acting through its nearest axis point
  Vec3 torque = Vec3::Zero();
  const Points& y = contact.vertices();
  for (index_t v = 0; v < y.cols(); ++v) {
    const ToolDistance d = tool_distance(t.shape, t.pose, y.col(v));
    const double g = d.penetration;
    if (g <= 0) continue;
    torque += (d.core - t.pose.position).cross(-g * d.normal);
  }
  // the penalty is per vertex area, equal on the flat top: the torque's direction is that of sum g (q - c) x -n
  ASSERT_GT(load.torque.norm(), 1e-6 * load.force.norm() * t.shape.length);
  EXPECT_GT(load.torque.normalized().dot(torque.normalized()), 0.99);
}

TEST(SurfaceContact, APressingToolPushesEveryPointThatCarriesTheSurfaceAwayFromIt) {
  // the exact map pulls the layer under the outer points up into the tool (its negative weights); without
  // them (non_negative_weights) every point's contact force points down, away from a tool pressing the top
  // (a ball: its surface lies beyond the outer points everywhere, where a lattice's box has points on its faces)
  const double ball = 0.02, radius = 0.01, depth = 0.002;
  const Block b{build_model(sample_sphere(Vec3::Zero(), ball, spacing), MaterialParams{}, KernelParams{}),
                sphere_surface(Vec3::Zero(), ball, spacing / 2)};
  SurfaceContactParams params;
  params.non_negative_weights = true;
  SurfaceContact contact(b.model, b.surface, build_surface_map(b.model, b.surface.V),
                         ToolShape{ToolKind::SPHERE, radius, 0}, params);
  contact.set_pose(ToolPose{Vec3(0, ball + radius - depth, 0), Eigen::Quaterniond::Identity()});
  Points f = Points::Zero(3, b.model.n_points);
  const Points u = Points::Zero(3, b.model.n_points);
  contact.add_forces(b.model, u, f);
  ASSERT_GT(contact.last_load().contacts, 3);
  EXPECT_LE(f.row(1).maxCoeff(), 0.0);
  EXPECT_NEAR(-f.row(1).sum(), contact.last_load().force.y(), 1e-12 * contact.last_load().force.y());
  for (index_t e = 0; e < static_cast<index_t>(contact.map().weight.size()); ++e)
    EXPECT_GE(contact.map().weight[static_cast<std::size_t>(e)], 0.0);
  // the exact map (the default) pulls some points up, into the tool
  SurfaceContact exact(b.model, b.surface, build_surface_map(b.model, b.surface.V),
                       ToolShape{ToolKind::SPHERE, radius, 0});
  exact.set_pose(contact.pose());
  f.setZero();
  exact.add_forces(b.model, u, f);
  EXPECT_GT(f.row(1).maxCoeff(), 0.0);
}

TEST(SurfaceContact, StaticIndentationMeetsTheConstraintAndBalancesTheSupports) {
  const double radius = 0.01, depth = 0.001;
  Press press = pressed_block(radius, depth, 0.02, 0.02);
  Simulation& sim = press.sim;
  const TriangleMesh& surface = press.surface;
  ASSERT_EQ(sim.step().status, StepStatus::CONVERGED);
  const RunSummary s = sim.summary();
  ASSERT_TRUE(s.tool.present);
  ASSERT_EQ(s.reactions.size(), 1u);
  EXPECT_TRUE(s.converged);
  EXPECT_LT(s.residual, 1e-6);
  // pressed down, the object pushes the tool up; the supports hold the same force
  EXPECT_GT(s.tool.force.y(), 0);
  EXPECT_LT(std::hypot(s.tool.force.x(), s.tool.force.z()), 1e-6 * s.tool.force.y());
  EXPECT_NEAR(s.reactions[0].y(), s.tool.force.y(), 1e-4 * s.tool.force.y());
  // no vertex inside beyond 1% of the depth (the default tolerance is 1e-4 of the radius)
  EXPECT_LT(s.tool.penetration, 0.01 * depth);
  // the top face under the tool went down by about the depth
  const Points y = sim.held_tool()->contact().vertices();
  double lowest_top = 1;
  for (index_t v = 0; v < y.cols(); ++v)
    if (surface.V(1, v) > 0.02 - 1e-9 && (surface.V.col(v) - Vec3(0.02, 0.02, 0.02)).norm() < 1e-9)
      lowest_top = y(1, v);
  EXPECT_NEAR(lowest_top, 0.02 - depth, 0.01 * depth);
}

TEST(SurfaceContact, FrictionForcesAreTheEnergyGradientAndTheTangentTheirDerivative) {
  const Block b = block();
  for (const ToolCase& t : tools()) {
    SCOPED_TRACE(t.name);
    SurfaceContactParams params;
    params.friction = 0.3;
    SurfaceContact contact(b.model, b.surface, build_surface_map(b.model, b.surface.V), t.shape, params);
    contact.set_pose(t.pose);
    const Points u = random_field(b.model.n_points, 1e-4, 3);
    ASSERT_FALSE(contact.update_multipliers(b.model, u));  // multipliers, and anchors where the vertices are
    ToolPose moved = t.pose;
    moved.position += Vec3(3e-4, 0, -2e-4);  // the anchors move with the tool: the vertices are dragged
    contact.set_pose(moved);
    Points f = Points::Zero(3, b.model.n_points);
    contact.add_forces(b.model, u, f);
    const ToolLoad load = contact.load(b.model, u);
    ASSERT_GT(std::hypot(load.force.x(), load.force.z()), 0.0);
    EXPECT_LT((load.force + f.rowwise().sum()).norm(), 1e-9 * load.force.norm());
    expect_forces_are_the_gradient_and_the_tangent_their_derivative(contact, b.model, u, f);
  }
}

TEST(SurfaceContact, FrictionSticksForASmallMoveAndSlidesWithMuTimesTheNormalForce) {
  Block b = block(true);
  const TriangleMesh surface = b.surface;
  SolverSpec spec;
  spec.kind = SolverKind::STATIC;
  Simulation sim(std::move(b.model), spec, 2);
  const double radius = 0.01, depth = 0.001, mu = 0.3;
  SurfaceContactParams params;
  params.friction = mu;
  const auto at = [&](double x) {
    return ToolPose{Vec3(0.02 + x, 0.02 + radius - depth, 0.02), Eigen::Quaterniond::Identity()};
  };
  sim.hold_tool(ToolShape{ToolKind::SPHERE, radius, 0}, at(0), surface, build_surface_map(sim.model(), surface.V),
                params);
  const StepReport first = sim.step();
  ASSERT_EQ(first.status, StepStatus::CONVERGED) << first.failure;
  const double pressed = sim.summary().tool.force.y();
  EXPECT_LT(std::abs(sim.summary().tool.force.x()), 1e-6 * pressed);  // straight down: no drag
  // a small move sticks: the tool drags the surface along, resisted by less than mu N
  sim.set_tool_pose(at(1e-5));
  const StepReport small = sim.step();
  ASSERT_EQ(small.status, StepStatus::CONVERGED) << small.failure;
  RunSummary s = sim.summary();
  EXPECT_LT(s.tool.force.x(), -0.01 * mu * s.tool.force.y());  // the object holds the tool back
  EXPECT_GT(s.tool.force.x(), -mu * s.tool.force.y());
  // a longer one slides: mu times the normal force, against the motion
  for (int k = 1; k <= 8; ++k) {
    sim.set_tool_pose(at(k * 5e-4));
    const StepReport slid = sim.step();
    ASSERT_EQ(slid.status, StepStatus::CONVERGED) << k << ": " << slid.failure;
  }
  s = sim.summary();
  // the friction's part of the force is mu times the pressure's, against the motion; the whole force on the
  // tool also has the tilted normals' share (this coarse surface holds one or two vertices under the tool)
  const ToolLoad load = sim.held_tool()->load(sim.model(), sim.state().u);
  const Vec3 pressure = load.force - load.friction;
  EXPECT_NEAR(load.friction.norm() / pressure.norm(), mu, 0.05 * mu);
  EXPECT_LT(load.friction.x(), -0.95 * load.friction.norm());
  EXPECT_LT(s.tool.force.x(), -0.5 * mu * s.tool.force.y());
  EXPECT_LT(s.tool.penetration, 0.01 * depth);
  // the supports hold what the tool does to the object, along x too
  EXPECT_NEAR(s.reactions[0].x(), s.tool.force.x(), 1e-3 * s.tool.force.y());
}

// The god-object's test of a move (SurfaceContact::enters): a segment entering the surface through a face, as
// it is carried, is seen, one leaving it or beside it is not.
TEST(SurfaceContact, AMoveIntoTheCarriedSurfaceIsSeenAndOneOutOfItIsNot) {
  const Block b = block();
  SurfaceContact contact(b.model, b.surface, build_surface_map(b.model, b.surface.V),
                         ToolShape{ToolKind::SPHERE, 0.002, 0});
  Points u = Points::Zero(3, b.model.n_points);
  u.row(1).setConstant(0.01);  // the block carried 1 cm up: its top face at y = 3 cm
  contact.load(b.model, u);
  const Vec3 above(0.013, 0.031, 0.017), below(0.013, 0.029, 0.017);
  EXPECT_TRUE(contact.enters(above, below));
  EXPECT_FALSE(contact.enters(below, above));
  EXPECT_FALSE(contact.enters(above, Vec3(0.013, 0.035, 0.017)));
  EXPECT_FALSE(contact.enters(Vec3(-0.01, 0.031, 0.017), Vec3(-0.01, 0.029, 0.017)));  // beside the block
  // the reference surface's top (y = 2 cm) is not where the carried one is
  EXPECT_FALSE(contact.enters(Vec3(0.013, 0.021, 0.017), Vec3(0.013, 0.019, 0.017)));
  // through the block, in through the top and out through the bottom: it enters
  EXPECT_TRUE(contact.enters(Vec3(0.013, 0.04, 0.017), Vec3(0.013, 0.0, 0.017)));
}

}  // namespace
}  // namespace pointhaptics
