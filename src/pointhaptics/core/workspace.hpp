#pragma once
/// @file Solver-owned scratch memory, sized once per model so that a step never allocates.
#include <pointhaptics/core/model.hpp>

#include <array>
#include <memory>
#include <vector>

namespace pointhaptics {

/// Points with a zero fourth row, so that each point's vector is one SIMD load  (4 x n)
using PaddedPoints = Eigen::Matrix<double, 4, Eigen::Dynamic>;
/// A 3x3 matrix per point as its three columns, each padded to 4 doubles  (12 x n)
using PaddedGradients = Eigen::Matrix<double, 12, Eigen::Dynamic>;

/// Scratch of Newton's method and of the implicit and static steps (3 x n each unless noted).
struct SolverScratch {
  Points r, dx, trial;                               ///< Newton: residual, step, line-search iterate
  Points cg_r, cg_z, cg_p, cg_q;                     ///< its conjugate gradients
  Eigen::Matrix<double, 9, Eigen::Dynamic> blocks;   ///< the inverted diagonal blocks of the preconditioner (9 x n)
  std::vector<Mat3> gradients;                       ///< every G_i of an energy evaluation (n)
  Points anchor, next, load, start, tool_forces;     ///< implicit: the inertia's anchor, the iterate, the load, u_n,
                                                     ///< the tools' forces; static: the increment's load and iterate
  Eigen::Matrix<double, 9, Eigen::Dynamic> springs;  ///< implicit: the tools' springs (9 x n)
  Points term_forces;                                ///< Newton: the forces of its problem's further term
};

/// Scratch buffers and the thread pool of the force evaluation and the solvers: the one owner of every
/// buffer a step writes besides the state.
/// Not shared between threads that step different simulations.
/// The cores this process may run on (its CPU affinity: `taskset`, a container's cpuset), at least 1.
int available_cores();

class Workspace {
 public:
  /// Size every buffer for `model`; n_threads = 0 means all hardware threads.
  Workspace(const Model& model, int n_threads = 0);
  ~Workspace();
  Workspace(Workspace&&) noexcept;
  Workspace& operator=(Workspace&&) noexcept;

  int n_threads() const { return n_threads_; }
  /// Contiguous point range [first, last) handled by chunk c (one chunk per thread).
  index_t chunk_begin(int c) const { return chunk_offset_[c]; }
  index_t chunk_end(int c) const { return chunk_offset_[c + 1]; }
  /// Columns [first, last) that chunk c's stencils write to (its points and their neighbours).
  index_t scatter_begin(int c) const { return scatter_range_[2 * c]; }
  index_t scatter_end(int c) const { return scatter_range_[2 * c + 1]; }
  /// Run fn(c) for every chunk c in [0, n_threads), in parallel on this workspace's threads.
  template <class Fn>
  void for_each_chunk(Fn&& fn);

  Points f_int;         ///< internal elastic forces, N  (3 x n)
  Points acceleration;  ///< scratch of the explicit solver, m/s^2  (3 x n)
  // scratch of the stencil loop (mechanics/detail/stencil_loop.hpp)
  PaddedPoints padded_u;      ///< the displacement (or increment) the loop reads
  PaddedGradients gradients;  ///< G_i of the last stencil pass, by columns
  /// G_i of the last stencil pass, unpadded.
  Mat3 gradient(index_t i) const {
    Mat3 G;
    for (int c = 0; c < 3; ++c) G.col(c) = gradients.block<3, 1>(4 * c, i);
    return G;
  }
  /// Within a step of a viscoelastic model (mechanics/viscoelasticity.hpp): the share of the shear modulus
  /// left to the material (1: elastic), and the overstress H_i of the history (6 x n, Voigt; sized for a
  /// viscoelastic model only) when `overstress_active`.
  double viscous_shear_factor = 1;
  bool overstress_active = false;
  Eigen::Matrix<double, 6, Eigen::Dynamic> overstress;
  /// The points that sleep (a body at rest that nothing touches, issue 47): explicit steps neither evaluate their
  /// stencils nor move them, and `awake` lists the point ranges [first, last) that do not (empty when all sleep).
  /// `asleep` empty: none sleeps.
  /// Set between steps by the one who decides (ModelSimulation); only explicit steps read them.
  std::vector<char> asleep;
  std::vector<std::array<index_t, 2>> awake;
  std::vector<PaddedPoints> chunk_forces;  ///< per-chunk scatter targets, summed into the result  (n_threads)
  std::vector<double> chunk_scalars;       ///< one value per chunk for reductions without atomics  (n_threads)
  /// The solvers' scratch, sized for the model on the first call (explicit dynamics never pays for it);
  /// after that no call allocates.
  SolverScratch& solver_scratch();

 private:
  void run_chunks(void (*call)(void*, int), void* context);
  int n_threads_ = 1;
  index_t n_points_ = 0;
  SolverScratch solver_;
  bool solver_sized_ = false;
  std::vector<index_t> chunk_offset_;
  std::vector<index_t> scatter_range_;
  struct ThreadPool;  ///< a TBB arena of n_threads, kept out of this header
  std::unique_ptr<ThreadPool> pool_;
};

template <class Fn>
void Workspace::for_each_chunk(Fn&& fn) {
  if (n_threads_ == 1) {
    fn(0);
    return;
  }
  run_chunks([](void* ctx, int c) { (*static_cast<Fn*>(ctx))(c); }, &fn);
}

}  // namespace pointhaptics
