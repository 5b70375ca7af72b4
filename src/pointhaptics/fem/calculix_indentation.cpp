#include <pointhaptics/fem/calculix_indentation.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/fem/calculix.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
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
  out += material_card("TISSUE", constants);
  out += fmt::format("*MATERIAL, NAME=RIGID\n*ELASTIC\n{:.13g}, 0.3\n", 1e4 * p.material.young);
  out += "*SOLID SECTION, ELSET=BLOCK, MATERIAL=TISSUE\n*SOLID SECTION, ELSET=SPHERE, MATERIAL=RIGID\n";
  // frictionless: no *FRICTION card
  out += fmt::format(
      "*SURFACE INTERACTION, NAME=FRICTIONLESS\n*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{:.13g}\n"
      "*CONTACT PAIR, INTERACTION=FRICTIONLESS, TYPE=SURFACE TO SURFACE\nSTOP, SBALL\n",
      penalty);
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
  IndentationPoint before{0, 0};
  for (const IndentationPoint& point : curve) {
    if (point.depth >= depth * (1 - 1e-9)) {
      const double span = point.depth - before.depth;
      return span <= 0 ? point.force : before.force + (point.force - before.force) * (depth - before.depth) / span;
    }
    before = point;
  }
  return curve.back().force;
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

}  // namespace pointhaptics::fem
