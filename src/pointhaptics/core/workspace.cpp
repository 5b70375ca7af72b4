#include <pointhaptics/core/workspace.hpp>

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <sched.h>

#include <algorithm>
#include <thread>

namespace pointhaptics {

struct Workspace::ThreadPool {
  explicit ThreadPool(int n) : arena(n) {}
  tbb::task_arena arena;
};

int available_cores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

Workspace::Workspace(const Model& model, int n_threads) : n_points_(model.n_points) {
  if (n_threads <= 0) n_threads = available_cores();
  // a chunk per thread, but never a chunk without points
  n_threads_ = std::max(1, std::min<int>(n_threads, std::max<index_t>(1, model.n_points)));
  chunk_offset_.resize(n_threads_ + 1);
  // chunks split the stencils evenly; the last one also takes the passive points (no stencil)
  const std::int64_t stencils = model.n_points - model.n_passive;
  for (int c = 0; c < n_threads_; ++c) chunk_offset_[c] = static_cast<index_t>(stencils * c / n_threads_);
  chunk_offset_[n_threads_] = model.n_points;
  // the columns each chunk scatters into: its own points and their neighbours
  scatter_range_.resize(2 * n_threads_);
  const Csr& nbr = model.neighbours;
  const bool has_neighbours = nbr.n_rows() == model.n_points;
  for (int c = 0; c < n_threads_; ++c) {
    index_t lo = chunk_offset_[c], hi = chunk_offset_[c + 1];
    for (index_t i = chunk_offset_[c]; has_neighbours && i < chunk_offset_[c + 1]; ++i)
      for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
        lo = std::min(lo, nbr.index[e]);
        hi = std::max(hi, nbr.index[e] + 1);
      }
    scatter_range_[2 * c] = lo;
    scatter_range_[2 * c + 1] = hi;
  }
  f_int = Points::Zero(3, model.n_points);
  acceleration = Points::Zero(3, model.n_points);
  padded_u = PaddedPoints::Zero(4, model.n_points);
  if (!model.material.prony.empty()) overstress = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, model.n_points);
  gradients = PaddedGradients::Zero(12, model.n_points);
  chunk_scalars.assign(static_cast<std::size_t>(n_threads_), 0.0);
  chunk_forces.assign(n_threads_, PaddedPoints::Zero(4, model.n_points));
  // the chunks (and so the sums' order) are as asked; the threads that run them are at most the cores this
  // process may use: an arena wider than them made TBB warn "the number of workers is currently limited to 0"
  // on one core (issue 52)
  if (n_threads_ > 1) pool_ = std::make_unique<ThreadPool>(std::min(n_threads_, available_cores()));
}

Workspace::~Workspace() = default;
SolverScratch& Workspace::solver_scratch() {
  if (!solver_sized_) {
    SolverScratch& s = solver_;
    for (Points* p : {&s.r, &s.dx, &s.trial, &s.cg_r, &s.cg_z, &s.cg_p, &s.cg_q, &s.anchor, &s.next, &s.load, &s.start,
                      &s.tool_forces, &s.term_forces})
      p->setZero(3, n_points_);
    s.blocks.setZero(9, n_points_);
    s.springs.setZero(9, n_points_);
    s.gradients.resize(static_cast<std::size_t>(n_points_));
    solver_sized_ = true;
  }
  return solver_;
}

Workspace::Workspace(Workspace&&) noexcept = default;
Workspace& Workspace::operator=(Workspace&&) noexcept = default;

void Workspace::run_chunks(void (*call)(void*, int), void* context) {
  pool_->arena.execute([&] {
    tbb::parallel_for(
        0, n_threads_, [&](int c) { call(context, c); }, tbb::static_partitioner());
  });
}

}  // namespace pointhaptics
