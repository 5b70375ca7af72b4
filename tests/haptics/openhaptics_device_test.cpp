// Tests for haptics/devices/openhaptics_device against the stand-in library tests/support/fake_hd.cpp
// (not real hardware): loading, unit conversion at the boundary, specs, and failures.
#include <pointhaptics/haptics/devices/openhaptics_device.hpp>
#include <pointhaptics/haptics/haptic_loop.hpp>

#include <gtest/gtest.h>

#include <dlfcn.h>

namespace pointhaptics {
namespace {

// the test hooks of the stand-in, from the same (already loaded) library
template <class Fn>
Fn hook(const char* name) {
  void* lib = ::dlopen(PH_FAKE_HD_PATH, RTLD_NOW | RTLD_NOLOAD);
  EXPECT_NE(lib, nullptr);
  return reinterpret_cast<Fn>(::dlsym(lib, name));
}

TEST(OpenHapticsDevice, ConvertsUnitsAndReadsSpecs) {
  OpenHapticsDevice device(PH_FAKE_HD_PATH);
  const DeviceSpecs s = device.specs();
  EXPECT_DOUBLE_EQ(s.max_force, 0.88);
  EXPECT_DOUBLE_EQ(s.max_stiffness, 400.0);          // 0.4 N/mm
  EXPECT_NEAR(s.max_damping, 3.0, 1e-12);            // 0.003 N s/mm
  EXPECT_NEAR(s.workspace_radius, 0.035, 1e-12);     // the 70 mm depth of the usable box, halved
  EXPECT_EQ(hook<int (*)()>("fake_hd_enabled")(), 1);
  const DeviceState st = device.read(0.001);
  EXPECT_NEAR(st.position.norm(), 0.010, 1e-12);     // 10 mm
  EXPECT_NEAR(st.velocity.norm(), 0.010 * 1000 * M_PI / 180, 1e-12);
  device.command(Vec3(0.1, -0.2, 0.3));
  double f[3];
  hook<void (*)(double*)>("fake_hd_last_force")(f);
  EXPECT_DOUBLE_EQ(f[1], -0.2);                      // N at the boundary, as HD wants
  device.stop();
  hook<void (*)(double*)>("fake_hd_last_force")(f);
  EXPECT_EQ(f[0] * f[0] + f[1] * f[1] + f[2] * f[2], 0.0);
  EXPECT_EQ(hook<int (*)()>("fake_hd_enabled")(), 0);
}

TEST(OpenHapticsDevice, MissingLibraryOrDeviceIsAClearError) {
  try {
    OpenHapticsDevice device("/nonexistent/libHD.so");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot load /nonexistent/libHD.so"), std::string::npos) << e.what();
  }
  EXPECT_THROW(OpenHapticsDevice(PH_FAKE_HD_PATH, "missing"), DeviceError);
}

TEST(OpenHapticsDevice, UnpluggedMidRunStopsTheLoopWithZeroForce) {
  OpenHapticsDevice device(PH_FAKE_HD_PATH);
  hook<void (*)(long)>("fake_hd_fail_after")(250);
  HapticLoop loop(device, WorkspaceMapping{}, CouplingGains{100.0, 0.0});
  int ticks = 0;
  while (loop.tick(ticks * 1e-3, 1e-3) && ticks < 1000) ++ticks;
  EXPECT_LT(ticks, 300);
  EXPECT_TRUE(loop.device_failed());
  EXPECT_NE(loop.stats().device_error.find("0x0302"), std::string::npos) << loop.stats().device_error;
  double f[3];
  hook<void (*)(double*)>("fake_hd_last_force")(f);
  EXPECT_EQ(f[0] * f[0] + f[1] * f[1] + f[2] * f[2], 0.0);
  EXPECT_EQ(hook<int (*)()>("fake_hd_enabled")(), 0);
  hook<void (*)(long)>("fake_hd_fail_after")(-1);
}

}  // namespace
}  // namespace pointhaptics
