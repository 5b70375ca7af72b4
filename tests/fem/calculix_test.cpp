// Tests for fem/calculix: the .inp writer (mesh, clamps, consistent loads), the .dat reader on good and
// malformed output, and ccx itself on the seed's cantilever (docs/cantilever-calculix.md).
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/fem/calculix.hpp>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <regex>
#include <sstream>

namespace pointhaptics::fem {
namespace {

BoxProblem cantilever(double force, int nx, int ny, int nz) {
  BoxProblem p;
  p.nx = nx;
  p.ny = ny;
  p.nz = nz;
  p.clamps.push_back({Vec3(-1, -1, -1), Vec3(0, 1, 1)});
  p.tractions.push_back({{Vec3(0.15, -1, -1), Vec3(1, 1, 1)}, Vec3(0, -force, 0)});
  return p;
}

int count(const std::string& text, const std::regex& pattern) {
  return static_cast<int>(
      std::distance(std::sregex_iterator(text.begin(), text.end(), pattern), std::sregex_iterator()));
}

TEST(CalculixDeck, MeshHasTheNodesAndElementsOfAQuadraticGrid) {
  const BoxProblem p = cantilever(0.01, 2, 1, 1);
  const Points nodes = mesh_nodes(p);
  // corners 3*2*2 + mid-edges along x 2*2*2, y 3*1*2, z 3*2*1
  EXPECT_EQ(nodes.cols(), 12 + 8 + 6 + 6);
  EXPECT_NEAR(nodes.row(0).maxCoeff(), 0.15, 1e-15);
  const std::string deck = write_inp(p);
  EXPECT_NE(deck.find("TYPE=C3D20R"), std::string::npos);
  // two elements of 20 nodes, split over two lines each
  EXPECT_EQ(count(deck, std::regex("^[12], (\\d+, ){14}\\d+,\n(\\d+, ){4}\\d+$", std::regex::multiline)), 2);
  // the clamp holds the 8 nodes of the face x = 0
  const auto nset = deck.substr(deck.find("*NSET, NSET=NFIX\n") + 17);
  EXPECT_EQ(count(nset.substr(0, nset.find('*')), std::regex("\\d+")), 8);
}

TEST(CalculixDeck, TractionBecomesConsistentNodalForcesThatSumToTheTotal) {
  const BoxProblem p = cantilever(0.01, 4, 2, 2);
  const std::string deck = write_inp(p);
  std::istringstream in(deck.substr(deck.find("*CLOAD\n") + 7));
  std::string line;
  double sum = 0, corner = 0, mid = 0;
  int lines = 0;
  const Points nodes = mesh_nodes(p);
  while (std::getline(in, line) && line[0] != '*') {
    int node, dof;
    double value;
    char comma;
    std::istringstream l(line);
    ASSERT_TRUE(l >> node >> comma >> dof >> comma >> value) << line;
    EXPECT_EQ(dof, 2);
    EXPECT_NEAR(nodes(0, node - 1), 0.15, 1e-12);
    sum += value;
    ++lines;
    // the tip face's corner node (y = z = 0) belongs to one face: -1/12 of that face's load
    if (nodes(1, node - 1) == 0 && nodes(2, node - 1) == 0) corner = value;
    if (nodes(1, node - 1) == 0 && std::abs(nodes(2, node - 1) - 0.0075) < 1e-12) mid = value;
  }
  EXPECT_EQ(lines, 21);            // the 5 x 5 node face without its 4 face centres
  EXPECT_NEAR(sum, -0.01, 1e-14);  // 13 significant digits in the deck
  EXPECT_NEAR(corner, 0.01 / 4 / 12, 1e-15);
  EXPECT_NEAR(mid, -0.01 / 4 / 3, 1e-15);
}

TEST(CalculixDeck, GravityAndNonlinearStepAreWritten) {
  BoxProblem p = cantilever(0.0, 2, 1, 1);
  p.tractions.clear();
  p.gravity = Vec3(0, -9.81, 0);
  p.nlgeom = true;
  const std::string deck = write_inp(p);
  EXPECT_NE(deck.find("*STEP, NLGEOM"), std::string::npos);
  EXPECT_EQ(count(deck, std::regex("\nEALL, GRAV, 9\\.81\\d*, 0, -1, 0\n")), 1);
  EXPECT_NE(deck.find("*DENSITY\n1000"), std::string::npos);
  EXPECT_EQ(deck.find("*CLOAD"), std::string::npos);
}

TEST(CalculixDeck, MalformedProblemsAreNamedErrors) {
  BoxProblem p = cantilever(0.01, 2, 1, 1);
  p.clamps.clear();
  EXPECT_THROW(write_inp(p), Error);
  p = cantilever(0.01, 2, 1, 1);
  p.tractions[0].region = {Vec3(0.2, 0, 0), Vec3(0.3, 1, 1)};
  try {
    write_inp(p);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("covers no boundary face"), std::string::npos) << e.what();
  }
  p = cantilever(0.01, 0, 1, 1);
  EXPECT_THROW(write_inp(p), Error);
}

const char* dat_block = R"(
 displacements (vx,vy,vz) for set NALL and time  0.5000000E+00

         1  0.000000E+00  0.000000E+00  0.000000E+00
         2  1.000000E-03 -2.000000E-03  3.000000E-04
         3  1.000000E-03 -2.000000E-03  3.000000E-04
)";

const char* dat_last = R"(
 displacements (vx,vy,vz) for set NALL and time  0.1000000E+01

         3  2.000000E-03 -4.000000E-03  6.000000E-04
         1  0.000000E+00  0.000000E+00  0.000000E+00
         2  2.000000E-03 -4.000000E-03  6.000000E-04
)";

TEST(CalculixDat, ReadsTheLastDisplacementBlock) {
  std::istringstream in(std::string(dat_block) + dat_last);
  const Points u = read_dat_displacements(in, 3, "job.dat");
  EXPECT_EQ(u.col(0), Vec3::Zero());
  EXPECT_EQ(u.col(1), Vec3(2e-3, -4e-3, 6e-4));
  EXPECT_EQ(u.col(2), Vec3(2e-3, -4e-3, 6e-4));
}

void expect_error(const std::string& text, index_t n, const std::string& message) {
  std::istringstream in(text);
  try {
    read_dat_displacements(in, n, "job.dat");
    FAIL() << "no error for: " << message;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("job.dat"), std::string::npos) << e.what();
  }
}

TEST(CalculixDat, MalformedOutputIsANamedError) {
  expect_error("", 3, "no displacement block");
  expect_error(" *ERROR in ccx\n", 3, "no displacement block");
  expect_error(dat_block, 4, "lists 3 of the mesh's 4 nodes");
  expect_error(dat_block, 2, "node 3 is outside the mesh's 1..2");
  std::string text = dat_block;
  expect_error(text.replace(text.find("1.000000E-03"), 12, "1.0000x0E-03"), 3, "malformed displacement line");
  text = dat_block;
  expect_error(text.replace(text.find("1.000000E-03"), 12, "nan"), 3, "non-finite");
  text = dat_block;
  expect_error(text.replace(text.find("         3 "), 11, "         2 "), 3, "node 2 appears twice");
  expect_error(" displacements (vx,vy,vz) for set NALL\n\n 1 0 0\n", 1, "malformed");
}

TEST(CalculixRun, MissingProgramIsAClearError) {
  const char* saved = std::getenv("PH_CCX");
  ::setenv("PH_CCX", "/nonexistent/ccx", 1);
  try {
    solve(cantilever(0.01, 2, 1, 1));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("PH_CCX = \"/nonexistent/ccx\" is not an executable file"), std::string::npos);
  }
  const char* path = std::getenv("PATH");
  const std::string saved_path = path ? path : "";
  ::unsetenv("PH_CCX");
  ::setenv("PATH", "/nonexistent", 1);
  EXPECT_THROW(find_ccx(), Error);
  ::setenv("PATH", saved_path.c_str(), 1);
  if (saved) ::setenv("PH_CCX", saved, 1);
}

TEST(CalculixDeck, HyperelasticCardsCarryOurModelsConstants) {
  // neo-Hookean: C10 = mu / 2, D1 = 2 / K; Mooney-Rivlin: the split of mu and the same D1; corotated: none
  MaterialParams m;
  m.young = 1e4;
  m.poisson = 0.45;
  m.model = MaterialModel::NEO_HOOKEAN;
  BoxProblem p = cantilever(0.1, 4, 1, 1);
  set_material(p, m);
  EXPECT_EQ(p.material, FemMaterial::NEO_HOOKE);
  EXPECT_NEAR(p.c10, m.mu() / 2, 1e-9);
  EXPECT_NEAR(p.d1, 2 / m.bulk_modulus(), 1e-18);
  EXPECT_NE(write_inp(p).find(fmt::format("*HYPERELASTIC, NEO HOOKE\n{:.13g}, {:.13g}\n", p.c10, p.d1)),
            std::string::npos);
  m.model = MaterialModel::MOONEY_RIVLIN;
  m.c10 = 3, m.c01 = 1;
  set_material(p, m);
  EXPECT_NEAR(p.c10 + p.c01, m.mu() / 2, 1e-9);
  EXPECT_NEAR(p.c10 / p.c01, 3.0, 1e-12);
  EXPECT_NE(write_inp(p).find("*HYPERELASTIC, MOONEY-RIVLIN\n"), std::string::npos);
  m.model = MaterialModel::SVK;
  set_material(p, m);
  EXPECT_NE(write_inp(p).find("*ELASTIC\n"), std::string::npos);
  m.model = MaterialModel::COROTATED;
  EXPECT_THROW(set_material(p, m), Error);
}

TEST(CalculixDeck, PrescribedSetsMoveTheirFreeNodesAndPrintTheirReactions) {
  BoxProblem p = cantilever(0.0, 4, 2, 2);
  p.tractions.clear();
  Prescribed end;
  end.region = {Vec3(0.15, -1, -1), Vec3(1, 1, 1)};
  end.displacement = Vec3(0.01, 0, 0);
  p.prescribed.push_back(end);
  p.nlgeom = true;
  p.fixed_increments = 4;
  const std::string deck = write_inp(p);
  EXPECT_NE(deck.find("*NSET, NSET=NMOVE1\n"), std::string::npos);
  EXPECT_NE(deck.find("NMOVE1, 1, 1, 0.01\n"), std::string::npos);
  EXPECT_NE(deck.find("*STATIC, DIRECT\n0.25, 1.0\n"), std::string::npos);
  EXPECT_NE(deck.find("*NODE PRINT, NSET=NMOVE1, TOTALS=ONLY\nRF\n"), std::string::npos);
  p.prescribed[0].radius = 1e-6;  // a footprint that takes no node
  p.prescribed[0].centre = Vec3(0.15, 0.0151, 0.0151);
  EXPECT_THROW(write_inp(p), Error);
}

TEST(CalculixDat, ReadsTheReactionTotalsOfEachIncrement) {
  std::istringstream dat(
      " total force (fx,fy,fz) for set NMOVE1 and time  0.5000000E+00\n\n"
      "        1.000000E-01 -2.000000E+00  3.000000E-03\n\n"
      " total force (fx,fy,fz) for set NOTHIS and time  0.5000000E+00\n\n        9 9 9\n"
      " total force (fx,fy,fz) for set NMOVE1 and time  0.1000000E+01\n\n"
      "        2.000000E-01 -4.000000E+00  6.000000E-03\n");
  const std::vector<Reaction> r = read_dat_totals(dat, "NMOVE1", "job.dat");
  ASSERT_EQ(r.size(), 2u);
  EXPECT_DOUBLE_EQ(r[0].time, 0.5);
  EXPECT_DOUBLE_EQ(r[1].force.y(), -4.0);
  std::istringstream bad(" total force (fx,fy,fz) for set NMOVE1 and time  0.5\n\n   1.0 nan-ish\n");
  EXPECT_THROW(read_dat_totals(bad, "NMOVE1", "job.dat"), Error);
}

TEST(CalculixDat, ReadsOneSetsDisplacementAtEveryIncrement) {
  std::istringstream dat(
      " displacements (vx,vy,vz) for set NCENTRE and time  0.5000000E+00\n\n"
      "       247  0.000000E+00 -2.500000E-04  0.000000E+00\n\n"
      " displacements (vx,vy,vz) for set NOTHIS and time  0.5000000E+00\n\n        9 9 9 9\n"
      " displacements (vx,vy,vz) for set NCENTRE and time  0.1000000E+01\n\n"
      "       247  1.000000E-06 -5.000000E-04  0.000000E+00\n");
  const auto u = read_dat_set_displacements(dat, "NCENTRE", "job.dat");
  ASSERT_EQ(u.size(), 2u);
  EXPECT_DOUBLE_EQ(u[0].first, 0.5);
  EXPECT_DOUBLE_EQ(u[0].second.y(), -2.5e-4);
  EXPECT_DOUBLE_EQ(u[1].second.x(), 1e-6);
  std::istringstream bad(" displacements (vx,vy,vz) for set NCENTRE and time  0.5\n\n   247 1.0 nan-ish 0\n");
  EXPECT_THROW(read_dat_set_displacements(bad, "NCENTRE", "job.dat"), Error);
  std::istringstream short_line(" displacements (vx,vy,vz) for set NCENTRE and time  0.5\n\n   247 1.0\n");
  EXPECT_THROW(read_dat_set_displacements(short_line, "NCENTRE", "job.dat"), Error);
}

// ccx is installed by scripts/setup (Debian calculix-ccx); its absence is a failure here, not a skip
TEST(CalculixRun, CantileverMatchesTheReferenceValues) {
  // linear, 20 x 4 x 4 C3D20R: within ~0.4% of the converged 1.6795 mm at the tip-face centre node
  const Solution linear = solve(cantilever(0.01, 20, 4, 4), 2);
  Eigen::Index centre = -1;
  for (Eigen::Index k = 0; k < linear.nodes.cols(); ++k)
    if ((linear.nodes.col(k) - Vec3(0.15, 0.015, 0.015)).norm() < 1e-12) centre = k;
  ASSERT_GE(centre, 0);
  EXPECT_NEAR(-linear.displacement(1, centre), 1.6795e-3, 0.005 * 1.6795e-3);
  EXPECT_EQ(linear.displacement.col(0), Vec3::Zero());  // node 1 is clamped
  // NLGEOM at 0.3 N: geometric stiffening takes ~9% off (converged 4.5951e-2 m)
  BoxProblem p = cantilever(0.3, 20, 4, 4);
  p.nlgeom = true;
  const Solution nonlinear = solve(p, 2);
  EXPECT_NEAR(-nonlinear.displacement(1, centre), 4.5951e-2, 0.01 * 4.5951e-2);
}

}  // namespace
}  // namespace pointhaptics::fem
