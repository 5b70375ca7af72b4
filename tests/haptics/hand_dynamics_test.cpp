// Tests for haptics/hand_dynamics: the endpoint settles on the hand's target, gives way to a force by F / k,
// rings at the mass-spring frequency, and bad parameters are named errors.
#include <pointhaptics/haptics/hand_dynamics.hpp>

#include <pointhaptics/core/error.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace pointhaptics {
namespace {

TEST(HandEndpoint, SettlesOnTheTargetAndGivesWayToAForceByItOverTheGrip) {
  HandDynamics hand;
  HandEndpoint endpoint(hand, Vec3::Zero());
  const Vec3 target(0.01, 0.02, -0.01);
  endpoint.advance(2.0, [&](double) { return target; });
  EXPECT_LE((endpoint.position() - target).norm(), 1e-6);
  EXPECT_LT(endpoint.velocity().norm(), 1e-5);
  endpoint.set_force(Vec3(0, -1.5, 0));
  endpoint.advance(4.0, [&](double) { return target; });
  EXPECT_NEAR(endpoint.position().y(), target.y() - 1.5 / hand.stiffness, 1e-6);
  EXPECT_DOUBLE_EQ(endpoint.time(), 4.0);
}

TEST(HandEndpoint, RingsAtTheMassSpringFrequencyWithoutDamping) {
  HandDynamics hand;
  hand.damping = 0;
  HandEndpoint endpoint(hand, Vec3(1e-3, 0, 0));
  // released 1 mm off the target at rest: x(t) = 1 mm cos(omega t); after half a period, -1 mm
  const double omega = std::sqrt(hand.stiffness / hand.mass);
  endpoint.advance(M_PI / omega, [](double) { return Vec3::Zero(); });
  EXPECT_NEAR(endpoint.position().x(), -1e-3, 2e-5);
}

TEST(HandEndpoint, TimeOnlyMovesForwardAndBadHandsAreRefused) {
  HandEndpoint endpoint(HandDynamics{}, Vec3::Zero());
  endpoint.advance(0.5, [](double) { return Vec3(0.01, 0, 0); });
  const Vec3 at = endpoint.position();
  endpoint.advance(0.2, [](double) { return Vec3(1, 1, 1); });  // earlier: nothing happens
  EXPECT_EQ(endpoint.position(), at);
  HandDynamics massless;
  massless.mass = 0;
  EXPECT_THROW(HandEndpoint(massless, Vec3::Zero()), Error);
  HandDynamics negative;
  negative.damping = -1;
  EXPECT_THROW(HandEndpoint(negative, Vec3::Zero()), Error);
}

}  // namespace
}  // namespace pointhaptics
