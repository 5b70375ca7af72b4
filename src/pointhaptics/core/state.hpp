#pragma once
/// @file The dynamic state that solvers advance: exactly what save/load copies.
#include <pointhaptics/core/model.hpp>

namespace pointhaptics {

struct State {
  /// Rows of `viscous` for a model: 6 (terms + 1) with a Prony series, else 0.
  static Eigen::Index viscous_rows(const Model& model) {
    return model.material.prony.empty() ? 0 : 6 * static_cast<Eigen::Index>(model.material.prony.size() + 1);
  }

  Points u;         ///< displacements, m  (3 x n)
  Points velocity;  ///< velocities, m/s  (3 x n)
  double time = 0;  ///< s
  /// A viscoelastic material's history (mechanics/viscoelasticity.hpp), per point: the overstress Q_k of each
  /// Prony term, then the shear stress S of the last step, each a symmetric tensor as 6 doubles (xx, yy, zz,
  /// yz, xz, xy), Pa  (6 (terms + 1) x n; empty for an elastic material)
  Eigen::MatrixXd viscous;

  /// The rest state of a model: zero displacement and velocity at t = 0.
  static State at_rest(const Model& model) {
    State s;
    s.u = Points::Zero(3, model.n_points);
    s.velocity = Points::Zero(3, model.n_points);
    s.viscous = Eigen::MatrixXd::Zero(viscous_rows(model), model.n_points);
    return s;
  }
};

}  // namespace pointhaptics
