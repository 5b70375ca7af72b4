#pragma once
/// @file The solver of a reduced model (issue 49, `[reduction]`): the basis and the polynomial are made when it is
/// (the set-up), then each static solve or backward Euler step runs full Newton in the r reduced coordinates
/// (reduced_integrator.hpp) and writes u = U q and v = U q' into the state, so every output reads it as a full
/// model's. Where tools act (a probe), the points around them are solved in full and coupled to the reduced rest
/// (contact_patch.hpp): u = U q + P w there.
#include <pointhaptics/reduction/contact_patch.hpp>
#include <pointhaptics/reduction/modal_basis.hpp>
#include <pointhaptics/reduction/reduced_integrator.hpp>
#include <pointhaptics/solvers/solver.hpp>

#include <memory>
#include <string>

namespace pointhaptics {

class ReducedSolver final : public Solver {
 public:
  /// Builds the basis (spec.reduction.modes vectors; the model's constant loads' static response among them) and
  /// the polynomial. Throws Error for what a reduced model does not do yet: an explicit solver, held points moved
  /// by a prescribed displacement, a material other than St. Venant-Kirchhoff (svk_polynomial.hpp).
  ReducedSolver(const Model& model, const SolverSpec& spec, Workspace& ws);
  /// A static solve or one backward Euler step. The tools' forces and springs (a probe's) act on a contact patch in
  /// full resolution; forces that are a term of the energy (held tools, obstacles, contact between bodies) are not
  /// coupled yet: a step given any FAILS, naming them.
  StepReport step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) override;
  const ModalBasis& basis() const { return basis_; }
  const SvkPolynomial& polynomial() const { return *polynomial_; }
  /// the contact region in full resolution (nullptr until a tool acted)
  const ContactPatch* contact_patch() const { return patch_.get(); }
  double setup_s() const { return setup_s_; }
  /// the file the basis was read from or kept in (`[reduction] cache`; empty: none), whether it was read from
  /// it, and what went wrong with the file when something did (the run goes on: the basis is made, or not kept)
  const std::string& cache_file() const { return cache_file_; }
  bool from_cache() const { return from_cache_; }
  const std::string& cache_note() const { return cache_note_; }
  /// The inverted neighbourhoods at `state` (= U q), for the step's diagnostics. No force evaluation leaves
  /// gradients in `ws` here, and a stencil pass costs about a step, so it answers by a bound first:
  /// |G_p(q)|_2 <= |q| c_p, with c_p^2 = sum_k |G_pk|_F^2 over the basis vectors' gradients G_pk; while
  /// |q| max c_p < 1 no det(I + G_p) can reach zero and the count is 0 without a pass. Beyond it (large
  /// rotations pass it too), every point's gradient is computed from u at every `exact_count_every`-th step, the
  /// last count standing in between. The run's summary counts exactly from the end state whatever the solver.
  index_t count_inverted(const Model& model, const State& state, Workspace& ws) override;
  static constexpr int exact_count_every = 16;
  /// a step that took more Newton iterations than this has the contact patch's Hessian made again for the next
  static constexpr int refresh_after_iterations = 2;
  /// max_p c_p above, per unit of q (SvkPolynomial::gradient_bound)
  double gradient_bound() const { return polynomial_->gradient_bound(); }
  /// Without tools a step writes nothing into the state: u = U q and v = U q' are written when something reads
  /// them (ModelSimulation::state(): outputs, the summary, Python), so a run that reads the state every k steps
  /// pays for it every k steps. With tools (a probe reads the surface at every step) the step writes u, and v where
  /// the contact patch solved the points in full; the rest of v waits to be read.
  bool unpublished() const override { return positions_unpublished_ || velocities_unpublished_; }
  bool displacement_unpublished() const override { return positions_unpublished_; }
  void publish(State& state, Workspace& ws) override;
  /// A state given from outside (ModelSimulation::set_state()): q and q' become its projection on the basis,
  /// U^T M u and U^T M v (U is mass-orthonormal), so the next step continues from it; the state keeps what was
  /// given (outside the basis' span, the part the basis does not hold is lost at the next step, except under a
  /// probe's contact patch, which takes it as its correction).
  void take_state(const Model& model, const State& state);
  /// the reduced model's lowest natural frequency about rest, Hz
  double first_frequency_hz() const { return first_frequency_hz_; }

 private:
  /// The basis (basis_): read from the cache when `spec_.reduction.cache` names one and a good file is there,
  /// else made (on the points, or on a coarser sampling and carried) and kept there; sets the cache_* members.
  void make_or_read_basis(const Model& model, Workspace& ws);
  /// u = U q and v = U q' into the state, each when asked for (and the contact patch's velocities over v's)
  void write(State& state, Workspace& ws, bool positions, bool velocities);
  /// This step's contact patch for the tools' forces and springs at `state` (nullptr when they act on no point);
  /// `threads`: the step's (the patch's, when it is large).
  ContactPatch* begin_contact(const Model& model, const State& state, DynamicForces& forces, int threads);
  SolverSpec spec_;
  ModalBasis basis_;
  std::unique_ptr<SvkPolynomial> polynomial_;
  std::unique_ptr<ReducedIntegrator> integrator_;
  ReducedState reduced_;
  double setup_s_ = 0;
  std::string cache_file_, cache_note_;
  bool from_cache_ = false;
  double first_frequency_hz_ = 0;
  std::unique_ptr<ContactPatch> patch_;
  Points tool_forces_;
  Eigen::VectorXd reduced_anchor_;
  ContactPatch::Blocks springs_;
  bool positions_unpublished_ = false, velocities_unpublished_ = false;
  bool patch_in_state_ = false;  ///< the last step solved a contact patch, whose points' velocities are its own
  Points inversion_u_;           ///< U q for the exact inversion count (the state may not hold it yet)
  int steps_since_count_ = exact_count_every;
  index_t last_count_ = 0;
};

}  // namespace pointhaptics
