// Tests for haptics/trajectory: interpolation, holding at the ends, CSV reading and its errors.
#include <pointhaptics/haptics/trajectory.hpp>

#include <pointhaptics/core/error.hpp>

#include <gtest/gtest.h>

#include <fstream>

namespace pointhaptics {
namespace {

TEST(Trajectory, InterpolatesLinearlyAndHoldsAtTheEnds) {
  const Trajectory tr({{0.0, Vec3(0, 0, 0), false}, {1.0, Vec3(0, 0.1, 0), true}, {2.0, Vec3(0.1, 0.1, 0), false}});
  EXPECT_EQ(tr.position(-1.0), Vec3::Zero());
  EXPECT_LE((tr.position(0.5) - Vec3(0, 0.05, 0)).norm(), 1e-15);
  EXPECT_LE((tr.position(1.5) - Vec3(0.05, 0.1, 0)).norm(), 1e-15);
  EXPECT_EQ(tr.position(5.0), Vec3(0.1, 0.1, 0));
  EXPECT_FALSE(tr.button(0.5));
  EXPECT_TRUE(tr.button(1.0));
  EXPECT_TRUE(tr.button(1.99));
  EXPECT_FALSE(tr.button(2.5));
  EXPECT_DOUBLE_EQ(tr.duration(), 2.0);
  EXPECT_THROW(Trajectory({{1.0, Vec3::Zero(), false}, {1.0, Vec3::Zero(), false}}), Error);
}

std::string write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

TEST(Trajectory, ReadsCsvAndNamesTheBadLine) {
  const Trajectory tr =
      Trajectory::from_csv(write("probe.csv", "t,x,y,z,button\n0, 0, 0, 0\n0.5, 0, 0.01, 0, 1 # grab\n\n1 0 0 0\n"));
  ASSERT_EQ(tr.keyframes().size(), 3u);
  EXPECT_TRUE(tr.button(0.6));
  try {
    Trajectory::from_csv(write("bad.csv", "0, 0, 0, 0\n0.5, 0, nan, 0\n"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:2:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Trajectory::from_csv(write("back.csv", "1, 0, 0, 0\n0.5, 0, 0, 0\n")), Error);
  EXPECT_THROW(Trajectory::from_csv(write("empty.csv", "# nothing\n")), Error);
  EXPECT_THROW(Trajectory::from_csv("/nonexistent/probe.csv"), Error);
}

}  // namespace
}  // namespace pointhaptics
