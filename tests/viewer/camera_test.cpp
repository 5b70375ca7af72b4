// Tests for the viewer's camera: projection and rays agree, framing shows the whole box, orbit keeps the
// distance, pan moves the target with the cursor, the view-plane construction the mouse probe uses.
#include "camera.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace pointhaptics::viewer {
namespace {

const Viewport vp{340, 0, 940, 800};

TEST(OrbitCamera, TheRayThroughAProjectedPointPassesThroughIt) {
  OrbitCamera c;
  c.target = Vec3(0.1, 0.02, -0.03);
  c.distance = 0.4;
  c.yaw = 0.7;
  c.pitch = -0.3;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(-0.1, 0.1);
  for (int k = 0; k < 50; ++k) {
    const Vec3 p = c.target + Vec3(d(rng), d(rng), d(rng));
    const Eigen::Vector2d px = c.project(p, vp);
    ASSERT_TRUE(px.allFinite());
    const Ray r = c.ray(px.x(), px.y(), vp);
    EXPECT_NEAR(r.direction.norm(), 1.0, 1e-12);
    const Vec3 to_p = p - r.origin;
    EXPECT_LE((to_p - to_p.dot(r.direction) * r.direction).norm(), 1e-9);  // p lies on the ray
  }
  EXPECT_FALSE(c.project(c.eye() - c.forward(), vp).allFinite());  // behind the eye
}

TEST(OrbitCamera, TheTargetIsAtTheViewportCentreAndUpIsUp) {
  OrbitCamera c;
  c.frame(Vec3(0, 0, 0), Vec3(0.135, 0.03, 0.03));
  const Eigen::Vector2d centre = c.project(c.target, vp);
  EXPECT_NEAR(centre.x(), vp.x + 0.5 * vp.width, 1e-9);
  EXPECT_NEAR(centre.y(), vp.y + 0.5 * vp.height, 1e-9);
  EXPECT_LT(c.project(c.target + 0.01 * Vec3::UnitY(), vp).y(), centre.y());  // higher is nearer the top
  EXPECT_NEAR(c.right().dot(c.forward()), 0.0, 1e-12);
  EXPECT_NEAR(c.up().dot(c.forward()), 0.0, 1e-12);
  EXPECT_GT(c.up().y(), 0.0);
}

TEST(OrbitCamera, FramingKeepsEveryCornerOfTheBoxInTheViewport) {
  for (const double yaw : {0.0, 0.35, 1.2, 2.5}) {
    OrbitCamera c;
    c.yaw = yaw;
    const Vec3 lo(-0.05, 0.0, -0.05), hi(0.05, 0.05, 0.05);
    c.frame(lo, hi);
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 p((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(), (corner & 4) ? hi.z() : lo.z());
      const Eigen::Vector2d px = c.project(p, vp);
      EXPECT_TRUE(vp.contains(px.x(), px.y())) << "yaw " << yaw << " corner " << corner;
    }
  }
}

TEST(OrbitCamera, OrbitKeepsTheDistancePanFollowsTheCursorZoomScales) {
  OrbitCamera c;
  c.frame(Vec3::Zero(), Vec3::Ones());
  const double d = c.distance;
  c.orbit(100, 40, vp);
  EXPECT_NEAR((c.eye() - c.target).norm(), d, 1e-12);
  c.orbit(0, 1e6, vp);  // clamped short of the pole
  EXPECT_LE(c.pitch, 1.5);
  // a point at the target's depth stays under the cursor while panning
  OrbitCamera p;
  p.frame(Vec3::Zero(), Vec3::Ones());
  const Vec3 anchor = p.target;
  const Eigen::Vector2d before = p.project(anchor, vp);
  p.pan(25, -10, vp);
  const Eigen::Vector2d after = p.project(anchor, vp);
  EXPECT_NEAR(after.x() - before.x(), 25, 1e-6);
  EXPECT_NEAR(after.y() - before.y(), -10, 1e-6);
  p.zoom(2.0);
  EXPECT_NEAR(p.distance, 2 * d, 1e-12);
}

TEST(OrbitCamera, TheViewPlaneThroughAPointHoldsItsDepth) {
  OrbitCamera c;
  c.frame(Vec3::Zero(), Vec3(0.1, 0.1, 0.1));
  const Vec3 anchor(0.02, 0.08, 0.03);
  const Vec3 q = on_view_plane(c, c.ray(600, 300, vp), anchor);
  ASSERT_TRUE(q.allFinite());
  EXPECT_NEAR((q - anchor).dot(c.forward()), 0.0, 1e-12);  // same depth
  const Eigen::Vector2d px = c.project(q, vp);
  EXPECT_NEAR(px.x(), 600, 1e-6);  // under the cursor
  EXPECT_NEAR(px.y(), 300, 1e-6);
  // a plane behind the eye is never met
  EXPECT_FALSE(on_view_plane(c, c.ray(600, 300, vp), c.eye() - c.forward()).allFinite());
}

TEST(CursorAnchor, TheTargetStaysUntilTheCursorMovesThenFollowsItsMotionWithoutAJump) {
  OrbitCamera c;
  c.frame(Vec3(0, 0, 0), Vec3(0.135, 0.03, 0.03));
  const Vec3 start(0.0675, 0.05, 0.015);  // above the beam
  CursorAnchor anchor;
  // the pointer rests over the middle of the beam: the target does not jump there
  const Eigen::Vector2d over_beam = c.project(Vec3(0.0675, 0.015, 0.015), vp);
  EXPECT_EQ(anchor.follow(c, vp, over_beam.x(), over_beam.y(), start), start);
  EXPECT_EQ(anchor.follow(c, vp, over_beam.x(), over_beam.y(), start), start);
  // the first motion anchors it where it is; 40 pixels more move it right by 40 pixels' worth at its depth
  Vec3 t = anchor.follow(c, vp, over_beam.x() + 1, over_beam.y(), start);
  EXPECT_LE((t - start).norm(), 1e-12);
  t = anchor.follow(c, vp, over_beam.x() + 41, over_beam.y(), t);
  const double depth = (start - c.eye()).dot(c.forward());
  EXPECT_NEAR((t - start).dot(c.right()), 40 / c.pixels_per_metre(depth, vp), 1e-6);
  EXPECT_NEAR((t - start).dot(c.up()), 0.0, 1e-6);
  EXPECT_NEAR((t - start).dot(c.forward()), 0.0, 1e-9);  // in the plane facing the camera
  // re-anchored after a reset: the next position is kept
  anchor.reset();
  EXPECT_LE((anchor.follow(c, vp, 10, 10, t) - t).norm(), 1e-12);
}

}  // namespace
}  // namespace pointhaptics::viewer
