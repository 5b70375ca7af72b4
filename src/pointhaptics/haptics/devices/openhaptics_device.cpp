#include <pointhaptics/haptics/devices/openhaptics_device.hpp>

#include <fmt/format.h>

#include <dlfcn.h>

#include <algorithm>
#include <cmath>

namespace pointhaptics {
namespace {

// the few HD definitions we use (OpenHaptics' hdDefines.h); the SDK's headers are not needed to build
using HHD = unsigned int;
using HDenum = unsigned int;
using HDerror = unsigned int;
struct HDErrorInfo {
  HDerror errorCode;
  int internalErrorCode;
  HHD hHD;
};
constexpr HDerror HD_SUCCESS = 0x0000;
constexpr HDenum HD_CURRENT_BUTTONS = 0x2000, HD_CURRENT_POSITION = 0x2050, HD_CURRENT_VELOCITY = 0x2051,
                 HD_CURRENT_TRANSFORM = 0x2052, HD_USABLE_WORKSPACE_DIMENSIONS = 0x2551, HD_OUTPUT_DOF = 0x2554,
                 HD_NOMINAL_MAX_STIFFNESS = 0x2602, HD_NOMINAL_MAX_CONTINUOUS_FORCE = 0x2604,
                 HD_NOMINAL_MAX_DAMPING = 0x2609, HD_NOMINAL_MAX_TORQUE_CONTINUOUS_FORCE = 0x2623,
                 HD_CURRENT_FORCE = 0x2700, HD_CURRENT_TORQUE = 0x2701, HD_FORCE_OUTPUT = 0x4000;
constexpr HHD HD_INVALID_HANDLE = 0xFFFFFFFF;

}  // namespace

struct OpenHapticsDevice::Api {
  void* library = nullptr;
  HHD (*hdInitDevice)(const char*) = nullptr;
  void (*hdDisableDevice)(HHD) = nullptr;
  void (*hdMakeCurrentDevice)(HHD) = nullptr;
  void (*hdBeginFrame)(HHD) = nullptr;
  void (*hdEndFrame)(HHD) = nullptr;
  void (*hdGetDoublev)(HDenum, double*) = nullptr;
  void (*hdGetIntegerv)(HDenum, int*) = nullptr;
  void (*hdSetDoublev)(HDenum, const double*) = nullptr;
  void (*hdEnable)(HDenum) = nullptr;
  HDErrorInfo (*hdGetError)() = nullptr;
  void (*hdStartScheduler)() = nullptr;
  void (*hdStopScheduler)() = nullptr;
  ~Api() {
    if (library) ::dlclose(library);
  }
};

OpenHapticsDevice::OpenHapticsDevice(const std::string& library, const std::string& device_name)
    : api_(std::make_unique<Api>()) {
  // dlopen("") opens this program itself, and the message then blamed hdInitDevice (issue 52)
  if (library.empty())
    throw Error(
        "OpenHaptics: device.library is empty: give the path of OpenHaptics' libHD.so (e.g. "
        "\"/usr/lib/libHD.so\")");
  api_->library = ::dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!api_->library)
    throw Error(
        fmt::format("OpenHaptics: cannot load {} ({}); install the OpenHaptics runtime and the device "
                    "driver, or use device.kind = \"virtual\"",
                    library, ::dlerror()));
  auto load = [&](auto& fn, const char* name) {
    fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(::dlsym(api_->library, name));
    if (!fn) throw Error(fmt::format("OpenHaptics: {} has no function {}", library, name));
  };
  load(api_->hdInitDevice, "hdInitDevice");
  load(api_->hdDisableDevice, "hdDisableDevice");
  load(api_->hdMakeCurrentDevice, "hdMakeCurrentDevice");
  load(api_->hdBeginFrame, "hdBeginFrame");
  load(api_->hdEndFrame, "hdEndFrame");
  load(api_->hdGetDoublev, "hdGetDoublev");
  load(api_->hdGetIntegerv, "hdGetIntegerv");
  load(api_->hdSetDoublev, "hdSetDoublev");
  load(api_->hdEnable, "hdEnable");
  load(api_->hdGetError, "hdGetError");
  load(api_->hdStartScheduler, "hdStartScheduler");
  load(api_->hdStopScheduler, "hdStopScheduler");

  handle_ = api_->hdInitDevice(device_name.empty() ? nullptr : device_name.c_str());
  check("initialising the device");
  if (handle_ == HD_INVALID_HANDLE) throw DeviceError("OpenHaptics: no device (invalid handle)");
  api_->hdMakeCurrentDevice(handle_);
  // specs, in SI: N, N/mm -> N/m, N s/mm -> N s/m, workspace box (mm) -> the radius of its inscribed sphere (m)
  double force = 0, stiffness = 0, damping = 0, box[6] = {0, 0, 0, 0, 0, 0};
  api_->hdGetDoublev(HD_NOMINAL_MAX_CONTINUOUS_FORCE, &force);
  api_->hdGetDoublev(HD_NOMINAL_MAX_STIFFNESS, &stiffness);
  api_->hdGetDoublev(HD_NOMINAL_MAX_DAMPING, &damping);
  api_->hdGetDoublev(HD_USABLE_WORKSPACE_DIMENSIONS, box);
  // a device with six output degrees of freedom (Phantom Premium 6DOF) renders a torque too: its largest
  // continuous one, mN m -> N m
  int output_dof = 3;
  api_->hdGetIntegerv(HD_OUTPUT_DOF, &output_dof);
  double torque = 0;
  if (output_dof >= 6) api_->hdGetDoublev(HD_NOMINAL_MAX_TORQUE_CONTINUOUS_FORCE, &torque);
  check("reading the device's specifications");
  specs_.name = "openhaptics";
  specs_.max_force = force;
  specs_.max_stiffness = 1e3 * stiffness;
  specs_.max_damping = 1e3 * damping;
  specs_.workspace_radius = 0.5e-3 * std::min({box[3] - box[0], box[4] - box[1], box[5] - box[2]});
  specs_.max_torque = output_dof >= 6 && torque > 0 ? 1e-3 * torque : 0.0;
  if (!(specs_.max_force > 0) || !(specs_.max_stiffness > 0))
    throw DeviceError(fmt::format("OpenHaptics: the device reports max force {} N and stiffness {} N/m",
                                  specs_.max_force, specs_.max_stiffness));
  api_->hdEnable(HD_FORCE_OUTPUT);
  api_->hdStartScheduler();
  check("starting the scheduler");
}

OpenHapticsDevice::~OpenHapticsDevice() {
  try {
    stop();
  } catch (...) {}
}

void OpenHapticsDevice::check(const char* what) {
  const HDErrorInfo e = api_->hdGetError();
  if (e.errorCode != HD_SUCCESS)
    throw DeviceError(
        fmt::format("OpenHaptics: error 0x{:04x} (internal {}) while {}", e.errorCode, e.internalErrorCode, what));
}

DeviceState OpenHapticsDevice::read(double t) {
  if (stopped_) throw DeviceError("OpenHaptics: the device was stopped");
  api_->hdBeginFrame(handle_);
  in_frame_ = true;
  double p[3] = {0, 0, 0}, v[3] = {0, 0, 0}, transform[16] = {};
  int buttons = 0;
  api_->hdGetDoublev(HD_CURRENT_POSITION, p);
  api_->hdGetDoublev(HD_CURRENT_VELOCITY, v);
  api_->hdGetDoublev(HD_CURRENT_TRANSFORM, transform);  // the stylus's pose: 4x4, column-major, mm
  api_->hdGetIntegerv(HD_CURRENT_BUTTONS, &buttons);
  check("reading the device");
  DeviceState s;
  s.time = t;
  s.position = 1e-3 * Vec3(p[0], p[1], p[2]);  // mm -> m
  s.velocity = 1e-3 * Vec3(v[0], v[1], v[2]);
  s.buttons = static_cast<unsigned>(buttons);
  if (!s.position.allFinite() || !s.velocity.allFinite())
    throw DeviceError("OpenHaptics: the device reported a non-finite position");
  // the stylus's orientation (a capsule tool turns with it): the transform's rotation, made orthonormal
  const Eigen::Map<const Eigen::Matrix4d> pose(transform);
  const Mat3 rotation = pose.topLeftCorner<3, 3>();
  if (rotation.allFinite() && std::abs(rotation.determinant() - 1) < 0.1)
    s.orientation = Eigen::Quaterniond(rotation).normalized();
  return s;
}

void OpenHapticsDevice::command(const Vec3& force) {
  if (stopped_) throw DeviceError("OpenHaptics: the device was stopped");
  const double f[3] = {force.x(), force.y(), force.z()};  // N, as HD wants
  if (!in_frame_) {
    api_->hdBeginFrame(handle_);
    in_frame_ = true;
  }
  api_->hdSetDoublev(HD_CURRENT_FORCE, f);
  if (specs_.max_torque > 0) {
    const double t[3] = {1e3 * torque_.x(), 1e3 * torque_.y(), 1e3 * torque_.z()};  // N m -> mN m (N mm), as HD wants
    api_->hdSetDoublev(HD_CURRENT_TORQUE, t);
  }
  api_->hdEndFrame(handle_);
  in_frame_ = false;
  check("commanding the force");
}

void OpenHapticsDevice::stop() {
  if (stopped_ || !api_ || !api_->library) return;
  stopped_ = true;
  const double zero[3] = {0, 0, 0};
  if (!in_frame_) api_->hdBeginFrame(handle_);
  api_->hdSetDoublev(HD_CURRENT_FORCE, zero);
  if (specs_.max_torque > 0) api_->hdSetDoublev(HD_CURRENT_TORQUE, zero);
  api_->hdEndFrame(handle_);
  in_frame_ = false;
  api_->hdStopScheduler();
  api_->hdDisableDevice(handle_);
  api_->hdGetError();  // clear: nothing more can be done about an error here
}

}  // namespace pointhaptics
