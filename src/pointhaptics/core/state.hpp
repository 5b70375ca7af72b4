#pragma once
/// @file The dynamic state that solvers advance: exactly what save/load copies.
#include <pointhaptics/core/model.hpp>

namespace pointhaptics {

struct State {
  Points u;         ///< displacements, m  (3 x n)
  Points velocity;  ///< velocities, m/s  (3 x n)
  double time = 0;  ///< s

  /// The rest state of a model: zero displacement and velocity at t = 0.
  static State at_rest(const Model& model) {
    State s;
    s.u = Points::Zero(3, model.n_points);
    s.velocity = Points::Zero(3, model.n_points);
    return s;
  }
};

}  // namespace pointhaptics
