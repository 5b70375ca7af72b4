// Tests for haptics/coupling and tools/probe_tool: the coupling solve balances the contact model and caps
// the force at the device's maximum; the probe tool settles where the coupling spring balances the object's
// contact forces, and its forces, springs and renumbering are those of its contact. On the surface the probe is
// a god-object: its centre is not taken into the surface between vertices, and it is put back on the surface
// when the surface flowed over it; its multipliers build at the same rate per second whatever the step.
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/haptics/coupling.hpp>
#include <pointhaptics/tools/probe_tool.hpp>

#include <pointhaptics/geometry/sampling.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

ContactModel pushing_back(double stiffness) {
  ContactModel m;
  m.p0 = Vec3(0, 0.01, 0);
  m.f0 = Vec3(0, 0.5, 0);
  m.K = -stiffness * Mat3::Identity();
  m.contacts = 4;
  return m;
}

TEST(Coupling, TheProbeBalancesTheSpringAndTheContactModel) {
  const ContactModel m = pushing_back(200);
  const Vec3 d(0.001, 0.005, -0.002);
  const double k = 400;
  const Vec3 p = coupled_probe(m, d, k, 100.0);
  EXPECT_LE((k * (d - p) + m.f0 + m.K * (p - m.p0)).norm(), 1e-12);
  // without contact the probe is the device point
  EXPECT_LE((coupled_probe(ContactModel{}, d, k, 100.0) - d).norm(), 1e-15);
}

TEST(Coupling, TheCouplingForceIsCappedAtTheDevicesMaximum) {
  // pressed 5 cm into a stiff object: k |d - p| would be far beyond 3.3 N
  const ContactModel m = pushing_back(1e5);
  const Vec3 d = m.p0 - Vec3(0, 0.05, 0);
  const double k = 400, max_force = 3.3;
  const Vec3 free = coupled_probe(m, d, k, 1e9);
  ASSERT_GT(k * (d - free).norm(), max_force);
  const Vec3 p = coupled_probe(m, d, k, max_force);
  // the probe sits where the device point, pulled in toward the free answer to the capped force, holds it
  const Vec3 pulled = free + (d - free) * (max_force / (k * (d - free).norm()));
  EXPECT_LE((k * (pulled - p) + m.f0 + m.K * (p - m.p0)).norm(), 1e-9);
  EXPECT_LT((p - m.p0).norm(), (free - m.p0).norm());
}

TEST(ProbeTool, SettlesWhereTheCouplingBalancesTheContactAndActsThroughIt) {
  MaterialParams material;
  material.young = 1e4;
  const Model model = build_model(test::jittered_box(6, 3, 6, 0.01, 0.0), material, KernelParams{});
  const State state = State::at_rest(model);
  ProbeParams params;
  params.radius = 0.008;
  const double k = 300;
  ProbeTool tool(model, params, k, 10.0);
  // the device point 4 mm into the top face (y = 0.02) above the middle
  const Vec3 device(0.025, 0.02 + params.radius - 0.004, 0.025);
  tool.place(model, state, device, false);
  Points f = Points::Zero(3, model.n_points);
  tool.add(model, state, f);
  const ContactModel m = tool.contact_model();
  ASSERT_GT(m.contacts, 0);
  // balanced: the coupling's pull equals the contact force on the probe
  EXPECT_LE((k * (device - tool.probe()) + m.f0).norm(), 1e-6 * m.f0.norm());
  // the points feel the opposite of the probe
  EXPECT_LE((f.rowwise().sum() + m.f0).norm(), 1e-9 * m.f0.norm());
  Eigen::Matrix<double, 9, Eigen::Dynamic> springs = Eigen::Matrix<double, 9, Eigen::Dynamic>::Zero(9, model.n_points);
  EXPECT_TRUE(tool.add_stiffness(model, state, springs));
  EXPECT_GT(springs.norm(), 0.0);
  EXPECT_DOUBLE_EQ(tool.max_point_stiffness(), material.young * model.spacing);  // the default contact stiffness
  // lifted off: no contact
  tool.place(model, state, Vec3::Constant(NAN), false);
  f.setZero();
  tool.add(model, state, f);
  EXPECT_EQ(tool.contact_model().contacts, 0);
  EXPECT_EQ(tool.contacts_before_step(), m.contacts);
  EXPECT_EQ(f.norm(), 0.0);
}

// A block 4 x 2 x 4 cm (bottom at y = 0, top at y = 2 cm) and a probe on its surface, of `edge` triangles
struct SurfaceProbe {
  Model model;
  TriangleMesh mesh;
  ProbeParams params;
  ProbeTool tool;
  /// the contact's penalty capped as a simulation caps it (E x spacing per point)
  /// (sample_spacing: SurfaceContactParams's; negative, the surface's vertices only)
  SurfaceProbe(double radius, double edge, double k, double sample_spacing = 0)
      : model(build_model(sample_box(Vec3::Zero(), Vec3(0.04, 0.02, 0.04), 0.005), MaterialParams{}, KernelParams{})),
        mesh(box_surface(Vec3::Zero(), Vec3(0.04, 0.02, 0.04), edge)),
        params(with_radius(radius)),
        tool(model, params, k, 10.0,
             SurfaceContact(model, mesh, build_surface_map(model, mesh.V), probe_shape(params),
                            capped(model, sample_spacing))) {}
  static SurfaceContactParams capped(const Model& model, double sample_spacing) {
    SurfaceContactParams p;
    p.sample_spacing = sample_spacing;
    p.max_point_stiffness = model.material.young * model.spacing;
    return p;
  }
  static ProbeParams with_radius(double radius) {
    ProbeParams p;
    p.radius = radius;
    return p;
  }
};

// A face of two triangles 4 cm across and a probe of 3 mm: pushed down through the face's middle, no vertex
// comes inside the probe, and only the test of its centre's path keeps it from going through (the contact
// without its samples on the triangles, which would otherwise catch it first).
TEST(ProbeTool, OnTheSurfaceAPushIsNotTakenThroughAFaceBetweenItsVertices) {
  SurfaceProbe s(0.003, 0.04, 300, -1);
  const State state = State::at_rest(s.model);
  const Vec3 above(0.012, 0.02 + 0.004, 0.021), deep(0.012, 0.002, 0.021);
  s.tool.place(s.model, state, above, false);
  ASSERT_NEAR((s.tool.probe() - above).norm(), 0.0, 1e-12);  // nothing touched yet
  for (int step = 0; step < 20; ++step) s.tool.place(s.model, state, deep, false);
  EXPECT_GE(s.tool.probe().y(), 0.02);          // its centre stopped at the face
  EXPECT_LT(s.tool.probe().y(), 0.02 + 0.004);  // it moved down to it
  EXPECT_NEAR(s.tool.probe().x(), 0.012, 1e-9);
}

// The surface carried over the probe's centre within a step (the block moved 2 R up under it): the probe is
// put back on the surface instead of being left inside it (where, with no vertex inside it, it sank through).
TEST(ProbeTool, OnTheSurfaceAProbeTheSurfaceFlowedOverIsPutBackOnIt) {
  const double radius = 0.004;
  SurfaceProbe s(radius, 0.005, 300);
  State state = State::at_rest(s.model);
  const Vec3 device(0.02, 0.02 + 0.5 * radius, 0.02);
  s.tool.place(s.model, state, device, false);
  ASSERT_LT(s.tool.probe().y(), 0.02 + radius);  // on the surface: touching it
  state.u.row(1).setConstant(2 * radius);        // the top face now 1.5 R above the probe's centre
  s.tool.place(s.model, state, device, false);
  EXPECT_GE(s.tool.probe().y(), 0.02 + 2 * radius);
  EXPECT_TRUE(s.tool.probe().allFinite());
}

// The multipliers build at the same rate per second whatever the step: after a 0.1 ms step they press a tenth of
// what they press after a 1 ms step from the same placement (an integral action whose share per step did not
// follow the step built ten times as fast at 0.1 ms, and the 100k half-sphere's run diverged sooner).
TEST(ProbeTool, OnTheSurfaceTheMultipliersBuildPerSecondNotPerStep) {
  auto multipliers_after = [](double step) {
    SurfaceProbe s(0.004, 0.005, 300);
    State state = State::at_rest(s.model);
    Workspace ws(s.model, 1);
    const Vec3 device(0.02, 0.02 + 0.004 - 0.003, 0.02);  // pressed 3 mm into the top face
    s.tool.place(s.model, state, device, false);
    Points f = Points::Zero(3, s.model.n_points);
    s.tool.add(s.model, state, f);
    const Vec3 penalty = s.tool.contact_model().f0;  // the penalty's alone: no multiplier yet
    state.time += step;
    s.tool.after_step(s.model, state, ws);
    EXPECT_GT(s.tool.contact_model().contacts, 0);
    return Vec3(s.tool.contact_model().f0 - penalty);
  };
  const Vec3 per_ms = multipliers_after(1e-3), per_tenth = multipliers_after(1e-4);
  ASSERT_GT(per_ms.norm(), 0.0);
  EXPECT_LT((per_tenth - 0.1 * per_ms).norm(), 1e-9 * per_ms.norm());
}

}  // namespace
}  // namespace pointhaptics
