#pragma once
/// @file Several forces acting on one model together (a probe and the obstacles, a held tool and the obstacles):
/// the solvers see their sum as one DynamicForces. Those that are terms of the energy (a contact met by an
/// augmented Lagrangian) are minimised together as one EnergyTerm; the others (a probe's linearised springs)
/// enter the Newton solvers as loads beside it (DynamicForces::add_beyond_energy).
#include <pointhaptics/solvers/solver.hpp>

#include <vector>

namespace pointhaptics {

class ForceSet final : public DynamicForces {
 public:
  /// Empty the set (keeps its storage: no allocation per step once it has held as many members).
  void clear();
  /// Add a member; the caller keeps it alive while it is in the set.
  void add_member(DynamicForces* forces);
  bool empty() const { return members_.empty(); }
  /// The wall time its members took since the last call (every call through the set: forces, energies, tangents,
  /// multipliers, after_step), s: a step's contact stage, which the solvers interleave with the material's.
  double take_seconds();

  void add(const Model& model, const State& state, Points& f) override;
  bool add_stiffness(const Model& model, const State& state,
                     Eigen::Matrix<double, 9, Eigen::Dynamic>& springs) override;
  /// The members' sum: a bound, since each bounds its own.
  double max_point_stiffness() const override;
  EnergyTerm* energy_term() override { return terms_.members.empty() ? nullptr : &terms_; }
  bool add_beyond_energy(const Model& model, const State& state, Points& f) override;
  void after_step(const Model& model, const State& state, Workspace& ws) override;

 private:
  /// The members' energy terms as one: every part is their sum.
  struct Terms final : EnergyTerm {
    std::vector<EnergyTerm*> members;
    double energy(const Model& model, const Points& u) override;
    void add_forces(const Model& model, const Points& u, Points& f) override;
    void linearise(const Model& model, const Points& u, TangentMode mode) override;
    void add_tangent_product(const Points& dx, Points& out) const override;
    void add_diagonal_blocks(Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks) const override;
    /// Every member's coupling; a member that has none adds its diagonal blocks (so the set always does).
    bool add_to_matrix(TangentMatrix& K) const override;
    /// Every member checks and updates its own: met when all are.
    bool update_multipliers(const Model& model, const Points& u) override;
    mutable double seconds = 0;  ///< the members' wall time in these calls, s
  };
  double seconds_ = 0;  ///< the members' wall time in the set's own calls, s
  std::vector<DynamicForces*> members_;
  Terms terms_;
};

}  // namespace pointhaptics
