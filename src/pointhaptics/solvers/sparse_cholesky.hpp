#pragma once
/// @file A sparse Cholesky factorisation of an assembled tangent over the free points (SuiteSparse CHOLMOD,
/// supernodal): the fill-reducing ordering and symbolic factor once per model, the numeric factor whenever
/// the caller asks (Newton reuses it over many steps as a preconditioner: a "lagged" factorisation), either
/// in place or on a worker thread while the old factor keeps serving (a background refactorisation).
#include <pointhaptics/mechanics/tangent_matrix.hpp>

#include <functional>
#include <memory>

namespace pointhaptics {

struct CholeskyStats {
  double factor_nonzeros = 0;      ///< entries of L
  double factor_bytes = 0;         ///< L's values and indices, bytes
  double factorisation_flops = 0;  ///< of one numeric factorisation (CHOLMOD's count from the analysis)
  double analyse_s = 0;            ///< the ordering and symbolic factor, s
  double factorise_s = 0;          ///< the last numeric factorisation, s (in the background: on the worker)
  long long factorisations = 0;
  long long background_factorisations = 0;  ///< of them, made on the worker thread and taken up
  double background_bytes = 0;  ///< the worker's copy of A and L (0 until a background factorisation), bytes
};

class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;

  /// Order and analyse K's pattern over the points that are not held (Model::fixed). Call again when the model
  /// (its points, stencils or held points) changes. This and factorise() honour a stop request within 5 ms
  /// when they are long (CHOLMOD cannot be interrupted: it is left to end on a thread of its own, and this is
  /// left unanalysed), and throw Interrupted.
  void analyse(const Model& model, const TangentMatrix& K);
  /// The model analyse() was called for (its address, points, pairs and free points), else false.
  bool analysed_for(const Model& model) const;
  /// Factorise K with its current values: false when K is not positive definite over the free points (then
  /// there is no factor until the next successful call).
  bool factorise(const TangentMatrix& K);
  bool factorised() const;
  /// z = K^-1 r on the free points (after a successful factorise()), zero at held points. Allocates only on the
  /// first call after analyse().
  void solve(const Points& r, Points& z);
  const CholeskyStats& stats() const { return stats_; }

  /// Start factorising K's current values on a worker thread (with its own CHOLMOD workspace and a second
  /// factor of the analysed pattern: twice L's memory), while factorised() and solve() keep the factor there
  /// is. False (nothing started) when a background factorisation is still running or nothing is analysed. The
  /// values are copied before this returns: K may change at once.
  bool factorise_in_background(const TangentMatrix& K);
  /// A background factorisation was started and has not been taken up by take_background() yet.
  bool background_pending() const;
  /// ... and it has finished (take_background() will not wait).
  bool background_ready() const;
  /// Take up the background factorisation (waiting for it if it is still running): true when it is positive
  /// definite, and then solve() uses it from now on; false when it is not (the factor in use is kept) or none
  /// was pending.
  bool take_background();
  /// For tests: called on the worker thread before each background factorisation (holds it back at will).
  std::function<void()> before_background_factorisation;

 private:
  struct Factor;      // CHOLMOD's objects, kept out of this header
  struct Background;  // the worker thread and its copy of A and L
  /// CHOLMOD's `work` on the factor in a stoppable call (core/stoppable_call.hpp): on a stop the factor is left
  /// to it, and this one starts again unanalysed.
  void call_on_factor(const char* where, void (*work)(Factor&), double expected_s = 0);
  /// Wait for a background factorisation that is running and drop it (a new analysis is made).
  void drop_background();
  std::shared_ptr<Factor> factor_;  // shared with a stoppable call (core/stoppable_call.hpp) while it runs
  std::unique_ptr<Background> background_;
  CholeskyStats stats_;
};

}  // namespace pointhaptics
