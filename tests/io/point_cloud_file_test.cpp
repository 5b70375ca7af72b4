// Tests for io/point_cloud_file: PLY (ASCII, binary little and big endian) and text clouds with their
// attributes, and malformed, truncated and hostile files, which must end in an error naming the file.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/mesh_file.hpp>
#include <pointhaptics/io/point_cloud_file.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace pointhaptics {
namespace {

std::string write(const std::string& name, const std::string& data) {
  const auto path = std::filesystem::temp_directory_path() / ("ph_cloud_" + name);
  std::ofstream(path, std::ios::binary) << data;
  return path.string();
}

std::string error_of(const std::string& data, const std::string& format) {
  try {
    parse_point_cloud(data, format, "bad" + format, 0.01);
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

// a tetrahedron's corners and a fifth point, 1 cm apart; point 3 held, volumes 1..5 cm^3
const double corners[5][3] = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0, 0, 0.01}, {0.01, 0.01, 0.01}};

std::string text_cloud(char sep, bool attributes) {
  std::ostringstream s;
  for (int i = 0; i < 5; ++i) {
    s << corners[i][0] << sep << corners[i][1] << sep << corners[i][2];
    if (attributes) s << sep << (i == 3 ? 1 : 0) << sep << (i + 1) * 1e-6;
    s << '\n';
  }
  return s.str();
}

template <class T>
void put(std::string& out, T value, bool big) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
  out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

// a PLY of the five points: float x y z, a uchar colour to ignore, uchar fixed, double volume, behind an
// element that comes first and must be skipped; `header_format` may lie about the data's byte order
std::string ply(const std::string& format, bool big_data, const std::string& header_format = "") {
  std::string s =
      "ply\nformat " + (header_format.empty() ? format : header_format) +
      " 1.0\ncomment made by the tests\nelement camera 1\nproperty float view\n"
      "element vertex 5\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
      "property uchar fixed\nproperty double volume\nelement face 0\nproperty list uchar int vertex_indices\n"
      "end_header\n";
  if (format == "ascii") {
    s += "1.5\n";
    std::ostringstream lines;
    for (int i = 0; i < 5; ++i)
      lines << corners[i][0] << ' ' << corners[i][1] << ' ' << corners[i][2] << " 200 " << (i == 3 ? 1 : 0) << ' '
            << (i + 1) * 1e-6 << '\n';
    return s + lines.str();
  }
  put<float>(s, 1.5f, big_data);
  for (int i = 0; i < 5; ++i) {
    for (int a = 0; a < 3; ++a) put<float>(s, static_cast<float>(corners[i][a]), big_data);
    put<std::uint8_t>(s, 200, big_data);
    put<std::uint8_t>(s, i == 3 ? 1 : 0, big_data);
    put<double>(s, (i + 1) * 1e-6, big_data);
  }
  return s;
}

void expect_the_five_points(const PointCloud& c, bool attributes) {
  ASSERT_EQ(c.size(), 5);
  for (int i = 0; i < 5; ++i)
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(c.X(a, i), corners[i][a], 1e-9) << "point " << i;
  if (!attributes) {
    EXPECT_TRUE(c.held.empty());
    EXPECT_DOUBLE_EQ(c.volume[2], 1e-6);  // spacing^3
    return;
  }
  ASSERT_EQ(c.held.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(c.held[i], i == 3 ? 1 : 0);
  EXPECT_NEAR(c.volume[4], 5e-6, 1e-15);
}

TEST(PointCloudFile, ReadsXyzAndCsvWithAndWithoutAttributes) {
  expect_the_five_points(read_point_cloud(write("a.xyz", "# a comment\n" + text_cloud(' ', false)), 0.01), false);
  expect_the_five_points(read_point_cloud(write("b.xyz", text_cloud(' ', true)), 0.01), true);
  expect_the_five_points(read_point_cloud(write("c.csv", "x,y,z\n" + text_cloud(',', false)), 0.01), false);
  // a header names the columns, in any order
  std::ostringstream reordered;
  reordered << "volume, fixed, z, y, x\r\n";
  for (int i = 0; i < 5; ++i)
    reordered << (i + 1) * 1e-6 << ", " << (i == 3 ? 1 : 0) << ", " << corners[i][2] << ", " << corners[i][1] << ", "
              << corners[i][0] << "\r\n";
  expect_the_five_points(read_point_cloud(write("d.csv", reordered.str()), 0.01), true);
}

TEST(PointCloudFile, ReadsPlyInEveryEncoding) {
  expect_the_five_points(read_point_cloud(write("a.ply", ply("ascii", false)), 0.01), true);
  expect_the_five_points(read_point_cloud(write("l.ply", ply("binary_little_endian", false)), 0.01), true);
  expect_the_five_points(read_point_cloud(write("b.ply", ply("binary_big_endian", true)), 0.01), true);
}

TEST(PointCloudFile, HeldPointsOfAFileAreHeldInTheScene) {
  // a 4 x 4 x 4 lattice, its bottom layer marked fixed in the file
  std::ostringstream s;
  s << "x y z fixed\n";
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k)
        s << 0.01 * i << ' ' << 0.01 * j << ' ' << 0.01 * k << ' ' << (j == 0 ? 1 : 0) << '\n';
  const std::string cloud = write("lattice.xyz", s.str());
  const Scene scene =
      parse_scene("[object]\nshape = \"file\"\nfile = \"" + cloud + "\"\nspacing = 0.01\n", "file.toml");
  const Model m = build_scene_model(scene);
  ASSERT_EQ(m.n_points, 64);
  for (index_t i = 0; i < m.n_points; ++i) EXPECT_EQ(m.fixed[i] != 0, m.X(1, i) < 1e-9) << "point " << i;
}

TEST(PointCloudFile, DevicesFifosAndFoldersAreRefusedBeforeReading) {
  // issue 21: a FIFO blocked the reader and /dev/zero fed it without end
  const std::string fifo = (std::filesystem::temp_directory_path() / "ph_cloud_fifo.xyz").string();
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  for (const std::string& path : {fifo, std::string("/dev/zero"), std::filesystem::temp_directory_path().string()}) {
    try {
      read_point_cloud(path, 0.01);
      ADD_FAILURE() << path << " accepted";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_TRUE(what.find("not a regular file") != std::string::npos || what.find("is a folder") != std::string::npos)
          << what;
    }
  }
  std::filesystem::remove(fifo);
}

TEST(PointCloudFile, APlyMeshWithALongHeaderIsAMesh) {
  // issue 21: a header of more than 1000 lines hid the faces, and the mesh was refused as a cloud
  std::string header = "ply\nformat ascii 1.0\n";
  for (int k = 0; k < 1500; ++k) header += "comment line " + std::to_string(k) + "\n";
  header +=
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\n"
      "property list uchar int vertex_indices\nend_header\n";
  EXPECT_TRUE(ply_has_faces(
      write("long_header.ply", header + "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")));
}

TEST(PointCloudFile, MalformedTruncatedAndHostileFilesAreNamedErrors) {
  auto has = [](const std::string& error, const std::string& what) {
    EXPECT_NE(error.find(what), std::string::npos) << "expected \"" << what << "\" in: " << error;
    EXPECT_NE(error.find("bad."), std::string::npos) << "the file is not named: " << error;
  };
  // text
  has(error_of(text_cloud(' ', false) + "1 2\n", ".xyz"), "bad.xyz:6");
  has(error_of(text_cloud(' ', false) + "nan 0 0\n", ".xyz"), "not finite");
  has(error_of(text_cloud(' ', false) + "0.1 0.2 zero\n", ".xyz"), "\"zero\" is not a number");
  has(error_of("# nothing\n", ".xyz"), "no points");
  has(error_of("0 0 0 0 0 0 0\n", ".xyz"), "3 to 5 numbers");
  has(error_of(text_cloud(',', true) + "0.3,0.3,0.3,0,-1\n", ".csv"), "volume -1 m^3 is out of range");
  // issue 52: volumes of 1e-320 and 1e307 m^3 were taken, and the run "diverged"
  has(error_of(text_cloud(',', true) + "0.3,0.3,0.3,0,1e-320\n", ".csv"), "volume 1e-320 m^3 is out of range");
  has(error_of(text_cloud(',', true) + "0.3,0.3,0.3,0,1e307\n", ".csv"), "volume 1e+307 m^3 is out of range");
  // duplicates and degenerate clouds are reported, not simulated
  has(error_of(text_cloud(' ', false) + "0.01 0 0\n", ".xyz"), "coincide");
  has(error_of("0 0 0\n0.01 0 0\n0 0.01 0\n0.01 0.01 0\n0.02 0.01 0\n", ".xyz"), "lie on a plane");
  has(error_of("0 0 0\n0.01 0 0\n0.02 0 0\n0.03 0 0\n", ".xyz"), "lie on a line");
  has(error_of("0 0 0\n0.01 0 0\n0 0.01 0\n", ".xyz"), "no solid");
  has(error_of(text_cloud(' ', false) + "3e9 0 0\n", ".xyz"), "implausible");
  // PLY
  has(error_of("plx\n", ".ply"), "not a PLY file");
  has(error_of("ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\n", ".ply"), "no end_header");
  has(error_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n", ".ply"),
      "unknown property type");
  has(error_of("ply\nformat ebcdic 1.0\nend_header\n", ".ply"), "unknown PLY format");
  has(error_of("ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nend_header\n", ".ply"),
      "lacks x, y or z");
  const std::string binary = ply("binary_little_endian", false);
  has(error_of(binary.substr(0, binary.size() - 7), ".ply"), "holds only");  // truncated
  has(error_of(ply("ascii", false).substr(0, ply("ascii", false).size() - 20), ".ply"), "vertex 4: expected 6 numbers");
  std::string huge = binary;
  huge.replace(huge.find("element vertex 5"), 16, "element vertex 99999999999999");
  has(error_of(huge, ".ply"), "declares 99999999999999 vertices");  // a count to exhaust memory
  has(error_of(ply("binary_big_endian", true, "binary_little_endian"), ".ply"), "bad.ply: point");  // wrong byte order
  std::string nan = ply("ascii", false);
  nan.replace(nan.find("0.01 0 0 200"), 12, "nan 0 0 200");
  has(error_of(nan, ".ply"), "not finite");
  std::string faces = ply("ascii", false);
  faces.replace(faces.find("element face 0"), 14, "element face 2");
  has(error_of(faces, ".ply"), "surface mesh");
  has(error_of("solid\n", ".stl"), "not a point cloud this version reads");
  // issue 21: held flags other than 0 and 1, and more vertex lines than the header declares
  has(error_of(text_cloud(',', true) + "0.3,0.3,0.3,nan,1\n", ".csv"), "fixed = nan must be 0 or 1");
  has(error_of(text_cloud(',', true) + "0.3,0.3,0.3,2.5,1\n", ".csv"), "fixed = 2.5 must be 0 or 1");
  std::string held = ply("ascii", true);
  held.replace(held.find(" 1 4e-06"), 8, " 2 4e-06");
  has(error_of(held, ".ply"), "fixed = 2 must be 0 or 1");
  std::string more = ply("ascii", false);
  more.replace(more.find("element vertex 5"), 16, "element vertex 3");
  has(error_of(more, ".ply"), "holds 2 more data lines than its header declares (3 vertices)");
  try {
    read_point_cloud("/nonexistent/cloud.ply", 0.01);
    ADD_FAILURE() << "a missing file was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/cloud.ply"), std::string::npos);
  }
}

}  // namespace
}  // namespace pointhaptics
