#pragma once
/// @file The haptic device interface: SI units in and out (m, m/s, N); a device's own units are
/// converted at its boundary only.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/types.hpp>

#include <Eigen/Geometry>

#include <string>
#include <string_view>

namespace pointhaptics {

/// A device that failed or disconnected. The haptic loop stops the device (zero force) and reports it.
class DeviceError : public Error {
 public:
  using Error::Error;
};

/// What a device can render, as CHAI3D's cHapticDeviceInfo describes it.
struct DeviceSpecs {
  std::string name = "custom";
  double max_force = 3.3;           ///< largest continuous force, N
  double max_stiffness = 400.0;     ///< largest stiffness it renders stably at 1 kHz, N/m
  double max_damping = 3.0;         ///< largest damping it renders stably, N s/m
  double workspace_radius = 0.075;  ///< radius of its usable workspace, m
  double max_torque = 0;            ///< largest continuous torque, N m (0: it renders none)
};

/// Known devices: "touch" (3D Systems Touch: 3.3 N, 400 N/m, 0.075 m), "omni" (Phantom Omni: 3.3 N,
/// 700 N/m, 0.10 m), "falcon" (Novint Falcon: 8 N, 3000 N/m, 0.04 m), as CHAI3D codes their force,
/// stiffness and workspace; the damping limits are conservative values of ours. Throws Error naming
/// the name and the known ones for anything else.
DeviceSpecs known_device_specs(std::string_view name);

/// One reading of a device.
struct DeviceState {
  double time = 0;               ///< s, the device's clock
  Vec3 position = Vec3::Zero();  ///< m, in the device's frame
  Vec3 velocity = Vec3::Zero();  ///< m/s
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  unsigned buttons = 0;  ///< bit k: button k held
};

/// A haptic device (or a stand-in for one). Called from the haptic thread only, once per tick:
/// read(), then command(). Implementations never block for long and never allocate per tick.
class Device {
 public:
  virtual ~Device() = default;
  virtual DeviceSpecs specs() const = 0;
  /// Sample the device at time t (s since the loop started). Throws DeviceError when the device fails.
  virtual DeviceState read(double t) = 0;
  /// Command a force (N) until the next tick. Throws DeviceError when the device fails.
  virtual void command(const Vec3& force) = 0;
  /// The torque (N m, about the device point, in the device's axes) to render with the next command(), on a
  /// device whose specs give max_torque > 0; the others have nothing to render it with and ignore it.
  virtual void set_torque(const Vec3& /*torque*/) {}
  /// Stop: command zero force and release the device (also called after a DeviceError).
  virtual void stop() {}
};

}  // namespace pointhaptics
