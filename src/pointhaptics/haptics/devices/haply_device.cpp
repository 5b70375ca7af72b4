#include <pointhaptics/haptics/devices/haply_device.hpp>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/websocket.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <optional>

namespace pointhaptics {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using json = nlohmann::json;

namespace {

// Haply's axes (z up, y away from the user) and the device frame's (y up, z toward the user)
Vec3 from_haply(const json& v) {
  return Vec3(v.at("x").get<double>(), v.at("z").get<double>(), -v.at("y").get<double>());
}
json to_haply(const Vec3& v) { return {{"x", v.x()}, {"y", -v.z()}, {"z", v.y()}}; }

}  // namespace

struct HaplyDevice::Connection {
  HaplyOptions options;
  std::string address;
  asio::io_context io;
  websocket::stream<beast::tcp_stream> ws{io};
  beast::flat_buffer buffer;
  std::string out;  // the message being sent (kept: its capacity is reused)
  std::string id;
  DeviceState state;
  bool awaiting = false;  // a command was sent; its state update is not read yet
  bool open = false;

  [[noreturn]] void fail(const std::string& what) const {
    throw DeviceError(fmt::format("Haply Inverse3 at ws://{}: {}", address, what));
  }

  // runs one asynchronous operation to its end within the timeout (the synchronous ones have none: a stalled service
  // would hold the haptic thread)
  template <class Start>
  void within_timeout(const char* what, Start&& start) {
    std::optional<beast::error_code> done;
    start([&done](beast::error_code ec, std::size_t = 0) { done = ec; });
    io.restart();
    io.run_for(options.timeout);
    if (!done) {
      beast::get_lowest_layer(ws).cancel();
      io.restart();
      io.run();  // the cancelled handler
      open = false;
      fail(fmt::format("no {} within {} ms (is the Inverse Service running?)", what, options.timeout.count()));
    }
    if (*done) {
      open = false;
      fail(fmt::format("{}: {}", what, done->message()));
    }
  }

  json receive() {
    buffer.clear();
    within_timeout("state update", [&](auto handler) { ws.async_read(buffer, handler); });
    json message = json::parse(beast::buffers_to_string(buffer.data()), nullptr, false);
    if (message.is_discarded() || !message.is_object()) fail("a message that is not a JSON object");
    return message;
  }

  void send(const json& message) {
    out = message.dump();
    within_timeout("send", [&](auto handler) { ws.async_write(asio::buffer(out), handler); });
  }

  // the state of our Inverse3 (and of a VerseGrip) from a state update
  void take_state(const json& message, double t) {
    const auto devices = message.find("inverse3");
    if (devices == message.end() || !devices->is_array()) fail("a message without \"inverse3\" devices");
    const json* mine = nullptr;
    for (const json& d : *devices)
      if (d.value("device_id", std::string()) == id) mine = &d;
    if (!mine) fail(fmt::format("the state update does not list Inverse3 \"{}\" any more (disconnected?)", id));
    try {
      const json& s = mine->at("state");
      state.position = from_haply(s.at("cursor_position"));
      state.velocity = s.contains("cursor_velocity") ? from_haply(s.at("cursor_velocity")) : Vec3::Zero();
      for (const char* grips : {"wireless_verse_grip", "verse_grip"}) {
        const auto g = message.find(grips);
        if (g == message.end() || !g->is_array() || g->empty()) continue;
        const json& grip = g->front().at("state");
        if (const auto q = grip.find("orientation"); q != grip.end())
          state.orientation = Eigen::Quaterniond(q->at("w").get<double>(), q->at("x").get<double>(),
                                                 q->at("z").get<double>(), -q->at("y").get<double>())
                                  .normalized();
        unsigned buttons = 0;
        if (const auto b = grip.find("buttons"); b != grip.end()) {
          buttons |= b->value("a", false) ? 1u : 0u;
          buttons |= b->value("b", false) ? 2u : 0u;
        } else if (const auto b1 = grip.find("button"); b1 != grip.end() && b1->is_boolean()) {
          buttons = b1->get<bool>() ? 1u : 0u;
        }
        state.buttons = buttons;
        break;
      }
    } catch (const json::exception& e) {
      fail(fmt::format("a state update that is not Haply's: {}", e.what()));
    }
    if (!state.position.allFinite() || !state.velocity.allFinite()) fail("a position that is not finite");
    state.time = t;
  }

  json command(const char* name, const json& values) const {
    return {{"inverse3", json::array({{{"device_id", id}, {"commands", {{name, values}}}}})}};
  }
};

HaplyDevice::HaplyDevice(const HaplyOptions& options) : connection_(std::make_unique<Connection>()) {
  Connection& c = *connection_;
  c.options = options;
  c.address = fmt::format("{}:{}", options.host, options.port);
  try {
    asio::ip::tcp::resolver resolver(c.io);
    const auto endpoints = resolver.resolve(options.host, std::to_string(options.port));
    c.within_timeout("connection", [&](auto handler) {
      beast::get_lowest_layer(c.ws).async_connect(
          endpoints, [handler](beast::error_code ec, const auto&) mutable { handler(ec); });
    });
    c.within_timeout("handshake", [&](auto handler) {
      c.ws.async_handshake(options.host, "/", [handler](beast::error_code ec) mutable { handler(ec); });
    });
  } catch (const boost::system::system_error& e) {
    c.fail(e.what());
  }
  c.open = true;
  c.ws.text(true);
  // the inventory: every device the service has, with its id
  const json inventory = c.receive();
  const auto devices = inventory.find("inverse3");
  if (devices == inventory.end() || !devices->is_array() || devices->empty())
    c.fail("the service lists no Inverse3 (is it plugged in and powered?)");
  for (const json& d : *devices) {
    const std::string id = d.value("device_id", std::string());
    if (options.device_id.empty() || id == options.device_id) {
      c.id = id;
      break;
    }
  }
  if (c.id.empty()) {
    std::string ids;
    for (const json& d : *devices) ids += (ids.empty() ? "\"" : ", \"") + d.value("device_id", std::string()) + "\"";
    c.fail(fmt::format("no Inverse3 \"{}\" (the service lists {})", options.device_id, ids));
  }
  c.take_state(inventory, 0.0);
}

HaplyDevice::~HaplyDevice() {
  try {
    stop();
  } catch (...) {  // a destructor never throws; stop() reported what it could
  }
}

DeviceSpecs HaplyDevice::specs() const { return {"inverse3", 3.0, 1500.0, 3.0, 0.15, 0.0}; }

const std::string& HaplyDevice::device_id() const { return connection_->id; }

DeviceState HaplyDevice::read(double t) {
  Connection& c = *connection_;
  if (!c.open) c.fail("the connection is closed");
  // before the first command: ask for a state without applying a force
  if (!c.awaiting) c.send(c.command("probe_position", json::object()));
  c.awaiting = false;
  c.take_state(c.receive(), t);
  return c.state;
}

void HaplyDevice::command(const Vec3& force) {
  Connection& c = *connection_;
  if (!c.open) c.fail("the connection is closed");
  if (!force.allFinite()) c.fail("a force that is not finite was commanded");
  c.send(c.command("set_cursor_force", {{"vector", to_haply(force)}}));
  c.awaiting = true;
}

void HaplyDevice::stop() {
  Connection& c = *connection_;
  if (!c.open) return;
  try {
    if (c.awaiting) c.receive();
    c.send(c.command("set_cursor_force", {{"vector", to_haply(Vec3::Zero())}}));
    c.within_timeout("close", [&](auto handler) {
      c.ws.async_close(websocket::close_code::normal, [handler](beast::error_code ec) mutable { handler(ec); });
    });
  } catch (const DeviceError&) {  // already gone: nothing left to stop
  }
  c.open = false;
}

}  // namespace pointhaptics
