// Several deformable bodies (issue 47): [[object]] tables with named errors, one model whose neighbour lists never
// cross between bodies, bodies that start inside each other refused, contact between them that conserves
// momentum, and a block resting on a block on a table, each carrying what is above it.
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/session/scene_builder.hpp>
#include <pointhaptics/session/interactive.hpp>
#include <pointhaptics/session/scene_session.hpp>
#include <pointhaptics/world/simulation.hpp>
#include <pointhaptics/output/vtk_output.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/surface/cut_surface.hpp>
#include <pointhaptics/surface/object_surface.hpp>

#include "support/scene_sessions.hpp"

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

using namespace pointhaptics;

namespace {

constexpr double spacing = 0.005;

// a 4 x 2 x 4 cm lower block from the origin and a 2 x 2 x 2 cm upper block centred on it, `gap` above it
std::string two_blocks(double gap, const std::string& solver, const std::string& more = "") {
  return fmt::format(R"(
[material]
young = 1e5
poisson = 0.3
density = 1000.0
damping = 20.0
[[object]]
name = "lower"
shape = "box"
size = [0.04, 0.02, 0.04]
spacing = {}
[[object]]
name = "upper"
shape = "box"
origin = [0.01, {}, 0.01]
size = [0.02, 0.02, 0.02]
spacing = {}
material = {{ young = 2e5, density = 2000.0 }}
[solver]
{}
{}
)",
                     spacing, 0.02 + gap, spacing, solver, more);
}

// the two blocks under gravity on a table (friction 0.5)
const std::string on_a_table =
    "[[load]]\nkind = \"gravity\"\n[[obstacle]]\nname = \"table\"\nfriction = 0.5\nplane = { normal = [0.0, 1.0, 0.0] }";

constexpr double lower_weight = 0.04 * 0.02 * 0.04 * 1000.0 * 9.81;  // N
constexpr double upper_weight = 0.02 * 0.02 * 0.02 * 2000.0 * 9.81;  // N

using test::error_of;
using test::two_threads;

const BodySummary& body(const RunSummary& s, const std::string& name) {
  for (const BodySummary& b : s.bodies)
    if (b.name == name) return b;
  throw Error("no body " + name);
}

TEST(Bodies, TablesAreReadAndTheirMistakesNamed) {
  const Scene scene = parse_scene(two_blocks(0.0, "kind = \"static\"",
                                             "[[fixed]]\nobject = \"lower\"\nbox = { min = [-1.0, -1.0, -1.0], max = "
                                             "[1.0, 0.0, 1.0] }\n[[load]]\nkind = \"gravity\""),
                                  "scene.toml");
  ASSERT_EQ(scene.bodies.size(), 2u);
  EXPECT_EQ(scene.bodies[1].name, "upper");
  EXPECT_EQ(scene.bodies[1].material.young, 2e5);
  EXPECT_EQ(scene.bodies[1].material.poisson, 0.3) << "the keys it leaves out are [material]'s";
  EXPECT_EQ(scene.bodies[0].material.young, 1e5);
  EXPECT_EQ(scene.fixed[0].object, "lower");
  const auto fails = [](const std::string& text, const std::string& expected) {
    const std::string message = error_of(text, false);
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  };
  fails("[[object]]\nshape = \"box\"\nsize = [0.01, 0.01, 0.01]",
        "scene.toml:1: object[0].name: an [[object]] needs a name");
  fails("[[object]]\nname = \"a\"\nsize = [0.01, 0.01, 0.01]\n[[object]]\nname = \"a\"\nsize = [0.01, 0.01, 0.01]",
        "scene.toml:4: object[1].name: \"a\" is already the name of object[0]");
  fails(two_blocks(0.0, "kind = \"static\"", "[[fixed]]\nbox = { min = [0.0, 0.0, 0.0], max = [1.0, 0.0, 1.0] }"),
        "fixed[0].object: missing: with several [[object]] tables, name the one it applies to");
  fails(two_blocks(0.0, "kind = \"static\"",
                   "[[fixed]]\nobject = \"middle\"\nbox = { min = [0.0, 0.0, 0.0], max = [1.0, 0.0, 1.0] }"),
        "fixed[0].object: no [[object]] is named \"middle\" (the objects: \"lower\", \"upper\")");
  fails(two_blocks(0.0, "kind = \"static\"", "[[load]]\nkind = \"point\"\npoint = 0\nforce = [0.0, 1.0, 0.0]"),
        "load[0].object: missing");
  fails("[object]\nsize = [0.01, 0.01, 0.01]\n[[load]]\nkind = \"gravity\"\nobject = \"a\"",
        "load[0].object: \"a\" names an [[object]], but the scene has one [object]");
  fails(two_blocks(0.0, "kind = \"explicit\"", "[lod]\ncontact = [0.0, 0.0, 0.0]"),
        "lod: not yet with several [[object]] tables");
  const std::string cut =
      "[[cut]]\nedge = [[0.0, 0.05, 0.0], [0.0, 0.05, 0.04]]\nto = [[0.04, 0.05, 0.0], [0.04, 0.05, 0.04]]";
  fails(two_blocks(0.0, "kind = \"explicit\"", cut), "cut[0].object: missing: with several [[object]] tables");
  fails(two_blocks(0.0, "kind = \"explicit\"", cut + "\nobject = \"top\""),
        "cut[0].object: no [[object]] is named \"top\"");
  std::string coloured = two_blocks(0.0, "kind = \"static\"");
  coloured.replace(coloured.find("material = {"), 12, "material = { colour = 1,");
  fails(coloured, "object[1].material.colour: unknown key");
}

// [[region]] and [[refine]] tables name their body: each body gets its own stiff region and its own finer points
// (the two refinements touch in space at y = 0.02, which two tables of one body may not), and a table naming no
// body, an unknown one, or a spacing not finer than its own body's is a named error
TEST(Bodies, EachBodyHasItsOwnRegionsAndRefinements) {
  const std::string tables = R"(
[[region]]
object = "lower"
box = { min = [-1.0, -1.0, -1.0], max = [0.01, 1.0, 1.0] }
young = 1e6
[[refine]]
object = "lower"
box = { min = [0.01, 0.01, 0.01], max = [0.03, 0.02, 0.03] }
spacing = 0.0025
[[refine]]
object = "upper"
box = { min = [0.01, 0.02, 0.01], max = [0.03, 0.03, 0.03] }
spacing = 0.0025
)";
  const Scene plain = parse_scene(two_blocks(0.0, "kind = \"static\""), "scene.toml");
  const Scene scene = parse_scene(two_blocks(0.0, "kind = \"static\"", tables), "scene.toml");
  ASSERT_EQ(scene.refine.size(), 2u);
  EXPECT_EQ(scene.refine[1].object, "upper");
  EXPECT_EQ(scene.regions[0].object, "lower");
  const Model uniform = build_scene_model(plain), model = build_scene_model(scene);
  ASSERT_EQ(model.n_bodies(), 2);
  for (int b = 0; b < 2; ++b)
    EXPECT_GT(model.body_start[b + 1] - model.body_start[b], uniform.body_start[b + 1] - uniform.body_start[b])
        << "body " << b << " gained fine points";
  ASSERT_EQ(model.support.size(), model.n_points);
  const auto young = [&](index_t i) {
    return model.point_materials[model.material_of[static_cast<std::size_t>(i)]].young;
  };
  for (int b = 0; b < 2; ++b) {
    const double lo = b == 0 ? 0.0 : 0.02, hi = b == 0 ? 0.02 : 0.04;
    index_t fine = 0;
    for (index_t i = model.body_start[b]; i < model.body_start[b + 1]; ++i) {
      ASSERT_TRUE(model.X(1, i) >= lo - 1e-12 && model.X(1, i) <= hi + 1e-12) << "a point left its body";
      fine += model.support[i] < 0.75 * model.h;
      const double expected = b == 1 ? 2e5 : model.X(0, i) <= 0.01 + 1e-9 ? 1e6 : 1e5;
      ASSERT_EQ(young(i), expected) << "point " << i << " of body " << b;
    }
    EXPECT_GT(fine, 0) << "body " << b << " has points of the fine support";
  }
  // pressed together (the lower held at its base, the upper's top moved down 0.5 mm), statically: the refined
  // bodies touch, equal and opposite, and the lower's support carries what the upper pushes
  {
    const std::string held =
        "[[fixed]]\nobject = \"lower\"\nbox = { min = [-1.0, -1.0, -1.0], max = [1.0, 0.001, 1.0] }\n"
        "[[fixed]]\nobject = \"upper\"\nbox = { min = [-1.0, 0.039, -1.0], max = [1.0, 1.0, 1.0] }\n"
        "displacement = [0.0, -0.0005, 0.0]\n";
    SceneSession s =
        open_scene(parse_scene(two_blocks(0.0, "kind = \"static\"", tables + held), "scene.toml"), two_threads());
    s.simulation->step();
    const RunSummary r = s.simulation->summary();
    ASSERT_TRUE(r.converged) << r.failure;
    const Vec3 on_lower = body(r, "lower").contact_force, on_upper = body(r, "upper").contact_force;
    EXPECT_LT(on_lower.y(), -0.05) << "pressed";
    EXPECT_LT((on_lower + on_upper).norm(), 1e-9 * on_lower.norm());
    EXPECT_NEAR(r.reactions.at(0).y(), -on_lower.y(), 1e-3 * -on_lower.y());
  }
  const std::string unnamed = "[[refine]]\nbox = { min = [0.0, 0.0, 0.0], max = [0.01, 0.01, 0.01] }\nspacing = 0.0025";
  EXPECT_NE(error_of(two_blocks(0.0, "kind = \"static\"", unnamed), false).find("refine[0].object: missing"),
            std::string::npos);
  EXPECT_NE(error_of(two_blocks(0.0, "kind = \"static\"",
                                "[[region]]\nobject = \"middle\"\nbox = { min = [0.0, 0.0, 0.0], max = [0.01, 0.01, "
                                "0.01] }\nyoung = 1e6"),
                     false)
                .find("region[0].object: no [[object]] is named \"middle\""),
            std::string::npos);
  // upper at 4 mm: 4.5 mm is finer than the lower's 5 mm, not than its own
  std::string coarse = two_blocks(0.0, "kind = \"static\"",
                                  "[[refine]]\nobject = \"upper\"\nbox = { min = [0.01, 0.02, 0.01], max = [0.03, "
                                  "0.03, 0.03] }\nspacing = 0.0045");
  coarse.replace(coarse.rfind("spacing = 0.005"), 15, "spacing = 0.004");
  EXPECT_NE(
      error_of(coarse, false)
          .find("refine[0].spacing: 0.0045 is out of range: must be finer than object \"upper\"'s spacing (0.004 m)"),
      std::string::npos)
      << error_of(coarse, false);
}

// each body is built alone: its own spacing, material and held points; no neighbour pair crosses; the point load
// indexes its own body's points
TEST(Bodies, TheModelJoinsThemWithoutANeighbourAcross) {
  const Scene scene = parse_scene(two_blocks(0.0, "kind = \"static\"",
                                             "[[fixed]]\nobject = \"upper\"\nbox = { min = [-1.0, 0.039, -1.0], max = "
                                             "[1.0, 1.0, 1.0] }\n[[load]]\nkind = \"point\"\nobject = \"upper\"\n"
                                             "point = 0\nforce = [0.0, -1.0, 0.0]"),
                                  "scene.toml");
  const Model model = build_scene_model(scene);
  ASSERT_EQ(model.n_bodies(), 2);
  const index_t lower = model.body_start[1], upper = model.n_points - lower;
  EXPECT_EQ(lower, 9 * 5 * 9);
  EXPECT_EQ(upper, 5 * 5 * 5);
  for (index_t i = 0; i < model.n_points; ++i)
    for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e) {
      const index_t j = model.neighbours.index[e];
      ASSERT_EQ(model.body_of(i), model.body_of(j)) << i << " " << j;
      ASSERT_EQ(model.neighbours.index[model.reverse_pair[e]], i);
    }
  EXPECT_NEAR(model.mass.head(lower).sum(), lower_weight / 9.81, 1e-9);
  EXPECT_NEAR(model.mass.tail(upper).sum(), upper_weight / 9.81, 1e-9);
  EXPECT_EQ(model.young_at(0), 1e5);
  EXPECT_EQ(model.young_at(lower), 2e5);
  ASSERT_EQ(model.fixed_groups.size(), 1u);
  for (index_t i : model.fixed_groups[0].points) EXPECT_EQ(model.body_of(i), 1);
  EXPECT_EQ(model.f_ext.col(lower), Vec3(0, -1, 0)) << "the point load is on the upper body's point 0";
  EXPECT_EQ(model.f_ext.col(0), Vec3::Zero());
}

TEST(Bodies, ThatStartInsideEachOtherAreRefusedByName) {
  const std::string message = error_of(two_blocks(-0.003, "kind = \"static\""));
  EXPECT_NE(message.find("object[1]: \"upper\" starts inside object[0] \"lower\""), std::string::npos) << message;
  EXPECT_EQ(error_of(two_blocks(0.0, "kind = \"static\"")), "no error") << "touching is not inside";
}

// two free blocks thrown at each other, without gravity or damping: the contact's forces are equal and opposite,
// so the total momentum stays what it was while each body's changes
TEST(Bodies, AFreeCollisionConservesMomentum) {
  std::string text = two_blocks(0.002, "kind = \"explicit\"\ndt = 1e-4");
  text.replace(text.find("damping = 20.0"), 14, "damping = 0.0");
  SceneSession s = open_scene(parse_scene(text, "scene.toml"), two_threads());
  const Model& model = s.simulation->model();
  State state = s.simulation->state();
  const index_t lower = model.body_start[1];
  for (index_t i = 0; i < model.n_points; ++i)
    state.velocity.col(i) = i < lower ? Vec3(0, 0.1, 0) : Vec3(0.02, -0.4, 0);
  s.simulation->set_state(state);
  const auto momentum = [&](index_t first, index_t end) {
    Vec3 p = Vec3::Zero();
    for (index_t i = first; i < end; ++i) p += model.mass[i] * s.simulation->state().velocity.col(i);
    return p;
  };
  const Vec3 before = momentum(0, model.n_points), upper_before = momentum(lower, model.n_points);
  Vec3 largest_change = Vec3::Zero();
  int touching = 0;
  for (int k = 0; k < 200; ++k) {
    ASSERT_NE(s.simulation->step().status, StepStatus::FAILED);
    largest_change = largest_change.cwiseMax((momentum(lower, model.n_points) - upper_before).cwiseAbs());
    touching += s.simulation->body_contact()->loads(model, s.simulation->state().u).contacts > 0;
  }
  EXPECT_GT(touching, 0);
  EXPECT_GT(largest_change.y(), 0.3 * std::abs(upper_before.y())) << "the blocks met and pushed each other";
  EXPECT_LT((momentum(0, model.n_points) - before).norm(), 1e-9 * before.norm());
}

// the lower block on a table, the upper on it, under gravity, run to rest: the upper block carried by the lower,
// the table carrying both, the bodies apart by at most a hundredth of the spacing; the result has a block per body
TEST(Bodies, ABlockOnABlockOnATableEachCarriesWhatIsAboveIt) {
  SceneSession s = open_scene(
      parse_scene(two_blocks(0.0, "kind = \"implicit\"\ndt = 2e-3\nduration = 0.5", on_a_table), "scene.toml"),
      two_threads());
  s.simulation->run(0.5);
  const RunSummary summary = s.simulation->summary();
  ASSERT_TRUE(summary.converged) << summary.failure;
  ASSERT_EQ(summary.bodies.size(), 2u);
  EXPECT_NEAR(body(summary, "upper").contact_force.y(), upper_weight, 0.005 * upper_weight);
  EXPECT_NEAR(body(summary, "lower").contact_force.y(), -upper_weight, 0.005 * upper_weight);
  EXPECT_LT(std::hypot(body(summary, "upper").contact_force.x(), body(summary, "upper").contact_force.z()),
            1e-3 * upper_weight);
  ASSERT_EQ(summary.obstacles.size(), 1u);
  EXPECT_NEAR(summary.obstacles[0].second.force.y(), -(lower_weight + upper_weight),
              0.005 * (lower_weight + upper_weight));
  EXPECT_LT(summary.body_contact.penetration, 0.01 * spacing);
  EXPECT_GT(summary.body_contact.contacts, 0);
  const nlohmann::json doc = nlohmann::json::parse(result_json(s.simulation->model(), s.simulation->state(), summary));
  EXPECT_EQ(doc["bodies"]["upper"]["points"], 125);
  EXPECT_NEAR(doc["bodies"]["upper"]["mass"].get<double>(), upper_weight / 9.81, 1e-9);
  EXPECT_LT(doc["bodies"]["upper"]["mean_displacement"][1].get<double>(), 0.0) << "it settled down";
  EXPECT_GT(doc["body_contact"]["contacts"].get<int>(), 0);
}

// the same two blocks, both free, in one static solve: the table carries both, the lower one the upper, by contact
// and friction alone (nothing held). The table's vertices touch it exactly at the start, with no multiplier: the
// solve's first tangent counts them as pressing (SurfaceContact's kink tangent); without it the stack had no
// vertical stiffness in the first Newton iteration, its CG diverged and the solve found no equilibrium at all
TEST(Bodies, TwoFreeBlocksStackedOnATableSolveStatically) {
  SceneSession s = open_scene(
      parse_scene(two_blocks(0.0, "kind = \"static\"", "[contact]\nfriction = 0.5\n" + on_a_table), "scene.toml"),
      two_threads());
  s.simulation->run(0);
  const RunSummary summary = s.simulation->summary();
  ASSERT_TRUE(summary.converged) << summary.failure;
  EXPECT_NEAR(body(summary, "upper").contact_force.y(), upper_weight, 1e-6 * upper_weight);
  EXPECT_NEAR(body(summary, "lower").contact_force.y(), -upper_weight, 1e-6 * upper_weight);
  ASSERT_EQ(summary.obstacles.size(), 1u);
  EXPECT_NEAR(summary.obstacles[0].second.force.y(), -(lower_weight + upper_weight),
              1e-6 * (lower_weight + upper_weight));
  EXPECT_LT(summary.body_contact.penetration, 0.01 * spacing);
  EXPECT_LT(summary.obstacles[0].second.penetration, 0.01 * spacing);
  const Vec3 mean = s.simulation->state().u.rowwise().mean();
  EXPECT_LT(std::hypot(mean.x(), mean.z()), 0.01 * spacing) << "friction holds them where they stood";
}

}  // namespace

namespace {

// with several bodies a ParaView series per body beside the object's: body_<name>.pvd, each frame its own points
// with their rows of the arrays, and its own part of the surface (its triangles renumbered from its first vertex)
TEST(Bodies, EachBodyHasItsOwnParaViewSeries) {
  Scene scene =
      parse_scene(two_blocks(0.001, "kind = \"implicit\"\ndt = 2e-3", "[[load]]\nkind = \"gravity\""), "scene.toml");
  SceneSession s = open_scene(scene, two_threads());
  const ObjectSurface surface = build_object_surface(s.scene, s.simulation->model());
  const std::string folder = (std::filesystem::temp_directory_path() / "ph_bodies_vtk").string();
  std::filesystem::remove_all(folder);
  VtkSeries object(folder);
  std::vector<VtkSeries> bodies = body_vtk_series(folder, s.simulation->model());
  ASSERT_EQ(bodies.size(), 2u);
  add_vtk_frame(object, *s.simulation, &surface, &bodies);
  s.simulation->step();
  add_vtk_frame(object, *s.simulation, &surface, &bodies);
  const auto text = [](const std::string& path) {
    std::ifstream in(path);
    std::stringstream all;
    all << in.rdbuf();
    return all.str();
  };
  const Model& m = s.simulation->model();
  for (std::size_t k = 0; k < 2; ++k) {
    const std::string name = k == 0 ? "lower" : "upper";
    EXPECT_EQ(bodies[k].collection_path(), folder + "/body_" + name + ".pvd");
    const std::string pvd = text(bodies[k].collection_path());
    EXPECT_NE(pvd.find("body_" + name + "_000001.vtp"), std::string::npos) << pvd;
    const std::string frame = text(folder + "/body_" + name + "_000001.vtp");
    EXPECT_NE(frame.find(fmt::format("NumberOfPoints=\"{}\"", m.body_start[k + 1] - m.body_start[k])),
              std::string::npos);
    const std::string part = text(folder + "/body_" + name + "_surface_000001.vtp");
    EXPECT_NE(part.find(fmt::format("NumberOfPoints=\"{}\"",
                                    surface.body_vertex_start[k + 1] - surface.body_vertex_start[k])),
              std::string::npos);
    EXPECT_NE(
        part.find(fmt::format("NumberOfPolys=\"{}\"", surface.body_face_start[k + 1] - surface.body_face_start[k])),
        std::string::npos);
  }
  std::filesystem::remove_all(folder);
}

// the shipped scene opens with its two layers, apart, in contact with each other and the table at the start
TEST(Bodies, TheShippedLayersSceneOpensWithTwoBodiesInContact) {
  SceneSession s = open_scene_file(PH_SCENES "/layers_on_table.toml", two_threads());
  const Model& model = s.simulation->model();
  ASSERT_EQ(model.n_bodies(), 2);
  EXPECT_EQ(model.body_names, (std::vector<std::string>{"lower", "upper"}));
  ASSERT_NE(s.simulation->body_contact(), nullptr);
  EXPECT_GT(s.simulation->body_contact()->loads(model, s.simulation->state().u).force.size(), 1u);
  s.simulation->body_contact()->refresh(model, s.simulation->state().u);
  EXPECT_GT(s.simulation->body_contact()->pairs(), 0) << "the layers' faces are paired from the start";
}

}  // namespace
namespace {

// a 2 cm block resting on a 4 x 2 x 4 cm one whose base is held (E = 100 kPa, mass-proportional `damping`), under
// gravity tilted by atan(0.2); `more` adds the contact and the solver
std::string block_on_held_block_on_a_slope(double damping, const std::string& more) {
  return fmt::format(R"(
[material]
young = 1e5
poisson = 0.3
density = 1000.0
damping = {}
[[object]]
name = "lower"
size = [0.04, 0.02, 0.04]
spacing = 0.005
[[object]]
name = "upper"
origin = [0.01, 0.02, 0.01]
size = [0.02, 0.02, 0.02]
spacing = 0.005
[[fixed]]
object = "lower"
box = {{ min = [-1.0, -1.0, -1.0], max = [1.0, 0.0, 1.0] }}
[[load]]
kind = "gravity"
g = [1.962, -9.81, 0.0]
)",
                     damping) +
         more;
}

// a block resting on another whose base is held, under gravity tilted by atan(0.2): a static solve by contact
// alone converges when the friction between them (0.5) can hold it, friction carrying the sideways weight, and
// finds no equilibrium when it cannot (0.1: the block slides off)
TEST(Bodies, FrictionHoldsABlockOnATiltedBlockInAStaticSolveOrLetsItSlide) {
  // (15 Newton iterations a solve: the held block needs fewer; the sliding one fails the same way as with the
  // default 50, in a third of the time)
  const auto scene = [](double friction) {
    return block_on_held_block_on_a_slope(
        0.0, fmt::format("[contact]\nfriction = 0.1\npairs = [{{ bodies = [\"lower\", \"upper\"], friction = {} }}]\n"
                         "[solver]\nkind = \"static\"\nmax_iterations = 15\n",
                         friction));
  };
  const double mass = 0.02 * 0.02 * 0.02 * 1000.0;
  SceneSession held = open_scene(parse_scene(scene(0.5), "scene.toml"), two_threads());
  held.simulation->run(0);
  const RunSummary summary = held.simulation->summary();
  ASSERT_TRUE(summary.converged) << summary.failure;
  const BodyLoads loads = held.simulation->body_contact()->loads(held.simulation->model(), held.simulation->state().u);
  EXPECT_NEAR(loads.friction[1].x(), -mass * 1.962, 0.005 * mass * 1.962) << "friction carries the sideways weight";
  EXPECT_NEAR(body(summary, "upper").contact_force.y(), mass * 9.81, 0.005 * mass * 9.81);
  EXPECT_LT(body(summary, "upper").mean_displacement.x(), 0.02 * spacing) << "held where it rests (the bodies sheared)";
  EXPECT_LT(summary.body_contact.penetration, 0.01 * spacing);

  SceneSession slides = open_scene(parse_scene(scene(0.1), "scene.toml"), two_threads());
  EXPECT_EQ(slides.simulation->step().status, StepStatus::FAILED);
  EXPECT_FALSE(slides.simulation->summary().converged);
}

// two elastic spheres (R = 1 cm, neo-Hookean), each held at its far cap and refined to R/8 where they meet, pressed
// together statically by moving the upper one's cap 0.6 mm: the solve converges (a vertex kept the triangle it was
// paired with while that covered it; choosing afresh at each update, the pairing flipped between two sets of
// triangles of the faceted spheres, the force by 0.6% and 4% by turns, and the solve failed after 50 updates), the
// caps' reactions are equal and opposite and along the line of centres, and neither sphere is inside the other
TEST(Bodies, TwoElasticSpheresPressedTogetherStaticallyConverge) {
  const auto sphere = [](const char* name, double centre_y, double cap_from, double cap_to, const char* more) {
    return fmt::format(R"(
[[object]]
name = "{0}"
shape = "sphere"
radius = 0.01
origin = [0.0, {1}, 0.0]
spacing = 0.0025
surface_edge = 0.000625
[[fixed]]
object = "{0}"
box = {{ min = [-0.02, {2}, -0.02], max = [0.02, {3}, 0.02] }}
{4}
[[refine]]
object = "{0}"
sphere = {{ centre = [0.0, 0.01005, 0.0], radius = 0.004 }}
spacing = 0.00125
)",
                       name, centre_y, cap_from, cap_to, more);
  };
  const std::string text =
      "[material]\nmodel = \"neo_hookean\"\nyoung = 1e5\npoisson = 0.3\n[solver]\nkind = \"static\"\n" +
      sphere("lower", 0.0, -0.02, -0.007, "") +
      sphere("upper", 0.0201, 0.0271, 0.05, "displacement = [0.0, -0.0006, 0.0]");
  SceneSession s = open_scene(parse_scene(text, "scene.toml"), two_threads());
  s.simulation->run(0);
  const RunSummary summary = s.simulation->summary();
  ASSERT_TRUE(summary.converged) << summary.failure;
  ASSERT_EQ(summary.reactions.size(), 2u);
  const Vec3 lower = summary.reactions[0], upper = summary.reactions[1];
  EXPECT_GT(lower.y(), 0.02) << "pressed together (Hertz: 0.05 N at this approach)";
  EXPECT_LT((lower + upper).norm(), 1e-6 * lower.norm()) << "equal and opposite";
  EXPECT_LT(std::hypot(lower.x(), lower.z()), 1e-3 * lower.y()) << "along the line of centres";
  EXPECT_GT(summary.body_contact.contacts, 3);
  EXPECT_LT(summary.body_contact.penetration, 0.01 * 0.00125);
}

// a block resting on a held one under gravity tilted to a slope of 0.2, friction 0.5, in explicit steps: once it has
// settled (its drop onto the contact's give rings at first) it stays where it is, pressed with its weight and held
// by friction carrying the slope's pull. With the multipliers taking a fifth of the way each step, as in implicit
// steps, the ringing went on for good (the pressure between 0.13 and 2.3 times the weight) and the block crept
// 7-10 mm/s down the slope
TEST(Bodies, ABlockOnASlopeSettlesAndHoldsInExplicitSteps) {
  const std::string text =
      block_on_held_block_on_a_slope(20.0, "[contact]\nfriction = 0.5\n[solver]\nkind = \"explicit\"\ndt = 0.001\n");
  SceneSession s = open_scene(parse_scene(text, "scene.toml"), two_threads());
  Simulation& sim = *s.simulation;
  const Model& model = sim.model();
  const auto upper_x = [&] {
    double x = 0;
    for (index_t i = model.body_start[1]; i < model.body_start[2]; ++i) x += sim.state().u(0, i);
    return x / static_cast<double>(model.body_start[2] - model.body_start[1]);
  };
  const double mass = 0.02 * 0.02 * 0.02 * 1000.0;
  sim.run(0.3);
  const double settled = upper_x();
  sim.run(0.4);
  const RunSummary summary = sim.summary();
  ASSERT_TRUE(summary.converged) << summary.failure;
  EXPECT_LT(std::abs(upper_x() - settled), 0.01 * spacing) << "crept " << upper_x() - settled << " m in 0.4 s";
  EXPECT_NEAR(body(summary, "upper").contact_force.y(), mass * 9.81, 0.02 * mass * 9.81) << "pressed with its weight";
  EXPECT_NEAR(body(summary, "upper").contact_force.x(), -mass * 1.962, 0.05 * mass * 1.962)
      << "friction carries the slope's pull";
  EXPECT_LT(summary.body_contact.penetration, 0.01 * spacing);
}

TEST(Bodies, ContactTablesAreReadAndTheirMistakesNamed) {
  const auto fails = [](const std::string& text, const std::string& expected) {
    const std::string message = error_of(text, false);
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  };
  fails(
      two_blocks(0.0, "kind = \"static\"", "[contact]\npairs = [{ bodies = [\"lower\", \"middle\"], friction = 0.2 }]"),
      "contact.pairs[0].bodies: no [[object]] is named \"middle\"");
  fails(two_blocks(0.0, "kind = \"static\"", "[contact]\nfriction = -0.2"), "contact.friction: -0.2 is out of range");
  fails(two_blocks(0.0, "kind = \"static\"", "[contact]\npairs = [{ bodies = [\"lower\"], friction = 0.2 }]"),
        "contact.pairs[0].bodies: expected bodies = [\"NAME\", \"NAME\"]");
  fails("[object]\nsize = [0.01, 0.01, 0.01]\n[contact]\nfriction = 0.3",
        "contact: [contact] is between several [[object]] tables");
}

}  // namespace

namespace {

// a slab (6 x 1 x 2 cm) held at its left end 1 cm above a block (5 x 2 x 2 cm) held at its base, both E = 1 MPa,
// under gravity; `more` adds the solver and what cuts them
std::string slab_over_block(const std::string& more) {
  return R"(
[material]
young = 1e6
poisson = 0.3
density = 1000.0
damping = 20.0
[[object]]
name = "block"
shape = "box"
origin = [0.01, 0.0, 0.0]
size = [0.05, 0.02, 0.02]
spacing = 0.005
[[object]]
name = "slab"
shape = "box"
origin = [0.0, 0.03, 0.0]
size = [0.06, 0.01, 0.02]
spacing = 0.005
[[fixed]]
object = "block"
box = { min = [-1.0, -1.0, -1.0], max = [1.0, 0.001, 1.0] }
[[fixed]]
object = "slab"
box = { min = [-1.0, -1.0, -1.0], max = [0.006, 1.0, 1.0] }
[[load]]
kind = "gravity"
)" + more;
}

// a slab held at its left end 1 cm above a block held at its base; a scripted blade drawn down through both near the
// slab's root cuts the slab alone (the one it names): its free piece falls onto the block and comes to rest there,
// the block carrying its weight; the bodies' contact then goes on over the slab's surface split along the cut
TEST(Bodies, AScriptedCutCutsTheBodyItNamesAndItsPieceFallsOntoTheOther) {
  const std::string text = slab_over_block(R"(
[[cut]]
object = "slab"
edge = [[0.0175, 0.05, -0.01], [0.0175, 0.05, 0.03]]
to = [[0.0175, 0.005, -0.01], [0.0175, 0.005, 0.03]]
start = 0.0
duration = 0.02
[solver]
kind = "implicit"
dt = 2e-3
)");
  SceneSession s = open_scene(parse_scene(text, "scene.toml"), two_threads());
  Simulation& sim = *s.simulation;
  const Model& model = sim.model();
  ASSERT_EQ(model.n_bodies(), 2);
  // the slab's piece beyond the cut: its weight is what the block must carry
  double falling = 0;
  for (index_t i = model.body_start[1]; i < model.body_start[2]; ++i)
    if (model.X(0, i) > 0.0175) falling += model.mass[i] * 9.81;
  sim.run(0.8);
  const RunSummary summary = sim.summary();
  ASSERT_TRUE(summary.converged) << summary.failure;
  // the blade passed through both, but severed the slab's pairs alone: three pieces, the block whole
  std::vector<index_t> piece_of;
  EXPECT_EQ(piece_sizes(sim.model(), piece_of).size(), 3u);
  for (index_t i = model.body_start[0]; i < model.body_start[1]; ++i)
    for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e)
      ASSERT_FALSE(!sim.model().severed.empty() && sim.model().severed[e]) << "a pair of the block was cut";
  // the piece fell the 1 cm gap and rests on the block, which carries its weight
  EXPECT_NEAR(body(summary, "block").contact_force.y(), -falling, 0.01 * falling);
  EXPECT_NEAR(body(summary, "slab").contact_force.y(), falling, 0.01 * falling);
  EXPECT_LT(summary.body_contact.penetration, 0.01 * spacing);
  index_t below = 0;
  for (index_t i = model.body_start[1]; i < model.body_start[2]; ++i)
    if (model.X(0, i) > 0.03) below += sim.state().u(1, i) < -0.009;
  EXPECT_GT(below, 0) << "the free piece came down the gap";
  EXPECT_LT(summary.kinetic_energy, 1e-6);
  // the contact goes on over the split surface: the slab's part has the cut's faces, the block's is as it was
  const ObjectSurface whole = build_object_surface(parse_scene(text, "scene.toml"), model);
  const ObjectSurface split = split_surface(whole, sim.model(), sim.cut_sheets().triangles);
  EXPECT_GT(split.cut_faces, 0);
  EXPECT_EQ(split.body_vertex_start[1], whole.body_vertex_start[1]) << "the block's surface is not split";
  EXPECT_EQ(split.body_face_start[1], whole.body_face_start[1]);
  EXPECT_GT(split.body_vertex_start[2], whole.body_vertex_start[2]) << "the slab's is";
  ASSERT_NE(sim.body_contact(), nullptr);
  EXPECT_EQ(sim.body_contact()->vertex_start(), split.body_vertex_start) << "the bodies touch by the split surface";
  EXPECT_GE(summary.cut.surface_splits, 1);
}

// the same slab and block, cut by a device's blade (a capsule 4 cm long, its edge along z) that the hand draws down
// with its button held through the slab and 8 mm into the block, then lifts: a scalpel cuts what it passes through,
// so the slab comes apart and the block is cut but stays one piece; the slab's free piece falls onto the block
TEST(Bodies, ADevicesBladeCutsEveryBodyItPassesThrough) {
  const std::string text = slab_over_block(R"(
[solver]
kind = "implicit"
dt = 2e-3
duration = 1.0
[[device]]
name = "hand"
[[tool]]
name = "scalpel"
device = "hand"
mode = "cut"
shape = "capsule"
radius = 0.001
length = 0.04
origin = [0.0175, 0.05, 0.01]
keyframes = [[0.0, 0.0, 0.0, 0.0, 1], [0.15, 0.0, -0.038, 0.0, 1], [0.2, 0.0, -0.038, 0.0, 0], [0.4, 0.0, 0.0, 0.0, 0]]
)");
  SceneSession s = open_scene(parse_scene(text, "scene.toml"), two_threads());
  Simulation& sim = *s.simulation;
  const Model& model = sim.model();
  double falling = 0;
  for (index_t i = model.body_start[1]; i < model.body_start[2]; ++i)
    if (model.X(0, i) > 0.0175) falling += model.mass[i] * 9.81;
  InteractiveOptions o = s.interactive;
  o.real_time = false;
  o.log = false;
  const InteractiveResult r = run_interactive(sim, *s.device, o);
  RunSummary summary = sim.summary();
  add_interactive_summary(summary, r);
  ASSERT_TRUE(summary.converged) << summary.failure;
  EXPECT_GT(summary.cut.sweeps, 0);
  EXPECT_GE(summary.cut.surface_splits, 1);
  // the slab in two, the block cut 8 mm deep but whole: three pieces
  std::vector<index_t> piece_of;
  EXPECT_EQ(piece_sizes(sim.model(), piece_of).size(), 3u);
  index_t block_severed = 0;
  for (index_t i = model.body_start[0]; i < model.body_start[1]; ++i)
    for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e)
      block_severed += !sim.model().severed.empty() && sim.model().severed[e];
  EXPECT_GT(block_severed, 0) << "the blade passed into the block too";
  // the slab's free piece fell onto the block, which carries its weight
  EXPECT_NEAR(body(summary, "block").contact_force.y(), -falling, 0.02 * falling);
  EXPECT_LT(summary.body_contact.penetration, 0.01 * 0.005);
}

}  // namespace

namespace {

// the shipped scene of two layers, one cut while the other is pressed: by the time the blade has passed (0.2 s) the
// upper layer is in two pieces and the lower one whole, the probe on the lower layer feels it, and the bodies touch
// by the upper layer's split surface
TEST(Bodies, TheShippedSceneCutsOneLayerWhileTheOtherIsPressed) {
  SceneSession s = open_scene_file(PH_SCENES "/two_layers_cut_and_pressed.toml", two_threads());
  InteractiveOptions options = s.interactive;
  options.real_time = false;
  options.log = false;
  options.duration = 0.25;
  const InteractiveResult result = run_interactive(*s.simulation, *s.device, options);
  const Simulation& sim = *s.simulation;
  const Model& model = sim.model();
  ASSERT_FALSE(sim.diagnostics().failed);
  std::vector<index_t> piece_of;
  const std::vector<index_t> pieces = piece_sizes(model, piece_of);
  ASSERT_EQ(pieces.size(), 3u);
  EXPECT_EQ(pieces[0], model.body_start[1]) << "the lower layer is one piece";
  EXPECT_GT(result.tool.force.y(), 0.1) << "the probe presses the lower layer";
  const RunSummary summary = s.simulation->summary();
  EXPECT_GT(body(summary, "upper").contact_force.y(), 0.5 * 0.04 * 0.01 * 0.04 * 1000.0 * 9.81)
      << "the lower layer holds the upper one up";
  EXPECT_EQ(summary.cut.surface_splits, 2) << "the probe's and the bodies' surfaces, each split once the cut stopped";
  const ObjectSurface whole = build_object_surface(s.scene, model);
  const std::vector<index_t>& touching = s.simulation->body_contact()->vertex_start();
  EXPECT_EQ(touching[1], whole.body_vertex_start[1]) << "the lower layer's surface is whole";
  EXPECT_GT(touching[2], whole.body_vertex_start[2]) << "the upper layer's is split along the cut";
}

}  // namespace

namespace {

// one body cut in two: a block held at its base, sawn through horizontally at mid-height; its top piece rests on the
// bottom one by their cut faces (without the contact between the pieces it falls through: 0.8 m in 0.4 s), and the
// base carries the whole weight
TEST(Bodies, ThePiecesOfACutBodyTouch) {
  const std::string text = R"(
[object]
shape = "box"
size = [0.02, 0.02, 0.02]
spacing = 0.0025
[material]
young = 1e5
poisson = 0.3
density = 1000.0
damping = 20.0
[[fixed]]
box = { min = [-1.0, -1.0, -1.0], max = [1.0, 0.0005, 1.0] }
[[load]]
kind = "gravity"
[[cut]]
edge = [[-0.01, 0.01125, -0.01], [-0.01, 0.01125, 0.03]]
to = [[0.03, 0.01125, -0.01], [0.03, 0.01125, 0.03]]
duration = 0.02
[solver]
kind = "implicit"
dt = 2e-3
)";
  SceneSession s = open_scene(parse_scene(text, "scene.toml"), two_threads());
  Simulation& sim = *s.simulation;
  EXPECT_EQ(sim.body_contact(), nullptr) << "one body in one piece touches nothing";
  sim.run(0.4);
  const RunSummary summary = sim.summary();
  ASSERT_TRUE(summary.converged) << summary.failure;
  const Model& model = sim.model();
  std::vector<index_t> piece_of;
  ASSERT_EQ(piece_sizes(model, piece_of).size(), 2u);
  ASSERT_NE(sim.body_contact(), nullptr);
  double top_mass = 0, top_moment = 0;
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.X(1, i) > 0.01125) {
      top_mass += model.mass[i];
      top_moment += model.mass[i] * sim.state().u(1, i);
    }
  EXPECT_GT(top_moment / top_mass, -0.05 * 0.0025) << "the top piece rests on the bottom one";
  EXPECT_TRUE(summary.body_contact.present);
  EXPECT_GT(summary.body_contact.contacts, 0);
  EXPECT_LT(summary.body_contact.penetration, 0.01 * 0.0025);
  ASSERT_EQ(summary.reactions.size(), 1u);
  const double weight = model.mass.sum() * 9.81;
  EXPECT_NEAR(summary.reactions[0].y(), weight, 0.01 * weight) << "the base carries both pieces";
  EXPECT_LT(summary.kinetic_energy, 1e-6);
  const nlohmann::json doc = nlohmann::json::parse(result_json(model, sim.state(), summary));
  EXPECT_GT(doc["body_contact"]["contacts"].get<int>(), 0);
  EXPECT_FALSE(doc.contains("bodies")) << "one body: no bodies block";
}

}  // namespace

namespace {

// two blocks apart on a table (explicit), a resting free, b held at its base: once at rest both sleep (their stencils
// are not evaluated); a hand that comes down on b wakes it and feels what it would have felt had b never slept, and
// a sleeps on, where it would have been had it stayed awake
TEST(Bodies, ABodyAtRestThatNothingTouchesSleepsAndWakesWhenTouched) {
  const auto scene = [](bool sleep) {
    return fmt::format(R"(
[material]
young = 1e5
poisson = 0.3
density = 1000.0
damping = 20.0
[[object]]
name = "a"
shape = "box"
size = [0.02, 0.01, 0.02]
spacing = 0.0025
[[object]]
name = "b"
shape = "box"
origin = [0.03, 0.0, 0.0]
size = [0.02, 0.01, 0.02]
spacing = 0.0025
[[fixed]]
object = "b"
box = {{ min = [0.0, -1.0, -1.0], max = [1.0, 0.0005, 1.0] }}
[[load]]
kind = "gravity"
[[obstacle]]
name = "table"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
[solver]
kind = "explicit"
dt = 1e-3
duration = 1.3
sleep = {}
[device]
kind = "virtual"
[probe]
radius = 0.004
origin = [0.04, 0.02, 0.01]
keyframes = [[0.0, 0.0, 0.0, 0.0], [0.8, 0.0, 0.0, 0.0], [1.1, 0.0, -0.009, 0.0], [1.3, 0.0, -0.009, 0.0]]
)",
                       sleep);
  };
  const auto run = [](const std::string& text) {
    SceneSession s = open_scene(parse_scene(text, "scene.toml"), two_threads());
    InteractiveOptions options = s.interactive;
    options.real_time = false;
    options.log = false;
    const InteractiveResult result = run_interactive(*s.simulation, *s.device, options);
    RunSummary summary = s.simulation->summary();
    add_interactive_summary(summary, result);
    return summary;
  };
  const RunSummary sleeping = run(scene(true)), awake = run(scene(false));
  ASSERT_TRUE(sleeping.converged) << sleeping.failure;
  EXPECT_TRUE(body(sleeping, "a").asleep) << "a rests, and nothing touches it";
  EXPECT_GT(body(sleeping, "a").slept_steps, 200);
  EXPECT_FALSE(body(sleeping, "b").asleep) << "the hand came down on b";
  EXPECT_GT(body(sleeping, "b").slept_steps, 50) << "b slept before the hand came";
  EXPECT_GT(sleeping.tool.force.y(), 0.1) << "b wakes under the hand, which feels it";
  EXPECT_NEAR(sleeping.tool.force.y(), awake.tool.force.y(), 0.01 * awake.tool.force.y());
  EXPECT_EQ(body(awake, "a").slept_steps, 0) << "sleep = false";
  // asleep, a stays where it came to rest
  EXPECT_NEAR(body(sleeping, "a").mean_displacement.y(), body(awake, "a").mean_displacement.y(),
              0.01 * std::abs(body(awake, "a").mean_displacement.y()));
  ASSERT_EQ(sleeping.obstacles.size(), 1u);
  const double weight = 0.02 * 0.01 * 0.02 * 1000.0 * 9.81;
  EXPECT_GT(-sleeping.obstacles[0].second.force.y(), weight) << "the table carries a, asleep on it";
}

}  // namespace
