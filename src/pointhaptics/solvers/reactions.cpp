#include <pointhaptics/solvers/reactions.hpp>

#include <algorithm>
#include <cmath>

namespace pointhaptics {

std::vector<Vec3> support_reactions(const Model& model, const Points& f_int) {
  std::vector<Vec3> reactions;
  reactions.reserve(model.fixed_groups.size());
  for (const FixedGroup& group : model.fixed_groups) {
    Vec3 r = Vec3::Zero();
    for (index_t i : group.points) r -= f_int.col(i) + model.f_ext.col(i);
    reactions.push_back(r);
  }
  return reactions;
}

double relative_residual(const Model& model, const Points& f_int) {
  double out_of_balance = 0;
  for (index_t i = 0; i < model.n_points; ++i)
    if (!model.fixed[i]) out_of_balance += (f_int.col(i) + model.f_ext.col(i)).squaredNorm();
  const double scale = std::max({model.f_ext.norm(), f_int.norm(), force_floor(model), 1e-300});
  return std::sqrt(out_of_balance) / scale;
}

double force_floor(const Model& model) {
  if (model.n_points == 0) return 0;
  const double extent = (model.X.rowwise().maxCoeff() - model.X.rowwise().minCoeff()).maxCoeff();
  return 1e-9 * model.material.young * extent * extent;
}

}  // namespace pointhaptics
