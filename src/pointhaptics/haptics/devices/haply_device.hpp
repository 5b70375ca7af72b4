#pragma once
/// @file A Haply Inverse3 through its vendor service's local WebSocket (the Inverse Service's simulation channel,
/// ws://localhost:10001 by default; JSON messages, no SDK). The service sends the devices' inventory when a client
/// connects, then one state update per message the client sends: each tick this device reads the update that
/// answers the last command, then sends the next force (set_cursor_force). Haply's axes (right-handed, z up) are
/// turned into the device frame the library uses for every device (y up, z toward the user): x = x_haply,
/// y = z_haply, z = -y_haply. A VerseGrip's buttons and orientation are read when the service reports one.
/// Tested against a loopback WebSocket server that speaks the same messages (tests/haptics/haply_device_test.cpp),
/// not against real hardware.
#include <pointhaptics/haptics/device.hpp>

#include <chrono>
#include <memory>
#include <string>

namespace pointhaptics {

struct HaplyOptions {
  std::string host = "127.0.0.1";
  int port = 10001;
  std::string device_id;  ///< the Inverse3 to drive (its device_id; empty: the first the service lists)
  /// How long a reply may take before the device counts as disconnected (DeviceError): the haptic loop then stops
  /// commanding it. A service answers within a tick.
  std::chrono::milliseconds timeout{100};
};

class HaplyDevice final : public Device {
 public:
  /// Connects and reads the inventory. Throws DeviceError naming the address when no service answers there, when it
  /// lists no Inverse3 (or not options.device_id), or when its first message is not the inventory.
  explicit HaplyDevice(const HaplyOptions& options = {});
  ~HaplyDevice() override;
  /// Inverse3's: 3 N continuous (Haply gives more in bursts), a workspace of about 0.15 m in radius; the stiffness and
  /// damping limits are conservative values of ours, as for the other known devices.
  DeviceSpecs specs() const override;
  /// The state update answering the last command (or a probe_position's, before the first). Throws DeviceError
  /// when the service closes, stalls beyond the timeout or sends what is not a state update.
  DeviceState read(double t) override;
  void command(const Vec3& force) override;
  void stop() override;  ///< a zero force, then the connection closed (idempotent)
  const std::string& device_id() const;

 private:
  struct Connection;
  std::unique_ptr<Connection> connection_;
};

}  // namespace pointhaptics
