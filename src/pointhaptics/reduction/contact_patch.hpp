#pragma once
/// @file The region a tool touches in full resolution, coupled to a reduced model (issue 49, item 2): a probe
/// pressing a stiff beam feels the local indentation and the global bending together.
///
/// The displacement is u = U q + P w: the reduced model everywhere, and a correction w on the points A around what
/// the tools touch (zero elsewhere). A is the points that carry the tools' forces and springs, grown by a number of
/// neighbour rings; the patch (mechanics/model_patch.hpp) is A free with three rings around it held, so that its
/// energy E_P changes with A exactly as the object's does (ContactPatch.ThePatchsEnergyChange...). The energy of the coupled system is
///   Pi(q, w) = W(q) - f . U q + inertia(q) + E_P(U_P q + w) - E_P(U_P q) - (f + t)_A . w + springs(U_A q + w)
/// (W: the reduced polynomial, exact for St. Venant-Kirchhoff, which already holds E_P(U_P q); t, S: the tools'
/// forces and springs at the step's start, as the full implicit solver takes a probe's), and backward Euler's
/// inertia of u itself, k/2 |U q + P w - a|_M^2 = k/2 |q - a_q|^2 + k/2 |u_A - a_A|_M^2 - k/2 |U_A (q - a_q)|_M^2
/// (U is mass-orthonormal): the coupled system is the full model's step restricted to the subspace {U q + P w},
/// and keeps its stability (a first version without the patch's mass diverged under a hand in real time).
/// The patch's points on A, v = U_A q + w, are unknowns of the reduced Newton beside q (ReducedCoupling: one Newton
/// on both, v eliminated in each iteration's linear system):
///   H_qq = K_W(q) - U_P^T K_P(U_P q) U_P - k U_A^T M_A U_A + U_R^T H_RR U_R,   H_qv = U_R^T H_RA,   H_vv = H_AA,
/// H the patch's tangent with the springs and the inertia at u (its positive semi-definite part), so that the
/// condensed Hessian H_qq - U_R^T H_RA H_AA^-1 H_AR U_R is the reduced model's stiffness with the full model's where
/// the tool presses. It lags from step to step (a modified Newton: the gradient is exact, and so is the answer).
/// (A first version minimised v out at every q with a Newton solve of its own: the same answers at 3.6 ms a step
/// on the 10k-point stiff beam, most of it those solves.)
#include <pointhaptics/mechanics/model_patch.hpp>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/reduction/reduced_integrator.hpp>
#include <pointhaptics/solvers/newton.hpp>

#include <memory>
#include <vector>

namespace pointhaptics {

class ContactPatch final : public ReducedCoupling {
 public:
  using Blocks = Eigen::Matrix<double, 9, Eigen::Dynamic>;
  /// For `model` and its basis U (3n x r); `rings`: how far A reaches beyond the points the tools act on, in
  /// neighbour rings (at least 1).
  ContactPatch(const Model& model, const Eigen::MatrixXd& U, int rings, int threads);

  /// What a step gives the patch.
  struct Step {
    const Points* tool_forces = nullptr;  ///< t, 3 x n over the model, at the step's start
    const Blocks* springs = nullptr;      ///< S, 9 x n, pulling toward the start's u
    const State* start = nullptr;         ///< u at the step's start (A's points start from it)
    /// backward Euler's inertia k (0: a static solve) and anchors: a = u + carry v on the points, and the reduced
    /// model's own a_q (reduced_integrator.hpp)
    double inertia = 0, carry = 0;
    const Eigen::VectorXd* reduced_anchor = nullptr;
    /// q', for the velocity of points the last step did not solve in full (the state's may not be written:
    /// ReducedSolver::publish()); none: at rest
    const Eigen::VectorXd* reduced_velocity = nullptr;
  };
  /// Chooses A for this step, kept from the last step while the points the tools act on stay inside it with a ring
  /// to spare, and for release_steps after they act on none. False when there is no patch (then u = U q).
  bool begin_step(const Model& model, const Step& step);
  /// ReducedCoupling: the energy at q and the patch's points as they are now (the rings at U_R q)
  bool evaluate(const Eigen::VectorXd& q, double& energy, Eigen::VectorXd& gradient) override;
  double residual() const override;
  /// Made when asked for after a new patch or refresh_hessian(), else the last one. A Hessian that lags costs
  /// iterations: the solver refreshes it for the next step when one takes more than a few, and within a step after
  /// lagged_iterations. Making it costs the rest tangent's and the patch tangent's r products, the patch tangent's
  /// Cholesky factor on A and r CG solves preconditioned with it (condensation_tolerance, at most
  /// condensation_iterations each, warm-started from the last Hessian's).
  void add_hessian(Eigen::MatrixXd& hessian) override;
  void condense(Eigen::VectorXd& gradient) override;
  double begin_move(const Eigen::VectorXd& dq) override;
  void move(double alpha) override;
  void refresh_hessian() { hessian_valid_ = false; }
  static constexpr double condensation_tolerance = 1e-6;
  static constexpr int condensation_iterations = 10;
  /// condense()'s solve of H_AA s = g_v, a Newton direction's: relative tolerance and CG iterations at most
  static constexpr double direction_tolerance = 1e-3;
  static constexpr int direction_iterations = 20;
  static constexpr int release_steps = 200;
  /// Newton iterations within one step on one Hessian before it is made again
  static constexpr int lagged_iterations = 3;
  /// The step's end on A, written into the state (the rest of it is the reduced model's, written before): u = v,
  /// and the velocity (v - u_start) / dt, which the patch also keeps for the next step and for write_velocities().
  void finish_step(Points& u, Points& velocity, double dt);
  /// A's velocities of the last step finished, written again (after the reduced model's v = U q' was written over
  /// them); nothing once the patch is released
  void write_velocities(Points& velocity) const;
  /// The kept velocities dropped (a state set from outside: the next step's anchors take the reduced model's,
  /// U q', the state's projection)
  void forget_velocities();

  bool active() const { return active_; }
  /// the patch's free points (A) and all its points (A and the held rings)
  index_t free_points() const { return active_ ? patch_.n_free : 0; }
  index_t patch_points() const { return active_ ? patch_.model.n_points : 0; }
  /// the points the tools' forces or springs acted on at the last begin_step() (every other point's are zero)
  const std::vector<index_t>& touched() const { return touched_; }
  /// the most free points a patch had
  index_t largest_free_points() const { return largest_free_points_; }
  /// patches made (A chosen anew) since construction
  long long rebuilds() const { return rebuilds_; }
  /// Hessians made since construction (each a Cholesky factor of the patch's tangent on A)
  long long hessians() const { return hessians_; }
  /// why the last evaluation failed (empty when it did not)
  const char* failure() const { return failure_; }

 private:
  void build(const Model& model, const std::vector<index_t>& touched);
  /// the patch's rows of U times x, as the patch's 3 x n points
  void basis_product(const Eigen::VectorXd& x, Points& out) const;
  /// the part of the patch's energy that moves with A (strain_energy_near), at u
  double energy_near(const Points& u);
  /// the patch's own problem on A: the loads, the tools' springs and the inertia
  NewtonProblem problem();

  const Eigen::MatrixXd& U_;
  int rings_, threads_;
  bool active_ = false;
  int steps_untouched_ = 0, uses_this_step_ = 0;
  ModelPatch patch_;
  std::unique_ptr<Workspace> ws_;
  Model inner_;  ///< the patch for its tangent on A (H_AA): its rings beyond the first passive
  std::unique_ptr<Workspace> inner_ws_;
  NewtonSolver newton_;           ///< the tangent on A and its factor (H_AA)
  Eigen::MatrixXd U_patch_;       ///< 3 n_patch x r: the patch's rows of U
  std::vector<index_t> touched_;  ///< the points the tools act on this step
  /// the last finished step's A (model points) and their velocities; per model point its column there, or -1
  std::vector<index_t> finished_free_, velocity_slot_;
  Points velocity_;
  std::vector<char> inside_;                      ///< per model point: within A less its outer ring (A kept while the
                                                  ///< tools act only there)
  Points tool_, load_, start_, rest_, star_;      ///< patch: t, f + t, the springs' anchor, U_P q, u (v on A)
  Points anchor_, reduced_anchor_;                ///< patch: a, and U_P a_q
  Points residual_, solved_, move_start_, move_;  ///< on A: g_v, H_AA^-1 g_v, v where the move began, dv
  double inertia_ = 0;
  double reach_ = 1;  ///< |U_A|_2, the reduced gradient's most per unit of force on A (residual())
  Points forces_at_rest_, scratch_, product_;
  Blocks springs_;
  std::vector<Mat3> gradients_;
  Tangent rest_tangent_, star_tangent_;
  Eigen::MatrixXd hessian_;          ///< its Hessian, once made (hessian_valid_)
  Eigen::MatrixXd z_free_, y_free_;  ///< H_AR U_R and H_AA^-1 H_AR U_R on A's rows (H_vq and H_vv^-1 H_vq)
  bool hessian_valid_ = false;
  std::vector<Points> condensed_start_;  ///< H_AA^-1 H_AR U_R e_k of the last Hessian: the next one's warm starts
  index_t largest_free_points_ = 0;
  long long rebuilds_ = 0, hessians_ = 0;
  const char* failure_ = "";
};

}  // namespace pointhaptics
