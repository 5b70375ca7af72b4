// Tests for io/volume_file: synthetic NIfTI and NRRD volumes made here (a sphere, an ellipsoid with a
// hole), voxel spacing, orientation and units honoured, and bad files as named errors.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/volume_file.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>

namespace pointhaptics {
namespace {

const std::string dir = (std::filesystem::temp_directory_path() / "ph_volume_test").string();

// voxel (i, j, k) -> world (mm): x flipped, 1 mm voxels, origin `o`
struct Grid {
  int n = 41;
  double origin[3] = {60.0, 10.0, 20.0};
  Vec3 world(int i, int j, int k) const { return Vec3(origin[0] - i, origin[1] + j, origin[2] + k); }
};

std::vector<float> voxels(const Grid& g, const std::function<float(const Vec3&)>& f) {
  std::vector<float> v(static_cast<std::size_t>(g.n * g.n * g.n));
  for (int k = 0; k < g.n; ++k)
    for (int j = 0; j < g.n; ++j)
      for (int i = 0; i < g.n; ++i) v[static_cast<std::size_t>(i + g.n * (j + g.n * k))] = f(g.world(i, j, k));
  return v;
}

template <class T>
void put(std::string& h, std::size_t at, T value) {
  std::memcpy(h.data() + at, &value, sizeof(T));
}

// a NIfTI-1 single file: 348-byte header, 4 bytes of extension flags, float32 data
std::string write_nifti(const std::string& name, const Grid& g, const std::vector<float>& v, int dims = 3) {
  std::string h(352, '\0');
  put<std::int32_t>(h, 0, 348);
  const std::int16_t dim[8] = {static_cast<std::int16_t>(dims),
                               static_cast<std::int16_t>(g.n),
                               static_cast<std::int16_t>(g.n),
                               static_cast<std::int16_t>(g.n),
                               static_cast<std::int16_t>(dims > 3 ? 2 : 1),
                               1,
                               1,
                               1};
  for (int d = 0; d < 8; ++d) put<std::int16_t>(h, 40 + 2 * d, dim[d]);
  put<std::int16_t>(h, 70, 16);  // float32
  put<std::int16_t>(h, 72, 32);
  const float pixdim[8] = {-1, 1, 1, 1, 1, 0, 0, 0};
  for (int d = 0; d < 8; ++d) put<float>(h, 76 + 4 * d, pixdim[d]);
  put<float>(h, 108, 352.0f);    // vox_offset
  put<float>(h, 112, 1.0f);      // scl_slope
  h[123] = 2;                    // millimetres
  put<std::int16_t>(h, 254, 1);  // sform_code
  const float srow[3][4] = {{-1, 0, 0, static_cast<float>(g.origin[0])},
                            {0, 1, 0, static_cast<float>(g.origin[1])},
                            {0, 0, 1, static_cast<float>(g.origin[2])}};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) put<float>(h, 280 + 16 * r + 4 * c, srow[r][c]);
  std::memcpy(h.data() + 344, "n+1\0", 4);
  const std::string path = dir + "/" + name;
  std::ofstream out(path, std::ios::binary);
  out.write(h.data(), static_cast<std::streamsize>(h.size()));
  out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(float)));
  return path;
}

std::string write_nrrd(const std::string& name, const Grid& g, const std::vector<float>& v) {
  const std::string path = dir + "/" + name;
  std::ofstream out(path, std::ios::binary);
  out << "NRRD0004\ntype: float\ndimension: 3\nsizes: " << g.n << ' ' << g.n << ' ' << g.n
      << "\nspace: right-anterior-superior\nspace directions: (-1,0,0) (0,1,0) (0,0,1)\nspace origin: (" << g.origin[0]
      << ',' << g.origin[1] << ',' << g.origin[2]
      << ")\nspace units: \"mm\" \"mm\" \"mm\"\nencoding: raw\nendian: little\n\n";
  out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(float)));
  return path;
}

const Vec3 centre_mm(40.0, 30.0, 40.0);

float sphere(const Vec3& x) { return (x - centre_mm).norm() <= 10.0 ? 100.0f : 0.0f; }

float ellipsoid_with_hole(const Vec3& x) {
  const Vec3 d = x - centre_mm;
  const double e = std::pow(d.x() / 15, 2) + std::pow(d.y() / 10, 2) + std::pow(d.z() / 8, 2);
  return e <= 1.0 && d.norm() > 4.0 ? 200.0f : 10.0f;
}

void expect_sphere(const PointCloud& c, const std::string& what) {
  const double exact = 4.0 / 3.0 * std::numbers::pi * 1e-6;  // r = 1 cm
  EXPECT_NEAR(c.volume.sum(), exact, 0.08 * exact) << what;
  const Vec3 mean = c.X.rowwise().mean();
  EXPECT_LE((mean - 1e-3 * centre_mm).norm(), 5e-4)
      << what << ": centroid " << mean.transpose();  // metres, orientation honoured
}

// the message of the Error f throws, or "accepted"
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

class VolumeFile : public ::testing::Test {
 protected:
  void SetUp() override { std::filesystem::create_directories(dir); }
};

TEST_F(VolumeFile, NiftiAndNrrdSpheresLandWhereTheImageSays) {
  const Grid g;
  const std::vector<float> v = voxels(g, sphere);
  const std::string nii = write_nifti("sphere.nii", g, v);
  const VolumeImage image = read_volume(nii);
  EXPECT_EQ(image.nx, 41);
  EXPECT_NEAR(image.voxel_to_world(0, 0), -1e-3, 1e-12);  // millimetres to metres, x flipped
  expect_sphere(sample_volume(image, 50, 150, 0.001, nii), "nifti");
  expect_sphere(sample_volume(read_volume(write_nrrd("sphere.nrrd", g, v)), 50, 150, 0.001, "nrrd"), "nrrd");
  // gzipped NIfTI, through nifti2's zlib
  ASSERT_EQ(std::system(("gzip -f -k " + nii).c_str()), 0);
  expect_sphere(sample_volume(read_volume(nii + ".gz"), 50, 150, 0.001, "nii.gz"), "nii.gz");
}

TEST_F(VolumeFile, AnEllipsoidWithAHoleKeepsItsHoleInAScene) {
  const Grid g;
  const std::string nii = write_nifti("ellipsoid.nii", g, voxels(g, ellipsoid_with_hole));
  const Scene scene = parse_scene(
      "[object]\nshape = \"file\"\nfile = \"" + nii + "\"\nspacing = 0.001\nthreshold = [150, 250]\n", "volume.toml");
  const Model m = build_scene_model(scene);
  const double exact = 4.0 / 3.0 * std::numbers::pi * (15.0 * 10.0 * 8.0 - 64.0) * 1e-9;
  EXPECT_NEAR(m.volume.sum(), exact, 0.1 * exact);
  for (index_t i = 0; i < m.n_points; ++i)
    ASSERT_GT((m.X.col(i) - 1e-3 * centre_mm).norm(), 3e-3) << "a point in the hole";
  // without a threshold the scene says what is missing
  try {
    build_scene_model(
        parse_scene("[object]\nshape = \"file\"\nfile = \"" + nii + "\"\nspacing = 0.001\n", "volume.toml"));
    ADD_FAILURE() << "a volume without a threshold was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("object.threshold"), std::string::npos) << e.what();
  }
}

// a sphere of soft tissue (intensity 100) with a stiffer core (intensity 300 within 5 mm of the centre)
float sphere_with_core(const Vec3& x) {
  const double r = (x - centre_mm).norm();
  return r <= 5.0 ? 300.0f : r <= 10.0 ? 100.0f : 0.0f;
}

TEST_F(VolumeFile, AStiffnessMapGivesEachPointTheYoungsModulusOfItsIntensity) {
  const Grid g;
  const std::string nii = write_nifti("core.nii", g, voxels(g, sphere_with_core));
  const std::string text =
      "[object]\nshape = \"file\"\nfile = \"" + nii +
      "\"\nspacing = 0.001\nthreshold = [50, 350]\nstiffness_map = [[100, 1e4], [200, 5e4], [300, 9e4]]\n"
      "[material]\nyoung = 2e4\n";
  const Model m = build_scene_model(parse_scene(text, "core.toml"));
  ASSERT_EQ(m.stiffness_scale.size(), m.n_points);
  int core = 0, soft = 0;
  for (index_t i = 0; i < m.n_points; ++i) {
    const double r = (m.X.col(i) - 1e-3 * centre_mm).norm();
    if (r < 4e-3) {  // well inside the core: 9e4 Pa
      EXPECT_NEAR(m.young_at(i), 9e4, 1e-6);
      ++core;
    } else if (r > 6e-3) {  // the soft shell: 1e4 Pa
      EXPECT_NEAR(m.young_at(i), 1e4, 1e-6);
      ++soft;
    }
    // the stress weight carries it: a stencil's stress is its material's times E_i / E
    EXPECT_NEAR(m.stiffness_volume[i], m.volume[i] * m.young_at(i) / 2e4, 1e-18);
  }
  EXPECT_GT(core, 100);
  EXPECT_GT(soft, 1000);
  // interpolation between the rows, and the named errors
  EXPECT_THROW(parse_scene(std::string(text).replace(text.find("[[100, 1e4]"), 11, "[[200, 1e4]"), "bad.toml"), Error);
  try {
    build_scene_model(
        parse_scene("[object]\nshape = \"box\"\nsize = [0.01, 0.01, 0.01]\nspacing = 0.005\n"
                    "stiffness_map = [[0, 1e4], [1, 2e4]]\n",
                    "box.toml"));
    ADD_FAILURE() << "a stiffness map without a volume image was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("object.stiffness_map: needs a volume image"), std::string::npos) << e.what();
  }
}

TEST_F(VolumeFile, BadVolumesAreNamedErrors) {
  const Grid g;
  const std::vector<float> v = voxels(g, sphere);
  EXPECT_NE(error_of([] { read_volume("/nonexistent/brain.nii"); }).find("/nonexistent/brain.nii"), std::string::npos);
  const std::string junk = dir + "/junk.nii";
  std::ofstream(junk) << "this is not an image";
  EXPECT_NE(error_of([&] { read_volume(junk); }).find("junk.nii"), std::string::npos);
  // truncated: the header promises 41^3 floats
  const std::string truncated = write_nifti("truncated.nii", g, std::vector<float>(v.begin(), v.begin() + 1000));
  EXPECT_NE(error_of([&] { read_volume(truncated); }).find("truncated.nii"), std::string::npos);
  // 4-D
  std::vector<float> twice = v;
  twice.insert(twice.end(), v.begin(), v.end());
  EXPECT_NE(error_of([&] { read_volume(write_nifti("4d.nii", g, twice, 4)); }).find("a 3-D image is needed"),
            std::string::npos);
  // NaN intensities: nifti2 sets non-finite floats to 0 while reading (its documented fallback)
  std::vector<float> nan = v;
  nan[77] = NAN;
  const VolumeImage cleaned = read_volume(write_nifti("nan.nii", g, nan));
  EXPECT_EQ(cleaned.values[77], 0.0f);
  // an empty window
  const VolumeImage image = read_volume(write_nifti("ok.nii", g, v));
  EXPECT_NE(error_of([&] { sample_volume(image, 500, 600, 0.001, "ok.nii"); }).find("no voxel"), std::string::npos);
  EXPECT_NE(error_of([&] { sample_volume(image, 50, 150, 1e-7, "ok.nii"); }).find("too many"), std::string::npos);
  // a NRRD with a broken header
  const std::string bad_nrrd = dir + "/bad.nrrd";
  std::ofstream(bad_nrrd) << "NRRD0004\ntype: float\ndimension: 3\nsizes: 4 4\nencoding: raw\n\n";
  EXPECT_NE(error_of([&] { read_volume(bad_nrrd); }).find("bad.nrrd: not a readable NRRD file"), std::string::npos);
  // issue 21: a small file whose header declares gigabytes is refused before anything is allocated
  const std::string huge = dir + "/huge.nrrd";
  std::ofstream(huge)
      << "NRRD0004\ntype: float\ndimension: 3\nsizes: 2000 2000 2000\nencoding: raw\nendian: little\n\n0000";
  EXPECT_NE(error_of([&] { read_volume(huge); }).find("huge.nrrd: the header declares 8e+09 voxels"),
            std::string::npos);
  const std::string short_raw = dir + "/short.nrrd";
  std::ofstream(short_raw)
      << "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 700 700 700\nencoding: raw\nendian: little\n\n0000";
  EXPECT_NE(
      error_of([&] { read_volume(short_raw); }).find("short.nrrd: truncated: the header declares 343000000 bytes"),
      std::string::npos);
  // a device or a folder is not an image
  EXPECT_NE(error_of([] { read_volume("/dev/zero.nii"); }).find("no such file"), std::string::npos);
  EXPECT_NE(error_of([&] { read_volume(dir); }).find("is a folder"), std::string::npos);
}

// issue 52: where the voxel data starts, a voxel's size and a compressed file's inflated size are checked before
// the data is read
TEST_F(VolumeFile, OffsetsSpacingsAndCompressedSizesAreCheckedBeforeTheData) {
  const Grid g;
  const std::vector<float> v = voxels(g, sphere);
  for (const float offset : {0.0f, -100.0f, 1e30f, NAN}) {
    const std::string path = write_nifti("offset.nii", g, v);
    std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(108);
    file.write(reinterpret_cast<const char*>(&offset), sizeof offset);
    file.close();
    const std::string error = error_of([&] { read_volume(path); });
    EXPECT_NE(error.find("vox_offset"), std::string::npos) << offset << ": " << error;
  }
  // a voxel spacing of 1e300 mm is named, not "inf lattice cells" later
  const std::string far = dir + "/far.nrrd";
  {
    std::ofstream out(far, std::ios::binary);
    out << "NRRD0004\ntype: float\ndimension: 3\nsizes: " << g.n << ' ' << g.n << ' ' << g.n
        << "\nspace: right-anterior-superior\nspace directions: (1e300,0,0) (0,1,0) (0,0,1)\nencoding: raw\nendian: "
           "little\n\n";
    out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(float)));
  }
  EXPECT_NE(error_of([&] { read_volume(far); }).find("a voxel spacing must lie in [1e-9, 1e3] m"), std::string::npos)
      << error_of([&] { read_volume(far); });
  // a .nii.gz whose gzip trailer does not match what its header declares is refused before it is inflated
  const std::string plain = write_nifti("packed.nii", g, v);
  ASSERT_EQ(std::system(("gzip -f -k " + plain).c_str()), 0);
  const std::string packed = plain + ".gz";
  EXPECT_EQ(read_volume(packed).values.size(), v.size());  // the intact file reads
  {
    std::fstream file(packed, std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(-4, std::ios::end);
    const std::uint32_t lie = 3'900'000'000u;
    file.write(reinterpret_cast<const char*>(&lie), sizeof lie);
  }
  EXPECT_NE(error_of([&] { read_volume(packed); }).find("inflates to 3900000000 bytes"), std::string::npos)
      << error_of([&] { read_volume(packed); });
}

}  // namespace
}  // namespace pointhaptics
