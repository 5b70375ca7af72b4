// libFuzzer targets for the readers of untrusted input: point clouds (PLY, text) and scene files. Every
// input must end in a cloud or scene, or in pointhaptics::Error; a crash, a hang, a leak, undefined
// behaviour or any other exception is a finding. Built by the `fuzz` preset (clang), run by scripts/test.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/point_cloud_file.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/io/volume_file.hpp>

#include <fstream>
#include <string>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string_view>

#ifndef PH_FUZZ_FORMAT
#error "PH_FUZZ_FORMAT names the reader: \".ply\", \".xyz\", \".csv\", \".nii\", \".nrrd\" or \"scene\""
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::string_view format = PH_FUZZ_FORMAT;
  try {
    if (format == "scene") {
      pointhaptics::parse_scene(input, "fuzz.toml", ".");
    } else if (format == ".nii" || format == ".nrrd") {
      // the image libraries read files: one per process, rewritten for every input
      static const std::string path = "/tmp/ph_fuzz_" + std::to_string(getpid()) + std::string(format);
      std::ofstream(path, std::ios::binary | std::ios::trunc)
          .write(input.data(), static_cast<std::streamsize>(input.size()));
      const pointhaptics::VolumeImage image = pointhaptics::read_volume(path);
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
