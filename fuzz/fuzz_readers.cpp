// libFuzzer targets for the readers of untrusted input: point clouds (PLY, text), scene files, volume images,
// surface meshes (OBJ, STL, PLY with faces: read and volume-sampled) and haptic logs (the replay device's).
// Every input must end in what the reader promises, or in pointhaptics::Error; a crash, a hang, a leak, undefined
// behaviour or any other exception is a finding. Built by the `fuzz` preset (clang), run by scripts/test.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/triangle_mesh.hpp>
#include <pointhaptics/io/haptic_log.hpp>
#include <pointhaptics/io/mesh_file.hpp>
#include <pointhaptics/io/point_cloud_file.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/io/volume_file.hpp>

#include <fstream>
#include <string>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#ifndef PH_FUZZ_FORMAT
#error \
    "PH_FUZZ_FORMAT names the reader: \".ply\", \".xyz\", \".csv\", \".nii\", \".nrrd\", \"scene\", \"mesh.obj\", \"mesh.stl\", \"mesh.ply\" or \"log\""
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::string_view format = PH_FUZZ_FORMAT;
  try {
    // the file readers read files: one per process, rewritten for every input
    const auto as_file = [&](std::string_view extension) {
      static const std::string path = "/tmp/ph_fuzz_" + std::to_string(getpid()) + std::string(extension);
      std::ofstream(path, std::ios::binary | std::ios::trunc)
          .write(input.data(), static_cast<std::streamsize>(input.size()));
      return path;
    };
    if (format == "scene") {
      pointhaptics::parse_scene(input, "fuzz.toml", ".");
    } else if (format == "log") {
      const std::vector<pointhaptics::HapticLogRow> rows = pointhaptics::read_haptic_log(as_file(".csv"));
      for (std::size_t k = 0; k < rows.size(); ++k)
        if (!rows[k].position.allFinite() || rows[k].buttons > 65535 || (k > 0 && !(rows[k].t > rows[k - 1].t)))
          __builtin_trap();
    } else if (format.substr(0, 5) == "mesh.") {
      const pointhaptics::TriangleMesh mesh = pointhaptics::read_mesh(as_file(format.substr(4)));
      // sampled at an eighth of its extent (a bounded lattice): the volumes sum to the enclosed volume
      const double extent = (mesh.V.rowwise().maxCoeff() - mesh.V.rowwise().minCoeff()).maxCoeff();
      const pointhaptics::PointCloud cloud = pointhaptics::sample_mesh_volume(mesh, extent / 8, "fuzz");
      const double enclosed = pointhaptics::enclosed_volume(mesh);
      if (!(cloud.volume.array() > 0).all() || !(std::abs(cloud.volume.sum() - enclosed) <= 1e-6 * enclosed))
        __builtin_trap();
    } else if (format == ".nii" || format == ".nrrd") {
      const pointhaptics::VolumeImage image = pointhaptics::read_volume(as_file(format));
      if (image.values.size() != static_cast<std::size_t>(image.nx) * image.ny * image.nz) __builtin_trap();
    } else {
      const pointhaptics::PointCloud cloud = pointhaptics::parse_point_cloud(input, format, "fuzz", 0.01);
      // what the reader promises
      if (cloud.size() < 4 || !cloud.X.allFinite() || !(cloud.volume.array() > 0).all()) __builtin_trap();
    }
  } catch (const pointhaptics::Error&) {
    // a named error: what bad input must give
  }
  return 0;
}
