// The Haply Inverse3 backend against a loopback WebSocket server that speaks the Inverse Service's simulation
// channel: the inventory on connection, then one state update per client message. Axes, forces, buttons, the device
// chosen by id, and a service that is absent, stalls or closes: each a DeviceError naming the address.
#include <pointhaptics/haptics/devices/haply_device.hpp>
#include <pointhaptics/haptics/haptic_loop.hpp>

#include <gtest/gtest.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/websocket.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

namespace pointhaptics {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
using json = nlohmann::json;

// A stand-in for the Inverse Service on a free loopback port: it lists Inverse3 "04BA" (and "05CC") and a VerseGrip,
// moves the cursor 1 mm along Haply's x per message, and records the forces it is sent. `replies` messages are
// answered; then it stalls (keeps the connection open, answers nothing) or closes.
class StubService {
 public:
  enum class After { STALL, CLOSE };
  explicit StubService(int replies = 1 << 30, After after = After::STALL)
      : acceptor_(io_, {asio::ip::make_address("127.0.0.1"), 0}), replies_(replies), after_(after) {
    port_ = acceptor_.local_endpoint().port();
    thread_ = std::thread([this] { serve(); });
  }
  ~StubService() {
    done_ = true;
    if (thread_.joinable()) thread_.join();
  }
  int port() const { return port_; }
  std::vector<json> forces() {
    std::lock_guard lock(mutex_);
    return forces_;
  }
  std::vector<std::string> commands() {
    std::lock_guard lock(mutex_);
    return commands_;
  }

 private:
  json state(int k) const {
    const json cursor = {{"device_id", "04BA"},
                         {"state",
                          {{"cursor_position", {{"x", 0.001 * k}, {"y", 0.02}, {"z", 0.03}}},
                           {"cursor_velocity", {{"x", 1.0}, {"y", 0.0}, {"z", 0.0}}}}}};
    const json other = {{"device_id", "05CC"}, {"state", {{"cursor_position", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}}}}}};
    const json grip = {{"device_id", "61548"},
                       {"state",
                        {{"buttons", {{"a", k >= 3}, {"b", false}}},
                         {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}, {"w", 1.0}}}}}};
    return {{"inverse3", json::array({cursor, other})}, {"wireless_verse_grip", json::array({grip})}};
  }

  void serve() {
    try {
      asio::ip::tcp::socket socket(io_);
      acceptor_.accept(socket);
      beast::websocket::stream<asio::ip::tcp::socket> ws(std::move(socket));
      ws.accept();
      ws.text(true);
      ws.write(asio::buffer(state(0).dump()));
      for (int k = 1;; ++k) {
        beast::flat_buffer buffer;
        ws.read(buffer);
        const json message = json::parse(beast::buffers_to_string(buffer.data()));
        {
          std::lock_guard lock(mutex_);
          const json& commands = message.at("inverse3").at(0).at("commands");
          for (const auto& [name, value] : commands.items()) {
            commands_.push_back(name);
            if (name == "set_cursor_force") forces_.push_back(value.at("vector"));
          }
        }
        if (k > replies_) break;
        ws.write(asio::buffer(state(k).dump()));
      }
      if (after_ == After::CLOSE) {
        ws.close(beast::websocket::close_code::going_away);
        return;
      }
      while (!done_) std::this_thread::sleep_for(std::chrono::milliseconds(5));  // stalled, the connection open
    } catch (const std::exception&) {                                            // the client went away
    }
  }

  asio::io_context io_;
  asio::ip::tcp::acceptor acceptor_;
  int port_ = 0;
  int replies_;
  After after_;
  std::atomic<bool> done_{false};
  std::mutex mutex_;
  std::vector<json> forces_;
  std::vector<std::string> commands_;
  std::thread thread_;
};

HaplyOptions at(const StubService& service) {
  HaplyOptions o;
  o.port = service.port();
  o.timeout = std::chrono::milliseconds(200);
  return o;
}

TEST(HaplyDevice, ReadsTheCursorInTheDeviceFrameAndSendsForcesInHaplys) {
  StubService service;
  HaplyDevice device(at(service));
  EXPECT_EQ(device.device_id(), "04BA") << "the first Inverse3 the service lists";
  EXPECT_EQ(device.specs().name, "inverse3");
  // Haply (x, y, z), z up, to the device frame (x, z, -y), y up
  const DeviceState s1 = device.read(0.001);  // a probe_position's reply: cursor x = 1 mm
  EXPECT_NEAR(s1.position.x(), 0.001, 1e-12);
  EXPECT_NEAR(s1.position.y(), 0.03, 1e-12);
  EXPECT_NEAR(s1.position.z(), -0.02, 1e-12);
  EXPECT_NEAR(s1.velocity.x(), 1.0, 1e-12);
  EXPECT_EQ(s1.buttons, 0u);
  device.command(Vec3(0.5, 1.0, -2.0));  // up 1 N, toward the user 2 N... in Haply: y = 2, z = 1
  const DeviceState s2 = device.read(0.002);
  EXPECT_NEAR(s2.position.x(), 0.002, 1e-12) << "the reply to the command";
  device.command(Vec3::Zero());
  const DeviceState s3 = device.read(0.003);
  EXPECT_EQ(s3.buttons, 1u) << "the VerseGrip's button a";
  EXPECT_EQ(s3.time, 0.003);
  device.stop();
  const std::vector<json> forces = service.forces();
  ASSERT_GE(forces.size(), 2u);
  EXPECT_DOUBLE_EQ(forces[0]["x"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(forces[0]["y"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(forces[0]["z"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(forces.back()["z"].get<double>(), 0.0) << "stop() leaves it at zero force";
  EXPECT_EQ(service.commands().front(), "probe_position") << "no force before the first command";
}

TEST(HaplyDevice, DrivesTheInverse3ItIsGivenByIdAndNamesTheOthers) {
  {
    StubService service;
    HaplyOptions o = at(service);
    o.device_id = "05CC";
    HaplyDevice device(o);
    EXPECT_EQ(device.device_id(), "05CC");
    EXPECT_NEAR(device.read(0.001).position.x(), 0.0, 1e-12) << "05CC's cursor, not 04BA's";
  }
  StubService service;
  HaplyOptions o = at(service);
  o.device_id = "0000";
  try {
    HaplyDevice device(o);
    FAIL() << "no such device";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("no Inverse3 \"0000\" (the service lists \"04BA\", \"05CC\")"),
              std::string::npos)
        << e.what();
  }
}

TEST(HaplyDevice, AnAbsentServiceIsNamed) {
  int port = 0;
  {
    StubService closed(0, StubService::After::CLOSE);  // a port that was free a moment ago
    port = closed.port();
    HaplyDevice device(at(closed));
  }
  HaplyOptions o;
  o.port = port;
  try {
    HaplyDevice device(o);
    FAIL() << "nothing listens there";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find(fmt::format("ws://127.0.0.1:{}", port)), std::string::npos) << e.what();
  }
}

TEST(HaplyDevice, AStalledOrClosedServiceIsADeviceErrorWithinTheTimeout) {
  for (const StubService::After after : {StubService::After::STALL, StubService::After::CLOSE}) {
    StubService service(2, after);
    HaplyDevice device(at(service));
    device.read(0.001);
    device.command(Vec3::Zero());
    device.read(0.002);
    device.command(Vec3::Zero());  // its reply never comes
    const auto start = std::chrono::steady_clock::now();
    try {
      device.read(0.003);
      FAIL() << "no reply";
    } catch (const DeviceError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("Haply Inverse3 at ws://127.0.0.1"), std::string::npos) << message;
      if (after == StubService::After::STALL) {
        EXPECT_NE(message.find("no state update within 200 ms"), std::string::npos) << message;
      }
    }
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
    EXPECT_THROW(device.read(0.004), DeviceError) << "closed from then on";
  }
}

TEST(HaplyDevice, AHapticLoopStopsCommandingADeviceTheServiceDropped) {
  StubService service(50, StubService::After::CLOSE);
  HaplyDevice device(at(service));
  HapticLoop loop(device, WorkspaceMapping{}, coupling_budget(device.specs(), 1.0));
  int ticks = 0;
  while (loop.tick(0.001 * (ticks + 1), 0.001) && ticks < 200) ++ticks;
  EXPECT_GE(ticks, 49);
  EXPECT_LT(ticks, 200) << "the loop stopped at the dropped connection";
  EXPECT_TRUE(loop.stats().device_failed);
  EXPECT_NE(loop.stats().device_error.find("Haply"), std::string::npos) << loop.stats().device_error;
}

}  // namespace
}  // namespace pointhaptics
