// Tests for io/vtk: a frame's structure and values, the collection, and named errors.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/vtk.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace pointhaptics {
namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Vtk, FramesAndTheirCollection) {
  const auto dir = std::filesystem::temp_directory_path() / "ph_vtk_test";
  std::filesystem::remove_all(dir);
  Points x(3, 2);
  x << 0, 1, 0, 2, 0.5, 3;
  VtkSeries series(dir.string());
  const std::string first = series.add(0.0, x, {{"speed", 1, {1.5, 2.5}, false}, {"held", 1, {1, 0}, true}});
  series.add(0.25, x, {{"speed", 1, {3.5, 4.5}, false}, {"held", 1, {1, 0}, true}});
  EXPECT_EQ(series.frames(), 2);
  const std::string frame = slurp(first);
  EXPECT_NE(frame.find("<Piece NumberOfPoints=\"2\" NumberOfVerts=\"2\""), std::string::npos) << frame;
  EXPECT_NE(frame.find("0 0 0.5\n1 2 3\n"), std::string::npos) << frame;  // points, column by column
  EXPECT_NE(frame.find("Name=\"speed\" NumberOfComponents=\"1\" format=\"ascii\">\n1.5\n2.5\n"), std::string::npos)
      << frame;
  EXPECT_NE(frame.find("type=\"UInt8\" Name=\"held\""), std::string::npos) << frame;
  const std::string pvd = slurp(series.collection_path());
  EXPECT_NE(pvd.find("timestep=\"0.25\" group=\"\" part=\"0\" file=\"frame_000001.vtp\""), std::string::npos) << pvd;
}

TEST(Vtk, BadArraysAndUnwritableFoldersAreNamedErrors) {
  Points x = Points::Zero(3, 3);
  const auto dir = std::filesystem::temp_directory_path() / "ph_vtk_bad";
  std::filesystem::create_directories(dir);
  try {
    write_vtp((dir / "a.vtp").string(), x, {{"v", 3, {1, 2, 3}, false}});
    ADD_FAILURE() << "a short array was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("array \"v\""), std::string::npos) << e.what();
  }
  EXPECT_THROW(write_vtp("/nonexistent/dir/a.vtp", x, {}), Error);
  EXPECT_THROW(VtkSeries("/proc/ph_cannot_create"), Error);
}

}  // namespace
}  // namespace pointhaptics
