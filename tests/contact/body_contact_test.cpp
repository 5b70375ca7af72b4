// Contact between two deformable bodies (contact/body_contact.hpp): at a state where they press into each other,
// its forces are the negative gradient of its energy and its tangent the derivative of its forces (central
// differences), its forces sum to zero (equal and opposite), and the multipliers' update meets the constraint.
#include <pointhaptics/contact/body_contact.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/surface/object_surface.hpp>
#include <pointhaptics/session/scene_builder.hpp>

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

// the checks at u: forces against central differences of the energy, the tangent against those of the forces,
// the diagonal blocks against the tangent's
void check_derivatives(BodyContact& contact, const Model& model, const Points& u) {
  Points f = Points::Zero(3, model.n_points);
  contact.add_forces(model, u, f);
  ASSERT_GT(f.norm(), 0) << "they press";
  EXPECT_LT(f.rowwise().sum().norm(), 1e-10 * f.norm()) << "equal and opposite";
  const double eps = 1e-8;
  int checked = 0;
  for (index_t i = 0; i < model.n_points && checked < 40; i += 3)
    for (int a = 0; a < 3; ++a) {
      if (std::abs(f(a, i)) < 1e-6 * f.cwiseAbs().maxCoeff()) continue;
      Points up = u, down = u;
      up(a, i) += eps;
      down(a, i) -= eps;
      const double gradient = (contact.energy(model, up) - contact.energy(model, down)) / (2 * eps);
      EXPECT_NEAR(-gradient, f(a, i), 1e-5 * std::abs(f(a, i)) + 1e-8 * f.cwiseAbs().maxCoeff()) << i << " " << a;
      ++checked;
    }
  EXPECT_GT(checked, 10);
  Points direction(3, model.n_points);
  for (index_t i = 0; i < model.n_points; ++i) direction.col(i) = Vec3(std::cos(i), std::sin(2.0 * i), 0.3);
  contact.linearise(model, u, TangentMode::EXACT);
  Points product = Points::Zero(3, model.n_points);
  contact.add_tangent_product(direction, product);
  const double h = 1e-9;
  Points f_up = Points::Zero(3, model.n_points), f_down = Points::Zero(3, model.n_points);
  contact.add_forces(model, u + h * direction, f_up);
  contact.add_forces(model, u - h * direction, f_down);
  const Points difference = -(f_up - f_down) / (2 * h);
  EXPECT_LT((difference - product).norm(), 1e-4 * product.norm());
  Eigen::Matrix<double, 9, Eigen::Dynamic> blocks = Eigen::Matrix<double, 9, Eigen::Dynamic>::Zero(9, model.n_points);
  contact.add_diagonal_blocks(blocks);
  for (index_t i : {model.body_start[1], index_t{0}, model.n_points - 1})
    for (int a = 0; a < 3; ++a) {
      Points unit = Points::Zero(3, model.n_points);
      unit(a, i) = 1;
      Points column = Points::Zero(3, model.n_points);
      contact.add_tangent_product(unit, column);
      EXPECT_NEAR(Eigen::Map<const Mat3>(blocks.col(i).data())(a, a), column(a, i),
                  1e-9 * (1 + std::abs(column(a, i))));
    }
}

TEST(BodyContact, ForcesAreTheEnergysGradientAndTheTangentTheirs) {
  const TwoBodies t = two_bodies();
  BodyContactParams params;
  params.penalty = 1e9;
  BodyContact contact(t.model, t.surface.mesh, t.surface.map, t.surface.body_vertex_start, t.surface.body_face_start,
                      params);
  const Points u = pressed(t.model);
  contact.refresh(t.model, Points::Zero(3, t.model.n_points));  // paired at rest, evaluated pressed in
  ASSERT_GT(contact.pairs(), 0);
  const BodyLoads loads = contact.loads(t.model, u);
  EXPECT_LT((loads.force[0] + loads.force[1]).norm(), 1e-12);
  EXPECT_GT(loads.force[1].y(), 0) << "the lower body pushes the upper up";
  EXPECT_NEAR(loads.penetration, 2e-4, 1e-4);
  check_derivatives(contact, t.model, u);
}

// with friction in force (after a multiplier update), on both sides of the cone: a slight shear sticks, a larger
// one slides
TEST(BodyContact, WithFrictionTooStickingAndSliding) {
  const TwoBodies t = two_bodies();
  BodyContactParams params;
  params.penalty = 1e9;
  params.friction = 0.5;
  params.tangential_share = 0.1;
  BodyContact contact(t.model, t.surface.mesh, t.surface.map, t.surface.body_vertex_start, t.surface.body_face_start,
                      params);
  const Points u = pressed(t.model);
  contact.refresh(t.model, u);
  EXPECT_FALSE(contact.update_multipliers(t.model, u));  // the multipliers take the pressure, friction anchors
  std::vector<double> held_back;
  for (const double shear : {1e-7, 5e-3, 1e-2}) {  // the cone is about mu lambda / k_t = 1.6 mm of slip away
    SCOPED_TRACE(shear);
    Points sheared = u;
    for (index_t i = t.model.body_start[1]; i < t.model.n_points; ++i) sheared(0, i) += shear;
    const BodyLoads loads = contact.loads(t.model, sheared);
    ASSERT_LT(loads.friction[1].x(), 0) << "friction holds the upper body back";
    EXPECT_LT((loads.friction[0] + loads.friction[1]).norm(), 1e-12);
    EXPECT_LT(-loads.friction[1].x(), 0.5 * loads.force[1].y()) << "within mu times the pressure";
    held_back.push_back(-loads.friction[1].x());
    check_derivatives(contact, t.model, sheared);
  }
  EXPECT_NEAR(held_back[0] / held_back[1], 0, 1e-3) << "a slight shear sticks: its force is its slip's";
  EXPECT_NEAR(held_back[2], held_back[1], 1e-5 * held_back[1]) << "sliding: on the cone, whatever the slip";
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
