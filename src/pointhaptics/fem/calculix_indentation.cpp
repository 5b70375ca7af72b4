#include <pointhaptics/fem/calculix_indentation.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/fem/calculix.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>

namespace pointhaptics::fem {
namespace {

// Element edges from 0 to `total`: `fine` covered by elements of size h, then each element 1.4 times the last
// (the last one takes what is left, so no sliver remains).
std::vector<double> graded(double fine, double total, double h) {
  std::vector<double> x{0.0};
  while (x.back() < std::min(fine, total) - 1e-9 * h) x.push_back(std::min(x.back() + h, total));
  double size = h;
  while (x.back() < total - 1e-9 * h) {
    size *= 1.4;
    x.push_back(x.back() + size * 1.5 > total ? total : x.back() + size);
  }
  return x;
}

// edges -> the half-step positions of a quadratic mesh's nodes (corners and mid-sides)
std::vector<double> half_steps(const std::vector<double>& edges) {
  std::vector<double> out;
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
    out.push_back(edges[k]);
    out.push_back(0.5 * (edges[k] + edges[k + 1]));
  }
  out.push_back(edges.back());
  return out;
}

// A CAX8 element's card from its corners and mid-sides as laid out in a grid (k0 -> k1 -> k2 -> k3 around, m01
// between k0 and k1, ...), turned counter-clockwise in (r, y) as ccx wants it; `faces` receives the element's
// face numbers whose both corners satisfy `on_surface` (S1: corners 1-2, S2: 2-3, S3: 3-4, S4: 4-1).
template <class OnSurface>
std::string cax8(int element, std::array<int, 8> n, const std::vector<Vec3>& where, const OnSurface& on_surface,
                 std::vector<std::pair<int, int>>* faces) {
  const auto at = [&](int id) { return where[static_cast<std::size_t>(id - 1)]; };
  double area = 0;
  for (int k = 0; k < 4; ++k) area += at(n[k]).x() * at(n[(k + 1) % 4]).y() - at(n[(k + 1) % 4]).x() * at(n[k]).y();
  if (area < 0) n = {n[0], n[3], n[2], n[1], n[7], n[6], n[5], n[4]};
  if (faces)
    for (int k = 0; k < 4; ++k)
      if (on_surface(at(n[k])) && on_surface(at(n[(k + 1) % 4])) && on_surface(at(n[4 + k])))
        faces->push_back({element, k + 1});
  return fmt::format("{}, {}, {}, {}, {}, {}, {}, {}, {}\n", element, n[0], n[1], n[2], n[3], n[4], n[5], n[6], n[7]);
}

// The force at `x` along a curve of points from (0, 0) in increasing `abscissa` (a member of Point), linear between
// them and exact at them; the caller has checked that x lies within it.
template <class Point>
double force_along(const std::vector<Point>& curve, double x, double Point::*abscissa) {
  double x0 = 0, f0 = 0;
  for (const Point& point : curve) {
    const double xp = point.*abscissa;
    if (xp >= x * (1 - 1e-9)) return xp - x0 <= 0 ? point.force : f0 + (point.force - f0) * (x - x0) / (xp - x0);
    x0 = xp;
    f0 = point.force;
  }
  return curve.back().force;
}

// The two bodies' cards: element set `tissue` of the material's constants, `rigid` linear and 10^4 times stiffer
// than `young`, and frictionless penalty contact (no *FRICTION card) of surface `dependent` against `independent`.
std::string tissue_and_rigid_in_contact(const BoxProblem& constants, double young, const char* tissue,
                                        const char* rigid, const char* dependent, const char* independent,
                                        double penalty) {
  std::string out = material_card("TISSUE", constants);
  out += fmt::format("*MATERIAL, NAME=RIGID\n*ELASTIC\n{:.13g}, 0.3\n", 1e4 * young);
  out += fmt::format("*SOLID SECTION, ELSET={}, MATERIAL=TISSUE\n*SOLID SECTION, ELSET={}, MATERIAL=RIGID\n", tissue,
                     rigid);
  out += fmt::format(
      "*SURFACE INTERACTION, NAME=FRICTIONLESS\n*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{:.13g}\n"
      "*CONTACT PAIR, INTERACTION=FRICTIONLESS, TYPE=SURFACE TO SURFACE\n{}, {}\n",
      penalty, dependent, independent);
  return out;
}

void write_ids(std::string& out, const std::vector<int>& ids) {
  for (std::size_t k = 0; k < ids.size(); ++k)
    out += fmt::format("{}{}", ids[k], (k + 1) % 16 == 0 || k + 1 == ids.size() ? ",\n" : ", ");
}

}  // namespace

std::string write_indentation_inp(const IndentationProblem& p, int* node_count, int* element_count) {
  const double R = p.sphere_radius;
  if (!(R > 0) || !(p.block_radius > 0) || !(p.height > 0) || p.elements_per_radius < 2 || p.increments < 1)
    throw Error("CalculiX indentation: sizes, elements per radius (>= 2) and increments must be positive");
  if (!(p.max_depth > 0) || p.max_depth >= 0.5 * R)
    throw Error(fmt::format("CalculiX indentation: depth {} m must be in (0, R/2)", p.max_depth));
  BoxProblem constants;  // the constitutive card's mapping, shared with the box models
  set_material(constants, p.material);
  const double h = R / p.elements_per_radius;
  // the fine zone holds the contact (radius about sqrt(R d), more with large strains) with room to spare
  const double fine_radius = std::min(p.block_radius, std::max(0.8 * R, 1.5 * std::sqrt(R * p.max_depth)));
  const std::vector<double> r = half_steps(graded(fine_radius, p.block_radius, h));
  std::vector<double> from_top = graded(0.6 * R, p.height, h), y_edges;
  for (auto it = from_top.rbegin(); it != from_top.rend(); ++it) y_edges.push_back(p.height - *it);
  const std::vector<double> y = half_steps(y_edges);
  const int nr = static_cast<int>(r.size() / 2), ny = static_cast<int>(y.size() / 2);

  std::string nodes_text, block_text, sphere_text;
  std::vector<int> bottom, axis, moved, top_faces, sphere_faces;
  int next = 1;
  // the block: a node where at most one half-step index is odd
  std::vector<int> id(r.size() * y.size(), 0);
  auto at = [&](std::size_t a, std::size_t b) { return id[b * r.size() + a]; };
  for (std::size_t b = 0; b < y.size(); ++b)
    for (std::size_t a = 0; a < r.size(); ++a) {
      if (a % 2 == 1 && b % 2 == 1) continue;
      id[b * r.size() + a] = next;
      nodes_text += fmt::format("{}, {:.13g}, {:.13g}, 0\n", next, r[a], y[b]);
      if (b == 0) bottom.push_back(next);
      else if (a == 0) axis.push_back(next);
      ++next;
    }
  int element = 1;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nr; ++i, ++element) {
      const std::size_t a = 2 * static_cast<std::size_t>(i), b = 2 * static_cast<std::size_t>(j);
      // CAX8: corners counter-clockwise in (r, y), then the mid-sides 1-2, 2-3, 3-4, 4-1
      block_text +=
          fmt::format("{}, {}, {}, {}, {}, {}, {}, {}, {}\n", element, at(a, b), at(a + 2, b), at(a + 2, b + 2),
                      at(a, b + 2), at(a + 1, b), at(a + 2, b + 1), at(a + 1, b + 2), at(a, b + 1));
      if (j == ny - 1 && r[a] < fine_radius - 1e-9 * h) top_faces.push_back(element);  // face 3-4 is the top
    }
  // the sphere: one layer of thickness h from its lowest point up to the fine zone's radius, touching the top
  // face at the start; its inner nodes are the ones moved
  const double arc = std::asin(std::min(1.0, (fine_radius + h) / R));
  const int n_arc = std::max(8, static_cast<int>(std::ceil(arc * R / h)));
  const double centre = p.height + R, radii[3] = {R - h, R - 0.5 * h, R};
  std::vector<int> sid(3 * (2 * static_cast<std::size_t>(n_arc) + 1), 0);
  auto sat = [&](int rho, int q) { return sid[static_cast<std::size_t>(q) * 3 + static_cast<std::size_t>(rho)]; };
  for (int q = 0; q <= 2 * n_arc; ++q)
    for (int rho = 0; rho < 3; ++rho) {
      if (rho == 1 && q % 2 == 1) continue;
      const double theta = -0.5 * std::numbers::pi + arc * q / (2.0 * n_arc);
      const double x = q == 0 ? 0.0 : radii[rho] * std::cos(theta);
      sid[static_cast<std::size_t>(q) * 3 + static_cast<std::size_t>(rho)] = next;
      nodes_text += fmt::format("{}, {:.13g}, {:.13g}, 0\n", next, x, centre + radii[rho] * std::sin(theta));
      if (rho == 0) moved.push_back(next);
      else if (q == 0) axis.push_back(next);
      ++next;
    }
  for (int k = 0; k < n_arc; ++k, ++element) {
    const int q = 2 * k;
    sphere_text += fmt::format("{}, {}, {}, {}, {}, {}, {}, {}, {}\n", element, sat(0, q), sat(2, q), sat(2, q + 2),
                               sat(0, q + 2), sat(1, q), sat(2, q + 1), sat(1, q + 2), sat(0, q + 1));
    sphere_faces.push_back(element);  // face 2-3 is the outer surface
  }
  if (node_count) *node_count = next - 1;
  if (element_count) *element_count = element - 1;

  const double penalty = p.penalty > 0 ? p.penalty : 100 * p.material.young / h;
  std::string out = fmt::format(
      "** PointHaptics: a rigid sphere (R = {} m) pressed into a cylinder, axisymmetric\n*HEADING\n"
      "PointHaptics indentation\n*NODE, NSET=NALL\n{}",
      R, nodes_text);
  out += "*ELEMENT, TYPE=CAX8, ELSET=BLOCK\n" + block_text + "*ELEMENT, TYPE=CAX8, ELSET=SPHERE\n" + sphere_text;
  out += "*NSET, NSET=NBOTTOM\n";
  write_ids(out, bottom);
  out += "*NSET, NSET=NAXIS\n";
  write_ids(out, axis);
  out += "*NSET, NSET=NMOVE\n";
  write_ids(out, moved);
  out += "*SURFACE, NAME=STOP, TYPE=ELEMENT\n";
  for (int e : top_faces) out += fmt::format("{}, S3\n", e);
  out += "*SURFACE, NAME=SBALL, TYPE=ELEMENT\n";
  for (int e : sphere_faces) out += fmt::format("{}, S2\n", e);
  out += tissue_and_rigid_in_contact(constants, p.material.young, "BLOCK", "SPHERE", "STOP", "SBALL", penalty);
  out += "*BOUNDARY\nNBOTTOM, 1, 2, 0\nNAXIS, 1, 1, 0\n";
  out += fmt::format(
      "*STEP{}, INC=1000\n*STATIC, DIRECT\n{:.13g}, 1\n*BOUNDARY\nNMOVE, 1, 1, 0\nNMOVE, 2, 2, {:.13g}\n"
      "*NODE PRINT, NSET=NMOVE, TOTALS=ONLY\nRF\n*END STEP\n",
      p.nlgeom ? ", NLGEOM" : "", 1.0 / p.increments, -p.max_depth);
  return out;
}

double IndentationSolution::force_at(double depth) const {
  if (curve.empty() || depth < 0 || depth > curve.back().depth * (1 + 1e-9))
    throw Error(fmt::format("CalculiX indentation: no force at depth {} m (the curve ends at {} m)", depth,
                            curve.empty() ? 0.0 : curve.back().depth));
  return force_along(curve, depth, &IndentationPoint::depth);
}

IndentationSolution solve_indentation(const IndentationProblem& problem, int threads) {
  IndentationSolution solution;
  const CcxRun run = run_ccx(write_indentation_inp(problem, &solution.nodes, &solution.elements), threads);
  solution.wall_s = run.wall_s;
  if (run.status != 0) throw run.failure(fmt::format("ccx exited with status {}", run.status));
  std::ifstream dat(run.dir / "job.dat");
  std::vector<Reaction> totals;
  try {
    totals = read_dat_totals(dat, "NMOVE", (run.dir / "job.dat").string());
  } catch (const Error& e) {
    throw run.failure(e.what());
  }
  // ccx may cut an increment that does not converge (then more are printed): every one is a point of the curve
  if (totals.empty() || std::abs(totals.back().time - 1) > 1e-6)
    throw run.failure(fmt::format("the step stopped at {} of its depth", totals.empty() ? 0.0 : totals.back().time));
  // an axisymmetric model's reactions are those of a 2 degree segment: the ring's is 180 times that
  for (const Reaction& t : totals) solution.curve.push_back({t.time * problem.max_depth, -180.0 * t.force.y()});
  run.remove();
  return solution;
}

namespace {

// Nodes merged by position (blocks of a structured mesh share their edges' nodes).
class MergedNodes {
 public:
  explicit MergedNodes(double quantum) : quantum_(quantum) {}
  int at(double r, double y) {
    const auto key = std::pair{std::llround(r / quantum_), std::llround(y / quantum_)};
    const auto [it, added] = ids_.try_emplace(key, static_cast<int>(where.size()) + 1);
    if (added) where.emplace_back(r, y, 0.0);
    return it->second;
  }
  /// A node of its own, never merged (another body's node at the same place).
  int separate(double r, double y) {
    where.emplace_back(r, y, 0.0);
    return static_cast<int>(where.size());
  }
  std::vector<Vec3> where;  ///< node id k + 1 at where[k]

 private:
  double quantum_;
  std::map<std::pair<long long, long long>, int> ids_;
};

}  // namespace

std::string write_sphere_on_plane_inp(const SphereOnPlaneProblem& p, int* node_count, int* element_count) {
  const double R = p.radius;
  if (!(R > 0) || p.elements_per_radius < 4 || p.increments < 1)
    throw Error("CalculiX sphere on a plane: the radius, elements per radius (>= 4) and increments must be positive");
  if (!(p.cap_from > 0) || !(p.cap_from < R))
    throw Error(
        fmt::format("CalculiX sphere on a plane: the cap from y = {} m must cut the sphere's upper half", p.cap_from));
  if (!(p.max_travel > 0) || p.max_travel > 0.25 * R)
    throw Error(fmt::format("CalculiX sphere on a plane: travel {} m must be in (0, R/4]", p.max_travel));
  BoxProblem constants;
  set_material(constants, p.material);
  const double h = R / p.elements_per_radius, a = 0.5 * R, quarter = 0.25 * std::numbers::pi;
  // the core's r edges, fine where the bottom block's arc (pi/4 R long over r in [0, a]) holds the contact
  const std::vector<double> rs = half_steps(graded(0.6 * a, a, h * a / (quarter * R)));
  // the core's y edges, fine near its bottom (R - a from the contact) and mirrored above, with a node at y = 0
  std::vector<double> y_edges;
  for (double e : graded(0.5 * a, a, 1.5 * h)) y_edges.push_back(-a + e);
  for (std::size_t k = y_edges.size() - 1; k-- > 0;) y_edges.push_back(-y_edges[k]);
  const std::vector<double> ys = half_steps(y_edges);
  // the outer blocks' radial parameter, 0 on the core and 1 on the circle, fine near the circle
  std::vector<double> t_edges;
  for (double e : graded(0.5, 1.0, h / (R - a))) t_edges.insert(t_edges.begin(), 1.0 - e);
  const std::vector<double> ts = half_steps(t_edges);

  MergedNodes nodes(1e-7 * R);
  std::string sphere_text, plane_text;
  std::vector<std::pair<int, int>> ball_faces, plane_faces;
  int element = 1;
  const auto on_circle = [&](const Vec3& x) { return std::abs(x.norm() - R) < 1e-6 * R && x.y() < -0.5 * R; };
  // a block: positions on a grid of half steps (i across, j along), CAX8 elements on its even nodes
  const auto block = [&](std::size_t ni, std::size_t nj, const auto& position, std::string& text, const auto& surface,
                         auto* faces) {
    std::vector<int> id(ni * nj);
    for (std::size_t j = 0; j < nj; ++j)
      for (std::size_t i = 0; i < ni; ++i) {
        if (i % 2 == 1 && j % 2 == 1) continue;
        const Vec3 x = position(i, j);
        id[j * ni + i] = nodes.at(x.x(), x.y());
      }
    const auto g = [&](std::size_t i, std::size_t j) { return id[j * ni + i]; };
    for (std::size_t j = 0; j + 2 < nj + 1; j += 2)
      for (std::size_t i = 0; i + 2 < ni + 1; i += 2, ++element)
        text += cax8(element,
                     {g(i, j), g(i + 2, j), g(i + 2, j + 2), g(i, j + 2), g(i + 1, j), g(i + 2, j + 1), g(i + 1, j + 2),
                      g(i, j + 1)},
                     nodes.where, surface, faces);
  };
  const auto arc = [&](double theta) { return Vec3(R * std::cos(theta), R * std::sin(theta), 0); };
  const auto blend = [&](const Vec3& edge, double theta, double t) { return Vec3((1 - t) * edge + t * arc(theta)); };
  block(
      rs.size(), ys.size(), [&](std::size_t i, std::size_t j) { return Vec3(rs[i], ys[j], 0); }, sphere_text, on_circle,
      &ball_faces);
  block(
      rs.size(), ts.size(),  // below the core, out to the arc from -90 to -45 degrees
      [&](std::size_t i, std::size_t j) {
        return blend(Vec3(rs[i], -a, 0), -2 * quarter + rs[i] / a * quarter, ts[j]);
      },
      sphere_text, on_circle, &ball_faces);
  block(
      ys.size(), ts.size(),  // beside it, from -45 to 45 degrees
      [&](std::size_t i, std::size_t j) {
        return blend(Vec3(a, ys[i], 0), -quarter + (ys[i] + a) / (2 * a) * 2 * quarter, ts[j]);
      },
      sphere_text, on_circle, &ball_faces);
  block(
      rs.size(), ts.size(),  // above it, from 90 down to 45 degrees
      [&](std::size_t i, std::size_t j) { return blend(Vec3(rs[i], a, 0), 2 * quarter - rs[i] / a * quarter, ts[j]); },
      sphere_text, on_circle, &ball_faces);
  const int sphere_nodes = static_cast<int>(nodes.where.size());
  // the plane: one layer 0.1 R thick and 0.6 R wide (past the contact's radius, sqrt(R travel) plus room) below the
  // lowest point, its nodes its own
  const double width = 0.6 * R, thickness = 0.1 * R;
  const std::vector<double> px = half_steps(graded(width, width, h));
  std::vector<int> plane_bottom, plane_axis;
  {
    std::vector<int> id(px.size() * 3);
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t i = 0; i < px.size(); ++i) {
        if (i % 2 == 1 && j == 1) continue;
        const int n = nodes.separate(px[i], -R - thickness * (1 - 0.5 * static_cast<double>(j)));
        id[j * px.size() + i] = n;
        if (j == 0) plane_bottom.push_back(n);
        else if (i == 0) plane_axis.push_back(n);
      }
    const auto g = [&](std::size_t i, std::size_t j) { return id[j * px.size() + i]; };
    const auto on_top = [&](const Vec3& x) { return std::abs(x.y() + R) < 1e-9 * R; };
    for (std::size_t i = 0; i + 2 < px.size() + 1; i += 2, ++element)
      plane_text +=
          cax8(element, {g(i, 0), g(i + 2, 0), g(i + 2, 2), g(i, 2), g(i + 1, 0), g(i + 2, 1), g(i + 1, 2), g(i, 1)},
               nodes.where, on_top, &plane_faces);
  }
  std::string nodes_text;
  std::vector<int> axis, cap, centre;
  for (int k = 0; k < static_cast<int>(nodes.where.size()); ++k) {
    const Vec3& x = nodes.where[static_cast<std::size_t>(k)];
    nodes_text += fmt::format("{}, {:.13g}, {:.13g}, 0\n", k + 1, x.x(), x.y());
    if (k >= sphere_nodes) continue;
    if (x.y() >= p.cap_from) cap.push_back(k + 1);
    else if (x.x() < 1e-9 * R) axis.push_back(k + 1);
    if (x.norm() < 1e-9 * R) centre.push_back(k + 1);
  }
  if (centre.size() != 1 || cap.empty())
    throw Error("CalculiX sphere on a plane: the mesh has no node at the centre or none in the cap (a bug)");
  if (node_count) *node_count = static_cast<int>(nodes.where.size());
  if (element_count) *element_count = element - 1;

  const double penalty = p.penalty > 0 ? p.penalty : 100 * p.material.young / h;
  std::string out = fmt::format(
      "** PointHaptics: an elastic sphere (R = {} m) held at its cap pressed onto a rigid plane, axisymmetric\n"
      "*HEADING\nPointHaptics sphere on a plane\n*NODE, NSET=NALL\n{}",
      R, nodes_text);
  out += "*ELEMENT, TYPE=CAX8, ELSET=SPHERE\n" + sphere_text + "*ELEMENT, TYPE=CAX8, ELSET=PLANE\n" + plane_text;
  const std::pair<const char*, const std::vector<int>*> sets[] = {{"NAXIS", &axis},
                                                                  {"NMOVE", &cap},
                                                                  {"NCENTRE", &centre},
                                                                  {"NPLANEBOTTOM", &plane_bottom},
                                                                  {"NPLANEAXIS", &plane_axis}};
  for (const auto& [name, ids] : sets) {
    out += fmt::format("*NSET, NSET={}\n", name);
    write_ids(out, *ids);
  }
  out += "*SURFACE, NAME=SBALL, TYPE=ELEMENT\n";
  for (const auto& [e, face] : ball_faces) out += fmt::format("{}, S{}\n", e, face);
  out += "*SURFACE, NAME=SPLANE, TYPE=ELEMENT\n";
  for (const auto& [e, face] : plane_faces) out += fmt::format("{}, S{}\n", e, face);
  out += tissue_and_rigid_in_contact(constants, p.material.young, "SPHERE", "PLANE", "SBALL", "SPLANE", penalty);
  out += "*BOUNDARY\nNPLANEBOTTOM, 1, 2, 0\nNPLANEAXIS, 1, 1, 0\nNAXIS, 1, 1, 0\n";
  out += fmt::format(
      "*STEP, NLGEOM, INC=1000\n*STATIC, DIRECT\n{:.13g}, 1\n*BOUNDARY\nNMOVE, 1, 1, 0\nNMOVE, 2, 2, {:.13g}\n"
      "*NODE PRINT, NSET=NMOVE, TOTALS=ONLY\nRF\n*NODE PRINT, NSET=NCENTRE\nU\n*END STEP\n",
      1.0 / p.increments, -p.max_travel);
  return out;
}

double SphereOnPlaneSolution::force_at_cap(double cap_travel) const {
  if (curve.empty() || cap_travel < 0 || cap_travel > curve.back().cap_travel * (1 + 1e-9))
    throw Error(fmt::format("CalculiX sphere on a plane: no force at a cap's travel of {} m (the curve ends at {} m)",
                            cap_travel, curve.empty() ? 0.0 : curve.back().cap_travel));
  return force_along(curve, cap_travel, &SphereOnPlanePoint::cap_travel);
}

SphereOnPlaneSolution solve_sphere_on_plane(const SphereOnPlaneProblem& problem, int threads) {
  SphereOnPlaneSolution solution;
  const CcxRun run = run_ccx(write_sphere_on_plane_inp(problem, &solution.nodes, &solution.elements), threads);
  solution.wall_s = run.wall_s;
  if (run.status != 0) throw run.failure(fmt::format("ccx exited with status {}", run.status));
  const std::string dat_path = (run.dir / "job.dat").string();
  std::vector<Reaction> totals;
  std::vector<std::pair<double, Vec3>> centre;
  try {
    std::ifstream dat(dat_path);
    totals = read_dat_totals(dat, "NMOVE", dat_path);
    std::ifstream again(dat_path);
    centre = read_dat_set_displacements(again, "NCENTRE", dat_path);
  } catch (const Error& e) {
    throw run.failure(e.what());
  }
  if (totals.empty() || std::abs(totals.back().time - 1) > 1e-6 || centre.size() != totals.size())
    throw run.failure(fmt::format("the step stopped at {} of its travel", totals.empty() ? 0.0 : totals.back().time));
  // an axisymmetric model's reactions are those of a 2 degree segment: the ring's is 180 times that
  for (std::size_t k = 0; k < totals.size(); ++k)
    solution.curve.push_back(
        {totals[k].time * problem.max_travel, -centre[k].second.y(), -180.0 * totals[k].force.y()});
  run.remove();
  return solution;
}

}  // namespace pointhaptics::fem
