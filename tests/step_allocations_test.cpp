// Tests that a simulation step allocates no memory and keeps the state's buffers (NumPy views point into
// them), for every solver kind. The program replaces malloc to count allocations.
#include <pointhaptics/pointhaptics.hpp>

#include <pointhaptics/reduction/modal_basis.hpp>
#include <pointhaptics/reduction/reduced_integrator.hpp>

#include "support/test_models.hpp"
#include "support/test_scenes.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>

// every allocation, C++'s and Eigen's (which calls malloc itself), goes through malloc: count it there.
// Sanitizers bring their own malloc, so those builds check the buffers only.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define PH_COUNTS_ALLOCATIONS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define PH_COUNTS_ALLOCATIONS 0
#endif
#endif
#ifndef PH_COUNTS_ALLOCATIONS
#define PH_COUNTS_ALLOCATIONS 1
#endif

namespace {
std::atomic<long long> allocations{0};
}  // namespace

#if PH_COUNTS_ALLOCATIONS
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void* malloc(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  *out = __libc_memalign(alignment, size);
  return *out ? 0 : ENOMEM;
}
}
#endif

namespace pointhaptics {
namespace {

// "implicit" or "implicit_viscoelastic" (the same beam with a Prony series: its history is updated each step),
// "implicit_cholesky" (its Cholesky preconditioner: the factor made in the first step is reused),
// "implicit_two_level" (the coarse level made in the first step is reused)
Simulation beam(const std::string& kind) {
  const bool viscous = kind.ends_with("_viscoelastic");
  const std::string preconditioner = kind.ends_with("_cholesky")    ? "cholesky"
                                     : kind.ends_with("_two_level") ? "two_level"
                                                                    : "";
  std::string text = test::cantilever_scene(kind.substr(0, kind.find('_')), "2e-3");
  if (viscous) text.replace(text.find("damping"), 0, "prony = [[0.3, 0.05], [0.2, 1.0]]\n");
  if (!preconditioner.empty())
    text.replace(text.find("[solver]") + 9, 0, "preconditioner = \"" + preconditioner + "\"\n");
  const Scene scene = parse_scene(text);
  return Simulation(build_scene_model(scene), scene.solver, 1);
}

class StepTest : public ::testing::TestWithParam<std::string> {};

TEST_P(StepTest, KeepsTheStateBuffersAndAllocatesNothing) {
  Simulation sim = beam(GetParam());
  const double* u = sim.state().u.data();
  const double* v = sim.state().velocity.data();
  sim.step();  // the first step may size what it keeps
  const long long before = allocations.load();
  for (int k = 0; k < 5; ++k) sim.step();
  const long long made = allocations.load() - before;
  // a refactorisation allocates CHOLMOD's workspace; a step that reuses the factor allocates nothing
  if (GetParam().ends_with("_cholesky")) {
    EXPECT_EQ(sim.summary().factorisations, 1);
  }
  if (GetParam().ends_with("_two_level")) {
    EXPECT_GT(sim.summary().coarse_points, 8) << "the coarse level is in use";
  }
  EXPECT_EQ(sim.state().u.data(), u) << "the displacement buffer was replaced: a NumPy view of it would go stale";
  EXPECT_EQ(sim.state().velocity.data(), v);
  if (PH_COUNTS_ALLOCATIONS) {
    EXPECT_EQ(made, 0) << "allocations in 5 " << GetParam() << " steps";
    // the count does see allocations, Eigen's included
    const long long probe = allocations.load();
    const Eigen::VectorXd scratch = Eigen::VectorXd::Ones(1000);
    EXPECT_GT(allocations.load(), probe);
    EXPECT_EQ(scratch.sum(), 1000.0);
  }
  EXPECT_LT(sim.state().u.minCoeff(), -1e-6);  // the beam did move
}

INSTANTIATE_TEST_SUITE_P(Solvers, StepTest,
                         ::testing::Values("explicit", "implicit", "static", "explicit_viscoelastic",
                                           "implicit_viscoelastic", "static_viscoelastic", "implicit_cholesky",
                                           "implicit_two_level"),
                         [](const auto& info) { return info.param; });

// a reduced step (issue 49): the polynomial's products and Newton in r unknowns, all on kept scratch
TEST(ReducedStep, AllocatesNothing) {
  MaterialParams m;
  m.young = 1e5;
  m.poisson = 0.3;
  Model model = build_model(test::jittered_box(10, 3, 3, 0.01, 0.1), m, KernelParams{});
  for (index_t i = 0; i < model.n_points; ++i) model.fixed[static_cast<std::size_t>(i)] = model.X(0, i) < 0.005;
  model.f_ext.setZero(3, model.n_points);
  model.f_ext.row(1).setConstant(-1e-3);
  Workspace ws(model, 2);
  ModalBasisSettings settings;
  settings.size = 8;
  const ModalBasis basis = build_modal_basis(model, settings, ws);
  const SvkPolynomial polynomial(model, basis.U, ws);
  ReducedIntegrator integrator(
      polynomial, basis.U.transpose() * Eigen::Map<const Eigen::VectorXd>(model.f_ext.data(), model.f_ext.size()), 5.0);
  ReducedState state{Eigen::VectorXd::Zero(8), Eigen::VectorXd::Zero(8)};
  ASSERT_TRUE(integrator.step(state, 1e-3).converged);
  const long long before = allocations.load();
  int converged = 0;
  for (int k = 0; k < 20; ++k) converged += integrator.step(state, 1e-3).converged;
  const long long made = allocations.load() - before;
  EXPECT_EQ(converged, 20);
  if (PH_COUNTS_ALLOCATIONS) {
    EXPECT_EQ(made, 0) << "allocations in 20 reduced steps";
  }
  EXPECT_GT(state.q.norm(), 0);
}

}  // namespace
}  // namespace pointhaptics
