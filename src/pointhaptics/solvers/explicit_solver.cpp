#include <pointhaptics/solvers/explicit_solver.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/neighbour_search.hpp>
#include <pointhaptics/mechanics/forces.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace pointhaptics {

double stable_time_step(const Model& model, double safety) {
  const std::vector<index_t> nearest = nearest_neighbour(model.X);
  double a = std::numeric_limits<double>::infinity();
  for (index_t i = 0; i < model.n_points; ++i)
    if (nearest[i] >= 0) a = std::min(a, (model.X.col(nearest[i]) - model.X.col(i)).norm());
  if (!std::isfinite(a)) a = model.spacing > 0 ? model.spacing : model.h;
  // the lightest point per unit volume vibrates fastest; in kernel-volume mode m_i / v_i is not the density
  double rho = std::numeric_limits<double>::infinity();
  for (index_t i = 0; i < model.n_points; ++i) rho = std::min(rho, model.mass[i] / model.volume[i]);
  const MaterialParams& m = model.material;
  const double modulus = model.lambda + 2 * model.mu + m.volume_stiffness + m.hourglass * m.young;
  return safety * a / std::sqrt(modulus / rho);
}

Vec3 prescribed_displacement(const FixedGroup& group, double t) {
  const double s = group.ramp > 0 ? std::clamp(t / group.ramp, 0.0, 1.0) : 1.0;
  return s * group.displacement;
}

ExplicitStepStats explicit_step(const Model& model, State& state, Workspace& ws, double dt, double stable_dt,
                                DynamicForces* extra) {
  const int n_sub = std::max(1, static_cast<int>(std::ceil(dt / stable_dt * (1 - 1e-12))));
  const double h = dt / n_sub;
  const double c = model.material.damping;
  const double limit2 = (100 * model.extent) * (100 * model.extent);
  for (int sub = 0; sub < n_sub; ++sub) {
    compute_internal_forces(model, state.u, ws);
    if (extra) {
      ws.acceleration.setZero();  // scratch for the dynamic forces
      extra->add(model, state, ws.acceleration);
    }
    std::atomic<index_t> bad_point{-1};
    ws.for_each_chunk([&](int chunk) {
      for (index_t i = ws.chunk_begin(chunk); i < ws.chunk_end(chunk); ++i) {
        if (model.fixed[i]) continue;
        auto v = state.velocity.col(i);
        auto u = state.u.col(i);
        Vec3 f = ws.f_int.col(i) + model.f_ext.col(i);
        if (extra) f += ws.acceleration.col(i);
        v = (v + h / model.mass[i] * f) / (1 + h * c);
        u += h * v;
        if (!(u.squaredNorm() < limit2)) bad_point = i;  // also catches NaN
      }
    });
    state.time += h;
    // held points follow their prescribed displacement
    for (const FixedGroup& group : model.fixed_groups) {
      const Vec3 target = prescribed_displacement(group, state.time);
      for (index_t i : group.points) {
        state.velocity.col(i) = (target - state.u.col(i)) / h;
        state.u.col(i) = target;
      }
    }
    if (bad_point >= 0) {
      const index_t i = bad_point;
      throw Error(fmt::format(
          "explicit solver diverged at t = {:.6g} s (sub-step {} of {}, h = {:.3g} s): point {} has displacement "
          "({:.3g}, {:.3g}, {:.3g}) m; lower dt, add damping or check the material",
          state.time, sub + 1, n_sub, h, i, state.u(0, i), state.u(1, i), state.u(2, i)));
    }
  }
  return {n_sub};
}

}  // namespace pointhaptics
