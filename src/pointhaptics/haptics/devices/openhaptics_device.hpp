#pragma once
/// @file Phantom / Touch devices through OpenHaptics' HD API, loaded at run time with dlopen so that the
/// build never needs the SDK. Units are converted here and only here (HD: mm, mm/s, N, N/mm, torque in mN m).
/// Tested only against a stand-in library with the same C functions (tests/support/fake_hd.cpp), not
/// against real hardware.
#include <pointhaptics/haptics/device.hpp>

#include <memory>
#include <string>

namespace pointhaptics {

class OpenHapticsDevice : public Device {
 public:
  /// library: the HD library to load (default "libHD.so", found by the dynamic loader); device_name:
  /// an OpenHaptics device configuration name ("" for the default device). Throws Error when the library
  /// or one of its functions is missing, DeviceError when the device cannot be initialised.
  explicit OpenHapticsDevice(const std::string& library = "libHD.so", const std::string& device_name = "");
  ~OpenHapticsDevice() override;
  DeviceSpecs specs() const override { return specs_; }
  DeviceState read(double t) override;  ///< begins an HD frame; the stylus's orientation from its transform
  /// Kept for the next command(), on a device with six output degrees of freedom (specs().max_torque > 0).
  void set_torque(const Vec3& torque) override { torque_ = torque; }
  void command(const Vec3& force) override;  ///< sets the force (and the torque) and ends the frame
  void stop() override;                      ///< zero force, scheduler stopped, device disabled (idempotent)

 private:
  struct Api;
  void check(const char* what);
  std::unique_ptr<Api> api_;
  DeviceSpecs specs_;
  unsigned handle_ = 0;
  Vec3 torque_ = Vec3::Zero();
  bool in_frame_ = false, stopped_ = false;
};

}  // namespace pointhaptics
