#include <pointhaptics/fem/calculix.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>

#include <fmt/format.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <istream>
#include <map>
#include <sstream>

namespace pointhaptics::fem {
namespace {

// The mesh lives on a grid of half element steps; a node sits where at most one index is odd.
struct Grid {
  int nx, ny, nz;
  std::vector<int> id;  // node id (1-based) per grid point, 0 where there is no node
  int a_size() const { return 2 * nx + 1; }
  int b_size() const { return 2 * ny + 1; }
  int c_size() const { return 2 * nz + 1; }
  int at(int a, int b, int c) const { return id[(static_cast<size_t>(c) * b_size() + b) * a_size() + a]; }
};

Grid make_grid(const BoxProblem& p) {
  if (p.nx < 1 || p.ny < 1 || p.nz < 1)
    throw Error(fmt::format("CalculiX mesh: element counts must be >= 1 (got {} x {} x {})", p.nx, p.ny, p.nz));
  if (!(p.size.array() > 0).all()) throw Error("CalculiX mesh: the box size must be positive along x, y and z");
  Grid g{p.nx, p.ny, p.nz, {}};
  g.id.assign(static_cast<size_t>(g.a_size()) * g.b_size() * g.c_size(), 0);
  int next = 1;
  for (int c = 0; c < g.c_size(); ++c)
    for (int b = 0; b < g.b_size(); ++b)
      for (int a = 0; a < g.a_size(); ++a)
        if ((a % 2) + (b % 2) + (c % 2) <= 1) g.id[(static_cast<size_t>(c) * g.b_size() + b) * g.a_size() + a] = next++;
  return g;
}

Vec3 grid_position(const BoxProblem& p, int a, int b, int c) {
  return p.origin + Vec3(p.size.x() * a / (2.0 * p.nx), p.size.y() * b / (2.0 * p.ny), p.size.z() * c / (2.0 * p.nz));
}

// C3D20 local node order as offsets in half steps: corners 1-8, bottom mid-edges 9-12, top 13-16, vertical 17-20
constexpr std::array<std::array<int, 3>, 20> element_offsets{
    {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 2}, {2, 0, 2}, {2, 2, 2}, {0, 2, 2}, {1, 0, 0}, {2, 1, 0},
     {1, 2, 0}, {0, 1, 0}, {1, 0, 2}, {2, 1, 2}, {1, 2, 2}, {0, 1, 2}, {0, 0, 1}, {2, 0, 1}, {2, 2, 1}, {0, 2, 1}}};

// Consistent nodal forces of uniform tractions on the boundary faces inside each traction's region.
std::map<int, Vec3> traction_forces(const BoxProblem& p, const Grid& g) {
  std::map<int, Vec3> forces;
  const double tol = 1e-9 * p.size.norm();
  for (size_t t = 0; t < p.tractions.size(); ++t) {
    const Traction& traction = p.tractions[t];
    struct Face {
      std::array<int, 8> corners_then_mids;
      double area;
    };
    std::vector<Face> faces;
    // the six sides: fixed axis, its grid index (0 or max), and the two in-plane axes
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
        const std::array<int, 3> n{p.nx, p.ny, p.nz};
        const double area = p.size[u_axis] / n[u_axis] * p.size[v_axis] / n[v_axis];
        for (int i = 0; i < n[u_axis]; ++i)
          for (int j = 0; j < n[v_axis]; ++j) {
            Face face{{}, area};
            bool inside = true;
            int k_corner = 0, k_mid = 4;
            for (int du = 0; du <= 2; ++du)
              for (int dv = 0; dv <= 2; ++dv) {
                if (du == 1 && dv == 1) continue;
                std::array<int, 3> idx{};
                idx[axis] = side ? 2 * n[axis] : 0;
                idx[u_axis] = 2 * i + du;
                idx[v_axis] = 2 * j + dv;
                inside = inside && traction.region.contains(grid_position(p, idx[0], idx[1], idx[2]), tol);
                const int node = g.at(idx[0], idx[1], idx[2]);
                if (du % 2 == 0 && dv % 2 == 0) face.corners_then_mids[k_corner++] = node;
                else face.corners_then_mids[k_mid++] = node;
              }
            if (inside) faces.push_back(face);
          }
      }
    double total_area = 0;
    for (const Face& f : faces) total_area += f.area;
    if (faces.empty())
      throw Error(
          fmt::format("CalculiX mesh: traction {} covers no boundary face of the {} x {} x {} mesh "
                      "(its region must hold whole element faces)",
                      t, p.nx, p.ny, p.nz));
    for (const Face& f : faces) {
      const Vec3 share = traction.total * (f.area / total_area);
      // 8-node serendipity face under uniform pressure: corners -1/12, mid-sides +1/3 of the face's load
      for (int k = 0; k < 8; ++k) {
        auto [it, fresh] = forces.try_emplace(f.corners_then_mids[k], Vec3::Zero());
        it->second += (k < 4 ? -1.0 / 12.0 : 1.0 / 3.0) * share;
      }
    }
  }
  return forces;
}

void write_id_list(std::string& out, const std::vector<int>& ids) {
  for (size_t k = 0; k < ids.size(); ++k)
    out += fmt::format("{}{}", ids[k], (k + 1) % 16 == 0 || k + 1 == ids.size() ? ",\n" : ", ");
}

}  // namespace

Points mesh_nodes(const BoxProblem& problem) {
  const Grid g = make_grid(problem);
  int count = 0;
  for (int v : g.id) count += v > 0;
  Points nodes(3, count);
  for (int c = 0; c < g.c_size(); ++c)
    for (int b = 0; b < g.b_size(); ++b)
      for (int a = 0; a < g.a_size(); ++a)
        if (const int id = g.at(a, b, c)) nodes.col(id - 1) = grid_position(problem, a, b, c);
  return nodes;
}

std::string material_card(const std::string& name, const BoxProblem& p) {
  std::string out = fmt::format("*MATERIAL, NAME={}\n", name);
  switch (p.material) {
    case FemMaterial::ELASTIC: out += fmt::format("*ELASTIC\n{:.13g}, {:.13g}\n", p.young, p.poisson); break;
    case FemMaterial::NEO_HOOKE: out += fmt::format("*HYPERELASTIC, NEO HOOKE\n{:.13g}, {:.13g}\n", p.c10, p.d1); break;
    case FemMaterial::MOONEY_RIVLIN:
      out += fmt::format("*HYPERELASTIC, MOONEY-RIVLIN\n{:.13g}, {:.13g}, {:.13g}\n", p.c10, p.c01, p.d1);
      break;
  }
  return out + fmt::format("*DENSITY\n{:.13g}\n", p.density);
}

// ccx reads real numbers in fields of 20 characters: 13 significant digits always fit
std::string write_inp(const BoxProblem& p) {
  const Grid g = make_grid(p);
  const Points nodes = mesh_nodes(p);
  if (p.clamps.empty()) throw Error("CalculiX mesh: no clamp; a free body has no static solution");
  if (!(p.young > 0) || !(p.poisson > -1 && p.poisson < 0.5) || !(p.density > 0))
    throw Error("CalculiX mesh: the material needs E > 0, -1 < nu < 0.5 and a positive density");
  std::string out = "** PointHaptics: box beam for comparison with the point-based model\n*HEADING\nPointHaptics box\n";
  out += "*NODE, NSET=NALL\n";
  for (Eigen::Index k = 0; k < nodes.cols(); ++k)
    out += fmt::format("{}, {:.13g}, {:.13g}, {:.13g}\n", k + 1, nodes(0, k), nodes(1, k), nodes(2, k));
  out += fmt::format("*ELEMENT, TYPE={}, ELSET=EALL\n", p.reduced_integration ? "C3D20R" : "C3D20");
  int element = 1;
  for (int k = 0; k < p.nz; ++k)
    for (int j = 0; j < p.ny; ++j)
      for (int i = 0; i < p.nx; ++i, ++element) {
        out += fmt::format("{}, ", element);
        for (int n = 0; n < 20; ++n) {
          const auto& o = element_offsets[n];
          // ccx reads at most 16 entries per line: the element number and 15 nodes, then 5 more
          out += fmt::format("{}{}", g.at(2 * i + o[0], 2 * j + o[1], 2 * k + o[2]),
                             n == 19   ? "\n"
                             : n == 14 ? ",\n"
                                       : ", ");
        }
      }
  const double tol = 1e-9 * p.size.norm();
  std::vector<int> held;
  for (Eigen::Index k = 0; k < nodes.cols(); ++k)
    for (const Box& clamp : p.clamps)
      if (clamp.contains(nodes.col(k), tol)) {
        held.push_back(static_cast<int>(k + 1));
        break;
      }
  if (held.empty()) throw Error("CalculiX mesh: the clamps hold no node of the mesh");
  out += "*NSET, NSET=NFIX\n";
  write_id_list(out, held);
  // the prescribed sets: a node already held stays held
  std::vector<std::vector<int>> moved(p.prescribed.size());
  for (Eigen::Index k = 0; k < nodes.cols(); ++k) {
    if (std::binary_search(held.begin(), held.end(), static_cast<int>(k + 1))) continue;
    for (size_t s = 0; s < p.prescribed.size(); ++s)
      if (p.prescribed[s].holds(nodes.col(k), tol)) {
        moved[s].push_back(static_cast<int>(k + 1));
        break;
      }
  }
  for (size_t s = 0; s < moved.size(); ++s) {
    if (moved[s].empty())
      throw Error(fmt::format("CalculiX mesh: prescribed set {} holds no free node of the mesh", s + 1));
    out += fmt::format("*NSET, NSET=NMOVE{}\n", s + 1);
    write_id_list(out, moved[s]);
  }
  // the elements of each inclusion (by their centres), the rest the body's
  std::vector<int> material_of(static_cast<size_t>(p.nx) * p.ny * p.nz, 0);
  for (size_t s = 0; s < p.inclusions.size(); ++s)
    for (int k = 0, e = 0; k < p.nz; ++k)
      for (int j = 0; j < p.ny; ++j)
        for (int i = 0; i < p.nx; ++i, ++e)
          if ((grid_position(p, 2 * i + 1, 2 * j + 1, 2 * k + 1) - p.inclusions[s].centre).norm() <=
              p.inclusions[s].radius)
            material_of[e] = static_cast<int>(s + 1);
  out += material_card("MAT", p);
  for (size_t s = 0; s < p.inclusions.size(); ++s) {
    BoxProblem inclusion;
    set_material(inclusion, p.inclusions[s].material);
    std::vector<int> elements;
    for (size_t e = 0; e < material_of.size(); ++e)
      if (material_of[e] == static_cast<int>(s + 1)) elements.push_back(static_cast<int>(e + 1));
    if (elements.empty()) throw Error(fmt::format("CalculiX mesh: inclusion {} holds no element centre", s + 1));
    out += fmt::format("*ELSET, ELSET=EINC{}\n", s + 1);
    write_id_list(out, elements);
    out += material_card(fmt::format("MAT{}", s + 1), inclusion);
  }
  std::vector<int> body;
  for (size_t e = 0; e < material_of.size(); ++e)
    if (material_of[e] == 0) body.push_back(static_cast<int>(e + 1));
  out += "*ELSET, ELSET=EBODY\n";
  write_id_list(out, body);
  out += "*SOLID SECTION, ELSET=EBODY, MATERIAL=MAT\n";
  for (size_t s = 0; s < p.inclusions.size(); ++s)
    out += fmt::format("*SOLID SECTION, ELSET=EINC{0}, MATERIAL=MAT{0}\n", s + 1);
  out += "*BOUNDARY\nNFIX, 1, 3\n";
  // the mirror planes: one component of the nodes not held or moved already
  for (size_t s = 0; s < p.symmetry.size(); ++s) {
    const Symmetry& plane = p.symmetry[s];
    if (plane.axis < 0 || plane.axis > 2)
      throw Error(fmt::format("CalculiX mesh: symmetry plane {} has axis {} (0, 1 or 2)", s + 1, plane.axis));
    std::vector<int> on;
    for (Eigen::Index k = 0; k < nodes.cols(); ++k) {
      const int id = static_cast<int>(k + 1);
      if (std::abs(nodes(plane.axis, k) - plane.at) > tol || std::binary_search(held.begin(), held.end(), id)) continue;
      if (std::any_of(moved.begin(), moved.end(),
                      [&](const std::vector<int>& m) { return std::binary_search(m.begin(), m.end(), id); }))
        continue;
      on.push_back(id);
    }
    if (on.empty()) throw Error(fmt::format("CalculiX mesh: symmetry plane {} holds no free node of the mesh", s + 1));
    std::string set = fmt::format("*NSET, NSET=NSYM{}\n", s + 1);
    write_id_list(set, on);
    out.insert(out.rfind("*BOUNDARY\nNFIX"), set);  // sets before the boundary cards
    out += fmt::format("NSYM{}, {}, {}\n", s + 1, plane.axis + 1, plane.axis + 1);
  }
  if (p.nlgeom && p.fixed_increments > 0) {
    const double dt = 1.0 / p.fixed_increments;
    out += fmt::format(
        "*STEP, NLGEOM, INC=1000\n*STATIC, DIRECT\n{:.13g}, 1.0\n*CONTROLS, PARAMETERS=FIELD\n1e-5, 1e-4\n", dt);
  } else if (p.nlgeom) {
    // small first increment, tightened equilibrium tolerances (ccx's defaults leave ~1e-3 error)
    out += "*STEP, NLGEOM, INC=1000\n*STATIC\n0.05, 1.0, 1e-6, 0.25\n*CONTROLS, PARAMETERS=FIELD\n1e-5, 1e-4\n";
  } else {
    out += "*STEP\n*STATIC\n";
  }
  if (!moved.empty()) {
    out += "*BOUNDARY\n";
    for (size_t s = 0; s < moved.size(); ++s)
      for (int a = 0; a < 3; ++a)
        out += fmt::format("NMOVE{}, {}, {}, {:.13g}\n", s + 1, a + 1, a + 1, p.prescribed[s].displacement[a]);
  }
  const std::map<int, Vec3> forces = traction_forces(p, g);
  if (!forces.empty()) {
    out += "*CLOAD\n";
    for (const auto& [node, f] : forces)
      for (int a = 0; a < 3; ++a)
        if (f[a] != 0) out += fmt::format("{}, {}, {:.13g}\n", node, a + 1, f[a]);
  }
  if (p.gravity.norm() > 0) {
    const Vec3 dir = p.gravity.normalized();
    out += fmt::format("*DLOAD\nEALL, GRAV, {:.13g}, {:.13g}, {:.13g}, {:.13g}\n", p.gravity.norm(), dir.x(), dir.y(),
                       dir.z());
  }
  out += "*NODE PRINT, NSET=NALL\nU\n";
  for (size_t s = 0; s < moved.size(); ++s) out += fmt::format("*NODE PRINT, NSET=NMOVE{}, TOTALS=ONLY\nRF\n", s + 1);
  out += "*END STEP\n";
  return out;
}

Points read_dat_displacements(std::istream& dat, index_t n_nodes, const std::string& source) {
  Points u(3, n_nodes);
  std::vector<unsigned char> seen;
  bool found = false;
  std::string line;
  long long line_no = 0;
  while (std::getline(dat, line)) {
    ++line_no;
    if (line.find("displacements (vx,vy,vz)") == std::string::npos) continue;
    // a new block (one per printed increment): the last one wins
    found = true;
    seen.assign(n_nodes, 0);
    index_t read = 0;
    while (std::getline(dat, line)) {
      ++line_no;
      if (line.find_first_not_of(" \t\r") == std::string::npos) {
        if (read == 0) continue;  // the blank line after the header
        break;
      }
      // id and three numbers; strtod so that ccx's NaN and Inf are read (and refused below), not misparsed
      std::istringstream in(line);
      std::string tokens[5];
      int n_tokens = 0;
      while (n_tokens < 5 && in >> tokens[n_tokens]) ++n_tokens;
      double values[4];
      bool ok = n_tokens == 4;
      for (int t = 0; ok && t < 4; ++t) {
        char* end = nullptr;
        values[t] = std::strtod(tokens[t].c_str(), &end);
        ok = end != tokens[t].c_str() && *end == '\0';
      }
      if (!ok || values[0] != std::floor(values[0]))
        throw Error(fmt::format("{}:{}: malformed displacement line \"{}\"", source, line_no, line));
      const long long id = static_cast<long long>(values[0]);
      const double x = values[1], y = values[2], z = values[3];
      if (id < 1 || id > n_nodes)
        throw Error(fmt::format("{}:{}: node {} is outside the mesh's 1..{}", source, line_no, id, n_nodes));
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        throw Error(fmt::format("{}:{}: node {} has a non-finite displacement", source, line_no, id));
      if (seen[id - 1]) throw Error(fmt::format("{}:{}: node {} appears twice", source, line_no, id));
      seen[id - 1] = 1;
      u.col(id - 1) = Vec3(x, y, z);
      ++read;
    }
    if (read != n_nodes)
      throw Error(fmt::format("{}: the displacement block lists {} of the mesh's {} nodes", source, read, n_nodes));
  }
  if (!found) throw Error(fmt::format("{}: no displacement block (\"displacements (vx,vy,vz)\") found", source));
  return u;
}

std::vector<Reaction> read_dat_totals(std::istream& dat, const std::string& set, const std::string& source) {
  std::vector<Reaction> out;
  std::string line;
  long long line_no = 0;
  const std::string key = "total force (fx,fy,fz) for set " + set + " and time";
  while (std::getline(dat, line)) {
    ++line_no;
    const size_t at = line.find(key);
    if (at == std::string::npos) continue;
    Reaction r;
    char* end = nullptr;
    const std::string time = line.substr(at + key.size());
    r.time = std::strtod(time.c_str(), &end);
    if (end == time.c_str()) throw Error(fmt::format("{}:{}: no time in \"{}\"", source, line_no, line));
    while (std::getline(dat, line)) {  // the totals follow after a blank line
      ++line_no;
      if (line.find_first_not_of(" \t\r") != std::string::npos) break;
    }
    std::istringstream in(line);
    std::string tokens[3];
    for (int a = 0; a < 3; ++a) {
      if (!(in >> tokens[a]))
        throw Error(fmt::format("{}:{}: malformed total force line \"{}\"", source, line_no, line));
      r.force[a] = std::strtod(tokens[a].c_str(), &end);
      if (end == tokens[a].c_str() || !std::isfinite(r.force[a]))
        throw Error(fmt::format("{}:{}: malformed total force line \"{}\"", source, line_no, line));
    }
    out.push_back(r);
  }
  return out;
}

std::vector<std::pair<double, Vec3>> read_dat_set_displacements(std::istream& dat, const std::string& set,
                                                                const std::string& source) {
  std::vector<std::pair<double, Vec3>> out;
  std::string line;
  long long line_no = 0;
  const std::string key = "displacements (vx,vy,vz) for set " + set + " and time";
  while (std::getline(dat, line)) {
    ++line_no;
    const size_t at = line.find(key);
    if (at == std::string::npos) continue;
    char* end = nullptr;
    const std::string time = line.substr(at + key.size());
    const double t = std::strtod(time.c_str(), &end);
    if (end == time.c_str()) throw Error(fmt::format("{}:{}: no time in \"{}\"", source, line_no, line));
    while (std::getline(dat, line)) {  // the node's line follows after a blank line
      ++line_no;
      if (line.find_first_not_of(" \t\r") != std::string::npos) break;
    }
    std::istringstream in(line);
    std::string tokens[4];
    Vec3 u;
    for (int a = 0; a < 4; ++a) {
      if (!(in >> tokens[a]))
        throw Error(fmt::format("{}:{}: malformed displacement line \"{}\"", source, line_no, line));
      if (a == 0) continue;
      u[a - 1] = std::strtod(tokens[a].c_str(), &end);
      if (end == tokens[a].c_str() || !std::isfinite(u[a - 1]))
        throw Error(fmt::format("{}:{}: malformed displacement line \"{}\"", source, line_no, line));
    }
    out.emplace_back(t, u);
  }
  return out;
}

void set_material(BoxProblem& problem, const MaterialParams& material) {
  problem.young = material.young;
  problem.poisson = material.poisson;
  problem.density = material.density;
  std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<M, StVenantKirchhoff>) {
          problem.material = FemMaterial::ELASTIC;
        } else if constexpr (std::is_same_v<M, NeoHookean>) {
          problem.material = FemMaterial::NEO_HOOKE;
          problem.c10 = m.c10();
          problem.d1 = 2 / m.bulk;
        } else if constexpr (std::is_same_v<M, MooneyRivlin>) {
          problem.material = FemMaterial::MOONEY_RIVLIN;
          problem.c10 = m.c10;
          problem.c01 = m.c01;
          problem.d1 = 2 / m.bulk;
        } else {
          throw Error(fmt::format("CalculiX has no {} material", to_string(material.model)));
        }
      },
      material_constants(material));
}

std::string find_ccx() {
  auto executable = [](const std::string& path) { return !path.empty() && ::access(path.c_str(), X_OK) == 0; };
  if (const char* env = std::getenv("PH_CCX")) {
    if (executable(env)) return env;
    throw Error(fmt::format("PH_CCX = \"{}\" is not an executable file", env));
  }
  if (const char* path = std::getenv("PATH")) {
    std::stringstream dirs(path);
    std::string dir;
    while (std::getline(dirs, dir, ':'))
      if (executable(dir + "/ccx")) return dir + "/ccx";
  }
  throw Error(
      "CalculiX (the ccx program) was not found on PATH; install the Debian package calculix-ccx "
      "(apt-get install calculix-ccx) or set PH_CCX to its path");
}

CcxRun run_ccx(const std::string& deck, int threads) {
  const std::string ccx = find_ccx();
  std::string dir_template = (std::filesystem::temp_directory_path() / "pointhaptics-ccx-XXXXXX").string();
  if (!::mkdtemp(dir_template.data())) throw Error("CalculiX: cannot create a temporary folder");
  CcxRun run;
  run.dir = dir_template;
  {
    std::ofstream inp(run.dir / "job.inp");
    inp << deck;
    if (!inp) throw Error(fmt::format("CalculiX: cannot write {}", (run.dir / "job.inp").string()));
  }
  const std::string command =
      fmt::format("cd '{}' && OMP_NUM_THREADS={} CCX_NPROC_EQUATION_SOLVER={} '{}' -i job > ccx.log 2>&1",
                  run.dir.string(), std::max(1, threads), std::max(1, threads), ccx);
  const auto start = std::chrono::steady_clock::now();
  run.status = std::system(command.c_str());
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

Error CcxRun::failure(const std::string& what) const {
  std::ifstream log(dir / "ccx.log");
  std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  if (text.size() > 600) text = "..." + text.substr(text.size() - 600);
  return Error(fmt::format("CalculiX run in {} failed: {}; end of ccx.log:\n{}", dir.string(), what, text));
}

void CcxRun::remove() const {
  std::error_code ignored;
  std::filesystem::remove_all(dir, ignored);
}

Solution solve(const BoxProblem& problem, int threads, bool partial) {
  const CcxRun run = run_ccx(write_inp(problem), threads);
  const std::filesystem::path dat_path = run.dir / "job.dat";
  Solution solution;
  solution.wall_s = run.wall_s;
  std::ifstream dat(dat_path);
  solution.nodes = mesh_nodes(problem);
  if (run.status != 0 && partial && dat) {
    // the increments ccx finished before it stopped: their reaction totals are in the .dat file (kept)
    solution.failure = run.failure(fmt::format("ccx exited with status {}", run.status)).what();
    for (size_t s = 0; s < problem.prescribed.size(); ++s) {
      std::ifstream again(dat_path);
      try {
        solution.reactions.push_back(read_dat_totals(again, fmt::format("NMOVE{}", s + 1), dat_path.string()));
      } catch (const Error&) {
        solution.reactions.emplace_back();
      }
    }
    return solution;
  }
  if (run.status != 0 || !dat) throw run.failure(fmt::format("ccx exited with status {}", run.status));
  try {
    solution.displacement = read_dat_displacements(dat, solution.nodes.cols(), dat_path.string());
    for (size_t s = 0; s < problem.prescribed.size(); ++s) {
      std::ifstream again(dat_path);
      solution.reactions.push_back(read_dat_totals(again, fmt::format("NMOVE{}", s + 1), dat_path.string()));
    }
  } catch (const Error& e) {
    throw run.failure(e.what());
  }
  run.remove();
  return solution;
}

}  // namespace pointhaptics::fem
