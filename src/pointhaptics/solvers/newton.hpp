#pragma once
/// @file Newton's method with a line search and preconditioned conjugate gradients on the matrix-free
/// tangent: the core of the static solver and of implicit dynamics.
#include <pointhaptics/core/workspace.hpp>

#include <algorithm>
#include <vector>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>
#include <pointhaptics/solvers/coarse_correction.hpp>
#include <pointhaptics/solvers/sparse_cholesky.hpp>

namespace pointhaptics {

struct NewtonSettings {
  double tolerance = 1e-8;       ///< converged when |residual| <= tolerance * force scale (see NewtonStats)
  int max_iterations = 50;       ///< Newton iterations per solve
  int max_cg_iterations = 2000;  ///< CG iterations per Newton iteration
  /// Accept the last iterate when max_iterations is reached instead of reporting failure
  /// (the real-time budget of implicit dynamics).
  bool accept_at_budget = false;
  Preconditioner preconditioner = Preconditioner::BLOCK_JACOBI;
  /// CHOLESKY: the factor is refreshed at the next Newton iteration after a CG solve that took more
  /// iterations than this
  int refactor_iterations = 8;
  /// CHOLESKY: where the refreshes run (in place, or on a worker thread while the old factor serves) ...
  Refactorisation refactorisation = Refactorisation::AUTO;
  /// ... and whether the simulation runs on the wall clock: a background factor is then taken up at the first
  /// Newton iteration after it is ready, else at the start of the next solve (waiting for it: reproducible)
  bool real_time = false;
  /// Whether refactorisations run in the background for a simulation on `threads` threads. AUTO: in real time,
  /// and only where the worker has a core of its own beside them and the haptic loop's. Sharing one it slows
  /// every step more than it saves (docs/performance.md: on 2 cores the longest steps of a probe pressing the
  /// stiff cantilever fell from about 65 to 35 ms, but the mean rose by 10-60%).
  bool refactor_in_background(int threads) const;
};

/// A term of the energy beyond the material, the loads, the inertia and the per-point springs: a tool's
/// contact, whose stiffness couples the points a surface vertex is carried by. Newton minimises it with
/// the rest: its value and forces at any iterate, its tangent at the iterate it was linearised at.
class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;
  /// The term's energy at u, J.
  virtual double energy(const Model& model, const Points& u) = 0;
  /// f += -dE/du at u (N, 3 x n).
  virtual void add_forces(const Model& model, const Points& u, Points& f) = 0;
  /// Fix the tangent at u: exact, or (TangentMode::PROJECTED) its positive semi-definite part.
  virtual void linearise(const Model& model, const Points& u, TangentMode mode) = 0;
  /// out += H dx, with H the tangent fixed by the last linearise().
  virtual void add_tangent_product(const Points& dx, Points& out) const = 0;
  /// The tangent's 3x3 diagonal blocks added into `blocks` (9 x n, column-major), for the preconditioner.
  virtual void add_diagonal_blocks(Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks) const = 0;
  /// The tangent's blocks (its positive semi-definite part, or a bound of it) added into the assembled tangent
  /// that the Cholesky preconditioner factorises, with its coupling between points: true if the term did so;
  /// false, and the factor takes its diagonal blocks only.
  virtual bool add_to_matrix(TangentMatrix&) const { return false; }
  /// A constrained term (augmented Lagrangian) checks its constraint at the minimiser u: true when it is met,
  /// else it updates its multipliers and the solver minimises again. Unconstrained terms: true.
  virtual bool update_multipliers(const Model&, const Points&) { return true; }
};

/// The energy Pi(u) = W(u) - b . u + 0.5 k sum_free m_i |u_i - a_i|^2 minimised over the free points
/// (held points keep the values they have in u). Static: k = 0; backward Euler: k = 1/dt^2 + c/dt.
struct NewtonProblem {
  const Points* load = nullptr;    ///< b, N  (3 x n)
  double inertia = 0;              ///< k, 1/s^2
  const Points* anchor = nullptr;  ///< a, m  (3 x n); needed when inertia > 0
  /// Optional per-point 3x3 springs (column-major, 9 x n, N/m) toward `spring_anchor`: the energy gains
  /// 0.5 sum_i (u_i - c_i)^T S_i (u_i - c_i). Implicit dynamics uses them to treat stiff contact springs
  /// linearly implicitly (S_i symmetric positive semi-definite).
  const Eigen::Matrix<double, 9, Eigen::Dynamic>* springs = nullptr;
  const Points* spring_anchor = nullptr;
  /// Optional: a further term of the energy (a tool's contact on the surface).
  EnergyTerm* term = nullptr;
};

struct NewtonStats {
  bool converged = false;
  int iterations = 0;           ///< Newton iterations
  long long cg_iterations = 0;  ///< CG iterations, summed
  int factorisations = 0;       ///< CHOLESKY: numeric factorisations of the tangent in this solve (made or taken up)
  int background_factorisations = 0;  ///< ... of them, made on the worker thread
  int stale_factor_fallbacks = 0;     ///< CG solves cut short with a factor far behind the tangent (while the worker
                                      ///< refactorises) and done again with block-Jacobi
  int projected = 0;                  ///< iterations that fell back to the positive semi-definite tangent
  double residual = 0;       ///< |r|_free / max(|b|, |f_int|, |k M (u - a)|, |tool forces|, force_floor) at the end
  bool stalled = false;      ///< stopped at the round-off floor above the tolerance (not converged)
  const char* failure = "";  ///< why it stopped without converging
};

/// Newton's method with its tangent; its vectors are the workspace's (Workspace::solver_scratch()).
class NewtonSolver {
 public:
  explicit NewtonSolver(const Model& model);
  /// Minimise the problem's energy from the initial guess u (updated in place). Never throws for a
  /// hard problem: it reports failure in the stats and leaves u at the last accepted iterate.
  NewtonStats solve(const Model& model, const NewtonProblem& problem, Points& u, Workspace& ws,
                    const NewtonSettings& settings);

  /// The problem's tangent at u, for solve_linearised(): its positive semi-definite part (TangentMode::PROJECTED)
  /// and the block-Jacobi preconditioner. (A tool's compliance: what the object gives under a load.) Without
  /// `material` only the term is linearised again, the material's tangent and the preconditioner lag (they
  /// cost most: a 9x9 eigen decomposition per point).
  void linearise(const Model& model, const NewtonProblem& problem, const Points& u, Workspace& ws,
                 bool material = true);
  /// H x = b over the free points with the tangent of the last linearise(), by PCG from the x given (a warm
  /// start) to |b - H x| <= tolerance |b| or max_iterations; x keeps the last iterate. Uses the workspace's
  /// solver scratch. Returns the CG iterations taken (negative when CG met a direction of non-positive
  /// curvature: x is then the last iterate before it).
  int solve_linearised(const Model& model, const NewtonProblem& problem, const Points& b, Points& x, double tolerance,
                       int max_iterations, Workspace& ws);
  /// linearise(), and the tangent's Cholesky factor made (over the free points, with the problem's inertia and
  /// springs) as solve_linearised()'s preconditioner, which then converges in a few CG iterations (the factor is of
  /// the assembled tangent, whose hourglass part is a bound); false when it cannot be made (a tangent that is not
  /// finite).
  bool linearise_factorised(const Model& model, const NewtonProblem& problem, const Points& u, Workspace& ws);
  /// The Cholesky factor's size and timings (zero unless the CHOLESKY preconditioner ran).
  const CholeskyStats& cholesky_stats() const { return cholesky_.stats(); }
  /// The Cholesky factor itself (its background work can be watched or, in tests, held back).
  SparseCholesky& cholesky() { return cholesky_; }
  /// TWO_LEVEL: the coarse level's points (0: none in use) and its factor's size and timings.
  index_t coarse_points() const { return two_level_ ? coarse_.n_coarse() : 0; }
  const CholeskyStats& coarse_stats() const { return coarse_.cholesky_stats(); }
  /// The preconditioner's factors' memory, bytes: CHOLESKY's L with the worker's copy of A and L when it
  /// refactorises in the background; TWO_LEVEL's coarse factor (the larger of the two when both were used).
  double preconditioner_bytes() const {
    const double coarse = coarse_points() > 0 ? coarse_stats().factor_bytes : 0.0;
    return std::max(cholesky_stats().factor_bytes + cholesky_stats().background_bytes, coarse);
  }

 private:
  /// Pi(u); `step`: the material within a viscoelastic step (viscoelasticity.hpp)
  double energy(const Model& model, const NewtonProblem& problem, const Points& u, std::vector<Mat3>& gradients,
                const ViscousStep& step) const;
  /// r = -grad Pi at u, zero at held points; returns the relative residual
  double residual(const Model& model, const NewtonProblem& problem, const Points& u, Workspace& ws, Points& r) const;
  void build_preconditioner(const Model& model, const NewtonProblem& problem, const Points& u, Workspace& ws);
  /// Assemble the problem's tangent (as last linearised) into matrix_ (the pattern analysed once per model).
  void assemble(const Model& model, const NewtonProblem& problem, Workspace& ws);
  /// Assemble and factorise it; false when it is not positive definite (CG then uses the block-Jacobi
  /// preconditioner).
  bool factorise(const Model& model, const NewtonProblem& problem, Workspace& ws);
  /// Take up a background factorisation (waiting for it if it is not ready): counted in stats when it is
  /// good, else the next iteration refactorises in place.
  void take_background_factor(NewtonStats& stats);
  /// z = B r with the preconditioner in use
  void precondition(const Points& r, Points& z, Workspace& ws);
  /// PCG on (K + k M) x = r over the free points to relative tolerance eta; returns false when it meets
  /// a direction of non-positive curvature (an indefinite tangent).
  bool conjugate_gradients(const Model& model, const NewtonProblem& problem, const Points& r, double eta,
                           int max_iterations, Workspace& ws, Points& x, long long& iterations);
  void mask_held(const Model& model, Points& x) const;
  /// q = H p with H the problem's tangent as last linearised (material, inertia, springs, term), zero at held points
  void apply_tangent(const Model& model, const NewtonProblem& problem, const Points& p, Workspace& ws, Points& q) const;

  /// The block-Jacobi blocks are stale: made for another model or problem, or CG has slowed since
  bool blocks_stale(const Model& model, const NewtonProblem& problem, Workspace& ws) const;
  /// Note one CG solve's iterations (to relative tolerance eta) for the lagged preconditioners.
  void note_cg_rate(long long iterations, double eta);

  Tangent tangent_;
  double force_floor_ = 0;  ///< N: the force scale's floor for this solve's model (reactions.hpp, force_floor)
  TangentMode preconditioner_mode_ = TangentMode::EXACT;
  // the block-Jacobi blocks lag across Newton iterations and solves (steps) like the Cholesky factor: made
  // for one model and problem, refreshed when CG's iterations per decade of residual grow by half
  const Model* blocks_model_ = nullptr;
  double blocks_inertia_ = -1;
  bool blocks_springs_ = false, blocks_term_ = false, refresh_blocks_ = true;
  double cg_rate_at_build_ = -1;  ///< CG iterations per decade in the first solve after a rebuild (-1: none yet)
  // CHOLESKY: the assembled tangent, its factor (kept across solves), and whether CG uses it now
  TangentMatrix matrix_;
  Eigen::Matrix<double, 9, Eigen::Dynamic> added_blocks_;
  SparseCholesky cholesky_;
  bool use_cholesky_ = false;
  bool refactorise_ = true;
  bool exact_indefinite_ = false;  ///< a factorisation of the exact tangent failed: factorise projected ones only
  TangentMode background_mode_ = TangentMode::EXACT;  ///< of the tangent factorised in the background
  bool factor_stale_ = false;  ///< CG with the factor was cut short: block-Jacobi until a new factor is taken up
  // TWO_LEVEL: block-Jacobi plus a coarse model's correction (coarse_correction.hpp), built and factorised
  // with the blocks; `kind_` is the last solve's preconditioner
  Preconditioner kind_ = Preconditioner::BLOCK_JACOBI;
  CoarseCorrection coarse_;
  bool two_level_ = false;
};

}  // namespace pointhaptics
