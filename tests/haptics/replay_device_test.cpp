// Tests for haptics/devices/replay_device: a replay follows the recorded positions and buttons, holds after
// the end, ignores the forces it is given, and refuses an empty log.
#include <pointhaptics/haptics/devices/replay_device.hpp>

#include <pointhaptics/core/error.hpp>

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

std::vector<HapticLogRow> recorded() {
  std::vector<HapticLogRow> rows;
  for (int k = 0; k <= 10; ++k)
    rows.push_back({k * 1e-3, Vec3(0, -1e-3 * k, 0), Vec3(0, -1.0, 0), k >= 5 ? 1u : 0u, Vec3(0, 0.01 * k, 0)});
  return rows;
}

TEST(ReplayDevice, FollowsTheRecordedPositionsAndHoldsAfterTheEnd) {
  ReplayDevice replay(recorded(), known_device_specs("touch"));
  EXPECT_DOUBLE_EQ(replay.duration(), 1e-2);
  EXPECT_NEAR(replay.read(2.5e-3).position.y(), -2.5e-3, 1e-12);
  EXPECT_EQ(replay.read(4e-3).buttons, 0u);
  EXPECT_EQ(replay.read(6e-3).buttons, 1u);
  EXPECT_NEAR(replay.read(1.0).position.y(), -1e-2, 1e-12);  // held after the end
  EXPECT_EQ(replay.read(1.0).velocity, Vec3::Zero());
}

TEST(ReplayDevice, IsOpenLoopAndReadsBackwardsToo) {
  ReplayDevice replay(recorded(), known_device_specs("touch"));
  const double before = replay.read(3e-3).position.y();
  replay.command(Vec3(0, 100.0, 0));  // a force cannot move a recording
  EXPECT_EQ(replay.read(3e-3).position.y(), before);
  EXPECT_NEAR(replay.read(8e-3).position.y(), -8e-3, 1e-12);
  EXPECT_NEAR(replay.read(1e-3).position.y(), -1e-3, 1e-12);  // the cursor goes back as well
}

TEST(ReplayDevice, AnEmptyLogIsANamedError) { EXPECT_THROW(ReplayDevice({}, known_device_specs("touch")), Error); }

}  // namespace
}  // namespace pointhaptics
