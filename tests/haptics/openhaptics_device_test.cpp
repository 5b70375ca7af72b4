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
  EXPECT_DOUBLE_EQ(s.max_stiffness, 400.0);       // 0.4 N/mm
  EXPECT_NEAR(s.max_damping, 3.0, 1e-12);         // 0.003 N s/mm
  EXPECT_NEAR(s.workspace_radius, 0.035, 1e-12);  // the 70 mm depth of the usable box, halved
  EXPECT_EQ(hook<int (*)()>("fake_hd_enabled")(), 1);
  const DeviceState st = device.read(0.001);
  EXPECT_NEAR(st.position.norm(), 0.010, 1e-12);  // 10 mm
  EXPECT_NEAR(st.velocity.norm(), 0.010 * 1000 * M_PI / 180, 1e-12);
  device.command(Vec3(0.1, -0.2, 0.3));
  double f[3];
  hook<void (*)(double*)>("fake_hd_last_force")(f);
  EXPECT_DOUBLE_EQ(f[1], -0.2);  // N at the boundary, as HD wants
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

TEST(OpenHapticsDevice, ASixDegreeOfFreedomDeviceTakesTheToolsTorqueInMilliNewtonMetres) {
  // the stand-in loaded here first, so that it is told its degrees of freedom before the device reads them
  void* library = ::dlopen(PH_FAKE_HD_PATH, RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(library, nullptr);
  hook<void (*)(int)>("fake_hd_set_output_dof")(6);
  {
    OpenHapticsDevice device(PH_FAKE_HD_PATH);
    EXPECT_DOUBLE_EQ(device.specs().max_torque, 0.15);  // 150 mN m
    // the stylus's orientation from its transform: turned about z by one degree a frame
    const DeviceState st = device.read(0.001);
    EXPECT_NEAR(st.orientation.angularDistance(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 180, Vec3::UnitZ()))), 0.0,
                1e-12);
    device.command(Vec3::Zero());  // (ends the frame the read began)
    // through the loop: the published contact's torque, ramped in with the force and within the device's
    // maximum, reaches the device in mN m
    HapticLoop loop(device, WorkspaceMapping{}, CouplingGains{100.0, 0.0}, {}, 1000.0, 1024);
    for (int k = 1; k <= 10; ++k) ASSERT_TRUE(loop.tick(k * 1e-3, 1e-3)) << loop.stats().device_error;
    ContactModel m;
    m.p0 = Vec3::Zero();
    m.contacts = 2;
    m.torque = Vec3(0.01, 0, -0.5);  // beyond the device's 0.15 N m
    loop.contact_models().back() = m;
    loop.contact_models().publish();
    for (int k = 11; k <= 800; ++k) ASSERT_TRUE(loop.tick(k * 1e-3, 1e-3)) << loop.stats().device_error;
    double t[3];
    hook<void (*)(double*)>("fake_hd_last_torque")(t);
    const Vec3 sent = Vec3(t[0], t[1], t[2]);
    EXPECT_NEAR(sent.norm(), 150.0, 1e-9);                                  // mN m: clamped to the maximum
    EXPECT_NEAR(sent.normalized().dot(m.torque.normalized()), 1.0, 1e-12);  // in the contact's direction
    loop.frames().update();
    EXPECT_NEAR((loop.frames().front().torque - 1e-3 * sent).norm(), 0.0, 1e-12);
    int logged = 0;
    loop.take_log([&](const HapticLogRow& row) { logged += row.torque.norm() > 0; });
    EXPECT_GT(logged, 700);
  }
  hook<void (*)(int)>("fake_hd_set_output_dof")(3);
  // a three-degree-of-freedom device renders none, and is sent none
  {
    OpenHapticsDevice device(PH_FAKE_HD_PATH);
    EXPECT_EQ(device.specs().max_torque, 0.0);
  }
  ::dlclose(library);
}

}  // namespace
}  // namespace pointhaptics
