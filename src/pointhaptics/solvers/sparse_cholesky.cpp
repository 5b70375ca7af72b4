#include <pointhaptics/solvers/sparse_cholesky.hpp>

#include <pointhaptics/core/stoppable_call.hpp>

#include <cholmod.h>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace pointhaptics {
namespace {

using Clock = std::chrono::steady_clock;

// CHOLMOD's analysis and numeric factorisation run on a thread of their own, so that a stop is honoured while
// they run, when they are expected to take more than a few ms: above these sizes (a thread costs ~50 us)
constexpr std::size_t stoppable_analysis_entries = 100'000;  // of A's lower triangle (~300 points)
constexpr double stoppable_factorisation_flops = 2e7;        // CHOLMOD's count for L (~5 ms)
// CHOLMOD's supernodal factorisation (OpenBLAS on 2 cores), flop/s: 2e10 on an 11,016-point box (224 GFlop in
// 11 s; 7e9 on the 1,519-point cantilever's smaller supernodes). A factorisation expected to take more than 2 s is
// announced, and its progress shown
constexpr double factorisation_rate = 2e10;

// a numeric factorisation that succeeded: CHOLMOD reports a failure (not positive definite) by L->minor < n
bool positive_definite(int ok, const cholmod_common& common, const cholmod_factor* L) {
  return ok && common.status == CHOLMOD_OK && L->minor == L->n;
}

double entries_of(const cholmod_factor* L) { return static_cast<double>(L->is_super ? L->xsize : L->nzmax); }

// L's values and indices, bytes
double bytes_of(const cholmod_factor* L) {
  return entries_of(L) * static_cast<double>(sizeof(double) + (L->is_super ? 0 : sizeof(int))) +
         static_cast<double>(L->is_super ? L->ssize : L->n + 1) * sizeof(int);
}

}  // namespace

struct SparseCholesky::Factor {
  cholmod_common common;
  cholmod_sparse* A = nullptr;  // lower triangle, compressed columns over the free dofs
  cholmod_factor* L = nullptr;
  cholmod_dense *X = nullptr, *Y = nullptr, *E = nullptr;  // cholmod_solve2's result and workspace, reused
  std::vector<double> b;                                   // the right-hand side over the free dofs
  std::vector<index_t> dof;                                // the first free dof of each point, -1 when held
  std::vector<std::size_t> source;                         // A's values: their places in TangentMatrix::values
  const Model* model = nullptr;
  index_t n_points = 0, n_pairs = 0, n_free = 0;
  double flops = 0;   // of a numeric factorisation, CHOLMOD's count from the analysis
  bool good = false;  // L holds a positive definite factor

  // K's values into A (this factor's, or the worker's copy of it: the same pattern)
  void copy_values(const TangentMatrix& K, cholmod_sparse* target) const {
    double* x = static_cast<double*>(target->x);
    for (std::size_t p = 0; p < source.size(); ++p) x[p] = K.values[source[p]];
  }

  // L from A's values (on whatever thread: this factor's common serves it)
  void factorise_values() {
    const int ok = cholmod_factorize(A, L, &common);
    good = positive_definite(ok, common, L);
  }

  Factor() {
    cholmod_start(&common);
    common.print = 0;  // failures are reported by return values, never printed
  }
  ~Factor() {
    release();
    cholmod_finish(&common);
  }
  void release() {
    cholmod_free_dense(&X, &common);
    cholmod_free_dense(&Y, &common);
    cholmod_free_dense(&E, &common);
    cholmod_free_factor(&L, &common);
    cholmod_free_sparse(&A, &common);
    good = false;
  }
};

// A worker thread that factorises a copy of A into a second factor of the same analysis, with its own CHOLMOD
// workspace (a cholmod_common serves one thread at a time). The simulation's thread hands a job over and never
// waits for it unless it asks to (take_background()); the two factors are swapped when it is taken up, so the
// worker's next job refactorises the one that was in use.
struct SparseCholesky::Background {
  cholmod_common common;
  cholmod_sparse* A = nullptr;
  cholmod_factor* L = nullptr;
  bool good = false;  // the worker's last result (read after `running` is seen false)
  double seconds = 0;
  bool pending = false;          // the simulation's thread only: a job was handed over and not yet taken up
  std::function<void()> before;  // SparseCholesky::before_background_factorisation, at the hand-over
  std::mutex mutex;
  std::condition_variable wake, finished;
  bool job = false, stop = false;
  std::atomic<bool> running{false};  // a job handed over that the worker has not finished
  std::thread worker;

  Background() {
    cholmod_start(&common);
    common.print = 0;
    worker = std::thread([this] { run(); });
  }
  ~Background() {
    {
      std::lock_guard lock(mutex);
      stop = true;
    }
    wake.notify_one();
    worker.join();  // a factorisation under way cannot be interrupted: it ends first
    release();
    cholmod_finish(&common);
  }
  void release() {
    cholmod_free_factor(&L, &common);
    cholmod_free_sparse(&A, &common);
  }
  void wait() {
    std::unique_lock lock(mutex);
    finished.wait(lock, [this] { return !running.load(std::memory_order_acquire); });
  }
  // ... unless a stop is requested first (then Interrupted; the job stays pending)
  void wait_stoppable() {
    std::unique_lock lock(mutex);
    while (!finished.wait_for(lock, std::chrono::milliseconds(5),
                              [this] { return !running.load(std::memory_order_acquire); }))
      throw_if_stop_requested("a background factorisation");
  }
  void run() {
    for (;;) {
      {
        std::unique_lock lock(mutex);
        wake.wait(lock, [this] { return job || stop; });
        if (stop) return;
        job = false;
      }
      if (before) before();
      const auto start = Clock::now();
      const int ok = cholmod_factorize(A, L, &common);
      good = positive_definite(ok, common, L);
      seconds = std::chrono::duration<double>(Clock::now() - start).count();
      {
        std::lock_guard lock(mutex);
        running.store(false, std::memory_order_release);
      }
      finished.notify_all();
    }
  }
};

SparseCholesky::SparseCholesky() : factor_(std::make_shared<Factor>()) {}
SparseCholesky::~SparseCholesky() {
  // a stopped run does not wait for a background factorisation to end
  if (background_ && stop_requested()) destroy_in_background(std::move(background_));
}
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::call_on_factor(const char* where, void (*work)(Factor&), double expected_s) {
  std::shared_ptr<Factor> owner = factor_;
  try {
    call_stoppable(
        where, [owner, work] { work(*owner); }, expected_s);
  } catch (const Interrupted&) {
    factor_ = std::make_shared<Factor>();  // the abandoned one is freed when CHOLMOD is done with it
    stats_ = {};
    throw;
  }
}

bool SparseCholesky::analysed_for(const Model& model) const {
  const Factor& f = *factor_;
  if (!f.L || f.model != &model || f.n_points != model.n_points || f.n_pairs != model.n_pairs()) return false;
  return f.n_free == static_cast<index_t>(std::count(model.fixed.begin(), model.fixed.end(), 0));
}
bool SparseCholesky::factorised() const { return factor_->good; }

void SparseCholesky::drop_background() {
  if (!background_) return;
  if (background_->running.load(std::memory_order_acquire) && stop_requested()) {
    destroy_in_background(std::move(background_));
    throw Interrupted("interrupted during a background factorisation");
  }
  background_->wait();
  background_->release();  // copies of the old analysis
  background_->pending = false;
  stats_.background_bytes = 0;
}

void SparseCholesky::analyse(const Model& model, const TangentMatrix& K) {
  const auto start = Clock::now();
  drop_background();
  Factor& f = *factor_;
  f.release();
  const index_t n = model.n_points;
  f.dof.assign(n, -1);
  index_t dofs = 0;
  for (index_t i = 0; i < n; ++i)
    if (!model.fixed[i]) f.dof[i] = dofs, dofs += 3;
  // the lower triangle by columns: column (k, b) holds rows (j, a) with j after k (points in order, so free
  // dofs in order), and a >= b on the diagonal block; K is symmetric, so its value is K_kj(b, a)
  const Csr& pattern = K.pattern;
  f.source.clear();
  std::vector<int> column_start{0}, rows;
  for (index_t k = 0; k < n; ++k) {
    if (f.dof[k] < 0) continue;
    for (int b = 0; b < 3; ++b) {
      for (index_t e = pattern.begin(k); e < pattern.end(k); ++e) {
        const index_t j = pattern.index[e];
        if (j < k || f.dof[j] < 0) continue;
        for (int a = j == k ? b : 0; a < 3; ++a) {
          rows.push_back(f.dof[j] + a);
          f.source.push_back(9 * static_cast<std::size_t>(e) + b + 3 * a);
        }
      }
      column_start.push_back(static_cast<int>(rows.size()));
    }
  }
  f.A = cholmod_allocate_sparse(dofs, dofs, rows.size(), /*sorted=*/1, /*packed=*/1, /*stype=*/-1, CHOLMOD_REAL,
                                &f.common);
  std::copy(column_start.begin(), column_start.end(), static_cast<int*>(f.A->p));
  std::copy(rows.begin(), rows.end(), static_cast<int*>(f.A->i));
  // CHOLMOD tries METIS after AMD when AMD's fill is high, as it is on a small, nearly dense tangent (the
  // two-level preconditioner's coarse one: 300 unknowns). There METIS's ordering costs more than the
  // factorisation it would save (1.9 ms to analyse the 99-point coarse level of the 1,519-point cantilever),
  // so below a few thousand unknowns AMD's ordering is taken as it is
  constexpr index_t small_system = 3000;
  if (dofs < small_system) {
    f.common.nmethods = 1;
    f.common.method[0].ordering = CHOLMOD_AMD;
  } else {
    f.common.nmethods = 0;  // CHOLMOD's default strategy
  }
  const auto order = [](Factor& g) { g.L = cholmod_analyze(g.A, &g.common); };
  if (rows.size() < stoppable_analysis_entries) order(f);
  else call_on_factor("the sparse factorisation's analysis", order);
  f.flops = f.common.fl;
  f.b.assign(dofs, 0.0);
  f.model = &model;
  f.n_points = n;
  f.n_pairs = model.n_pairs();
  f.n_free = dofs / 3;
  stats_ = {};
  stats_.factor_nonzeros = f.common.lnz;
  stats_.factorisation_flops = f.flops;
  stats_.analyse_s = std::chrono::duration<double>(Clock::now() - start).count();
}

bool SparseCholesky::factorise(const TangentMatrix& K) {
  Factor& f = *factor_;
  if (!f.L) return false;
  const auto start = Clock::now();
  f.copy_values(K, f.A);
  const double expected_s = f.flops / factorisation_rate;
  if (expected_s > 2 && stats_.factorisations == 0)
    announce(fmt::format("the sparse factorisation: {} unknowns, {:.3g} GFlop, about {} per factorisation",
                         f.n_free * 3, f.flops * 1e-9, format_duration(expected_s)));
  const auto factorise_values = [](Factor& g) { g.factorise_values(); };
  if (f.flops < stoppable_factorisation_flops) factorise_values(f);
  else call_on_factor("the sparse factorisation", factorise_values, expected_s);
  // (a failed factorisation leaves L incomplete, minor < n, but reusable by the next attempt)
  ++stats_.factorisations;
  stats_.factorise_s = std::chrono::duration<double>(Clock::now() - start).count();
  if (f.good) {
    stats_.factor_nonzeros = entries_of(f.L);
    stats_.factor_bytes = bytes_of(f.L);
  }
  return f.good;
}

bool SparseCholesky::factorise_in_background(const TangentMatrix& K) {
  Factor& f = *factor_;
  if (!f.L || (background_ && background_->running.load(std::memory_order_acquire))) return false;
  if (!background_) background_ = std::make_unique<Background>();
  Background& b = *background_;
  if (!b.A) {
    // the worker's own copy of the analysis (made once per analysis; it allocates)
    b.A = cholmod_copy_sparse(f.A, &b.common);
    b.L = b.A ? cholmod_copy_factor(f.L, &b.common) : nullptr;
    if (!b.L) {
      b.release();
      return false;
    }
    stats_.background_bytes = bytes_of(b.L) + static_cast<double>(f.source.size()) * (sizeof(double) + sizeof(int));
  }
  f.copy_values(K, b.A);
  {
    std::lock_guard lock(b.mutex);
    b.before = before_background_factorisation;
    b.job = true;
    b.running.store(true, std::memory_order_relaxed);
  }
  b.wake.notify_one();
  b.pending = true;
  return true;
}

bool SparseCholesky::background_pending() const { return background_ && background_->pending; }

bool SparseCholesky::background_ready() const {
  return background_pending() && !background_->running.load(std::memory_order_acquire);
}

bool SparseCholesky::take_background() {
  if (!background_pending()) return false;
  Background& b = *background_;
  b.wait_stoppable();
  b.pending = false;
  if (!b.good) return false;
  Factor& f = *factor_;
  std::swap(f.L, b.L);  // the worker refactorises the old one next time
  f.good = true;
  ++stats_.factorisations;
  ++stats_.background_factorisations;
  stats_.factorise_s = b.seconds;
  stats_.factor_nonzeros = entries_of(f.L);
  stats_.factor_bytes = bytes_of(f.L);
  return true;
}

void SparseCholesky::solve(const Points& r, Points& z) {
  Factor& f = *factor_;
  const index_t n = f.n_points;
  for (index_t i = 0; i < n; ++i)
    if (f.dof[i] >= 0)
      for (int a = 0; a < 3; ++a) f.b[f.dof[i] + a] = r(a, i);
  cholmod_dense B{};
  B.nrow = B.d = B.nzmax = f.b.size();
  B.ncol = 1;
  B.x = f.b.data();
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  cholmod_solve2(CHOLMOD_A, f.L, &B, nullptr, &f.X, nullptr, &f.Y, &f.E, &f.common);
  const double* x = static_cast<const double*>(f.X->x);
  for (index_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) z(a, i) = f.dof[i] >= 0 ? x[f.dof[i] + a] : 0.0;
}

}  // namespace pointhaptics
