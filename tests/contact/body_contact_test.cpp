// Contact between two deformable bodies (contact/body_contact.hpp): at a state where they press into each other,
// its forces are the negative gradient of its energy and its tangent the derivative of its forces (central
// differences), its forces sum to zero (equal and opposite), and the multipliers' update meets the constraint.
#include <pointhaptics/contact/body_contact.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/object_surface.hpp>
#include <pointhaptics/scene_builder.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace pointhaptics;

namespace {

struct TwoBodies {
  Scene scene;
  Model model;
  ObjectSurface surface;
};

// a 3 x 1.5 x 3 cm block and a 1.5 cm cube on it, touching
TwoBodies two_bodies() {
  TwoBodies t;
  t.scene = parse_scene(R"(
[material]
young = 1e5
poisson = 0.3
[[object]]
name = "lower"
size = [0.03, 0.015, 0.03]
spacing = 0.005
[[object]]
name = "upper"
origin = [0.0075, 0.015, 0.0075]
size = [0.015, 0.015, 0.015]
spacing = 0.005
material = { young = 3e5 }
)",
                        "scene.toml");
  t.model = build_scene_model(t.scene);
  t.surface = build_object_surface(t.scene, t.model);
  return t;
}

// the upper body pushed 0.2 mm into the lower and sheared a little, with a smooth field on top
Points pressed(const Model& model) {
  Points u = Points::Zero(3, model.n_points);
  for (index_t i = model.body_start[1]; i < model.n_points; ++i)
    u.col(i) = Vec3(1e-4 * std::sin(90 * model.X(1, i)), -2e-4 + 1e-4 * model.X(0, i), 5e-5);
  for (index_t i = 0; i < model.body_start[1]; ++i) u.col(i) = Vec3(0, 3e-3 * model.X(0, i) * model.X(2, i), 0);
  return u;
}

TEST(BodyContact, ForcesAreTheEnergysGradientAndTheTangentTheirs) {
  const TwoBodies t = two_bodies();
  BodyContact contact(t.model, t.surface.mesh, t.surface.map, t.surface.body_vertex_start, t.surface.body_face_start,
                      BodyContactParams{.penalty = 1e9});
  const Points u = pressed(t.model);
  contact.refresh(t.model, Points::Zero(3, t.model.n_points));  // paired at rest, evaluated pressed in
  ASSERT_GT(contact.pairs(), 0);
  Points f = Points::Zero(3, t.model.n_points);
  contact.add_forces(t.model, u, f);
  ASSERT_GT(f.norm(), 0) << "they press";
  EXPECT_LT(f.rowwise().sum().norm(), 1e-10 * f.norm()) << "equal and opposite";
  const BodyLoads loads = contact.loads(t.model, u);
  EXPECT_LT((loads.force[0] + loads.force[1]).norm(), 1e-12);
  EXPECT_GT(loads.force[1].y(), 0) << "the lower body pushes the upper up";
  EXPECT_NEAR(loads.penetration, 2e-4, 1e-4);

  // central differences of the energy along a few points' coordinates, and of the forces along a direction
  const double eps = 1e-8;
  int checked = 0;
  for (index_t i = 0; i < t.model.n_points && checked < 40; i += 7)
    for (int a = 0; a < 3; ++a) {
      if (std::abs(f(a, i)) < 1e-6 * f.cwiseAbs().maxCoeff()) continue;
      Points up = u, down = u;
      up(a, i) += eps;
      down(a, i) -= eps;
      const double gradient = (contact.energy(t.model, up) - contact.energy(t.model, down)) / (2 * eps);
      EXPECT_NEAR(-gradient, f(a, i), 1e-5 * std::abs(f(a, i)) + 1e-9) << i << " " << a;
      ++checked;
    }
  EXPECT_GT(checked, 10);
  Points direction(3, t.model.n_points);
  for (index_t i = 0; i < t.model.n_points; ++i) direction.col(i) = Vec3(std::cos(i), std::sin(2.0 * i), 0.3);
  contact.linearise(t.model, u, TangentMode::EXACT);
  Points product = Points::Zero(3, t.model.n_points);
  contact.add_tangent_product(direction, product);
  const double h = 1e-9;
  Points f_up = Points::Zero(3, t.model.n_points), f_down = Points::Zero(3, t.model.n_points);
  contact.add_forces(t.model, u + h * direction, f_up);
  contact.add_forces(t.model, u - h * direction, f_down);
  const Points difference = -(f_up - f_down) / (2 * h);
  EXPECT_LT((difference - product).norm(), 1e-4 * product.norm());
  // the diagonal blocks are the tangent's
  Eigen::Matrix<double, 9, Eigen::Dynamic> blocks = Eigen::Matrix<double, 9, Eigen::Dynamic>::Zero(9, t.model.n_points);
  contact.add_diagonal_blocks(blocks);
  const index_t i = t.model.body_start[1];  // a point of the upper body's base corner
  Points unit = Points::Zero(3, t.model.n_points);
  unit(1, i) = 1;
  Points column = Points::Zero(3, t.model.n_points);
  contact.add_tangent_product(unit, column);
  EXPECT_NEAR(Eigen::Map<const Mat3>(blocks.col(i).data())(1, 1), column(1, i), 1e-9 * (1 + std::abs(column(1, i))));
}

TEST(BodyContact, TheMultipliersMeetTheConstraintAndKeepTheirForceAcrossARefresh) {
  const TwoBodies t = two_bodies();
  BodyContact contact(t.model, t.surface.mesh, t.surface.map, t.surface.body_vertex_start, t.surface.body_face_start);
  const Points u = pressed(t.model);
  EXPECT_FALSE(contact.update_multipliers(t.model, u)) << "0.2 mm in: not met, the multipliers take the force";
  const Vec3 pushed = contact.loads(t.model, u).force[1];
  contact.refresh(t.model, u);
  EXPECT_LT((contact.loads(t.model, u).force[1] - pushed).norm(), 1e-9 * pushed.norm()) << "kept across a refresh";
  // where the bodies are apart, nothing presses, and the multipliers let go
  Points apart = Points::Zero(3, t.model.n_points);
  for (index_t i = t.model.body_start[1]; i < t.model.n_points; ++i) apart(1, i) = 1e-3;
  EXPECT_TRUE(contact.update_multipliers(t.model, apart));
  EXPECT_EQ(contact.loads(t.model, apart).contacts, 0);
}

}  // namespace
