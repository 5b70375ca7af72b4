// Tests for haptics/contact: push (sphere-sphere overlap, action and reaction, the local model), grab
// (the points under the probe follow it while the button is held), and bad probe positions.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/haptics/contact.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

const double s = 0.01;

Model block() { return build_model(test::jittered_box(6, 4, 6, s, 0.0), MaterialParams{}, KernelParams{}); }

// the block at rest with a probe of the given radius and mode, and a force buffer
struct ProbeOnBlock {
  ProbeOnBlock(double radius, ProbeMode mode) : model(block()), contact(model, params(radius, mode)) {}
  static ProbeParams params(double radius, ProbeMode mode) {
    ProbeParams p;
    p.radius = radius;
    p.mode = mode;
    return p;
  }
  Model model;
  ProbeContact contact;
  Points u = Points::Zero(3, model.n_points);
  Points f = Points::Zero(3, model.n_points);
};

TEST(ProbeContact, PushMovesTouchedPointsOutAndTheProbeFeelsTheOpposite) {
  const Model model = block();  // top face at y = 0.03
  ProbeParams p;
  p.radius = 0.008;
  ProbeContact contact(model, p);
  const Points u = Points::Zero(3, model.n_points);
  Points f = Points::Zero(3, model.n_points);
  const Vec3 probe(0.025, 0.03 + 0.008, 0.025);  // resting on the top face, overlapping by the point radius
  const ContactModel cm = contact.apply(model, u, probe, false, 0.0, f);
  EXPECT_GT(cm.contacts, 0);
  // action and reaction
  EXPECT_LE((f.rowwise().sum() + cm.f0).norm(), 1e-12);
  EXPECT_GT(cm.f0.y(), 0.0);  // the object pushes the probe up
  int touched = 0;
  for (index_t i = 0; i < model.n_points; ++i) {
    if (f.col(i).norm() == 0) continue;
    ++touched;
    EXPECT_LE((model.X.col(i) - probe).norm(), p.radius + 0.5 * s + 1e-12);  // only overlapping spheres
    EXPECT_GT((model.X.col(i) - probe).dot(f.col(i)), 0.0);                  // pushed away from the probe centre
  }
  EXPECT_EQ(touched, cm.contacts);
  // K is symmetric negative semi-definite
  EXPECT_LE((cm.K - cm.K.transpose()).norm(), 1e-9);
  EXPECT_LE(Eigen::SelfAdjointEigenSolver<Mat3>(cm.K).eigenvalues().maxCoeff(), 1e-9);
  // the local model predicts most of the force change of a small move into the object (it keeps only the
  // normal stiffness of each contact; the tangential part, left out to keep K negative semi-definite,
  // is the rest)
  const Vec3 dp(0, -1e-4, 0);
  Points f2 = Points::Zero(3, model.n_points);
  ProbeContact again(model, p);
  const ContactModel moved = again.apply(model, u, probe + dp, false, 0.0, f2);
  EXPECT_EQ(moved.contacts, cm.contacts);
  const double change = moved.f0.y() - cm.f0.y();
  EXPECT_GT(change, 0.0);
  EXPECT_NEAR((cm.f0 + cm.K * dp).y(), moved.f0.y(), 0.3 * change);
}

TEST(ProbeContact, GrabbedPointsFollowTheProbeWhileTheButtonIsHeld) {
  ProbeOnBlock b(0.006, ProbeMode::GRAB);
  auto& [model, contact, u, f] = b;
  const Vec3 probe(0.02, 0.03, 0.02);
  EXPECT_EQ(contact.apply(model, u, probe, false, 0.0, f).contacts, 0);  // not pressed: nothing
  const ContactModel press = contact.apply(model, u, probe, true, 0.0, f);
  ASSERT_GT(press.contacts, 0);
  EXPECT_TRUE(press.grabbing);
  EXPECT_LE(f.norm(), 1e-15);  // at the press the springs are relaxed
  const Vec3 pull(0, 0.002, 0);
  f.setZero();
  const ContactModel pulled = contact.apply(model, u, probe + pull, true, 0.001, f);
  EXPECT_EQ(pulled.contacts, press.contacts);
  const double k = contact.params().stiffness;
  EXPECT_DOUBLE_EQ(k, model.material.young * s);  // the default: the object's own stiffness scale
  for (index_t i : contact.grabbed()) EXPECT_LE((f.col(i) - k * pull).norm(), 1e-9 * k);
  EXPECT_LE((pulled.f0 + press.contacts * k * pull).norm(), 1e-9 * k);  // the probe is pulled back
  EXPECT_LE((pulled.K + press.contacts * k * Mat3::Identity()).norm(), 1e-9 * k);
  f.setZero();
  EXPECT_EQ(contact.apply(model, u, probe + pull, false, 0.002, f).contacts, 0);  // released
  EXPECT_EQ(f.norm(), 0.0);
}

TEST(ProbeContact, PushGrabPushesWithTheButtonUpAndGrabsWhileItIsHeld) {
  ProbeOnBlock b(0.008, ProbeMode::PUSH_GRAB);
  auto& [model, contact, u, f] = b;
  const Vec3 probe(0.025, 0.03 + 0.008, 0.025);
  const ContactModel pushed = contact.apply(model, u, probe, false, 0.0, f);
  ASSERT_GT(pushed.contacts, 0);
  EXPECT_FALSE(pushed.grabbing);
  EXPECT_GT(pushed.f0.y(), 0.0);  // pushed: the object pushes back up
  EXPECT_FALSE(contact.touched().empty());
  f.setZero();
  const ContactModel press = contact.apply(model, u, probe, true, 0.001, f);
  ASSERT_GT(press.contacts, 0);
  EXPECT_TRUE(press.grabbing);
  EXPECT_TRUE(contact.touched().empty());
  EXPECT_LE(f.norm(), 1e-15);  // relaxed at the press
  f.setZero();
  const ContactModel lifted = contact.apply(model, u, probe + Vec3(0, 0.003, 0), true, 0.002, f);
  EXPECT_EQ(lifted.contacts, press.contacts);
  EXPECT_LT(lifted.f0.y(), 0.0);  // the grabbed points pull the probe back down
  Eigen::Matrix<double, 9, Eigen::Dynamic> springs = Eigen::Matrix<double, 9, Eigen::Dynamic>::Zero(9, model.n_points);
  contact.add_stiffness(springs);
  EXPECT_NEAR(springs.col(contact.grabbed().front())(0), contact.params().stiffness, 1e-9);
  // released above the surface: neither grabbed nor touched
  f.setZero();
  const ContactModel released = contact.apply(model, u, probe + Vec3(0, 0.003, 0), false, 0.003, f);
  EXPECT_EQ(released.contacts, 0);
  EXPECT_TRUE(contact.grabbed().empty());
  EXPECT_EQ(f.norm(), 0.0);
}

TEST(ProbeContact, NonFiniteProbeMeansNoContact) {
  const Model model = block();
  ProbeContact contact(model, ProbeParams{});
  Points f = Points::Zero(3, model.n_points);
  const ContactModel cm = contact.apply(model, Points::Zero(3, model.n_points), Vec3(NAN, 0, 0), true, 0, f);
  EXPECT_EQ(cm.contacts, 0);
  EXPECT_EQ(f.norm(), 0.0);
  ProbeParams bad;
  bad.radius = -1;
  EXPECT_THROW(ProbeContact(model, bad), Error);
}

}  // namespace
}  // namespace pointhaptics
