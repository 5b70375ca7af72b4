#include <pointhaptics/haptics/device.hpp>

#include <pointhaptics/core/error.hpp>

#include <fmt/format.h>

namespace pointhaptics {

DeviceSpecs known_device_specs(std::string_view name) {
  if (name == "touch") return {"touch", 3.3, 400.0, 3.0, 0.075};
  if (name == "omni") return {"omni", 3.3, 700.0, 3.0, 0.10};
  if (name == "falcon") return {"falcon", 8.0, 3000.0, 20.0, 0.04};
  throw Error(fmt::format("unknown device \"{}\" (known: touch, omni, falcon, or custom specs)", name));
}

}  // namespace pointhaptics
