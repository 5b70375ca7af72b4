// Tests for io/haptic_log: the log round-trips and bad logs are named errors.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/haptic_log.hpp>

#include <gtest/gtest.h>

#include <fstream>

namespace pointhaptics {
namespace {

std::string temp(const std::string& name) { return ::testing::TempDir() + name; }

TEST(HapticLog, RoundTrips) {
  std::vector<HapticLogRow> rows;
  for (int k = 0; k <= 10; ++k)
    rows.push_back({k * 1e-3, Vec3(0, -1e-3 * k, 0), Vec3(0, -1.0, 0), k >= 5 ? 1u : 0u, Vec3(0, 0.01 * k, 0),
                    Vec3(1e-4 * k, 0, -2e-4)});
  write_haptic_log(temp("log.csv"), rows);
  const std::vector<HapticLogRow> back = read_haptic_log(temp("log.csv"));
  ASSERT_EQ(back.size(), rows.size());
  for (size_t k = 0; k < rows.size(); ++k) {
    EXPECT_NEAR(back[k].t, rows[k].t, 1e-9);
    EXPECT_LE((back[k].position - rows[k].position).norm(), 1e-12);
    EXPECT_EQ(back[k].buttons, rows[k].buttons);
    EXPECT_LE((back[k].force - rows[k].force).norm(), 1e-12);
    EXPECT_LE((back[k].torque - rows[k].torque).norm(), 1e-12);
  }
}

TEST(HapticLog, ALogWithoutTheTorquesColumnsReadsWithNone) {
  std::ofstream(temp("old.csv")) << "t,x,y,z,vx,vy,vz,buttons,fx,fy,fz\n0.001,0,0,0,0,0,0,1,0,0.5,0\n";
  const std::vector<HapticLogRow> back = read_haptic_log(temp("old.csv"));
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].force.y(), 0.5);
  EXPECT_EQ(back[0].torque.norm(), 0.0);
}

TEST(HapticLog, BadLogsAreNamedErrors) {
  auto error_of = [](const std::string& text) {
    std::ofstream(temp("bad.csv")) << text;
    try {
      read_haptic_log(temp("bad.csv"));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(error_of("t,x,y,z,vx,vy,vz,buttons,fx,fy,fz\n").find("no rows"), std::string::npos);
  EXPECT_NE(error_of("0,0,0,0,0,0,0,0,0,0\n").find("bad.csv:1:"), std::string::npos);            // 10 fields
  EXPECT_NE(error_of("0,0,0,0,0,0,0,0,0,0,0,0\n").find("bad.csv:1:"), std::string::npos);        // 12 fields
  EXPECT_NE(error_of("0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n").find("bad.csv:1:"), std::string::npos);  // 15 fields
  EXPECT_NE(error_of("0,0,nan,0,0,0,0,0,0,0,0\n").find("bad.csv:1:"), std::string::npos);
  EXPECT_NE(error_of("1,0,0,0,0,0,0,0,0,0,0\n0.5,0,0,0,0,0,0,0,0,0,0\n").find("bad.csv:2: time does not increase"),
            std::string::npos);
  EXPECT_THROW(read_haptic_log("/nonexistent/log.csv"), Error);
  // issue 52: a buttons column of -1, 1e30 or 0.5 is not a button mask (they were taken as pressed)
  for (const char* buttons : {"-1", "1e30", "0.5", "65536"})
    EXPECT_NE(error_of(std::string("0,0,0,0,0,0,0,") + buttons + ",0,0,0\n").find("is not a button mask"),
              std::string::npos)
        << buttons;
  EXPECT_EQ(error_of("0,0,0,0,0,0,0,3,0,0,0\n"), "accepted");
}

}  // namespace
}  // namespace pointhaptics
