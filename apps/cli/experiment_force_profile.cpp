#include "experiment_force_profile.hpp"

#include "plots.hpp"

#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <filesystem>

namespace pointhaptics::experiments {

int run_force_profile_experiment(const ForceProfileOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(options.out);
  const fs::path out = options.out;
  // the seed's haptic beam (scenes/beam_fixed_both_ends.toml): 10 x 3 x 3 points 15 mm apart, both ends held
  Scene scene;
  scene.path = "force-profile";
  scene.object.size = Vec3(0.135, 0.03, 0.03);
  scene.object.spacing = 0.015;
  scene.material.young = 1e5;
  scene.material.poisson = 0.4;
  scene.material.density = 1000;
  scene.material.damping = 20;
  FixedSpec left, right;
  left.box = {Vec3(-1, -1, -1), Vec3(0, 1, 1)};
  right.box = {Vec3(0.135, -1, -1), Vec3(1, 1, 1)};
  scene.fixed = {left, right};
  scene.solver.kind = SolverKind::EXPLICIT;
  scene.solver.dt = 1e-3;
  Simulation sim(build_scene_model(scene), scene.solver, 1);
  // the dragged point: point 54, on the upper face near mid-span (the seed's loaded point)
  const index_t dragged = 54;
  const Vec3 at = sim.model().X.col(dragged);
  // the hand: rest, grab at 0.2 s, pull 15 mm up by 1.2 s, hold, let go at 2 s, watch until 4 s
  const double lift = 0.015;
  VirtualDevice device(Trajectory({{0.0, Vec3::Zero(), false},
                                   {0.2, Vec3::Zero(), true},
                                   {1.2, Vec3(0, lift, 0), true},
                                   {2.0, Vec3(0, lift, 0), false},
                                   {4.0, Vec3(0, lift, 0), false}}),
                       known_device_specs("touch"));
  InteractiveOptions o;
  o.duration = 4.0;
  o.real_time = options.real_time;
  o.probe.radius = 0.005;  // with the point radius it reaches 12.5 mm: only the dragged point
  o.probe.mode = ProbeMode::GRAB;
  o.mapping.origin = at;
  const InteractiveResult r = run_interactive(sim, device, o);
  if (r.haptic.device_failed) throw Error(fmt::format("force-profile: the device failed: {}", r.haptic.device_error));
  if (sim.diagnostics().failed) throw Error(fmt::format("force-profile: {}", sim.diagnostics().failure));

  auto csv = fmt::output_file((out / "force-profile.csv").string());
  csv.print("t_s,force_n,fx_n,fy_n,fz_n,device_y_m,button\n");
  double peak = 0, peak_t = 0, held = 0, after = 0;
  for (const HapticLogRow& row : r.log) {
    csv.print("{:.4f},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{}\n", row.t, row.force.norm(), row.force.x(), row.force.y(),
              row.force.z(), row.position.y(), row.buttons);
    if (row.force.norm() > peak) {
      peak = row.force.norm();
      peak_t = row.t;
    }
    if (row.t <= 1.95) held = row.force.norm();
    if (row.t >= 3.5) after = std::max(after, row.force.norm());
  }
  csv.close();
  auto md = fmt::output_file((out / "summary.md").string());
  md.print(
      "# Force profile (seed Fig. 2c)\n\n"
      "The seed's beam (90 points, 0.135 x 0.03 x 0.03 m, E = 1e5 Pa, nu = 0.4, both ends held). A virtual hand "
      "(Touch specs, coupling at half its stable stiffness) grabs point {} at ({:.3f}, {:.3f}, {:.3f}) m at 0.2 s, "
      "pulls it {} mm up by 1.2 s, holds, and lets go at 2 s. {} run: {} haptic ticks, {} simulation steps.\n\n"
      "- peak force {:.3f} N at {:.3f} s\n- force while holding (1.95 s) {:.3f} N\n- largest force after 3.5 s "
      "(released, ringing down) {:.4f} N\n- passivity observer minimum {:.2e} J\n",
      dragged, at.x(), at.y(), at.z(), 1e3 * lift, options.real_time ? "Real-time" : "Deterministic (simulated time)",
      r.haptic.ticks, r.simulation_steps, peak, peak_t, held, after, r.haptic.min_observed_energy);
  md.close();
  fmt::print("force profile: peak {:.3f} N at {:.3f} s, {:.3f} N while holding, {:.4f} N after release\n", peak, peak_t,
             held, after);
  if (run_plot_script("plot_force_profile.py", out.string()) != 0) return 1;
  fmt::print("wrote {}\n", out.string());
  return 0;
}

}  // namespace pointhaptics::experiments
