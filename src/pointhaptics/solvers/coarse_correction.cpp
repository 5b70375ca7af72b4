#include <pointhaptics/solvers/coarse_correction.hpp>
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace pointhaptics {

namespace {
// The coarse cells of a fine model: coarsening() spacings wide from its low corner.
struct Cells {
  Vec3 low;
  double size;
  explicit Cells(const Model& fine)
      : low(fine.X.rowwise().minCoeff()), size(CoarseCorrection::coarsening(fine) * fine.spacing) {}
  // the cell of x, shifted by an eighth of a cell so that lattice points on a cell's low faces fall inside it
  // despite sampling round-off; t is x in cells
  std::uint64_t key(const Vec3& x, Vec3* t_out = nullptr) const {
    const Vec3 t = (x - low) / size + Vec3::Constant(0.125);
    if (t_out) *t_out = t;
    return (static_cast<std::uint64_t>(std::floor(t.x())) << 42) |
           (static_cast<std::uint64_t>(std::floor(t.y())) << 21) | static_cast<std::uint64_t>(std::floor(t.z()));
  }
};
}  // namespace

double CoarseCorrection::coarsening(const Model& fine) {
  return std::max(2.0, std::cbrt(static_cast<double>(fine.n_points) / target_coarse_points));
}

std::vector<index_t> CoarseCorrection::coarse_points(const Model& fine) {
  const index_t n = fine.n_points;
  if (n == 0 || !(fine.spacing > 0)) return {};
  const Cells cells(fine);
  // each cell keeps the point nearest its low corner (on a lattice at a ratio of 2: the points of even indices)
  struct Kept {
    index_t point;
    double distance;
  };
  std::unordered_map<std::uint64_t, Kept> kept;
  kept.reserve(static_cast<std::size_t>(n / 4));
  for (index_t i = 0; i < n; ++i) {
    Vec3 t;
    const std::uint64_t key = cells.key(fine.X.col(i), &t);
    const double distance = (t - t.array().floor().matrix()).squaredNorm();
    auto [it, fresh] = kept.try_emplace(key, Kept{i, distance});
    if (!fresh && (distance < it->second.distance || (distance == it->second.distance && i < it->second.point)))
      it->second = {i, distance};
  }
  std::vector<index_t> points;
  points.reserve(kept.size());
  for (const auto& [key, k] : kept) points.push_back(k.point);
  std::sort(points.begin(), points.end());  // the fine order (deterministic whatever the hash's)
  return points;
}

bool CoarseCorrection::built_for(const Model& fine) const {
  return fine_ == &fine && fine_points_ == fine.n_points && fine_pairs_ == fine.n_pairs();
}

bool CoarseCorrection::build(const Model& fine) {
  fine_ = &fine, fine_points_ = fine.n_points, fine_pairs_ = fine.n_pairs();
  ready_ = false;
  coarse_.reset();
  selected_ = coarse_points(fine);
  const index_t n = static_cast<index_t>(selected_.size());
  if (n < 8 || n >= fine.n_points) return false;
  // the coarse cloud: each fine point's volume goes to its cell's coarse point (the total is kept)
  const double ratio = coarsening(fine);
  PointCloud cloud;
  cloud.X.resize(3, n);
  for (index_t c = 0; c < n; ++c) cloud.X.col(c) = fine.X.col(selected_[c]);
  cloud.spacing = ratio * fine.spacing;
  cloud.surface.assign(static_cast<std::size_t>(n), 0);
  cloud.volume = Eigen::VectorXd::Zero(n);
  if (fine.support.size()) {
    cloud.support.resize(n);
    for (index_t c = 0; c < n; ++c) cloud.support[c] = ratio * fine.support[selected_[c]];
  }
  KernelParams kernel = fine.kernel;
  kernel.support = ratio * fine.h;
  try {
    const Cells cells(fine);
    std::unordered_map<std::uint64_t, index_t> of_cell;
    of_cell.reserve(static_cast<std::size_t>(n));
    for (index_t c = 0; c < n; ++c) of_cell[cells.key(fine.X.col(selected_[c]))] = c;
    for (index_t i = 0; i < fine.n_points; ++i) cloud.volume[of_cell.at(cells.key(fine.X.col(i)))] += fine.volume[i];
    if (fine.stiffness_scale.size()) {
      cloud.stiffness_scale.resize(n);
      for (index_t c = 0; c < n; ++c) cloud.stiffness_scale[c] = fine.stiffness_scale[selected_[c]];
    }
    std::vector<std::uint8_t> material_of;
    if (!fine.material_of.empty())
      for (index_t c = 0; c < n; ++c) material_of.push_back(fine.material_of[selected_[c]]);
    coarse_ = std::make_unique<Model>(build_model(cloud, fine.material, kernel, fine.point_materials, material_of));
    for (index_t c = 0; c < n; ++c) coarse_->fixed[c] = fine.fixed[selected_[c]];
    for (index_t c = 0; c < n; ++c)
      if (!coarse_->fixed[c] && coarse_->neighbours.end(c) == coarse_->neighbours.begin(c))
        throw Error("a lone coarse point");
    prolongation_ = build_surface_map(*coarse_, fine.X);
  } catch (const Error&) {
    coarse_.reset();
    return false;
  }
  coarse_ws_ = std::make_unique<Workspace>(*coarse_, 1);
  coarse_u_.setZero(3, n), coarse_r_.setZero(3, n), coarse_z_.setZero(3, n);
  fine_zero_.setZero(3, fine.n_points), fine_dz_.setZero(3, fine.n_points);
  build_tangent_pattern(*coarse_, matrix_);
  cholesky_.analyse(*coarse_, matrix_);
  return true;
}

bool CoarseCorrection::factorise(const Model& fine, const Points& u, double inertia) {
  ready_ = false;
  if (!coarse_ || !built_for(fine)) return false;
  const index_t n = coarse_->n_points;
  for (index_t c = 0; c < n; ++c) coarse_u_.col(c) = u.col(selected_[c]);
  tangent_.linearise(*coarse_, coarse_u_, TangentMode::PROJECTED, coarse_ws_.get());
  assemble_tangent(*coarse_, tangent_, matrix_, coarse_ws_.get());
  if (inertia > 0)
    for (index_t c = 0; c < n; ++c)
      Eigen::Map<Mat3>(matrix_.values.data() + 9 * static_cast<std::size_t>(matrix_.diagonal[c])) +=
          inertia * coarse_->mass[c] * Mat3::Identity();
  ready_ = cholesky_.factorise(matrix_);
  return ready_;
}

void CoarseCorrection::add_correction(const Model& fine, const Points& r, Points& z) {
  if (!ready_) return;
  coarse_r_.setZero();
  spread_surface_forces(prolongation_, r, coarse_r_);             // P^T r (held fine points carry r = 0)
  cholesky_.solve(coarse_r_, coarse_z_);                          // zero at held coarse points
  carry_surface(prolongation_, fine_zero_, coarse_z_, fine_dz_);  // P z_c
  for (index_t i = 0; i < fine.n_points; ++i)
    if (!fine.fixed[i]) z.col(i) += fine_dz_.col(i);
}

}  // namespace pointhaptics
