// Tests for the reduced model's basis kept on disk ([reduction] cache): a kept basis is read back exactly and skips
// the set-up's factor; a damaged, truncated or foreign file is never used; a changed object finds no file; a cache
// that cannot be written costs the next run its set-up, never this run its result.
#include <pointhaptics/pointhaptics.hpp>
#include <pointhaptics/reduction/basis_cache.hpp>
#include <pointhaptics/reduction/reduced_solver.hpp>
#include <pointhaptics/world/model_simulation.hpp>

#include "support/test_scenes.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace pointhaptics {
namespace {

namespace fs = std::filesystem;

// a folder of its own per test, emptied first
std::string fresh_folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("ph_basis_cache_{}_{}", name, ::getpid());
  fs::remove_all(dir);
  return dir.string();
}

std::string cached_scene(const std::string& dir, const std::string& young = "") {
  std::string text = test::cantilever_scene("static");
  if (!young.empty()) text.replace(text.find("young = 1e5"), 11, "young = " + young);
  return text + fmt::format("[reduction]\nmodes = 12\ncache = \"{}\"\n", dir);
}

struct CachedRun {
  double tip = 0;
  RunSummary summary;
};

CachedRun run(const std::string& text) {
  Scene scene = parse_scene(text);
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  sim.run(scene.solver.duration);
  EXPECT_TRUE(sim.summary().converged) << sim.summary().failure;
  return {test::cantilever_tip_deflection(sim.model(), sim.state().u), sim.summary()};
}

TEST(BasisCache, ASecondRunReadsTheKeptBasisAndGivesTheSameAnswerWithoutTheFactor) {
  const std::string dir = fresh_folder("second");
  const CachedRun first = run(cached_scene(dir));
  EXPECT_FALSE(first.summary.reduction.from_cache);
  EXPECT_GT(first.summary.reduction.factorise_s, 0);
  ASSERT_FALSE(first.summary.reduction.cache_file.empty());
  EXPECT_TRUE(fs::exists(first.summary.reduction.cache_file));
  EXPECT_EQ(fs::path(first.summary.reduction.cache_file).parent_path(), fs::path(dir));
  EXPECT_TRUE(first.summary.reduction.cache_note.empty()) << first.summary.reduction.cache_note;

  const CachedRun second = run(cached_scene(dir));
  EXPECT_TRUE(second.summary.reduction.from_cache);
  EXPECT_EQ(second.summary.reduction.factorise_s, 0);
  EXPECT_EQ(second.summary.reduction.cache_file, first.summary.reduction.cache_file);
  // the same basis, bit for bit, and the same answer (the polynomial's tables are summed in a fixed order)
  EXPECT_EQ(second.tip, first.tip);
  EXPECT_EQ(second.summary.reduction.first_frequency_hz, first.summary.reduction.first_frequency_hz);
  EXPECT_EQ(second.summary.reduction.linear_modes, first.summary.reduction.linear_modes);
  EXPECT_EQ(second.summary.reduction.derivatives, first.summary.reduction.derivatives);
  // the result JSON says where the basis came from
  Scene scene = parse_scene(cached_scene(dir));
  Simulation sim(build_scene_model(scene), scene.solver, 2);
  const auto json = nlohmann::json::parse(result_json(sim.model(), sim.state(), sim.summary()));
  EXPECT_TRUE(json.at("reduction").at("from_cache").get<bool>());
  EXPECT_EQ(json.at("reduction").at("cache_file").get<std::string>(), first.summary.reduction.cache_file);

  // another material is another basis: a file of its own, and the first one untouched
  const CachedRun stiffer = run(cached_scene(dir, "2e5"));
  EXPECT_FALSE(stiffer.summary.reduction.from_cache);
  EXPECT_NE(stiffer.summary.reduction.cache_file, first.summary.reduction.cache_file);
  EXPECT_NEAR(stiffer.tip, first.tip / 2, 0.05 * first.tip);
  fs::remove_all(dir);
}

TEST(BasisCache, ADamagedTruncatedOrForeignFileIsNeverUsed) {
  const std::string dir = fresh_folder("damaged");
  const CachedRun first = run(cached_scene(dir));
  const std::string file = first.summary.reduction.cache_file;
  ASSERT_TRUE(fs::exists(file));
  const auto size = fs::file_size(file);
  Scene scene = parse_scene(cached_scene(dir));
  const Model model = build_scene_model(scene);
  ModalBasisSettings settings;
  settings.size = 12;
  const std::uint64_t key = basis_key(model, settings, 0.0);
  EXPECT_EQ(basis_cache_file(dir, key), file);
  const CachedBasis good = read_basis_cache(file, key, model.n_points, 12);
  ASSERT_TRUE(good.basis) << good.why;
  EXPECT_EQ(good.basis->U.rows(), 3 * model.n_points);
  EXPECT_EQ(good.basis->U.cols(), 12);

  const auto expect_refused = [&](const std::string& what, const std::string& because) {
    const CachedBasis read = read_basis_cache(file, key, model.n_points, 12);
    EXPECT_FALSE(read.basis) << what;
    EXPECT_FALSE(read.missing) << what;
    EXPECT_NE(read.why.find(because), std::string::npos) << what << ": " << read.why;
  };
  // one number changed in the middle of the basis
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(size / 2));
    f.put('\x5a');
  }
  expect_refused("a byte changed", "checksum");
  // the run then makes the basis again, says so, and keeps the good one over the damaged file
  const CachedRun rebuilt = run(cached_scene(dir));
  EXPECT_FALSE(rebuilt.summary.reduction.from_cache);
  EXPECT_NE(rebuilt.summary.reduction.cache_note.find("checksum"), std::string::npos)
      << rebuilt.summary.reduction.cache_note;
  EXPECT_EQ(rebuilt.tip, first.tip);
  EXPECT_TRUE(read_basis_cache(file, key, model.n_points, 12).basis);
  // cut short
  fs::resize_file(file, size - 100);
  expect_refused("truncated", "truncated");
  // another format
  {
    std::ofstream f(file, std::ios::binary | std::ios::trunc);
    f << "not a basis at all";
  }
  expect_refused("another format", "not a basis file");
  // another key or shape: another object's file under this name
  fs::remove(file);
  EXPECT_TRUE(read_basis_cache(file, key, model.n_points, 12).missing);
  run(cached_scene(dir));
  const CachedBasis other_key = read_basis_cache(file, key + 1, model.n_points, 12);
  EXPECT_FALSE(other_key.basis);
  EXPECT_NE(other_key.why.find("another object"), std::string::npos) << other_key.why;
  EXPECT_FALSE(read_basis_cache(file, key, model.n_points, 11).basis);
  fs::remove_all(dir);
}

TEST(BasisCache, TheKeyFollowsWhatTheBasisDependsOn) {
  const Model model = build_scene_model(parse_scene(cached_scene("x")));
  ModalBasisSettings settings;
  settings.size = 12;
  const std::uint64_t key = basis_key(model, settings, 0.0);
  EXPECT_EQ(basis_key(build_scene_model(parse_scene(cached_scene("x"))), settings, 0.0), key);
  EXPECT_NE(basis_key(build_scene_model(parse_scene(cached_scene("x", "2e5"))), settings, 0.0), key);
  EXPECT_NE(basis_key(model, settings, 0.01), key);
  ModalBasisSettings more = settings;
  more.size = 13;
  EXPECT_NE(basis_key(model, more, 0.0), key);
  Model held = model;
  held.fixed[static_cast<std::size_t>(model.n_points) - 1] = 1;
  EXPECT_NE(basis_key(held, settings, 0.0), key);
  Model loaded = model;
  loaded.f_ext(1, 0) += 1e-3;
  EXPECT_NE(basis_key(loaded, settings, 0.0), key);
}

TEST(BasisCache, ACacheThatCannotBeWrittenLeavesTheRunWhole) {
  // the folder's place is taken by a file: nothing can be kept, the run goes on and says why
  const std::string blocker = fresh_folder("blocked");
  { std::ofstream(blocker) << "a file"; }
  const CachedRun run_without = run(cached_scene(blocker + "/inside"));
  EXPECT_FALSE(run_without.summary.reduction.from_cache);
  EXPECT_TRUE(run_without.summary.reduction.cache_file.empty());
  EXPECT_NE(run_without.summary.reduction.cache_note.find("not kept"), std::string::npos)
      << run_without.summary.reduction.cache_note;
  fs::remove(blocker);
  // and none asked for: nothing read or written
  Scene none = parse_scene(test::cantilever_scene("static") + "[reduction]\nmodes = 12\ncache = \"none\"\n");
  EXPECT_TRUE(none.solver.reduction.cache.empty());
  ModelSimulation sim(build_scene_model(none), none.solver, 2);
  EXPECT_TRUE(dynamic_cast<const ReducedSolver&>(sim.solver_impl()).cache_file().empty());
  // the default is the user's cache folder
  EXPECT_EQ(parse_scene(test::cantilever_scene("static") + "[reduction]\nmodes = 12\n").solver.reduction.cache, "auto");
  EXPECT_THROW(parse_scene(test::cantilever_scene("static") + "[reduction]\nmodes = 12\ncache = \"\"\n"), Error);
}

}  // namespace
}  // namespace pointhaptics
