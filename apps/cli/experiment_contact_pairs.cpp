#include "experiment_contact_pairs.hpp"

#include "plots.hpp"

#include <pointhaptics/fem/calculix_indentation.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace pointhaptics::experiments {

namespace {

constexpr double g = 9.81;

/// One quantity a contact pair must give, against what statics says it is.
struct Check {
  std::string pair, quantity;
  double measured = 0, expected = 0;
  double tolerance = 0;  ///< on the relative error (|measured - expected| / |expected|); 0: a yes-or-no check
  bool holds = false;
  double relative_error() const { return expected != 0 ? std::abs(measured - expected) / std::abs(expected) : 0.0; }
};

Check within(std::string pair, std::string quantity, double measured, double expected, double tolerance) {
  Check c{std::move(pair), std::move(quantity), measured, expected, tolerance, false};
  c.holds = std::isfinite(measured) && c.relative_error() <= tolerance;
  return c;
}
Check yes(std::string pair, std::string quantity, bool holds) {
  return Check{std::move(pair), std::move(quantity), holds ? 1.0 : 0.0, 1.0, 0.0, holds};
}

SceneSession open(const std::string& text, const std::string& name, int threads) {
  SessionOptions options;
  options.threads = threads;
  return open_scene(parse_scene(text, name), options);
}

const ToolSummary& named(const std::vector<std::pair<std::string, ToolSummary>>& loads, const std::string& name) {
  for (const auto& [n, t] : loads)
    if (n == name) return t;
  throw Error(fmt::format("experiment contact-pairs: nothing named \"{}\" in the summary", name));
}

const std::string table =
    "[[obstacle]]\nname = \"table\"\nplane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }\nfriction = 0.5\n";

// a soft block (4 x 2 x 4 cm, E = 100 kPa) resting on a table, static: the table carries its weight
void block_on_table(std::vector<Check>& checks, int threads) {
  SceneSession s = open(
      "[object]\nshape = \"box\"\nsize = [0.04, 0.02, 0.04]\nspacing = 0.005\n[material]\nyoung = 1e5\npoisson = "
      "0.3\ndensity = 1000.0\n[solver]\nkind = \"static\"\n[[load]]\nkind = \"gravity\"\n" +
          table,
      "block-on-table", threads);
  s.simulation->step();
  const RunSummary r = s.simulation->summary();
  const double weight = 0.04 * 0.02 * 0.04 * 1000.0 * g;
  checks.push_back(yes("body-table", "static solve converged", r.converged));
  checks.push_back(
      within("body-table", "table's support / weight", -named(r.obstacles, "table").force.y(), weight, 0.005));
}

// a block (2 x 2 x 2 cm, E = 200 kPa, 16 g) on a block (4 x 2 x 4 cm, E = 100 kPa, 32 g) on a table, both free
// (nothing held: contact and friction alone), solved statically and run to rest in implicit dynamics (0.5 s): the
// lower one carries the upper's weight, the table both
void block_on_block(std::vector<Check>& checks, int threads) {
  for (const bool statics : {true, false}) {
    SceneSession s = open(
        "[material]\nyoung = 1e5\npoisson = 0.3\ndensity = 1000.0\ndamping = 20.0\n"
        "[[object]]\nname = \"lower\"\nshape = \"box\"\nsize = [0.04, 0.02, 0.04]\nspacing = 0.005\n"
        "[[object]]\nname = \"upper\"\nshape = \"box\"\nsize = [0.02, 0.02, 0.02]\norigin = [0.01, 0.02, "
        "0.01]\nspacing = 0.005\nmaterial = { young = 2e5, density = 2000.0 }\n"
        "[contact]\nfriction = 0.5\n[solver]\n" +
            std::string(statics ? "kind = \"static\"" : "kind = \"implicit\"\ndt = 2e-3") +
            "\n[[load]]\nkind = \"gravity\"\n" + table,
        "block-on-block", threads);
    s.simulation->run(statics ? 0.0 : 0.5);
    const RunSummary r = s.simulation->summary();
    const std::string how = statics ? "stacked blocks, static" : "stacked blocks, implicit to rest";
    checks.push_back(yes("body-body", how + (statics ? ": converged" : ": every step converged"), r.converged));
    double upper = 0, total = 0;
    Vec3 on_upper = Vec3::Zero();
    for (const BodySummary& b : r.bodies) {
      total += b.mass * g;
      if (b.name == "upper") upper = b.mass * g, on_upper = b.contact_force;
    }
    checks.push_back(
        within("body-body", how + ": lower block's support of the upper / its weight", on_upper.y(), upper, 0.005));
    checks.push_back(within("body-table", how + ": table's support of both / their weight",
                            -named(r.obstacles, "table").force.y(), total, 0.005));
  }
}

// a vertical jaw (a capsule of 5 mm radius, axis along y) pressing 1 mm into the face x = 0 or x = 0.02 of a 2 cm
// sample
std::string jaw(const std::string& name, double mu, const std::string& where, double length) {
  return fmt::format(
      "[[tool]]\nname = \"{}\"\nshape = \"capsule\"\nradius = 0.005\nlength = {}\norientation = "
      "[0.7071067811865476, -0.7071067811865476, 0.0, 0.0]\nfriction = {}\n{}\n",
      name, length, mu, where);
}
std::string sample(const std::string& solver, const std::string& more) {
  return "[object]\nshape = \"box\"\nsize = [0.02, 0.02, 0.02]\nspacing = 0.0025\n[material]\nyoung = "
         "5e4\npoisson = 0.3\ndensity = 1000.0\ndamping = 0.05\n[solver]\n" +
         solver + "\n[[load]]\nkind = \"gravity\"\n" + more;
}

// two jaws pinch a free 2 cm sample (8 g) 1 mm deep, static: friction carries its weight, half on each, their
// pressures equal and opposite; below W / (2 N) it slips (no equilibrium), above it holds
void pinch(std::vector<Check>& checks, int threads) {
  const double weight = 0.02 * 0.02 * 0.02 * 1000.0 * g;
  const auto solve = [&](double mu) {
    SceneSession s = open(
        sample("kind = \"static\"\nmax_iterations = 15", jaw("left", mu, "position = [-0.004, 0.01, 0.01]", 0.04) +
                                                             jaw("right", mu, "position = [0.024, 0.01, 0.01]", 0.04)),
        "pinch", threads);
    s.simulation->step();
    return s.simulation->summary();
  };
  const RunSummary held = solve(0.5);
  const ToolSummary &left = named(held.tools, "left"), &right = named(held.tools, "right");
  checks.push_back(yes("tool-body", "pinched sample: static solve converged", held.converged));
  checks.push_back(
      within("tool-body", "the jaws' lift / the sample's weight", -(left.force.y() + right.force.y()), weight, 0.005));
  checks.push_back(within("tool-body", "left jaw's lift / half the weight", -left.force.y(), 0.5 * weight, 0.005));
  checks.push_back(within("tool-body", "left jaw's pressure / the right's", -left.force.x(), right.force.x(), 1e-6));
  const double threshold = weight / (2 * right.force.x());
  const RunSummary below = solve(0.95 * threshold), above = solve(1.05 * threshold);
  checks.push_back(yes("tool-body",
                       fmt::format("slips at mu = 0.95 W / 2N = {:.4f} (no equilibrium)", 0.95 * threshold),
                       !below.converged && below.failure.find("no equilibrium") != std::string::npos));
  checks.push_back(
      yes("tool-body", fmt::format("holds at mu = 1.05 W / 2N = {:.4f}", 1.05 * threshold), above.converged));
}

// two jaws close 1 mm into a sample on a table over 0.1 s, lift it 1 cm over 0.2 s and hold it (implicit, 0.4 s)
void lift(std::vector<Check>& checks, int threads) {
  const double weight = 0.02 * 0.02 * 0.02 * 1000.0 * g;
  const auto path = [](double x0, double x1) {
    return fmt::format("keyframes = [[0.0, {0}, 0.0125, 0.01], [0.1, {1}, 0.0125, 0.01], [0.3, {1}, 0.0225, 0.01]]", x0,
                       x1);
  };
  SceneSession s =
      open(sample("kind = \"implicit\"\ndt = 0.002", table + jaw("left", 0.5, path(-0.0055, -0.004), 0.016) +
                                                         jaw("right", 0.5, path(0.0255, 0.024), 0.016)),
           "lift", threads);
  s.simulation->run(0.4);
  const RunSummary r = s.simulation->summary();
  checks.push_back(yes("tool-body", "lifted: every implicit step converged", r.converged));
  checks.push_back(within("tool-body", "lifted sample's mean rise / the jaws' 1 cm",
                          s.simulation->state().u.row(1).mean(), 0.01, 0.1));
  checks.push_back(
      yes("body-table", "lifted sample off the table (no contact)", named(r.obstacles, "table").contacts == 0));
  checks.push_back(within("tool-body", "lifting jaws' lift / the weight",
                          -(named(r.tools, "left").force.y() + named(r.tools, "right").force.y()), weight, 0.01));
}

// the seed's cantilever under its weight, cut through near its root at 0.2 s: the free piece falls 2 cm onto a
// table and comes to rest (implicit, 1.5 s); the table carries the piece, the root the stump
void cut_piece_falls(std::vector<Check>& checks, int threads) {
  SceneSession s = open(
      "[object]\nshape = \"box\"\nsize = [0.15, 0.03, 0.03]\nspacing = 0.0075\n[material]\nyoung = 1e6\npoisson = "
      "0.4\ndensity = 1000.0\ndamping = 20.0\n[[fixed]]\nbox = { min = [-1.0, -1.0, -1.0], max = [0.0, 1.0, 1.0] "
      "}\n[[load]]\nkind = \"gravity\"\n[[cut]]\nedge = [[0.03375, 0.04, -0.01], [0.03375, 0.04, 0.04]]\nto = "
      "[[0.03375, -0.01, -0.01], [0.03375, -0.01, 0.04]]\nstart = 0.2\nduration = 0.05\n[solver]\nkind = "
      "\"implicit\"\ndt = 2e-3\n[[obstacle]]\nname = \"table\"\nplane = { point = [0.0, -0.02, 0.0], normal = [0.0, "
      "1.0, 0.0] }\nfriction = 0.5\n",
      "cut-piece", threads);
  s.simulation->run(1.5);
  const RunSummary r = s.simulation->summary();
  const Model& model = s.simulation->model();
  std::vector<index_t> piece_of;
  const std::vector<index_t> pieces = piece_sizes(model, piece_of);
  checks.push_back(yes("body-table", "cut piece: two pieces, every step converged", r.converged && pieces.size() == 2));
  // the piece that holds no fixed point falls: its weight is what the table must carry
  std::vector<bool> held_piece(pieces.size(), false);
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.fixed[static_cast<std::size_t>(i)])
      held_piece[static_cast<std::size_t>(piece_of[static_cast<std::size_t>(i)])] = true;
  double falling = 0;
  for (index_t i = 0; i < model.n_points; ++i)
    if (!held_piece[static_cast<std::size_t>(piece_of[static_cast<std::size_t>(i)])]) falling += model.mass[i] * g;
  checks.push_back(within("body-table", "table's support of the cut piece / its weight",
                          -named(r.obstacles, "table").force.y(), falling, 0.005));
  checks.push_back(yes("body-table",
                       fmt::format("cut piece at rest on the table (kinetic energy {:.2g} J)", r.kinetic_energy),
                       r.kinetic_energy < 1e-9 && named(r.obstacles, "table").contacts > 0));
}

/// One [[refine]] sphere around where the spheres meet: spacing R / refine within region R.
struct RefineLevel {
  int refine = 0;
  double region = 0;
};

/// Two elastic spheres pressed together, against CalculiX and Hertz's two-body law.
struct HertzRow {
  std::vector<RefineLevel> levels;  ///< coarsest first, each inside the one before (the rest of each sphere R / 4)
  double travel = 0;                ///< the caps' travel towards each other, m
  double approach = 0;              ///< the centres' approach, m
  double force = 0;                 ///< N
  double hertz = 0;                 ///< N
  int contacts = 0;
  double solve_s = 0;
  bool converged = false;
};

constexpr double sphere_radius = 0.01, sphere_young = 1e5, sphere_poisson = 0.3, sphere_gap = 1e-4;

// Hertz's two-body law for the two spheres: F = 4/3 E* sqrt(R*) d^(3/2) with R* = R / 2, 1 / E* = 2 (1 - nu^2) / E,
// d the approach of the centres (the spheres' bulk compression between the centres and the contact is in d too)
double hertz_two_spheres(double approach) {
  const double effective_young = sphere_young / (2 * (1 - sphere_poisson * sphere_poisson));
  return 4.0 / 3.0 * effective_young * std::sqrt(sphere_radius / 2) * std::pow(std::max(approach, 0.0), 1.5);
}

// "R/16 within 0.3 R in R/8 within 0.6 R"
std::string refinement(const std::vector<RefineLevel>& levels) {
  std::string text;
  for (auto level = levels.rbegin(); level != levels.rend(); ++level)
    text += fmt::format("{}R/{} within {} R", text.empty() ? "" : " in ", level->refine, level->region);
  return text;
}

// two neo-Hookean spheres (R = 1 cm, E = 100 kPa, nu = 0.3), 0.1 mm apart, each held at its far cap (3 mm high) and
// refined where they meet (`levels`); the upper cap is moved down by `travel`, statically
HertzRow press_spheres(const std::vector<RefineLevel>& levels, double travel, std::vector<Check>& checks, int threads) {
  constexpr double R = sphere_radius, gap = sphere_gap;
  const double fine = R / levels.back().refine;
  const auto sphere = [&](const char* name, double centre_y, double cap_from, double cap_to, const std::string& more) {
    std::string text = fmt::format(
        "[[object]]\nname = \"{0}\"\nshape = \"sphere\"\nradius = {1}\norigin = [0.0, {2}, 0.0]\nspacing = "
        "{3}\nsurface_edge = {4}\n[[fixed]]\nobject = \"{0}\"\nbox = {{ min = [-0.02, {5}, -0.02], max = [0.02, {6}, "
        "0.02] }}\n{7}\n",
        name, R, centre_y, R / 4, fine / 2, cap_from, cap_to, more);
    for (const RefineLevel& level : levels)
      text += fmt::format(
          "[[refine]]\nobject = \"{}\"\nsphere = {{ centre = [0.0, {}, 0.0], radius = {} }}\nspacing = {}\n", name,
          R + gap / 2, level.region * R, R / level.refine);
    return text;
  };
  const std::string text =
      fmt::format("[material]\nmodel = \"neo_hookean\"\nyoung = {}\npoisson = {}\n[solver]\nkind = \"static\"\n",
                  sphere_young, sphere_poisson) +
      sphere("lower", 0.0, -2 * R, -0.7 * R, "") +
      sphere("upper", 2 * R + gap, 2.7 * R + gap, 5 * R, fmt::format("displacement = [0.0, {}, 0.0]", -travel));
  SceneSession s = open(text, "two-spheres", threads);
  s.simulation->step();
  const RunSummary r = s.simulation->summary();
  const Model& model = s.simulation->model();
  const Points& u = s.simulation->state().u;
  // the centres' points (each sphere's lattice has one there)
  const auto centre = [&](const Vec3& c) {
    index_t nearest = 0;
    for (index_t i = 1; i < model.n_points; ++i)
      if ((model.X.col(i) - c).squaredNorm() < (model.X.col(nearest) - c).squaredNorm()) nearest = i;
    return nearest;
  };
  const index_t lower = centre(Vec3::Zero()), upper = centre(Vec3(0, 2 * R + gap, 0));
  HertzRow row;
  row.levels = levels;
  row.travel = travel;
  row.approach = u(1, lower) - u(1, upper) - gap;
  row.force = r.reactions.size() == 2 ? r.reactions[0].y() : 0.0;
  row.hertz = hertz_two_spheres(row.approach);
  row.contacts = r.body_contact.contacts;
  row.solve_s = r.solve_s;
  row.converged = r.converged;
  const std::string label = fmt::format("spheres {}, approach {:.3f} R", refinement(levels), row.approach / R);
  checks.push_back(yes("body-body", label + ": static solve converged", r.converged));
  if (r.reactions.size() == 2)
    checks.push_back(within("body-body", label + ": upper cap's reaction / the lower's (opposite)", -r.reactions[1].y(),
                            r.reactions[0].y(), 1e-6));
  return row;
}

// The same spheres in CalculiX: by symmetry one sphere, held at the same cap, pressed onto a rigid frictionless plane
// (its contact with the plane is the spheres' plane of symmetry), to the caps' half travel past first touch. R/20 at
// the contact: R/40 and R/80 give forces within 0.3% (tests/fem/calculix_indentation_test.cpp).
fem::SphereOnPlaneSolution spheres_in_calculix(double max_travel, int threads) {
  fem::SphereOnPlaneProblem p;
  p.radius = sphere_radius;
  p.cap_from = 0.7 * sphere_radius;
  p.material.model = MaterialModel::NEO_HOOKEAN;
  p.material.young = sphere_young;
  p.material.poisson = sphere_poisson;
  p.max_travel = 0.5 * (max_travel - sphere_gap);
  p.increments = 10;
  p.elements_per_radius = 20;
  fem::SphereOnPlaneSolution s = fem::solve_sphere_on_plane(p, threads);
  fmt::print("contact-pairs: CalculiX sphere on a plane ({} nodes): {:.4f} N at a cap's travel of {:.3f} R, {:.1f} s\n",
             s.nodes, s.curve.back().force, s.curve.back().cap_travel / sphere_radius, s.wall_s);
  return s;
}

}  // namespace

int run_contact_pairs_experiment(const ContactPairsOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(options.out);
  const fs::path out = options.out;
  std::vector<Check> checks;
  block_on_table(checks, options.threads);
  block_on_block(checks, options.threads);
  pinch(checks, options.threads);
  lift(checks, options.threads);
  cut_piece_falls(checks, options.threads);
  std::vector<HertzRow> hertz;
  const double travels[] = {0.0006, 0.0011};
  const fem::SphereOnPlaneSolution reference = spheres_in_calculix(travels[1], options.threads);
  // the reference's force at the same travel of the caps (each sphere's cap moves half of what the two close, past
  // the gap), and its Hertz ratio at its own approach
  const auto calculix = [&](const HertzRow& h) { return reference.force_at_cap(0.5 * (h.travel - sphere_gap)); };
  // R/8 and R/16 within 0.4 R of the contact, and R/16 within 0.6 R and 0.8 R: where the fine points meet the coarse
  // ones; graded, R/16 within 0.3 R inside R/8 within 0.6 R, and R/32 within 0.15 R inside that
  const std::vector<std::vector<RefineLevel>> refinements = {
      {{8, 0.4}}, {{16, 0.4}}, {{16, 0.6}}, {{16, 0.8}}, {{8, 0.6}, {16, 0.3}}, {{8, 0.7}, {16, 0.4}, {32, 0.25}}};
  for (const std::vector<RefineLevel>& levels : refinements)
    for (double travel : travels) hertz.push_back(press_spheres(levels, travel, checks, options.threads));
  // the graded spheres (the cheapest that holds) against CalculiX at both travels, and against Hertz's law at the
  // small one, within 5%
  for (const HertzRow& h : hertz) {
    if (refinement(h.levels) != refinement(refinements[4])) continue;
    const std::string label =
        fmt::format("spheres {}, approach {:.3f} R", refinement(h.levels), h.approach / sphere_radius);
    checks.push_back(
        within("body-body", label + ": force / CalculiX's at the same travel", h.force, calculix(h), 0.05));
    if (h.travel == travels[0])
      checks.push_back(within("body-body", label + ": force / Hertz's two-body law", h.force, h.hertz, 0.05));
  }
  auto hertz_csv = fmt::output_file((out / "two-spheres.csv").string());
  hertz_csv.print(
      "refinement,travel_m,approach_m,approach_over_r,force_n,hertz_n,ratio,calculix_n,"
      "ratio_to_calculix,contacts,solve_s,converged\n");
  for (const HertzRow& h : hertz)
    hertz_csv.print("\"{}\",{:.6g},{:.6g},{:.4f},{:.6g},{:.6g},{:.4f},{:.6g},{:.4f},{},{:.2f},{}\n",
                    refinement(h.levels), h.travel, h.approach, h.approach / sphere_radius, h.force, h.hertz,
                    h.force / h.hertz, calculix(h), h.force / calculix(h), h.contacts, h.solve_s, h.converged ? 1 : 0);
  hertz_csv.close();
  auto fem_csv = fmt::output_file((out / "two-spheres-calculix.csv").string());
  // in the two spheres' terms: the caps close by twice the one cap's travel plus the gap, the centres by twice the
  // one centre's
  fem_csv.print("travel_m,approach_m,approach_over_r,force_n,hertz_n,ratio\n");
  for (const fem::SphereOnPlanePoint& f : reference.curve)
    fem_csv.print("{:.6g},{:.6g},{:.4f},{:.6g},{:.6g},{:.4f}\n", 2 * f.cap_travel + sphere_gap, 2 * f.centre_travel,
                  2 * f.centre_travel / sphere_radius, f.force, hertz_two_spheres(2 * f.centre_travel),
                  f.force / hertz_two_spheres(2 * f.centre_travel));
  fem_csv.close();
  auto csv = fmt::output_file((out / "contact-pairs.csv").string());
  csv.print("pair,quantity,measured,expected,relative_error,tolerance,holds\n");
  for (const Check& c : checks)
    csv.print("{},\"{}\",{:.9g},{:.9g},{:.3g},{:.3g},{}\n", c.pair, c.quantity, c.measured, c.expected,
              c.relative_error(), c.tolerance, c.holds ? 1 : 0);
  csv.close();
  const int plots = run_plot_script("plot_contact_pairs.py", out.string(), options.plot_script);
  auto md = fmt::output_file((out / "summary.md").string());
  md.print(
      "# Contact pairs (issue 47)\n\n"
      "Each kind of contact pair against what statics says it must carry (`contact-pairs.csv`; the relative errors "
      "against their tolerances in `contact-pairs.png`).\n\n"
      "| pair | quantity | measured | expected | relative error | tolerance | holds |\n|---|---|---|---|---|---|---|\n");
  for (const Check& c : checks)
    md.print("| {} | {} | {:.6g} | {:.6g} | {} | {} | {} |\n", c.pair, c.quantity, c.measured, c.expected,
             c.tolerance > 0 ? fmt::format("{:.2e}", c.relative_error()) : "-",
             c.tolerance > 0 ? fmt::format("{:.1e}", c.tolerance) : "-", c.holds ? "yes" : "**no**");
  md.print(
      "\n## Two elastic spheres: CalculiX and Hertz's two-body law\n\n"
      "Two neo-Hookean spheres (R = 1 cm, E = 100 kPa, nu = 0.3), each held at its far cap, spacing R/4 refined "
      "where they meet, pressed together statically (`two-spheres.csv`). Hertz: F = 4/3 E* sqrt(R*) d^(3/2), "
      "R* = R/2, E* = E / (2 (1 - nu^2)), d the centres' approach. CalculiX: by symmetry one of the spheres, held at "
      "the same cap, pressed onto a rigid frictionless plane (axisymmetric, quadratic elements of R/20 at the contact; "
      "R/40 and R/80 move its force by under 0.3%), its force at the same travel of the caps "
      "(`two-spheres-calculix.csv`).\n\n"
      "| refined where they meet | approach / R | force (N) | CalculiX (N) | / CalculiX | Hertz (N) | / Hertz | "
      "vertices pressing | solve (s) |\n|---|---|---|---|---|---|---|---|---|\n");
  for (const HertzRow& h : hertz)
    md.print("| {} | {:.3f} | {:.4f} | {:.4f} | {:.3f} | {:.4f} | {:.3f} | {} | {:.1f} |\n", refinement(h.levels),
             h.approach / sphere_radius, h.force, calculix(h), h.force / calculix(h), h.hertz, h.force / h.hertz,
             h.contacts, h.solve_s);
  md.print(
      "\nCalculiX's own curve against Hertz's law, at its own approach of the centres:\n\n"
      "| approach / R | force (N) | Hertz (N) | / Hertz |\n|---|---|---|---|\n");
  for (const fem::SphereOnPlanePoint& f : reference.curve)
    md.print("| {:.3f} | {:.4f} | {:.4f} | {:.3f} |\n", 2 * f.centre_travel / sphere_radius, f.force,
             hertz_two_spheres(2 * f.centre_travel), f.force / hertz_two_spheres(2 * f.centre_travel));
  md.print(
      "\nThe exact solution of these spheres departs from Hertz's law as the approach grows: Hertz assumes "
      "half-spaces and small strains, and the contact's strains here are finite (a neo-Hookean solid stiffens in "
      "compression). So the point model is checked against CalculiX at the same travel of the caps (the graded "
      "spheres, within 5% at both travels), and against Hertz's law at the small approach only.\n\n"
      "Not settled: R/8 at the contact is far too coarse (0.63 and 0.82 of CalculiX); every R/16 layout gives 0.94 to "
      "0.98; but R/32 within 0.25 R gives 0.95 and 0.93, further from CalculiX, not closer. The points are not "
      "converged towards the reference at R/32 yet.\n");
  md.close();
  bool all = plots == 0;
  for (const Check& c : checks) {
    fmt::print("{:<10} {:<60} {:>12.6g} {:>12.6g} {}\n", c.pair, c.quantity, c.measured, c.expected,
               c.holds ? "holds" : "FAILS");
    all = all && c.holds;
  }
  fmt::print("wrote {}\n", out.string());
  if (!all) fmt::print(stderr, "experiment contact-pairs: a check failed (see {})\n", (out / "summary.md").string());
  return all ? 0 : 1;
}

}  // namespace pointhaptics::experiments
