#include "viewer.hpp"

#include <pointhaptics/session/scene_session.hpp>

#include "gl_context.hpp"
#include "panels.hpp"
#include "point_renderer.hpp"
#include "scene_view.hpp"
#include "viewer_session.hpp"

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/scene_toml.hpp>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <fmt/format.h>
#include <imgui.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <thread>
#include <vector>

#ifndef PH_SCENES_SOURCE_DIR
#define PH_SCENES_SOURCE_DIR ""
#endif
#ifndef PH_SCENES_INSTALLED_DIR
#define PH_SCENES_INSTALLED_DIR ""
#endif

namespace pointhaptics::viewer {

std::string default_scene() {
  for (const char* dir : {PH_SCENES_SOURCE_DIR, PH_SCENES_INSTALLED_DIR}) {
    const std::filesystem::path p = std::filesystem::path(dir) / "beam_probe.toml";
    if (*dir && std::filesystem::exists(p)) return p.string();
  }
  throw Error("view: no scene given and the default scene (scenes/beam_probe.toml) is not found");
}

namespace {

// the scene, with the tool the mouse (or --probe's source) drives first among its device-driven tools
Scene read_viewer_scene(const ViewerOptions& o) {
  Scene scene = read_scene_file(o.scene.empty() ? default_scene() : o.scene);
  if (!o.tool.empty()) put_hand_first(scene, o.tool);
  return scene;
}

// ImGui without a platform backend (headless): the display size and a clock are all it needs
void begin_headless_imgui_frame(int width, int height) {
  ImGuiIO& io = ImGui::GetIO();
  io.DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
  io.DeltaTime = 1.0f / 60.0f;
  ImGui_ImplOpenGL3_NewFrame();
  ImGui::NewFrame();
}

struct ImGuiContextGuard {
  ImGuiContextGuard() {
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the user's folder
    ImGui::StyleColorsDark();
  }
  ~ImGuiContextGuard() { ImGui::DestroyContext(); }
};

// The mouse drives the probe: the cursor moves it in the plane facing the camera through it, the wheel in
// depth, the left button grabs.
struct MouseProbe {
  Vec3 target = Vec3::Constant(NAN);  ///< scene position the hand the cursor drives aims at
  std::vector<Vec3> targets;          ///< every hand's, where the cursor left it (the driven one's is `target`)
  CursorAnchor anchor;                ///< moves it with the cursor's motion (from the first motion on)
  bool follow = true;
  double scroll = 0;      ///< wheel clicks since the last frame (from the GLFW callback)
  std::vector<int> keys;  ///< keys pressed since the last frame (from the callback: a tap
                          ///< shorter than a frame is not lost)
};

// The view a window or a screenshot starts with: the colours asked for, the object framed.
SceneView initial_view(const ViewerOptions& o, const Prepared& prepared) {
  SceneView view;
  view.colour_by = o.colour == "band"        ? ColourBy::LOD_BAND
                   : o.colour == "von_mises" ? ColourBy::VON_MISES
                                             : ColourBy::DISPLACEMENT;
  view.draw_surface = o.draw == "surface";
  view.camera.frame(prepared.lo, prepared.hi);
  return view;
}

MouseProbe* mouse_probe_of(GLFWwindow* w) { return static_cast<MouseProbe*>(glfwGetWindowUserPointer(w)); }

}  // namespace

int render_screenshot(const ViewerOptions& o) {
  const Scene scene = read_viewer_scene(o);
  const bool scripted =
      !scene.probe.keyframes.empty() || !scene.probe.trajectory.empty() || scene.device.kind == "replay";
  const ProbeSource source =
      o.probe == "auto" ? (scripted ? ProbeSource::SCRIPT : ProbeSource::MOUSE) : probe_source_of(o.probe);
  auto prepared = prepare(scene, source, o.threads);
  const DisplayFrame frame = simulate_frame(*prepared, o.time);
  // a picture of a run that failed would show a state that is no result
  if (prepared->simulation->diagnostics().failed)
    throw Error(fmt::format("view: {}: the run failed at t = {:.4g} s: {}", scene.path, frame.time,
                            prepared->simulation->diagnostics().failure));

  HeadlessContext context(o.width, o.height);
  ImGuiContextGuard imgui;
  if (!ImGui_ImplOpenGL3_Init("#version 330")) throw Error("viewer: Dear ImGui's OpenGL 3 renderer did not start");
  Renderers renderer;
  SceneView view = initial_view(o, *prepared);
  const Viewport vp = scene_viewport(o.width, o.height, o.panels);
  PanelState state{prepared->scene, false, {}};
  LiveStats live;
  // a frame as the window makes it: spheres from the frame, panels, drawing; the last one is kept
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < std::max(o.frames, 1); ++k) {
    if (k > 0) view.camera.yaw += 0.01;
    build_scene(*prepared, frame, view);
    begin_headless_imgui_frame(o.width, o.height);
    if (o.panels) draw_panels(nullptr, *prepared, frame, view, state, live, o.width, o.height);
    draw_overlay(*prepared, frame, view, vp);
    ImGui::Render();
    renderer.draw(view, vp, o.width, o.height);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    glFinish();
  }
  if (o.frames > 1) {
    const double ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / o.frames;
    fmt::print("{} frames of {} points at {} x {}: {:.2f} ms per frame ({:.0f} frames/s)\n", o.frames,
               prepared->reference.cols(), o.width, o.height, ms, 1e3 / ms);
  }
  write_png(o.screenshot, o.width, o.height, read_pixels(o.width, o.height));
  if (!o.info.empty()) write_frame_info(o.info, *prepared, frame, view, vp, o.width, o.height, 0.0);
  ImGui_ImplOpenGL3_Shutdown();
  fmt::print("wrote {} ({} x {}, t = {:.3g} s, {}, rendered by {})\n", o.screenshot, o.width, o.height, frame.time,
             prepared->device_name, context.renderer());
  return 0;
}

int run_window(const ViewerOptions& o) {
  const Scene scene = read_viewer_scene(o);
  const ProbeSource source = probe_source_of(o.probe);
  ViewerSession session(prepare(scene, source, o.threads), source, o.threads);

  // Under Mesa's software renderer (llvmpipe) the drawing would otherwise take a thread per core from the
  // simulation and the haptic loop (on 2 cores: 21 instead of 27 frames/s, and the simulation 1.5x faster).
  // A user's own setting wins; GPU drivers ignore it.
  setenv("LP_NUM_THREADS", "1", 0);
  Window window(o.width, o.height, fmt::format("PointHaptics - {}", scene.path));
  MouseProbe mouse;
  glfwSetWindowUserPointer(window.handle(), &mouse);
  // installed before ImGui's, which chains to it
  glfwSetScrollCallback(window.handle(), [](GLFWwindow* w, double, double dy) { mouse_probe_of(w)->scroll += dy; });
  glfwSetKeyCallback(window.handle(), [](GLFWwindow* w, int key, int, int action, int) {
    if (action == GLFW_PRESS) mouse_probe_of(w)->keys.push_back(key);
  });
  ImGuiContextGuard imgui;
  ImGui_ImplGlfw_InitForOpenGL(window.handle(), true);
  if (!ImGui_ImplOpenGL3_Init("#version 330")) throw Error("viewer: Dear ImGui's OpenGL 3 renderer did not start");
  struct Backends {
    ~Backends() {
      ImGui_ImplOpenGL3_Shutdown();
      ImGui_ImplGlfw_Shutdown();
    }
  } backends;

  Renderers renderer;
  SceneView view = initial_view(o, session.current());
  PanelState state{session.current().scene, false, {}};
  LiveStats live;
  session.start();

  // every hand aims at its workspace's origin until the cursor drives it
  const auto aim_at_origins = [&] {
    const Prepared& p = session.current();
    mouse.targets.clear();
    for (std::size_t k = 0; k < p.hand_names.size(); ++k) mouse.targets.push_back(hand_origin(p, k));
    mouse.target = hand_origin(p, p.driven);
    mouse.anchor.reset();
  };
  aim_at_origins();
  // the cursor passes to hand k; the one it drove stays where it left it
  const auto drive = [&](std::size_t k) {
    Prepared& p = session.current();
    if (p.mice.empty() || k == p.driven || k >= p.mice.size()) return;
    mouse.targets[p.driven] = mouse.target;
    drive_hand(p, k);
    mouse.target = mouse.targets[k];
    mouse.anchor.reset();
  };

  const auto start = std::chrono::steady_clock::now();
  const auto wall = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  double last_x = 0, last_y = 0;
  int frames = 0;
  double fps_t0 = 0;
  while (!window.should_close()) {
    glfwPollEvents();
    const double t = wall();
    if (session.poll()) {  // a rebuild took over
      view.camera.frame(session.current().lo, session.current().hi);
      state.edit = session.current().scene;
      aim_at_origins();
    }
    Prepared& p = session.current();
    const DisplayFrame& frame = session.frame();
    live.sample(t, frame);
    if (++frames % 30 == 0) {
      live.frames_per_s = 30.0 / std::max(t - fps_t0, 1e-9);
      fps_t0 = t;
    }

    int ww = 0, wh = 0;
    glfwGetWindowSize(window.handle(), &ww, &wh);
    const Viewport vp = scene_viewport(ww, wh, o.panels);
    double cx = 0, cy = 0;
    glfwGetCursorPos(window.handle(), &cx, &cy);
    const ImGuiIO& io = ImGui::GetIO();
    const bool over_view = vp.contains(cx, cy) && !io.WantCaptureMouse;
    const bool shift = glfwGetKey(window.handle(), GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                       glfwGetKey(window.handle(), GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    const bool ctrl = glfwGetKey(window.handle(), GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS ||
                      glfwGetKey(window.handle(), GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS;
    const double dx = cx - last_x, dy = cy - last_y;
    last_x = cx;
    last_y = cy;
    // camera
    if (over_view && glfwGetMouseButton(window.handle(), GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS) {
      if (shift) view.camera.pan(dx, dy, vp);
      else view.camera.orbit(dx, dy, vp);
      mouse.anchor.reset();  // the plane the probe moves in turned
    }
    if (over_view && glfwGetMouseButton(window.handle(), GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) {
      view.camera.pan(dx, dy, vp);
      mouse.anchor.reset();
    }
    if (over_view && mouse.scroll != 0) {
      if (shift || ctrl) view.camera.zoom(std::pow(0.9, mouse.scroll));
      else if (mouse.target.allFinite())
        mouse.target += view.camera.forward() * (-0.5 * p.options.probe.radius * mouse.scroll);
      mouse.anchor.reset();
    }
    mouse.scroll = 0;
    bool save_key = false;
    for (const int key : mouse.keys) {
      if (io.WantCaptureKeyboard) break;  // typing into a panel
      if (key == GLFW_KEY_SPACE) {
        mouse.follow = !mouse.follow;
        mouse.anchor.reset();
      }
      if (key == GLFW_KEY_R) {
        view.camera = initial_view(o, p).camera;
        mouse.anchor.reset();
      }
      if (key == GLFW_KEY_Q || key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(window.handle(), 1);
      if (key == GLFW_KEY_S) save_key = true;
      if (key == GLFW_KEY_TAB && !p.mice.empty()) drive((p.driven + 1) % p.mice.size());
    }
    if (state.drive >= 0) drive(static_cast<std::size_t>(state.drive));
    state.drive = -1;
    mouse.keys.clear();
    // the probe follows the cursor in the plane through the hand's target
    if (p.mouse) {
      if (over_view && mouse.follow) mouse.target = mouse.anchor.follow(view.camera, vp, cx, cy, mouse.target);
      const bool grab = over_view && glfwGetMouseButton(window.handle(), GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
      p.mouse->set_target(session.device_of_scene(mouse.target), grab ? 1u : 0u);
    }

    build_scene(p, frame, view);
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    if (o.panels) draw_panels(&session, p, frame, view, state, live, ww, wh);
    draw_overlay(p, frame, view, vp);
    ImGui::Render();
    const int fw = window.framebuffer_width(), fh = window.framebuffer_height();
    renderer.draw(view, vp, fw, fh, window.pixel_ratio());
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

    const bool last = o.run_for > 0 && t >= o.run_for;
    if ((last && !o.screenshot.empty()) || save_key) {
      const std::string path = last ? o.screenshot : fmt::format("pointhaptics-{:.0f}.png", frame.time * 1e3);
      glReadBuffer(GL_BACK);
      write_png(path, fw, fh, read_pixels(fw, fh));
      if (last && !o.info.empty()) {
        const double r = window.pixel_ratio();
        write_frame_info(o.info, p, frame, view, {vp.x * r, vp.y * r, vp.width * r, vp.height * r}, fw, fh,
                         live.haptic_rate.latest());
      }
      state.screenshot_message = "saved " + path;
    }
    window.swap();
    if (state.apply) {
      state.apply = false;
      session.rebuild(state.edit);
    }
    if (last) break;
    // at most 60 frames a second (a display's vsync does this too; Xvfb has none): the cores left over
    // are the simulation's
    const double spare = 1.0 / 60.0 - (wall() - t);
    if (spare > 0) std::this_thread::sleep_for(std::chrono::duration<double>(spare));
  }
  session.stop();
  if (!session.error().empty()) fmt::print(stderr, "view: {}\n", session.error());
  return 0;
}

}  // namespace pointhaptics::viewer
