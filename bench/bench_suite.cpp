#include "bench_suite.hpp"

#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/geometry/sampling.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <random>

namespace pointhaptics::bench {
namespace {

// a cube-ish box of about n points, h = 2 spacing (~26 neighbours inside), default material
const Model& bench_model(int n) {
  static std::map<int, std::unique_ptr<Model>> cache;
  auto& slot = cache[n];
  if (!slot) {
    const int side = std::max(2, static_cast<int>(std::lround(std::cbrt(static_cast<double>(n)))));
    const double spacing = 0.005;
    const PointCloud cloud = sample_box(Vec3::Zero(), Vec3::Constant(spacing * (side - 1)), spacing);
    slot = std::make_unique<Model>(build_model(cloud, MaterialParams{}, KernelParams{}));
  }
  return *slot;
}

Points random_displacement(const Model& model) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1e-3 * model.spacing);
  Points u(3, model.n_points);
  for (Eigen::Index k = 0; k < u.size(); ++k) u.data()[k] = noise(rng);
  return u;
}

void set_counters(benchmark::State& state, const Model& model, int threads) {
  const double evaluations = static_cast<double>(state.iterations()) * model.n_points;
  state.counters["points"] = model.n_points;
  state.counters["threads"] = threads;
  state.counters["neighbours_per_point"] = static_cast<double>(model.n_pairs()) / model.n_points;
  state.counters["point_steps_per_s"] = benchmark::Counter(evaluations, benchmark::Counter::kIsRate);
  state.counters["ns_per_pair"] = benchmark::Counter(static_cast<double>(state.iterations()) * model.n_pairs() * 1e-9,
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void force_benchmark(benchmark::State& state) {
  const Model& model = bench_model(static_cast<int>(state.range(0)));
  const int threads = static_cast<int>(state.range(1));
  Workspace ws(model, threads);
  const Points u = random_displacement(model);
  for (auto _ : state) {
    compute_internal_forces(model, u, ws);
    benchmark::DoNotOptimize(ws.f_int.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, model, threads);
}

void step_benchmark(benchmark::State& state) {
  const Model& model = bench_model(static_cast<int>(state.range(0)));
  const int threads = static_cast<int>(state.range(1));
  Workspace ws(model, threads);
  State s = State::at_rest(model);
  s.u = random_displacement(model);
  const double dt = stable_time_step(model);
  for (auto _ : state) {
    explicit_step(model, s, ws, dt, dt);  // exactly one sub-step
    benchmark::DoNotOptimize(s.u.data());
  }
  set_counters(state, model, threads);
}

// collects each run's counters for the JSON while the console reporter prints the table
class CollectingReporter : public benchmark::ConsoleReporter {
 public:
  nlohmann::json force = nlohmann::json::array(), step = nlohmann::json::array();
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred) continue;
      nlohmann::json row;
      for (const char* key : {"points", "threads", "neighbours_per_point", "ns_per_pair", "point_steps_per_s"}) {
        auto it = run.counters.find(key);
        row[key] = it == run.counters.end() ? 0.0 : static_cast<double>(it->second.value);
      }
      row["points"] = static_cast<long long>(row["points"].get<double>());
      row["threads"] = static_cast<int>(row["threads"].get<double>());
      (run.benchmark_name().rfind("forces", 0) == 0 ? force : step).push_back(row);
    }
  }
};

}  // namespace

int run_bench_suite(const BenchOptions& options) {
  for (int n : options.sizes)
    for (int t : options.threads) {
      benchmark::RegisterBenchmark(fmt::format("forces/points:{}/threads:{}", n, t).c_str(), force_benchmark)
          ->Args({n, t})->Unit(benchmark::kMicrosecond)->MinTime(options.min_time)->UseRealTime();
      benchmark::RegisterBenchmark(fmt::format("step/points:{}/threads:{}", n, t).c_str(), step_benchmark)
          ->Args({n, t})->Unit(benchmark::kMicrosecond)->MinTime(options.min_time)->UseRealTime();
    }
  std::string filter_flag = "--benchmark_filter=" + options.filter;
  std::string name = "pointhaptics-bench";
  char* argv[] = {name.data(), filter_flag.data(), nullptr};
  int argc = 2;
  benchmark::Initialize(&argc, argv);
  CollectingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  if (!options.json_path.empty()) {
    std::ofstream out(options.json_path);
    if (!out) {
      fmt::print(stderr, "pointhaptics bench: cannot write {}\n", options.json_path);
      return 1;
    }
    out << nlohmann::json{{"force", reporter.force}, {"step", reporter.step}}.dump(1) << '\n';
  }
  return 0;
}

}  // namespace pointhaptics::bench
