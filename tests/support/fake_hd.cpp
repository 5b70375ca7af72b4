// A stand-in for OpenHaptics' libHD.so with the same C functions, for testing the dlopen backend without
// the SDK or a device. The "device" moves its stylus on a 10 mm circle, one degree per frame, reports
// Touch-like specs in HD's units (mm, N, N/mm), and can be told to fail after a number of frames. Its stylus
// turns about z by the same angle; told to have six output degrees of freedom, it takes a torque (mN m) too.
#include <cmath>
#include <cstring>

extern "C" {

typedef unsigned int HHD;
typedef unsigned int HDenum;
typedef struct {
  unsigned int errorCode;
  int internalErrorCode;
  HHD hHD;
} HDErrorInfo;

namespace {
unsigned int error_code = 0;
long frames = 0, fail_after = -1;
bool in_frame = false, scheduler = false, enabled = false, force_output = false;
double last_force[3] = {0, 0, 0}, last_torque[3] = {0, 0, 0};
int output_dof = 3;
void set_error(unsigned int code) {
  if (error_code == 0) error_code = code;
}
}  // namespace

// test hooks
void fake_hd_fail_after(long n) { fail_after = n; }
void fake_hd_last_force(double* f) { std::memcpy(f, last_force, sizeof last_force); }
void fake_hd_last_torque(double* t) { std::memcpy(t, last_torque, sizeof last_torque); }
void fake_hd_set_output_dof(int dof) { output_dof = dof; }
int fake_hd_enabled() { return enabled && scheduler && force_output ? 1 : 0; }
long fake_hd_frames() { return frames; }

HHD hdInitDevice(const char* name) {
  if (name && std::strcmp(name, "missing") == 0) {
    set_error(0x0300);  // HD_DEVICE_FAULT
    return 0xFFFFFFFF;
  }
  enabled = true;
  frames = 0;
  return 1;
}
void hdDisableDevice(HHD) { enabled = false; }
void hdMakeCurrentDevice(HHD) {}
void hdEnable(HDenum cap) {
  if (cap == 0x4000) force_output = true;
}
void hdStartScheduler() { scheduler = true; }
void hdStopScheduler() { scheduler = false; }
void hdBeginFrame(HHD) {
  if (in_frame) set_error(0x0400);  // HD_ILLEGAL_BEGIN
  in_frame = true;
  ++frames;
  if (fail_after >= 0 && frames > fail_after) set_error(0x0302);  // HD_COMM_ERROR: unplugged
}
void hdEndFrame(HHD) {
  if (!in_frame) set_error(0x0401);  // HD_ILLEGAL_END
  in_frame = false;
}
HDErrorInfo hdGetError() {
  HDErrorInfo e{error_code, 0, 1};
  error_code = 0;
  return e;
}
void hdGetDoublev(HDenum what, double* v) {
  const double a = frames * M_PI / 180.0;
  switch (what) {
    case 0x2050:
      v[0] = 10 * std::cos(a);
      v[1] = 10 * std::sin(a);
      v[2] = 0;
      break;  // position, mm
    case 0x2051:
      v[0] = -10 * std::sin(a) * 1000 * M_PI / 180;
      v[1] = 10 * std::cos(a) * 1000 * M_PI / 180;
      v[2] = 0;
      break;                           // mm/s at 1 kHz
    case 0x2604: v[0] = 0.88; break;   // continuous force, N
    case 0x2602: v[0] = 0.4; break;    // stiffness, N/mm
    case 0x2609: v[0] = 0.003; break;  // damping, N s/mm
    case 0x2551: {
      const double box[6] = {-80, -60, -35, 80, 60, 35};
      std::memcpy(v, box, sizeof box);
      break;
    }
    case 0x2052: {  // the stylus's transform: turned about z by a, at the position; column-major, mm
      const double m[16] = {std::cos(a), std::sin(a), 0, 0, -std::sin(a),     std::cos(a),      0, 0,
                            0,           0,           1, 0, 10 * std::cos(a), 10 * std::sin(a), 0, 1};
      std::memcpy(v, m, sizeof m);
      break;
    }
    case 0x2623:  // continuous torque, mN m (six output degrees of freedom only)
      if (output_dof >= 6) v[0] = 150;
      else set_error(0x0100);
      break;
    default: set_error(0x0100);  // HD_INVALID_ENUM
  }
}
void hdGetIntegerv(HDenum what, int* v) {
  if (what == 0x2000) *v = frames > 100 ? 1 : 0;  // button 1 held after 100 frames
  else if (what == 0x2554) *v = output_dof;
  else set_error(0x0100);
}
void hdSetDoublev(HDenum what, const double* v) {
  if (what != 0x2700 && !(what == 0x2701 && output_dof >= 6)) {
    set_error(0x0100);
    return;
  }
  if (!in_frame) set_error(0x0102);  // HD_INVALID_OPERATION
  std::memcpy(what == 0x2700 ? last_force : last_torque, v, sizeof last_force);
}

}  // extern "C"
