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
/// forces and springs at the step's start, as the full implicit solver takes a probe's), and w carries no mass:
/// the indentation under a tool is quasi-static, its own vibrations far faster than a step. For each q the patch's
/// correction is minimised out (Newton on the patch, its rings held at U q), so the reduced Newton sees
///   Phi(q) = Pi(q, w*(q)),   dPhi/dq = dPi/dq at w*,
///   d2Phi/dq2 = K_W(q) - U_P^T K_P(U_P q) U_P + U_R^T (H_RR - H_RA H_AA^-1 H_AR) U_R,
/// the last term the patch's tangent with the springs (H, its positive semi-definite part) condensed onto its held
/// rings R: the object's stiffness where the tool presses is the full model's, the rest the reduced model's.
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

  /// For this step: the tools' forces and springs at its start (3 x n and 9 x n over the model; the springs pull
  /// toward `start`). Chooses A, kept from the last step while the points the tools act on stay inside it with a
  /// ring to spare. False when the tools act on no point (then there is no patch, and u = U q).
  /// `q`: the reduced coordinates at the step's start (the correction it starts from is start - U q).
  bool begin_step(const Model& model, const Eigen::VectorXd& q, const Points& tool_forces, const Blocks& springs,
                  const Points& start);
  bool evaluate(const Eigen::VectorXd& q, double& energy, Eigen::VectorXd& gradient) override;
  /// Made when asked for after a new patch or refresh_hessian(), else the last one (a modified Newton: the gradient
  /// is exact, and so is the answer; a Hessian that lags costs iterations, and the solver refreshes it when a step
  /// takes more than a few). Its condensation's solves are warm-started from the last one's and cut at
  /// condensation_iterations CG iterations.
  void add_hessian(Eigen::MatrixXd& hessian) override;
  void refresh_hessian() { hessian_valid_ = false; }
  /// Hessians made since construction
  long long hessians() const { return hessians_; }
  static constexpr double condensation_tolerance = 1e-6;
  static constexpr int condensation_iterations = 5;
  /// u += w of the last evaluation, on A.
  void add_correction(Points& u) const;

  bool active() const { return active_; }
  /// the patch's free points (A) and all its points (A and the held rings)
  index_t free_points() const { return active_ ? patch_.n_free : 0; }
  index_t patch_points() const { return active_ ? patch_.model.n_points : 0; }
  /// the most free points a patch had
  index_t largest_free_points() const { return largest_free_points_; }
  /// patches made (A chosen anew) since construction
  long long rebuilds() const { return rebuilds_; }
  /// Newton iterations of the patch's solves, and CG iterations of the condensation, since construction
  long long inner_iterations() const { return inner_iterations_; }
  long long condensation_cg_iterations() const { return condensation_cg_; }
  /// why the last evaluation failed (empty when it did not)
  const char* failure() const { return failure_; }

 private:
  void build(const Model& model, const std::vector<index_t>& touched);
  /// the patch's rows of U times x, as the patch's 3 x n points
  void basis_product(const Eigen::VectorXd& x, Points& out) const;
  /// the patch's own problem: the loads and the tools' springs, no inertia (w is quasi-static)
  NewtonProblem problem();

  const Eigen::MatrixXd& U_;
  int rings_, threads_;
  bool active_ = false;
  ModelPatch patch_;
  std::unique_ptr<Workspace> ws_;
  NewtonSolver newton_;
  NewtonSettings settings_;
  Eigen::MatrixXd U_patch_;                       ///< 3 n_patch x r: the patch's rows of U
  std::vector<char> inside_;                      ///< per model point: within A less its outer ring (A kept while the
                                                  ///< tools act only there)
  std::vector<index_t> patch_of_;                 ///< per model point: its patch index, or -1
  Points tool_, load_, start_, rest_, star_, w_;  ///< patch: t, f + t, the springs' anchor, U_P q, u*, u* - U_P q
  Points forces_at_rest_, scratch_, product_;
  Blocks springs_;
  std::vector<Mat3> gradients_;
  Tangent rest_tangent_, star_tangent_;
  Eigen::VectorXd q_;        ///< the q last evaluated
  Eigen::MatrixXd hessian_;  ///< its Hessian, once made (hessian_valid_)
  bool hessian_valid_ = false;
  std::vector<Points> condensed_start_;  ///< H_AA^-1 H_AR U_R e_k of the last Hessian: warm starts
  index_t largest_free_points_ = 0;
  long long hessians_ = 0, rebuilds_ = 0, inner_iterations_ = 0, condensation_cg_ = 0;
  const char* failure_ = "";
};

}  // namespace pointhaptics
