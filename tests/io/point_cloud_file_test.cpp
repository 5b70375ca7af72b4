// Tests for io/point_cloud_file: text clouds and bad input.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/point_cloud_file.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace pointhaptics {
namespace {

std::string write(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("ph_cloud_" + name);
  std::ofstream(path) << text;
  return path.string();
}

std::string error_of(const std::string& path) {
  try {
    read_point_cloud(path, 0.01);
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

TEST(PointCloudFile, ReadsXyzAndCsvWithHeadersAndComments) {
  const PointCloud a = read_point_cloud(write("a.xyz", "# a comment\n0 0 0\n0.01 0 0\n\n0 0.01 0.02\n"), 0.01);
  ASSERT_EQ(a.size(), 3);
  EXPECT_DOUBLE_EQ(a.X(2, 2), 0.02);
  EXPECT_DOUBLE_EQ(a.volume[0], 1e-6);
  const PointCloud b = read_point_cloud(write("b.csv", "x,y,z\n1,2,3\n4,5,6\n"), 0.01);
  ASSERT_EQ(b.size(), 2);
  EXPECT_DOUBLE_EQ(b.X(1, 1), 5.0);
}

TEST(PointCloudFile, BadInputIsANamedError) {
  EXPECT_NE(error_of("/nonexistent/cloud.xyz").find("/nonexistent/cloud.xyz"), std::string::npos);
  const std::string truncated = error_of(write("t.xyz", "0 0 0\n1 2\n"));
  EXPECT_NE(truncated.find("t.xyz:2"), std::string::npos) << truncated;
  EXPECT_NE(error_of(write("n.xyz", "0 0 0\nnan 0 0\n")).find("not finite"), std::string::npos);
  EXPECT_NE(error_of(write("e.xyz", "# nothing\n")).find("no points"), std::string::npos);
  EXPECT_NE(error_of(write("m.ply", "ply\n")).find("not readable yet"), std::string::npos);
}

}  // namespace
}  // namespace pointhaptics
