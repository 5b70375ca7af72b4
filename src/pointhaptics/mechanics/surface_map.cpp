#include <pointhaptics/mechanics/surface_map.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/kd_tree.hpp>
#include <pointhaptics/mechanics/energies/lanes.hpp>
#include <pointhaptics/mechanics/kernels.hpp>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>

namespace pointhaptics {
namespace {

using Mat4 = Eigen::Matrix4d;
using Vec4 = Eigen::Vector4d;

struct VertexWeights {
  std::vector<index_t> points;
  std::vector<double> weight;
  bool widened = false;
  bool carried = true;  // false: too few points around it, after every widening
};

/// The MLS weights of vertex y with support h, widened until the moment matrix is well conditioned.
VertexWeights vertex_weights(const Model& model, const KdTree& tree, const Vec3& y, double h, index_t vertex,
                             bool skip_uncarried, const VertexSees& sees) {
  std::vector<std::pair<index_t, double>> found;
  nanoflann::SearchParams params;
  params.sorted = false;
  VertexWeights out;
  for (int widening = 0; widening <= 5; ++widening, h *= 1.5) {
    found.clear();
    tree.index().radiusSearch(y.data(), h * h, found, params);
    if (sees) std::erase_if(found, [&](const std::pair<index_t, double>& f) { return !sees(vertex, f.first); });
    if (found.size() < 4) {
      out.widened = true;
      continue;
    }
    Mat4 M = Mat4::Zero();
    out.points.clear();
    out.weight.clear();
    std::vector<Vec4> basis;
    for (const auto& [j, r2] : found) {
      const Vec3 x = (model.X.col(j) - y) / h;
      // the viscosity kernel is infinite at r = 0: a vertex on a point gets a large finite weight instead
      const double w = kernel_value(model.kernel.type, std::max(std::sqrt(r2), 1e-6 * h), h);
      if (!(w > 0)) continue;
      const Vec4 p(1, x.x(), x.y(), x.z());
      M += w * p * p.transpose();
      out.points.push_back(j);
      out.weight.push_back(w);
      basis.push_back(p);
    }
    const Eigen::SelfAdjointEigenSolver<Mat4> eig(M, Eigen::EigenvaluesOnly);
    if (out.points.size() < 4 || !(eig.eigenvalues()[0] > 1e-8 * eig.eigenvalues()[3])) {
      out.widened = true;
      continue;
    }
    const Vec4 a = M.ldlt().solve(Vec4::UnitX());  // M^-1 p(0)
    for (std::size_t k = 0; k < out.points.size(); ++k) out.weight[k] *= a.dot(basis[k]);
    return out;
  }
  if (!skip_uncarried)
    throw Error(
        fmt::format("surface vertex {} at ({:.4g}, {:.4g}, {:.4g}) m: too few points around it to carry it "
                    "(none or only a flat set within {:.3g} m)",
                    vertex, y.x(), y.y(), y.z(), h / 1.5));
  return VertexWeights{{}, {}, true, false};
}

}  // namespace

SurfaceMap build_surface_map(const Model& model, const Points& Y, std::vector<char>* uncarried,
                             const VertexSees& sees) {
  if (model.n_points < 4)
    throw Error(fmt::format("surface: {} points cannot carry a surface (at least 4)", model.n_points));
  if (!Y.allFinite()) throw Error("surface: a vertex is not finite");
  const index_t m = static_cast<index_t>(Y.cols());
  const KdTree tree(model.X);
  std::vector<VertexWeights> rows(static_cast<std::size_t>(m));
  tbb::parallel_for(tbb::blocked_range<index_t>(0, m, 256), [&](const tbb::blocked_range<index_t>& range) {
    for (index_t v = range.begin(); v != range.end(); ++v) {
      const Vec3 y = Y.col(v);
      double h = model.h;
      if (model.support.size() == model.n_points) {  // per-point supports: the nearest point's
        index_t nearest = 0;
        double d2 = 0;
        tree.index().knnSearch(y.data(), 1, &nearest, &d2);
        h = model.support[nearest];
      }
      rows[static_cast<std::size_t>(v)] = vertex_weights(model, tree, y, h, v, uncarried != nullptr, sees);
    }
  });
  SurfaceMap map;
  map.points.offset.reserve(static_cast<std::size_t>(m) + 1);
  if (uncarried) uncarried->assign(static_cast<std::size_t>(m), 0);
  for (const VertexWeights& row : rows) {
    if (!row.carried) (*uncarried)[static_cast<std::size_t>(&row - rows.data())] = 1;
    map.points.index.insert(map.points.index.end(), row.points.begin(), row.points.end());
    map.weight.insert(map.weight.end(), row.weight.begin(), row.weight.end());
    map.points.offset.push_back(static_cast<index_t>(map.points.index.size()));
    map.widened += row.widened;
  }
  return map;
}

void interpolate_at_surface(const SurfaceMap& map, const Eigen::Ref<const Eigen::MatrixXd>& field,
                            Eigen::MatrixXd& out) {
  out.setZero(field.rows(), map.n_vertices());
  for (index_t v = 0; v < map.n_vertices(); ++v)
    for (index_t e = map.points.begin(v); e < map.points.end(v); ++e)
      out.col(v) += map.weight[e] * field.col(map.points.index[e]);
}

// The carry runs for every frame drawn or written (and, with contact on the surface, every step), so it is
// written for speed (issue 15: under 10% of a 10k-point explicit step): the displacements are first padded to
// four doubles per point, so that a weight's term is one load and one multiply-add of a SIMD register, and
// each vertex keeps four partial sums, so that its multiply-adds do not wait on one another. Measured on the
// bench box (10.6k vertices, 20 weights each): 0.6 of the three-scalar loop's time.
void carry_surface(const SurfaceMap& map, const Points& Y, const Points& u, Points& y) {
  y.resize(3, map.n_vertices());
  carry_surface_into(map, Y, u, y);
}

void carry_surface_into(const SurfaceMap& map, const Points& Y, const Points& u, Eigen::Ref<Points> y) {
  const index_t n_vertices = map.n_vertices();
  thread_local std::vector<Lanes> padded;  // grown once per thread, reused: no allocation per carry
  padded.resize(static_cast<std::size_t>(u.cols()));
  for (index_t j = 0; j < u.cols(); ++j) padded[static_cast<std::size_t>(j)] = Lanes{u(0, j), u(1, j), u(2, j), 0.0};
  const index_t* point = map.points.index.data();
  const double* weight = map.weight.data();
  const Lanes* displacement = padded.data();
  for (index_t v = 0; v < n_vertices; ++v) {
    Lanes sum[4] = {Lanes{Y(0, v), Y(1, v), Y(2, v), 0.0}, Lanes{}, Lanes{}, Lanes{}};
    index_t e = map.points.begin(v);
    const index_t end = map.points.end(v);
    for (; e + 4 <= end; e += 4)
      for (int k = 0; k < 4; ++k) sum[k] += weight[e + k] * displacement[point[e + k]];
    for (; e < end; ++e) sum[0] += weight[e] * displacement[point[e]];
    const Lanes total = (sum[0] + sum[1]) + (sum[2] + sum[3]);
    y.col(v) = Vec3(total[0], total[1], total[2]);
  }
}

SurfaceMap without_negative_weights(SurfaceMap map) {
  for (index_t v = 0; v < map.n_vertices(); ++v) {
    double sum = 0;
    for (index_t e = map.points.begin(v); e < map.points.end(v); ++e) sum += std::max(map.weight[e], 0.0);
    // a carried vertex's weights sum to 1, so some are positive; an empty row stays empty
    for (index_t e = map.points.begin(v); e < map.points.end(v); ++e)
      map.weight[e] = sum > 0 ? std::max(map.weight[e], 0.0) / sum : 0.0;
  }
  return map;
}

// The carry's transpose, padded the same way: it runs at every CG iteration of the two-level preconditioner
// (P^T r), where the three-scalar loop was a fifth of the preconditioner's cost
void spread_surface_forces(const SurfaceMap& map, const Points& f_vertices, Points& f_points) {
  thread_local std::vector<Lanes> padded;  // grown once per thread, reused: no allocation per spread
  padded.assign(static_cast<std::size_t>(f_points.cols()), Lanes{});
  const index_t* point = map.points.index.data();
  const double* weight = map.weight.data();
  Lanes* force = padded.data();
  for (index_t v = 0; v < map.n_vertices(); ++v) {
    const Lanes f{f_vertices(0, v), f_vertices(1, v), f_vertices(2, v), 0.0};
    for (index_t e = map.points.begin(v); e < map.points.end(v); ++e) force[point[e]] += weight[e] * f;
  }
  for (index_t j = 0; j < f_points.cols(); ++j) {
    const Lanes& sum = padded[static_cast<std::size_t>(j)];
    f_points.col(j) += Vec3(sum[0], sum[1], sum[2]);
  }
}

}  // namespace pointhaptics
