#include "panels.hpp"

#include <fmt/format.h>
#include <imgui.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace pointhaptics::viewer {

void LiveStats::sample(double t, const DisplayFrame& frame) {
  force.push(t, static_cast<float>(frame.force.norm()));
  if (steps.update(t, frame.step)) step_rate.push(t, static_cast<float>(steps.rate()));
  if (ticks.update(t, frame.haptic_ticks)) haptic_rate.push(t, static_cast<float>(ticks.rate()));
}

namespace {

bool slider(const char* label, double& value, double lo, double hi, const char* format, bool logarithmic = false) {
  return ImGui::SliderScalar(label, ImGuiDataType_Double, &value, &lo, &hi, format,
                             logarithmic ? ImGuiSliderFlags_Logarithmic : ImGuiSliderFlags_None);
}

template <class Enum, std::size_t N>
bool combo(const char* label, Enum& value, const std::array<const char*, N>& names) {
  int k = static_cast<int>(value);
  const bool changed = ImGui::Combo(label, &k, names.data(), static_cast<int>(N));
  if (changed) value = static_cast<Enum>(k);
  return changed;
}

void plot(const char* label, const RollingSeries& series, std::vector<float>& scratch, const char* unit) {
  series.values(scratch);
  // round-off (a force of 1e-15 N when nothing touches) shows as the 0 it is
  const double latest =
      std::abs(series.latest()) < 1e-9 * std::max(1.0, static_cast<double>(series.max())) ? 0.0 : series.latest();
  const std::string overlay = fmt::format("{:.3g} {}", latest, unit);
  const float top = std::max(series.max() * 1.1f, 1e-6f);
  ImGui::PlotLines(label, scratch.data(), static_cast<int>(scratch.size()), 0, overlay.c_str(), 0.0f, top,
                   ImVec2(0, 60));
}

// with several device-driven tools and the mouse: which one the cursor drives (Tab: the next)
void hands_panel(const Prepared& p, PanelState& state) {
  if (p.mice.size() < 2) return;
  int k = static_cast<int>(p.driven);
  std::vector<const char*> names;
  for (const std::string& n : p.hand_names) names.push_back(n.c_str());
  if (ImGui::Combo("mouse drives (Tab)", &k, names.data(), static_cast<int>(names.size()))) state.drive = k;
}

void scene_panel(const ViewerSession* session, const Prepared& p, const DisplayFrame& f) {
  ImGui::TextWrapped("%s", p.scene.path.c_str());
  ImGui::Text("%ld points, %ld simulated, %d in contact", static_cast<long>(p.reference.cols()),
              static_cast<long>(f.simulated), f.contacts);
  ImGui::Text("probe: %s", p.device_name.c_str());
  if (!p.note.empty()) ImGui::TextWrapped("%s", p.note.c_str());
  if (session && session->rebuilding()) ImGui::TextColored(ImVec4(1, 0.8f, 0.3f, 1), "rebuilding the model ...");
  if (session && !session->error().empty())
    ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", session->error().c_str());
}

bool parameter_panels(Scene& s) {
  bool changed = false;
  if (ImGui::CollapsingHeader("Material", ImGuiTreeNodeFlags_DefaultOpen)) {
    changed |= slider("E (Pa)", s.material.young, 1e2, 1e9, "%.3g", true);
    changed |= slider("nu", s.material.poisson, 0.0, 0.49, "%.3f");
    changed |= slider("density", s.material.density, 10.0, 2e4, "%.4g", true);
    changed |= slider("damping (1/s)", s.material.damping, 0.0, 200.0, "%.3g");
  }
  if (ImGui::CollapsingHeader("Kernel and solver")) {
    changed |= combo("kernel", s.kernel.type,
                     std::array{"poly6 (Eq. 3)", "spiky (Eq. 4)", "viscosity (Eq. 5)", "quadratic (Eq. 6)"});
    changed |= slider("support (x spacing)", s.kernel.support_factor, 1.2, 4.0, "%.2f");
    int kind = s.solver.kind == SolverKind::IMPLICIT ? 1 : 0;
    if (ImGui::Combo("solver", &kind, "explicit\0implicit (backward Euler)\0")) {
      s.solver.kind = kind ? SolverKind::IMPLICIT : SolverKind::EXPLICIT;
      changed = true;
    }
    double dt_ms = s.solver.dt * 1e3;
    if (slider("dt (ms)", dt_ms, 0.1, 10.0, "%.2f", true)) {
      s.solver.dt = dt_ms * 1e-3;
      changed = true;
    }
  }
  if (ImGui::CollapsingHeader("Levels of detail")) {
    changed |= ImGui::Checkbox("simulate only near the contact", &s.lod.present);
    LodParams& l = s.lod.params;
    changed |= slider("T_r1 (x h)", l.k1, 0.5, 4.0, "%.2f");
    changed |= slider("T_r2 (x h)", l.k2, l.k1, 6.0, "%.2f");
    changed |= combo("scheme", l.scheme, std::array{"random (seed)", "dither"});
    changed |= ImGui::SliderInt("min neighbours", &l.min_neighbours, 4, 40);
    for (std::size_t i = 0; i < l.levels.size(); ++i) {
      ImGui::PushID(static_cast<int>(i));
      const double lo = i ? l.levels[i - 1].distance : l.k2;
      changed |= slider("P_i (x h)", l.levels[i].distance, lo, 20.0, "%.2f");
      changed |= ImGui::SliderInt("K_i", &l.levels[i].K, i ? l.levels[i - 1].K : 0, 10);
      ImGui::PopID();
    }
    if (ImGui::Button("add level")) {
      const double d = l.levels.empty() ? l.k2 + 1.0 : l.levels.back().distance + 1.0;
      l.levels.push_back({d, l.levels.empty() ? 5 : std::min(10, l.levels.back().K + 2)});
      changed = true;
    }
    ImGui::SameLine();
    if (ImGui::Button("remove level") && !l.levels.empty()) {
      l.levels.pop_back();
      changed = true;
    }
  }
  if (ImGui::CollapsingHeader("Probe", ImGuiTreeNodeFlags_DefaultOpen)) {
    double r_mm = s.probe.radius * 1e3;
    if (slider("radius (mm)", r_mm, 0.5, 100.0, "%.3g", true)) {
      s.probe.radius = r_mm * 1e-3;
      changed = true;
    }
    if (s.probe.grasper) {  // the button closes its jaws from the opening to the grip
      ImGui::TextWrapped("grasper: the button closes its jaws");
      double opening_mm = s.probe.opening * 1e3, grip_mm = s.probe.grip * 1e3;
      if (slider("opening (mm)", opening_mm, 1.0, 100.0, "%.3g", true)) {
        s.probe.opening = opening_mm * 1e-3;
        s.probe.grip = std::min(s.probe.grip, 0.99 * s.probe.opening);
        changed = true;
      }
      if (slider("grip (mm)", grip_mm, 0.0, opening_mm, "%.3g")) {
        s.probe.grip = std::min(grip_mm * 1e-3, 0.99 * s.probe.opening);
        changed = true;
      }
      return changed;
    }
    int mode = s.probe.cut ? 2 : s.probe.grab ? 1 : 0;
    if (ImGui::Combo("mode", &mode, "push (button grabs)\0grab only\0blade (button cuts)\0")) {
      s.probe.grab = mode == 1;
      s.probe.cut = mode == 2;
      // a blade is a capsule whose axis is its edge: four radii long unless the scene gave one
      if (s.probe.cut && !s.probe.capsule) {
        s.probe.capsule = true;
        s.probe.length = 4 * s.probe.radius;
      }
      changed = true;
    }
    if (s.probe.cut) {
      double length_mm = s.probe.length * 1e3;
      if (slider("blade length (mm)", length_mm, 1.0, 200.0, "%.3g", true)) {
        s.probe.length = length_mm * 1e-3;
        changed = true;
      }
      if (slider("cut resistance (J/m^2)", s.probe.cut_resistance, 0.0, 5000.0, "%.0f", false)) changed = true;
    }
  }
  return changed;
}

void display_panel(const Prepared& p, SceneView& view) {
  if (!ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) return;
  int by = static_cast<int>(view.colour_by);
  ImGui::RadioButton("displacement", &by, 0);
  ImGui::SameLine();
  ImGui::RadioButton("LOD band", &by, 1);
  ImGui::SameLine();
  ImGui::RadioButton("von Mises", &by, 2);
  view.colour_by = static_cast<ColourBy>(by);
  ImGui::Checkbox("auto scale", &view.auto_scale);
  if (!view.auto_scale && view.colour_by == ColourBy::VON_MISES) {
    float kpa = view.stress_max * 1e-3f;
    if (ImGui::SliderFloat("scale (kPa)", &kpa, 1e-3f, 1e4f, "%.3g", ImGuiSliderFlags_Logarithmic))
      view.stress_max = kpa * 1e3f;
  } else if (!view.auto_scale) {
    float mm = view.scale_max * 1e3f;
    if (ImGui::SliderFloat("scale (mm)", &mm, 1e-3f, 100.0f, "%.3g", ImGuiSliderFlags_Logarithmic))
      view.scale_max = mm * 1e-3f;
  }
  ImGui::SliderFloat("point size", &view.point_scale, 0.2f, 1.5f, "%.2f");
  if (p.surface) {
    ImGui::Checkbox("surface", &view.draw_surface);
    if (view.draw_surface) {
      ImGui::SameLine();
      ImGui::Checkbox("points too", &view.points_too);
    }
  }
  ImGui::Checkbox("interior points (hidden in a solid)", &view.interior);
}

void live_panel(const DisplayFrame& f, LiveStats& live) {
  if (!ImGui::CollapsingHeader("Live", ImGuiTreeNodeFlags_DefaultOpen)) return;
  plot("force", live.force, live.scratch, "N");
  plot("steps/s", live.step_rate, live.scratch, "/s");
  plot("haptic", live.haptic_rate, live.scratch, "Hz");
  ImGui::Text("t = %.2f s, %lld steps, %.0f frames/s", f.time, f.step, live.frames_per_s);
}

void controls_panel() {
  if (!ImGui::CollapsingHeader("Controls")) return;
  ImGui::TextWrapped(
      "mouse: moves the probe in the view plane\n"
      "wheel: probe in depth (shift/ctrl + wheel: zoom)\n"
      "left button: grab (held)\n"
      "right drag: orbit   middle drag: pan\n"
      "space: probe stops following the mouse\n"
      "Tab: the mouse drives the next tool (the others stay)\n"
      "R: reset view   S: screenshot   Q/Esc: quit");
}

}  // namespace

void draw_panels(const ViewerSession* session, const Prepared& p, const DisplayFrame& f, SceneView& view,
                 PanelState& state, LiveStats& live, double /*width*/, double height) {
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(static_cast<float>(panel_width), static_cast<float>(height)));
  ImGui::Begin("PointHaptics", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  ImGui::PushItemWidth(150);
  scene_panel(session, p, f);
  hands_panel(p, state);
  ImGui::Separator();
  const bool edited = parameter_panels(state.edit);
  (void)edited;
  const bool busy = !session || session->rebuilding();
  if (busy) ImGui::BeginDisabled();
  if (ImGui::Button("apply (rebuild the model)")) state.apply = true;
  ImGui::SameLine();
  if (ImGui::Button("revert")) state.edit = p.scene;
  if (busy) ImGui::EndDisabled();
  display_panel(p, view);
  if (session) {
    live_panel(f, live);
  } else if (ImGui::CollapsingHeader("Live", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::TextWrapped("t = %.2f s, %lld steps, |F| = %.3g N (a headless frame: the live plots run in the window)",
                       f.time, f.step, f.force.norm());
  }
  controls_panel();
  if (!state.screenshot_message.empty()) ImGui::TextWrapped("%s", state.screenshot_message.c_str());
  ImGui::PopItemWidth();
  ImGui::End();
}

}  // namespace pointhaptics::viewer
