#include "scene_view.hpp"

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/point_fields.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>

#include <fmt/format.h>
#include <imgui.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>

namespace pointhaptics::viewer {

Viewport scene_viewport(double width, double height, bool panels) {
  if (!panels) return {0, 0, std::max(width, 1.0), std::max(height, 1.0)};
  return {panel_width, 0, std::max(width - panel_width, 1.0), std::max(height, 1.0)};
}

namespace {

Sphere sphere(const Vec3& p, const Rgb& c, double radius) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()), c[0], c[1], c[2],
          static_cast<float>(radius)};
}

Rgb probe_colour_of(const SceneView& view) {
  return view.colour_by == ColourBy::LOD_BAND ? probe_colour_on_bands : probe_colour;
}

Rgb paler(const Rgb& c) {
  return {0.35f * c[0] + 0.65f * 0.55f, 0.35f * c[1] + 0.65f * 0.57f, 0.35f * c[2] + 0.65f * 0.6f};
}

// rise at once, fall slowly, so the colours do not flicker
void follow_scale(float& top, double largest, float floor) {
  top = std::max({static_cast<float>(largest), 0.97f * top, floor});
}

bool surface_drawn(const Prepared& p, const SceneView& view) { return p.drawn_surface() && view.draw_surface; }

/// The colour of point i (its flags first, then the chosen field: `magnitude` is its displacement's norm,
/// m, or its von Mises stress, Pa, as view.colour_by says); with `pale_unsimulated`, paler where levels of
/// detail do not simulate it (points; on a surface the dithered selection's scattered points made blotches).
Rgb point_colour(const Prepared& p, const DisplayFrame& f, const SceneView& view, std::size_t i, double magnitude,
                 bool pale_unsimulated) {
  const bool bands = f.lod_band.size() == p.fixed.size();
  if (p.fixed[i]) return held_colour;
  if (view.grabbed[i]) return grabbed_colour;
  if (view.colour_by == ColourBy::LOD_BAND && bands) return band_colour(f.lod_band[i]);
  const Rgb c = viridis(magnitude / (view.colour_by == ColourBy::VON_MISES ? view.stress_max : view.scale_max));
  return pale_unsimulated && bands && f.lod_band[i] < 0 ? paler(c) : c;
}

}  // namespace

void build_spheres(const Prepared& p, const DisplayFrame& f, SceneView& view) {
  const Eigen::Index n = p.reference.cols();
  view.spheres.clear();
  view.spheres.reserve(static_cast<std::size_t>(n) + 2);
  view.grabbed.assign(static_cast<std::size_t>(n), 0);
  for (const index_t i : f.grabbed)
    if (i >= 0 && i < n) view.grabbed[static_cast<std::size_t>(i)] = 1;
  const bool displacement_ok = f.u.cols() == n && f.u.allFinite();
  if (view.auto_scale && displacement_ok && n > 0) follow_scale(view.scale_max, f.u.colwise().norm().maxCoeff(), 1e-6f);
  // von Mises stress of every point, on this thread from the frame's displacements (the model is static)
  const bool stress = view.colour_by == ColourBy::VON_MISES && displacement_ok;
  if (stress) {
    view.von_mises = point_fields(p.simulation->model(), f.u).von_mises;
    if (view.auto_scale && n > 0) follow_scale(view.stress_max, view.von_mises.maxCoeff(), 1e-3f);
  }
  const double radius = p.point_radius * view.point_scale;
  // the surface shell only, unless asked (a point scaled below full size leaves gaps to see inside by); none
  // under a drawn surface unless asked
  const bool all = view.interior || view.point_scale < 0.9f;
  const Eigen::Index count = surface_drawn(p, view) && !view.points_too ? 0
                             : all                                      ? n
                                                                        : static_cast<Eigen::Index>(p.shell.size());
  for (Eigen::Index m = 0; m < count; ++m) {
    const Eigen::Index i = all ? m : p.shell[static_cast<std::size_t>(m)];
    const Vec3 u = displacement_ok ? Vec3(f.u.col(i)) : Vec3::Zero();
    const double magnitude = stress ? view.von_mises[i] : u.norm();
    view.spheres.push_back(
        sphere(p.reference.col(i) + u, point_colour(p, f, view, static_cast<std::size_t>(i), magnitude, true), radius));
  }
  const double probe_radius = p.options.probe.radius;
  if (f.probe.allFinite()) view.spheres.push_back(sphere(f.probe, probe_colour_of(view), probe_radius));
  if (f.device.allFinite() && f.probe.allFinite() && (f.device - f.probe).norm() > 0.3 * probe_radius)
    view.spheres.push_back(sphere(f.device, {0.8f, 0.8f, 0.85f}, 0.25 * probe_radius));
  for (const DisplayFrame::RigidShape& r : f.rigid)
    add_rigid_shape(r,
                    r.hand                                                             ? probe_colour_of(view)
                    : r.shape.kind == ToolKind::PLANE || r.shape.kind == ToolKind::BOX ? obstacle_colour
                                                                                       : posed_tool_colour,
                    p.lo, p.hi, p.point_radius, view.spheres);
}

void add_rigid_shape(const DisplayFrame::RigidShape& r, const Rgb& colour, const Vec3& lo, const Vec3& hi,
                     double dot_radius, std::vector<Sphere>& spheres) {
  const ToolShape& s = r.shape;
  const Vec3& at = r.pose.position;
  if (!at.allFinite()) return;
  const Eigen::Matrix3d axes = r.pose.orientation.toRotationMatrix();
  // a row of spheres from a to b, at most half their radius apart (at most 64)
  const auto row = [&](const Vec3& a, const Vec3& b, double radius) {
    const int n = std::clamp(static_cast<int>(std::ceil((b - a).norm() / (0.5 * radius))), 1, 64);
    for (int k = 0; k <= n; ++k) spheres.push_back(sphere(a + (b - a) * (static_cast<double>(k) / n), colour, radius));
  };
  switch (s.kind) {
    case ToolKind::SPHERE: spheres.push_back(sphere(at, colour, s.radius)); break;
    case ToolKind::CAPSULE: {
      const Vec3 half = 0.5 * s.length * axes.col(2);
      row(at - half, at + half, s.radius);
      break;
    }
    case ToolKind::BOX: {  // its twelve edges
      const Vec3 h = s.half_core.array() + s.radius;
      const double radius = std::max(s.radius, h.maxCoeff() / 64.0);
      for (int axis = 0; axis < 3; ++axis)
        for (int a = -1; a <= 1; a += 2)
          for (int b = -1; b <= 1; b += 2) {
            Vec3 corner = Vec3::Zero();
            corner[(axis + 1) % 3] = a * h[(axis + 1) % 3];
            corner[(axis + 2) % 3] = b * h[(axis + 2) % 3];
            Vec3 end = corner;
            corner[axis] = -h[axis];
            end[axis] = h[axis];
            row(at + axes * corner, at + axes * end, radius);
          }
      break;
    }
    case ToolKind::PLANE: {  // a grid of dots under the objects, twice their extent
      const Vec3 normal = axes.col(2);
      const Vec3 centre = 0.5 * (lo + hi);
      const Vec3 foot = centre - normal * normal.dot(centre - at);
      const double extent = std::max((hi - lo).norm(), 1e-3);
      const Vec3 t1 = axes.col(0), t2 = axes.col(1);
      constexpr int n = 16;
      for (int i = -n; i <= n; ++i)
        for (int j = -n; j <= n; ++j)
          spheres.push_back(sphere(foot + extent * (i * t1 + j * t2) / n, colour, 0.5 * dot_radius));
      break;
    }
  }
}

void build_surface(const Prepared& p, const DisplayFrame& f, SceneView& view) {
  view.surface_vertices.clear();
  if (!surface_drawn(p, view)) return;
  const ObjectSurface& surface = *p.drawn_surface();
  const Eigen::Index n = p.reference.cols(), m = surface.mesh.V.cols();
  if (view.indexed_surface != &surface) {  // a new object (a rebuild): its triangles
    view.indexed_surface = &surface;
    view.surface_indices.clear();
    for (const auto& t : surface.mesh.F)
      for (const index_t v : t) view.surface_indices.push_back(static_cast<unsigned>(v));
  }
  const bool displacement_ok = f.u.cols() == n && f.u.allFinite();
  if (displacement_ok) carry_surface(surface.map, surface.mesh.V, f.u, view.surface_positions);
  else view.surface_positions = surface.mesh.V;
  // smooth normals: each vertex the sum of its triangles' area vectors
  view.surface_normals.setZero(3, m);
  for (const auto& t : surface.mesh.F) {
    const Vec3 a = view.surface_positions.col(t[0]), b = view.surface_positions.col(t[1]),
               c = view.surface_positions.col(t[2]);
    const Vec3 area = (b - a).cross(c - a);
    for (const index_t v : t) view.surface_normals.col(v) += area;
  }
  const bool stress = view.colour_by == ColourBy::VON_MISES && view.von_mises.size() == n;
  if (stress) interpolate_at_surface(surface.map, view.von_mises.transpose(), view.surface_stress);
  view.surface_vertices.reserve(static_cast<std::size_t>(m));
  for (Eigen::Index v = 0; v < m; ++v) {
    const Vec3 y = view.surface_positions.col(v);
    const Vec3 normal = view.surface_normals.col(v).normalized();
    const double magnitude = stress ? view.surface_stress(0, v) : (y - surface.mesh.V.col(v)).norm();
    const Rgb c = point_colour(
        p, f, view, static_cast<std::size_t>(p.drawn_surface_point()[static_cast<std::size_t>(v)]), magnitude, false);
    view.surface_vertices.push_back({static_cast<float>(y.x()), static_cast<float>(y.y()), static_cast<float>(y.z()),
                                     static_cast<float>(normal.x()), static_cast<float>(normal.y()),
                                     static_cast<float>(normal.z()), c[0], c[1], c[2]});
  }
}

void build_scene(const Prepared& p, const DisplayFrame& f, SceneView& view) {
  build_spheres(p, f, view);
  build_surface(p, f, view);
}

void Renderers::draw(const SceneView& view, const Viewport& viewport, int fb_width, int fb_height, double pixel_ratio) {
  points.draw(view.spheres, view.camera, viewport, fb_width, fb_height, pixel_ratio);
  surface.draw(view.surface_vertices, view.surface_indices, view.camera, viewport, fb_width, fb_height, pixel_ratio);
}

void draw_overlay(const Prepared& p, const DisplayFrame& f, const SceneView& view, const Viewport& vp) {
  ImDrawList* draw = ImGui::GetForegroundDrawList();
  const ImU32 text = IM_COL32(230, 230, 235, 255);
  // colour bar at the right edge of the view
  const float x1 = static_cast<float>(vp.x + vp.width) - 24.0f, x0 = x1 - 16.0f;
  const float y0 = static_cast<float>(vp.y) + 40.0f, y1 = static_cast<float>(vp.y + vp.height) - 40.0f;
  if (view.colour_by != ColourBy::LOD_BAND && y1 > y0 + 40) {
    const bool stress = view.colour_by == ColourBy::VON_MISES;
    constexpr int steps = 32;
    for (int s = 0; s < steps; ++s) {
      const float a = y1 - (y1 - y0) * static_cast<float>(s) / steps,
                  b = y1 - (y1 - y0) * static_cast<float>(s + 1) / steps;
      draw->AddRectFilled(ImVec2(x0, b), ImVec2(x1, a), pack_rgba(viridis((s + 0.5) / steps)));
    }
    draw->AddRect(ImVec2(x0, y0), ImVec2(x1, y1), IM_COL32(200, 200, 205, 255));
    const std::string top =
        stress ? fmt::format("{:.3g} kPa", 1e-3 * view.stress_max) : fmt::format("{:.3g} mm", 1e3 * view.scale_max);
    const float w = ImGui::CalcTextSize(top.c_str()).x;
    draw->AddText(ImVec2(x1 - w, y0 - 20), text, top.c_str());
    draw->AddText(ImVec2(x1 - ImGui::CalcTextSize("0").x, y1 + 4), text, "0");
    const char* label = stress ? "von Mises" : "|u|";
    draw->AddText(ImVec2(x0 - 4 - ImGui::CalcTextSize(label).x, 0.5f * (y0 + y1)), text, label);
  } else if (view.colour_by == ColourBy::LOD_BAND && y1 > y0 + 40) {
    const char* names[] = {"T_r1", "T_r2", "level 1", "level 2", "level 3", "level 4+", "not simulated"};
    for (int b = 0; b < 7; ++b) {
      const float y = y0 + 22.0f * static_cast<float>(b);
      const Rgb c = band_colour(b < 6 ? b : -1);
      draw->AddRectFilled(ImVec2(x1 - 14, y), ImVec2(x1, y + 14), pack_rgba(c));
      draw->AddText(ImVec2(x1 - 20 - ImGui::CalcTextSize(names[b]).x, y), text, names[b]);
    }
  }
  // a drop line from the probe to the level of the object's base: where it is in depth, at a glance
  if (f.probe.allFinite()) {
    const Eigen::Vector2d top = view.camera.project(f.probe, vp);
    const Eigen::Vector2d foot = view.camera.project(Vec3(f.probe.x(), p.lo.y(), f.probe.z()), vp);
    if (top.allFinite() && foot.allFinite()) {
      const ImU32 line = IM_COL32(230, 230, 235, 90);
      draw->AddLine(ImVec2(static_cast<float>(top.x()), static_cast<float>(top.y())),
                    ImVec2(static_cast<float>(foot.x()), static_cast<float>(foot.y())), line, 1.0f);
      draw->AddCircle(ImVec2(static_cast<float>(foot.x()), static_cast<float>(foot.y())), 4.0f, line);
    }
  }
  const std::string caption = fmt::format("t = {:.2f} s   |F| = {:.2f} N   {} contacts   {} of {} points simulated",
                                          f.time, f.force.norm(), f.contacts, f.simulated, p.reference.cols());
  draw->AddText(ImVec2(static_cast<float>(vp.x) + 12, static_cast<float>(vp.y) + 10), text, caption.c_str());
}

void write_frame_info(const std::string& path, const Prepared& p, const DisplayFrame& f, const SceneView& view,
                      const Viewport& vp, int fb_width, int fb_height, double haptic_rate_hz) {
  using nlohmann::json;
  const auto vec = [](const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); };
  const OrbitCamera& c = view.camera;
  json j;
  j["image"] = {{"width", fb_width}, {"height", fb_height}};
  j["viewport"] = {vp.x, vp.y, vp.width, vp.height};
  j["camera"] = {{"eye", vec(c.eye())}, {"target", vec(c.target)}, {"up", vec(c.up())},
                 {"fov_y", c.fov_y},    {"near", c.near_plane()},  {"far", c.far_plane()}};
  j["probe"] = {{"position", f.probe.allFinite() ? vec(f.probe) : json(nullptr)},
                {"radius", p.options.probe.radius},
                {"colour", probe_colour_of(view)}};
  j["points"] = p.reference.cols();
  j["point_radius"] = p.point_radius * view.point_scale;
  const Points x = p.reference + (f.u.cols() == p.reference.cols() ? f.u : Points::Zero(3, p.reference.cols()));
  j["object"] = {{"min", vec(x.rowwise().minCoeff())}, {"max", vec(x.rowwise().maxCoeff())}};
  json samples = json::array();  // a few deformed points, for tests to project
  const Eigen::Index stride = std::max<Eigen::Index>(1, x.cols() / 300);
  for (Eigen::Index i = 0; i < x.cols(); i += stride) samples.push_back(vec(x.col(i)));
  j["sample_points"] = std::move(samples);
  // the drawn surface: its triangles, and a few deformed vertices for tests to project
  j["surface"] = {{"drawn", !view.surface_vertices.empty()},
                  {"triangles", view.surface_indices.size() / 3},
                  {"cut_faces", p.drawn_surface() ? p.drawn_surface()->cut_faces : 0}};
  json surface_samples = json::array();
  const std::size_t vertex_stride = std::max<std::size_t>(1, view.surface_vertices.size() / 300);
  for (std::size_t v = 0; v < view.surface_vertices.size(); v += vertex_stride) {
    const SurfaceVertex& s = view.surface_vertices[v];
    surface_samples.push_back({s.x, s.y, s.z});
  }
  j["surface"]["sample_vertices"] = std::move(surface_samples);
  j["displacement_max"] = f.u.cols() ? f.u.colwise().norm().maxCoeff() : 0.0;
  j["colour_scale_max"] = view.scale_max;
  j["time"] = f.time;
  j["steps"] = f.step;
  j["contacts"] = f.contacts;
  j["force"] = vec(f.force);
  j["haptic_rate_hz"] = haptic_rate_hz;
  std::ofstream out(path);
  if (!out) throw Error(fmt::format("{}: cannot write the frame info", path));
  out << j.dump(2) << '\n';
}

}  // namespace pointhaptics::viewer
