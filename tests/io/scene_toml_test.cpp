// Tests for io/scene_toml: the schema of design.md and one-line errors naming file, line and key.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/scene_toml.hpp>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace pointhaptics {
namespace {

const char* full_scene = R"(
[object]
shape   = "box"
size    = [0.15, 0.03, 0.03]
origin  = [0.0, 0.0, 0.0]
spacing = 0.0075
[material]
young = 1e5
poisson = 0.4
density = 1000.0
volume_stiffness = 0.0
damping = 2
hourglass = 0.05
volume = "kernel"
[kernel]
type = "quadratic"
support_factor = 2.5
[[fixed]]
box = { min = [-1.0, -1.0, -1.0], max = [0.0, 1.0, 1.0] }
[[fixed]]
box = { min = [0.15, -1.0, -1.0], max = [1.0, 1.0, 1.0] }
displacement = [0.0, -0.005, 0.0]
ramp = 0.5
[[load]]
kind  = "traction"
box   = { min = [0.15, -1.0, -1.0], max = [1.0, 1.0, 1.0] }
total = [0.0, -0.01, 0.0]
[[load]]
kind = "gravity"
g = [0, -9.81, 0]
[[load]]
kind = "point"
point = 111
force = [1, 2, 3]
[solver]
kind = "explicit"
dt = 2e-3
duration = 0.5
)";

TEST(SceneToml, ReadsEveryKeyOfTheSchema) {
  const Scene s = parse_scene(full_scene, "full.toml");
  EXPECT_EQ(s.object.shape, ShapeKind::BOX);
  EXPECT_DOUBLE_EQ(s.object.size.x(), 0.15);
  EXPECT_DOUBLE_EQ(s.object.spacing, 0.0075);
  EXPECT_DOUBLE_EQ(s.material.damping, 2.0);  // an integer where a float is expected is fine
  EXPECT_EQ(s.material.volume, VolumeMode::KERNEL);
  EXPECT_EQ(s.kernel.type, KernelType::QUADRATIC);
  EXPECT_DOUBLE_EQ(s.kernel.support_factor, 2.5);
  ASSERT_EQ(s.fixed.size(), 2u);
  EXPECT_DOUBLE_EQ(s.fixed[1].displacement.y(), -0.005);
  EXPECT_DOUBLE_EQ(s.fixed[1].ramp, 0.5);
  ASSERT_EQ(s.loads.size(), 3u);
  EXPECT_EQ(s.loads[0].kind, LoadKind::TRACTION);
  EXPECT_DOUBLE_EQ(s.loads[0].total.y(), -0.01);
  EXPECT_EQ(s.loads[1].kind, LoadKind::GRAVITY);
  EXPECT_EQ(s.loads[2].kind, LoadKind::POINT);
  EXPECT_EQ(s.loads[2].point, 111);
  EXPECT_EQ(s.solver.kind, SolverKind::EXPLICIT);
  EXPECT_DOUBLE_EQ(s.solver.dt, 2e-3);
  EXPECT_DOUBLE_EQ(s.solver.duration, 0.5);
}

// the error message of parsing `base` (the full scene by default) with one line replaced
std::string error_of(const std::string& find, const std::string& replace, const std::string& base = full_scene) {
  std::string text = base;
  const size_t at = text.find(find);
  EXPECT_NE(at, std::string::npos) << find;
  text.replace(at, find.size(), replace);
  try {
    parse_scene(text, "bad.toml");
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
    return what;
  }
  ADD_FAILURE() << "accepted: " << replace;
  return {};
}

int line_of(const std::string& needle) {
  std::string text = full_scene;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(text.find(needle)), '\n'));
}

TEST(SceneToml, UnknownKeyNamesFileLineAndKey) {
  const std::string e = error_of("damping = 2", "dampnig = 2");
  EXPECT_EQ(e, "bad.toml:" + std::to_string(line_of("damping = 2")) + ": material.dampnig: unknown key");
}

TEST(SceneToml, UnknownSectionAndNestedKeys) {
  EXPECT_NE(error_of("[solver]", "[solvr]").find("solvr: unknown key"), std::string::npos);
  EXPECT_NE(
      error_of("max = [0.0, 1.0, 1.0] }", "max = [0.0, 1.0, 1.0], mid = 1 }").find("fixed[0].box.mid: unknown key"),
      std::string::npos);
  EXPECT_NE(error_of("g = [0, -9.81, 0]", "gg = [0, -9.81, 0]").find("load[1].gg: unknown key"), std::string::npos);
}

TEST(SceneToml, WrongTypesAreNamed) {
  EXPECT_NE(error_of("young = 1e5", "young = \"stiff\"").find("material.young: expected a number, got a string"),
            std::string::npos);
  EXPECT_NE(error_of("size    = [0.15, 0.03, 0.03]", "size = [0.15, 0.03]").find("object.size: expected an array of 3"),
            std::string::npos);
  EXPECT_NE(error_of("point = 111", "point = 1.5").find("load[2].point: expected an integer"), std::string::npos);
  EXPECT_NE(error_of("type = \"quadratic\"", "type = 3").find("kernel.type: expected a string"), std::string::npos);
}

TEST(SceneToml, OutOfRangeValuesAreNamed) {
  const std::string poisson = error_of("poisson = 0.4", "poisson = 0.5");
  EXPECT_EQ(poisson, "bad.toml:" + std::to_string(line_of("poisson = 0.4")) +
                         ": material.poisson: 0.5 is out of range: must lie in (-1, 0.5)");
  EXPECT_NE(error_of("young = 1e5", "young = -5e4").find("material.young: -50000 is out of range"), std::string::npos);
  EXPECT_NE(error_of("density = 1000.0", "density = nan").find("material.density: nan is not a finite number"),
            std::string::npos);
  EXPECT_NE(error_of("spacing = 0.0075", "spacing = 0").find("object.spacing"), std::string::npos);
  // the surface's edge: positive, and not so fine that a surface of it could not be held
  for (const char* edge : {"spacing = 0.0075\nsurface_edge = -0.001", "spacing = 0.0075\nsurface_edge = 1e-9"})
    EXPECT_NE(error_of("spacing = 0.0075", edge).find("object.surface_edge"), std::string::npos) << edge;
  EXPECT_DOUBLE_EQ(parse_scene(std::string(full_scene)).object.surface_edge, 0.0);  // default: half the spacing
  std::string with_edge = full_scene;
  with_edge.replace(with_edge.find("spacing = 0.0075"), 16, "spacing = 0.0075\nsurface_edge = 0.002");
  EXPECT_DOUBLE_EQ(parse_scene(with_edge).object.surface_edge, 0.002);
  EXPECT_NE(error_of("dt = 2e-3", "dt = -1").find("solver.dt"), std::string::npos);
  EXPECT_NE(error_of("point = 111", "point = -3").find("load[2].point"), std::string::npos);
  EXPECT_NE(error_of("max = [0.0, 1.0, 1.0] }", "max = [-2.0, 1.0, 1.0] }").find("fixed[0].box"), std::string::npos);
}

TEST(SceneToml, UnknownChoicesListTheAllowedOnes) {
  EXPECT_NE(error_of("type = \"quadratic\"", "type = \"gauss\"")
                .find("unknown value \"gauss\" (expected poly6 | spiky | viscosity | quadratic)"),
            std::string::npos);
  EXPECT_NE(error_of("shape   = \"box\"", "shape = \"cube\"").find("object.shape"), std::string::npos);
  EXPECT_NE(error_of("kind = \"explicit\"", "kind = \"rk4\"").find("solver.kind"), std::string::npos);
  // the material model: one table of names (core/parameters.hpp) for the scene, the CLI and Python
  EXPECT_NE(
      error_of("young = 1e5", "model = \"jelly\"\nyoung = 1e5")
          .find("material.model: unknown value \"jelly\" (expected svk | neo_hookean | mooney_rivlin | corotated)"),
      std::string::npos);
  std::string svk = full_scene;
  svk.replace(svk.find("young = 1e5"), 11, "model = \"svk\"\nyoung = 1e5");
  EXPECT_EQ(parse_scene(svk).material.model, MaterialModel::SVK);
}

TEST(SceneToml, ThePreconditionerIsChosen) {
  // the full scene with `lines` added to its [solver]
  const auto with_solver = [](const std::string& lines) {
    std::string text = full_scene;
    text.replace(text.find("dt = 2e-3"), 9, "dt = 2e-3\n" + lines);
    return parse_scene(text);
  };
  EXPECT_EQ(parse_scene(std::string(full_scene)).solver.preconditioner, Preconditioner::BLOCK_JACOBI);
  const Scene scene = with_solver("preconditioner = \"cholesky\"\nrefactor_iterations = 4");
  EXPECT_EQ(scene.solver.preconditioner, Preconditioner::CHOLESKY);
  EXPECT_EQ(scene.solver.refactor_iterations, 4);
  EXPECT_EQ(with_solver("preconditioner = \"two_level\"").solver.preconditioner, Preconditioner::TWO_LEVEL);
  EXPECT_NE(error_of("dt = 2e-3", "dt = 2e-3\npreconditioner = \"ilu\"")
                .find("solver.preconditioner: unknown value \"ilu\" (expected block_jacobi | cholesky | two_level)"),
            std::string::npos);
  EXPECT_NE(error_of("dt = 2e-3", "dt = 2e-3\nrefactor_iterations = 0").find("solver.refactor_iterations"),
            std::string::npos);
  // where its refactorisations run
  EXPECT_EQ(scene.solver.refactorisation, Refactorisation::AUTO);
  EXPECT_EQ(with_solver("refactorisation = \"background\"").solver.refactorisation, Refactorisation::BACKGROUND);
  EXPECT_NE(error_of("dt = 2e-3", "dt = 2e-3\nrefactorisation = \"later\"")
                .find("solver.refactorisation: unknown value \"later\" (expected auto | in_place | background)"),
            std::string::npos);
}

TEST(SceneToml, MooneyRivlinTakesC10C01AndBulkInsteadOfYoungAndPoisson) {
  const std::string material = "young = 1e5\npoisson = 0.4";
  std::string text = full_scene;
  text.replace(text.find(material), material.size(), "model = \"mooney_rivlin\"\nc10 = 3000\nc01 = 1000\nbulk = 2e5");
  const MaterialParams m = parse_scene(text).material;
  EXPECT_EQ(m.model, MaterialModel::MOONEY_RIVLIN);
  EXPECT_DOUBLE_EQ(m.c10, 3000);
  EXPECT_NEAR(m.mu(), 2 * (3000 + 1000), 1e-9);  // young and poisson follow: the small-strain moduli
  EXPECT_NEAR(m.bulk_modulus(), 2e5, 1e-6);
  EXPECT_NE(error_of(material, "c10 = 3000\nc01 = 1000\nbulk = 2e5")
                .find("material.c10: c10, c01 and bulk are Mooney-Rivlin's"),
            std::string::npos);
  EXPECT_NE(error_of(material, "model = \"mooney_rivlin\"\nc10 = 3000").find("give all of c10, c01 and bulk"),
            std::string::npos);
  EXPECT_NE(
      error_of(material, "model = \"mooney_rivlin\"\nyoung = 1e5\nc10 = 3000\nc01 = 1\nbulk = 2e5").find("not both"),
      std::string::npos);
}

TEST(SceneToml, PronySeriesIsReadAndChecked) {
  const std::string material = "young = 1e5";
  std::string text = full_scene;
  text.replace(text.find(material), material.size(), "young = 1e5\nprony = [[0.3, 0.1], [0.2, 2]]");
  const MaterialParams m = parse_scene(text).material;
  ASSERT_EQ(m.prony.size(), 2u);
  EXPECT_DOUBLE_EQ(m.prony[1].g, 0.2);
  EXPECT_DOUBLE_EQ(m.prony[1].tau, 2.0);
  EXPECT_DOUBLE_EQ(m.prony_total(), 0.5);
  EXPECT_TRUE(parse_scene(full_scene).material.prony.empty());
  // the row that breaks the rule is named, with the rule
  const std::string sum = error_of(material, "young = 1e5\nprony = [[0.6, 0.1],\n [0.5, 2]]");
  EXPECT_NE(sum.find("material.prony: expected [[g, tau], ...]"), std::string::npos) << sum;
  EXPECT_NE(sum.find(":" + std::to_string(line_of(material) + 2) + ":"), std::string::npos) << sum;
  for (const char* bad :
       {"prony = [[0, 1]]", "prony = [[0.5, 0]]", "prony = [[0.5]]", "prony = []", "prony = 0.5",
        "prony = [[0.5, nan]]",
        "prony = [[0.1, 1], [0.1, 1], [0.1, 1], [0.1, 1], [0.1, 1], [0.1, 1], [0.1, 1], [0.1, 1], [0.1, 1]]"})
    EXPECT_NE(error_of(material, std::string("young = 1e5\n") + bad).find("material.prony"), std::string::npos) << bad;
}

TEST(SceneToml, RegionsTakeASelectorAndAnyOfTheMaterialKeys) {
  std::string text =
      std::string(full_scene) +
      "\n[[region]]\nsphere = { centre = [0.05, 0.015, 0.015], radius = 0.01 }\nyoung = 1e6\n"
      "model = \"neo_hookean\"\n\n[[region]]\nbox = { min = [0, 0, 0], max = [0.01, 0.03, 0.03] }\ndensity = 2000\n";
  const Scene s = parse_scene(text);
  ASSERT_EQ(s.regions.size(), 2u);
  EXPECT_EQ(*s.regions[0].young, 1e6);
  EXPECT_EQ(*s.regions[0].model, MaterialModel::NEO_HOOKEAN);
  EXPECT_FALSE(s.regions[0].poisson.has_value());
  EXPECT_EQ(*s.regions[1].density, 2000);
  EXPECT_FALSE(s.regions[1].young.has_value());
  const std::string bad =
      std::string(full_scene) + "\n[[region]]\nsphere = { centre = [0, 0, 0], radius = 0.01 }\nyoung = -3\n";
  try {
    parse_scene(bad, "bad.toml");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("region[0].young"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_scene(std::string(full_scene) + "\n[[region]]\nyoung = 1e6\n"), Error);  // no selector
  EXPECT_THROW(parse_scene(std::string(full_scene) +
                           "\n[[region]]\nbox = { min = [0, 0, 0], max = [1, 1, 1] }\nstiffness = 3\n"),
               Error);
}

TEST(SceneToml, FixedRegionsAreCheckedAndNamed) {
  const std::string box = "box = { min = [-1.0, -1.0, -1.0], max = [0.0, 1.0, 1.0] }";
  EXPECT_NE(error_of(box, "ramp = 0.0").find("give exactly one of box"), std::string::npos);
  EXPECT_NE(error_of(box, "sphere = { centre = [0, 0, 0] }").find("a sphere needs centre"), std::string::npos);
  EXPECT_NE(error_of(box, "sphere = { centre = [0, 0, 0], radius = -1 }").find("radius"), std::string::npos);
  EXPECT_NE(error_of(box, "cylinder = { centre = [0, 0, 0], axis = [0, 0, 0], radius = 1, half_length = 1 }")
                .find("axis: must not be zero"),
            std::string::npos);
  EXPECT_NE(error_of(box, "cylinder = { centre = [0, 0, 0], axis = [0, 1, 0], radius = 1 }").find("half_length"),
            std::string::npos);
  EXPECT_NE(error_of(box, "sphere = { centre = [0, 0, 0], radius = 1, colour = 2 }").find("colour"), std::string::npos);
  std::string text = full_scene;
  text.replace(text.find(box), box.size(),
               "cylinder = { centre = [0, 0, 0], axis = [0, 2, 0], radius = 0.01, half_length = 0.02 }");
  const Scene s = parse_scene(text);
  ASSERT_TRUE(s.fixed[0].cylinder.has_value());
  EXPECT_LE((s.fixed[0].cylinder->axis - Vec3::UnitY()).norm(), 1e-15);  // normalised
  EXPECT_FALSE(s.fixed[0].sphere.has_value());
}

TEST(SceneToml, MissingRequiredKeys) {
  EXPECT_NE(error_of("total = [0.0, -0.01, 0.0]", "").find("load[0].total"), std::string::npos);
  EXPECT_NE(error_of("size    = [0.15, 0.03, 0.03]", "").find("object.size"), std::string::npos);
  EXPECT_THROW(parse_scene("[material]\nyoung = 1e5\n"), Error);  // no [object]
}

TEST(SceneToml, SyntaxErrorNamesTheLine) {
  const std::string e = error_of("density = 1000.0", "density = = 1000.0");
  EXPECT_NE(e.find("bad.toml:" + std::to_string(line_of("density = 1000.0")) + ": TOML syntax error"),
            std::string::npos)
      << e;
}

TEST(SceneToml, DeeplyNestedKeysAreANamedErrorNotACrash) {
  // issue 21: a dotted key or table header of some ten thousand levels overflowed toml++'s recursion
  const std::string object = "[object]\nshape = \"box\"\nsize = [0.1, 0.1, 0.1]\nspacing = 0.05\n";
  std::string chain = "a";
  for (int k = 0; k < 100000; ++k) chain += ".a";
  std::string quoted = object;  // a quoted key first, on the line after a header
  quoted.append("[x]\n\"a\" . ").append(chain).append(" = 1\n");
  const std::pair<std::string, int> cases[] = {
      {object + chain + " = 1\n", 5}, {object + "[" + chain + "]\nx = 1\n", 5}, {quoted, 6}};
  for (const auto& [text, line] : cases) {
    try {
      parse_scene(text, "deep.toml");
      ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("deep.toml:" + std::to_string(line) +
                                           ": a key or table header nested more than 64 levels deep"),
                std::string::npos)
          << e.what();
    }
  }
  // dots in values, strings and comments are not keys: many on one line are fine
  std::string floats = "keyframes = [";
  for (int k = 0; k < 200; ++k) floats.append(fmt::format("[{}.5, 0.0, 0.5, 0.0], ", k));
  const std::string fine =
      object +
      "# a.b.c.d.e.f.g.h.i.j.k.l.m.n.o.p.q.r.s.t.u.v.w.x.y.z.a.b.c.d.e.f.g.h.i.j.k.l.m.n.o.p.q.r.s.t.u.v.w.x.y.z.a\n"
      "[probe]\n" +
      floats + "]\n";
  EXPECT_NO_THROW(parse_scene(fine, "fine.toml"));
}

TEST(SceneToml, ReadsTheLodSection) {
  const std::string lod =
      "[lod]\nk1 = 1.5\nk2 = 2\nlevels = [ { distance = 2.5, K = 6 }, { distance = 4.0, K = 8 } ]\n"
      "seed = 7\nscheme = \"dither\"\nreselect = 0.25\nmin_neighbours = 10\nmax_widening = 2.5\n"
      "contact = [0.1, 0.03, 0.0]\n[solver]";
  std::string text = full_scene;
  text.replace(text.find("[solver]"), 8, lod);
  const Scene s = parse_scene(text, "lod.toml");
  ASSERT_TRUE(s.lod.present);
  EXPECT_DOUBLE_EQ(s.lod.params.k1, 1.5);
  EXPECT_DOUBLE_EQ(s.lod.params.k2, 2.0);
  ASSERT_EQ(s.lod.params.levels.size(), 2u);
  EXPECT_DOUBLE_EQ(s.lod.params.levels[1].distance, 4.0);
  EXPECT_EQ(s.lod.params.levels[1].K, 8);
  EXPECT_EQ(s.lod.params.seed, 7u);
  EXPECT_EQ(s.lod.params.scheme, LodScheme::DITHER);
  EXPECT_DOUBLE_EQ(s.lod.params.reselect, 0.25);
  EXPECT_EQ(s.lod.params.min_neighbours, 10);
  EXPECT_DOUBLE_EQ(s.lod.params.max_widening, 2.5);
  EXPECT_DOUBLE_EQ(s.lod.contact.x(), 0.1);
  EXPECT_FALSE(parse_scene(full_scene).lod.present);
}

TEST(SceneToml, BadLodSectionsNameTheKey) {
  auto lod_error = [](const std::string& body) { return error_of("[solver]", "[lod]\n" + body + "\n[solver]"); };
  EXPECT_NE(lod_error("k1 = 2\nk2 = 1").find("lod.k2"), std::string::npos);
  EXPECT_NE(lod_error("levels = [ { distance = 1.0, K = 6 } ]").find("lod.levels.distance"), std::string::npos);
  EXPECT_NE(lod_error("levels = [ { distance = 3.0, K = 11 } ]").find("lod.levels.K"), std::string::npos);
  EXPECT_NE(lod_error("levels = [ { distance = 3.0, K = 8 }, { distance = 4.0, K = 6 } ]").find("non-decreasing"),
            std::string::npos);
  EXPECT_NE(lod_error("levels = [ { distance = 3.0 } ]").find("both distance and K"), std::string::npos);
  EXPECT_NE(lod_error("levels = [ { distance = 3.0, K = 6, w = 1 } ]").find("lod.levels.w: unknown key"),
            std::string::npos);
  EXPECT_NE(lod_error("scheme = \"blue\"").find("lod.scheme"), std::string::npos);
  EXPECT_NE(lod_error("reselect = 0").find("lod.reselect"), std::string::npos);
  EXPECT_NE(lod_error("seed = -1").find("lod.seed"), std::string::npos);
  EXPECT_NE(lod_error("k3 = 1").find("lod.k3: unknown key"), std::string::npos);
  // the scene has a point load (a contact point); without one and without a probe, contact is needed
  std::string no_contact = "[object]\nshape = \"box\"\nsize = [0.1, 0.02, 0.02]\nspacing = 0.01\n[lod]\nk1 = 1.0\n";
  try {
    parse_scene(no_contact, "nc.toml");
    ADD_FAILURE() << "a [lod] without a contact point was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("lod.contact"), std::string::npos) << e.what();
  }
}

TEST(SceneToml, FilesAreReadAndRelativePathsResolved) {
  const auto dir = std::filesystem::temp_directory_path() / "ph_scene_test";
  std::filesystem::create_directories(dir);
  const auto path = dir / "cloud_scene.toml";
  std::ofstream(path) << "[object]\nshape = \"file\"\nfile = \"cloud.xyz\"\nspacing = 0.01\n";
  const Scene s = read_scene_file(path.string());
  EXPECT_EQ(s.object.file, (dir / "cloud.xyz").string());
  try {
    read_scene_file((dir / "missing.toml").string());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.toml"), std::string::npos);
  }
}

}  // namespace
}  // namespace pointhaptics

namespace pointhaptics {
namespace {

const char* probe_section = R"(
[probe]
radius = 0.01
mode = "grab"
keyframes = [[0.0, 0.0, 0.0, 0.0], [1.0, 0.0, -0.01, 0.0, 1]]
origin = [0.07, 0.05, 0.015]
scale = 2.0
[device]
kind = "virtual"
specs = "omni"
)";

TEST(SceneToml, ReadsProbeAndDevice) {
  const Scene s = parse_scene(std::string(full_scene) + probe_section, "p.toml");
  EXPECT_TRUE(s.probe.present);
  EXPECT_DOUBLE_EQ(s.probe.radius, 0.01);
  EXPECT_TRUE(s.probe.grab);
  ASSERT_EQ(s.probe.keyframes.size(), 2u);
  EXPECT_DOUBLE_EQ(s.probe.keyframes[1][2], -0.01);
  EXPECT_DOUBLE_EQ(s.probe.keyframes[1][4], 1.0);
  EXPECT_DOUBLE_EQ(s.probe.origin.x(), 0.07);
  EXPECT_DOUBLE_EQ(s.probe.scale, 2.0);
  EXPECT_EQ(s.device.specs, "omni");
  EXPECT_EQ(s.device.max_torque, 0.0);
  // custom specs with a torque (a device with six output degrees of freedom)
  std::string six_dof = std::string(full_scene) + probe_section;
  six_dof.replace(
      six_dof.find("specs = \"omni\""), 14,
      "specs = \"custom\"\nmax_force = 3.0\nmax_stiffness = 500.0\nworkspace_radius = 0.1\nmax_torque = 0.05");
  EXPECT_DOUBLE_EQ(parse_scene(six_dof, "p.toml").device.max_torque, 0.05);
  // a trajectory file is resolved against the scene's folder
  std::string text = std::string(full_scene) + "[probe]\ntrajectory = \"probe.csv\"\n";
  EXPECT_EQ(parse_scene(text, "dir/p.toml", "dir").probe.trajectory, "dir/probe.csv");
}

// a tool held at a position (issue 16): a static indentation, its shape and pose
const char* held_tool_section = R"(
[probe]
radius = 0.01
position = [0.0, 0.06, 0.0]
shape = "capsule"
length = 0.02
orientation = [0.0, 1.0, 0.0, 0.0]
friction = 0.3
)";

TEST(SceneToml, ReadsAHeldTool) {
  std::string text = std::string(full_scene) + held_tool_section;
  text.replace(text.find("kind = \"explicit\""), 17, "kind = \"static\"");
  const Scene s = parse_scene(text, "t.toml", ".");
  EXPECT_TRUE(s.probe.held());
  EXPECT_TRUE(s.probe.capsule);
  EXPECT_DOUBLE_EQ(s.probe.length, 0.02);
  EXPECT_DOUBLE_EQ(s.probe.position.y(), 0.06);
  EXPECT_DOUBLE_EQ(s.probe.orientation[1], 1.0);
  EXPECT_DOUBLE_EQ(s.probe.friction, 0.3);
}

TEST(SceneToml, BadHeldToolIsANamedError) {
  const std::string text = std::string(full_scene) + held_tool_section;
  const auto error = [&](const std::string& find, const std::string& replace) { return error_of(find, replace, text); };
  EXPECT_NE(error("length = 0.02", "").find("probe.length: a capsule needs length > 0"), std::string::npos);
  EXPECT_NE(error("shape = \"capsule\"", "").find("only a capsule has a length"), std::string::npos);
  EXPECT_NE(error("friction = 0.3", "friction = -1").find("probe.friction"), std::string::npos);
  EXPECT_NE(error("shape = \"capsule\"", "shape = \"cone\"").find("probe.shape: unknown value \"cone\""),
            std::string::npos);
  EXPECT_NE(error("[0.0, 1.0, 0.0, 0.0]", "[1.0, 1.0, 0.0, 0.0]").find("norm is 1.41421, not 1"), std::string::npos);
  EXPECT_NE(error("[0.0, 1.0, 0.0, 0.0]", "[1.0, 0.0]").find("unit quaternion [w, x, y, z]"), std::string::npos);
  EXPECT_NE(
      error("length = 0.02", "length = 0.02\nkeyframes = [[0.0, 0.0, 0.0, 0.0]]").find("no trajectory or keyframes"),
      std::string::npos);
  EXPECT_NE(error("friction = 0.3", "friction = 0.3\n[device]\nkind = \"virtual\"").find("not driven by a [device]"),
            std::string::npos);
}

// A [probe] key with two values: off by default, on when the other value is given, and an unknown value named.
template <class Flag>
void expect_probe_choice(const std::string& key, const std::string& value, Flag flag) {
  const std::string probe = "\n[probe]\nkeyframes = [[0.0, 0.0, 0.0, 0.0]]\n";
  EXPECT_FALSE(flag(parse_scene(std::string(full_scene) + probe, "t.toml", ".").probe)) << key;
  EXPECT_TRUE(flag(parse_scene(std::string(full_scene) + probe + key + " = \"" + value + "\"\n", "t.toml", ".").probe))
      << key;
  EXPECT_NE(error_of("keyframes = [[0.0, 0.0, 0.0, 0.0]]", "keyframes = [[0.0, 0.0, 0.0, 0.0]]\n" + key + " = \"soft\"",
                     std::string(full_scene) + probe)
                .find("probe." + key + ": unknown value \"soft\""),
            std::string::npos)
      << key;
}

TEST(SceneToml, TheLocalModelsStiffnessIsChosen) {
  expect_probe_choice("local_stiffness", "object", [](const ProbeSpec& p) { return p.object_stiffness; });
}

TEST(SceneToml, TheContactsSurfaceMapIsChosen) {
  expect_probe_choice("surface_map", "non_negative", [](const ProbeSpec& p) { return p.non_negative_surface_map; });
}

// The contact's samples along the surface's edges: the tool's radius by default (0), a spacing given in m,
// and one that is not positive named.
TEST(SceneToml, ThePassivityControllerIsOnUnlessTurnedOff) {
  const std::string text = std::string(full_scene) + probe_section;
  EXPECT_TRUE(parse_scene(text, "p.toml").device.passivity_control);
  EXPECT_FALSE(parse_scene(text + "passivity_control = false\n", "p.toml").device.passivity_control);
  const std::string error = error_of("specs = \"omni\"", "specs = \"omni\"\npassivity_control = 1", text);
  EXPECT_NE(error.find("device.passivity_control: expected true or false, got an integer"), std::string::npos) << error;
}

TEST(SceneToml, TheContactsSampleSpacingIsGiven) {
  const std::string text = std::string(full_scene) + held_tool_section;
  EXPECT_EQ(parse_scene(text, "t.toml", ".").probe.sample_spacing, 0.0);
  EXPECT_EQ(parse_scene(text + "sample_spacing = 0.002\n", "t.toml", ".").probe.sample_spacing, 0.002);
  const std::string error = error_of("friction = 0.3", "friction = 0.3\nsample_spacing = 0.0", text);
  EXPECT_NE(error.find("probe.sample_spacing: 0 is out of range: must lie in (0, 1]"), std::string::npos) << error;
}

TEST(SceneToml, AHeldToolPressesAlongItsDirection) {
  std::string text = std::string(full_scene) + held_tool_section;
  EXPECT_EQ(parse_scene(text, "t.toml", ".").probe.direction, Vec3(0, -1, 0));  // the default
  text += "direction = [0.0, 0.0, -2.0]\n";
  EXPECT_EQ(parse_scene(text, "t.toml", ".").probe.direction, Vec3(0, 0, -1));  // normalised
  EXPECT_NE(error_of("direction = [0.0, 0.0, -2.0]", "direction = [0.0, 0.0, 0.0]", text)
                .find("probe.direction: must not be zero"),
            std::string::npos);
  EXPECT_NE(error_of("position = [0.0, 0.06, 0.0]", "", text).find("probe.direction: only a tool held at a position"),
            std::string::npos);
}

// A setting (--set, a study's parameter) changes a key as if the file said it, makes missing tables, indexes
// arrays of tables, and its errors name the setting.
TEST(SceneToml, SettingsChangeKeysAndTheirErrorsNameThem) {
  const std::vector<SceneSetting> settings = {
      parse_scene_setting("material.young=2e5"), parse_scene_setting("material.model=neo_hookean"),
      parse_scene_setting("load.0.total=[0, -0.5, 0]"), parse_scene_setting("lod.k1=0.5")};
  const Scene s = parse_scene(full_scene, "t.toml", ".", settings);
  EXPECT_DOUBLE_EQ(s.material.young, 2e5);
  EXPECT_EQ(s.material.model, MaterialModel::NEO_HOOKEAN);
  EXPECT_DOUBLE_EQ(s.loads[0].total.y(), -0.5);
  EXPECT_DOUBLE_EQ(s.material.poisson, 0.4);  // the rest as the file says
  EXPECT_TRUE(s.lod.present);                 // a missing table is made
  EXPECT_DOUBLE_EQ(s.lod.params.k1, 0.5);
  const auto error = [](const std::string& setting) {
    try {
      parse_scene(full_scene, "t.toml", ".", {parse_scene_setting(setting)});
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("material.young=-1"),
            "t.toml: material.young (set to -1): -1 is out of range: must lie in (0, 1e13] (Pa)");
  EXPECT_NE(error("material.young=abc").find("material.young (set to abc): expected a number, got a string"),
            std::string::npos);
  EXPECT_NE(error("load.7.total=[0, 0, 0]").find("\"7\" is not an index of the array (it has 3 entries)"),
            std::string::npos);
  EXPECT_NE(error("material.young.x=1").find("\"young\" is a value, not a table"), std::string::npos);
  EXPECT_NE(error("materia.young=1").find("materia (made for the setting materia.young=1): unknown key"),
            std::string::npos);
  EXPECT_NE(error("material.poisson=[1").find("not a TOML value"), std::string::npos);
  EXPECT_NE(error("material..young=1").find("an empty key on the path"), std::string::npos);
  EXPECT_THROW(parse_scene_setting("young"), Error);
  EXPECT_THROW(parse_scene_setting("=1"), Error);
}

TEST(SceneToml, ReadsRefineRegionsAndNamesTheirErrors) {
  const std::string refine = "\n[[refine]]\nsphere = { centre = [0.0, 0.03, 0.0], radius = 0.01 }\nspacing = 0.003\n";
  const Scene s = parse_scene(std::string(full_scene) + refine, "t.toml", ".");
  ASSERT_EQ(s.refine.size(), 1u);
  EXPECT_DOUBLE_EQ(s.refine[0].spacing, 0.003);
  ASSERT_TRUE(s.refine[0].sphere.has_value());
  EXPECT_DOUBLE_EQ(s.refine[0].bounds().max.y(), 0.04);
  const std::string text = std::string(full_scene) + refine;
  EXPECT_NE(error_of("spacing = 0.003", "", text).find("needs spacing"), std::string::npos);
  EXPECT_NE(error_of("spacing = 0.003", "spacing = 0.0075", text)
                .find("refine[0].spacing: 0.0075 is out of range: must be finer"),
            std::string::npos);
  EXPECT_NE(error_of("spacing = 0.003", "spacing = 0.0001", text).find("at least a twentieth"), std::string::npos);
  EXPECT_NE(error_of("sphere = {", "box = { min = [0.0, 0.0, 0.0], max = [0.01, 0.01, 0.01] }\nsphere = {", text)
                .find("exactly one of box"),
            std::string::npos);
}

TEST(SceneToml, ReadsScriptedCutsAndNamesTheirErrors) {
  const std::string cut =
      "\n[[cut]]\nedge = [[0.02, 0.05, -0.01], [0.02, 0.05, 0.05]]\nto = [[0.02, -0.01, -0.01], [0.02, -0.01, 0.05]]\n"
      "start = 0.1\nduration = 0.05\n";
  const std::string text = std::string(full_scene) + cut;
  const Scene s = parse_scene(text, "t.toml", ".");
  ASSERT_EQ(s.cuts.size(), 1u);
  EXPECT_DOUBLE_EQ(s.cuts[0].edge[1].z(), 0.05);
  EXPECT_DOUBLE_EQ(s.cuts[0].to[0].y(), -0.01);
  EXPECT_DOUBLE_EQ(s.cuts[0].start, 0.1);
  EXPECT_DOUBLE_EQ(s.cuts[0].duration, 0.05);
  EXPECT_NE(
      error_of("to = [[0.02, -0.01, -0.01], [0.02, -0.01, 0.05]]", "", text).find("cut[0].to: a [[cut]] needs edge"),
      std::string::npos);
  EXPECT_NE(error_of("to = [[0.02, -0.01, -0.01], [0.02, -0.01, 0.05]]", "to = [[0.02, -0.01, -0.01]]", text)
                .find("cut[0].to"),
            std::string::npos);
  EXPECT_NE(error_of("[0.02, 0.05, 0.05]]", "[0.02, 0.05, -0.01]]", text).find("zero length"), std::string::npos);
  EXPECT_NE(error_of("duration = 0.05", "duration = -1", text).find("cut[0].duration: -1 is out of range"),
            std::string::npos);
  EXPECT_NE(error_of("start = 0.1", "start = 0.1\nspeed = 2", text).find("cut[0].speed: unknown key"),
            std::string::npos);
  // with levels of detail too (a cut in the active set reaches the object)
  std::string with_lod = text;
  with_lod.replace(with_lod.find("[solver]"), 8, "[lod]\nk1 = 1.5\ncontact = [0.0, 0.0, 0.0]\n[solver]");
  const Scene cut_lod = parse_scene(with_lod, "t.toml", ".");
  EXPECT_TRUE(cut_lod.lod.present);
  EXPECT_EQ(cut_lod.cuts.size(), 1u);
}

std::string probe_error(const std::string& find, const std::string& replace) {
  return error_of(find, replace, std::string(full_scene) + probe_section);
}

TEST(SceneToml, ABladeIsACapsuleThatCutsAndNamesItsErrors) {
  std::string blade = std::string(full_scene) + probe_section;
  blade.replace(blade.find("mode = \"grab\""), 13,
                "mode = \"cut\"\nshape = \"capsule\"\nlength = 0.04\ncut_resistance = 200");
  const Scene s = parse_scene(blade, "t.toml", ".");
  EXPECT_TRUE(s.probe.cut);
  EXPECT_FALSE(s.probe.grab);
  EXPECT_DOUBLE_EQ(s.probe.cut_resistance, 200);
  EXPECT_NE(error_of("shape = \"capsule\"\nlength = 0.04\n", "", blade)
                .find("probe.shape: a blade (mode = \"cut\") is a capsule"),
            std::string::npos);
  EXPECT_NE(
      error_of("cut_resistance = 200", "cut_resistance = -1", blade).find("probe.cut_resistance: -1 is out of range"),
      std::string::npos);
  EXPECT_NE(probe_error("mode = \"grab\"", "mode = \"grab\"\ncut_resistance = 5").find("only a blade cuts"),
            std::string::npos);
  std::string blade_lod = blade;
  blade_lod.replace(blade_lod.find("[solver]"), 8, "[lod]\nk1 = 1.5\n[solver]");
  const Scene cutting_lod = parse_scene(blade_lod, "t.toml", ".");
  EXPECT_TRUE(cutting_lod.probe.cut && cutting_lod.lod.present);
}

TEST(SceneToml, ADevicesProbeHasFrictionButNotOnThePointSpheresOfLevelsOfDetail) {
  std::string with_friction = std::string(full_scene) + probe_section;
  with_friction.replace(with_friction.find("radius = 0.01"), 13, "radius = 0.01\nfriction = 0.3");
  EXPECT_DOUBLE_EQ(parse_scene(with_friction, "t.toml", ".").probe.friction, 0.3);
  EXPECT_NE(error_of("[solver]", "[lod]\nk1 = 1.5\n[solver]", with_friction)
                .find("probe.friction: a device's probe with levels of detail touches the point spheres"),
            std::string::npos);
}

TEST(SceneToml, BadProbeOrDeviceIsANamedError) {
  EXPECT_NE(probe_error("radius = 0.01", "radius = -1").find("probe.radius"), std::string::npos);
  EXPECT_NE(probe_error("mode = \"grab\"", "mode = \"poke\"").find("probe.mode: unknown value \"poke\""),
            std::string::npos);
  EXPECT_NE(probe_error("[1.0, 0.0, -0.01, 0.0, 1]", "[0.0, 0.0, -0.01]").find("probe.keyframes"), std::string::npos);
  EXPECT_NE(probe_error("[1.0, 0.0, -0.01, 0.0, 1]", "[0.0, 0.0, -0.01, 0.0]").find("times must increase"),
            std::string::npos);
  EXPECT_NE(probe_error("keyframes = [[0.0, 0.0, 0.0, 0.0], [1.0, 0.0, -0.01, 0.0, 1]]", "").find("needs trajectory"),
            std::string::npos);
  EXPECT_NE(probe_error("specs = \"omni\"", "specs = \"custom\"").find("custom specs need"), std::string::npos);
  const std::string custom = "specs = \"custom\"\nmax_force = 3.0\nmax_stiffness = 500.0\nworkspace_radius = 0.1\n";
  EXPECT_NE(probe_error("specs = \"omni\"", custom + "max_torque = -0.1")
                .find("device.max_torque: -0.1 is out of range: must lie in [0, 100]"),
            std::string::npos);
  EXPECT_NE(probe_error("specs = \"omni\"", "max_torque = 0.1").find("device.max_torque: unknown key"),
            std::string::npos);
  EXPECT_NE(probe_error("kind = \"virtual\"", "kind = \"replay\"").find("needs log"), std::string::npos);
  EXPECT_NE(
      probe_error("kind = \"virtual\"", "kind = \"openhaptics\"\nlibary = \"x.so\"").find("device.libary: unknown key"),
      std::string::npos);
  EXPECT_NE(probe_error("kind = \"explicit\"", "kind = \"static\"").find("give position = [x, y, z]"),
            std::string::npos);
  EXPECT_NE(probe_error("scale = 2.0", "scael = 2.0").find("probe.scael: unknown key"), std::string::npos);
}

}  // namespace
}  // namespace pointhaptics
