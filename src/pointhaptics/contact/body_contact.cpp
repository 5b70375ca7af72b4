#include <pointhaptics/contact/body_contact.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/mesh_distance.hpp>
#include <pointhaptics/mechanics/tangent_matrix.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pointhaptics {

namespace {

// barycentric coordinates of c, a point of triangle (a, b, d)
std::array<double, 3> barycentric(const Vec3& c, const Vec3& a, const Vec3& b, const Vec3& d) {
  const Vec3 e0 = b - a, e1 = d - a, r = c - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1), d20 = r.dot(e0), d21 = r.dot(e1);
  const double det = d00 * d11 - d01 * d01;
  if (!(det > 0)) return {1.0 / 3, 1.0 / 3, 1.0 / 3};
  const double beta = (d11 * d20 - d01 * d21) / det, gamma = (d00 * d21 - d01 * d20) / det;
  return {1 - beta - gamma, beta, gamma};
}

}  // namespace

BodyContact::BodyContact(const Model& model, TriangleMesh mesh, SurfaceMap map, std::vector<index_t> vertex_start,
                         std::vector<index_t> face_start, const BodyContactParams& params)
    : mesh_(std::move(mesh)),
      map_(std::move(map)),
      vertex_start_(std::move(vertex_start)),
      face_start_(std::move(face_start)) {
  const index_t nv = static_cast<index_t>(mesh_.V.cols());
  if (map_.n_vertices() != nv || vertex_start_.size() < 3 || vertex_start_.size() != face_start_.size() ||
      vertex_start_.back() != nv || face_start_.back() != static_cast<index_t>(mesh_.F.size()))
    throw Error("body contact: the surface's bodies do not match its vertices and triangles (at least two bodies)");
  const double spacing = model.spacing;
  tolerance_ = params.tolerance > 0 ? params.tolerance : 1e-3 * spacing;
  reach_ = params.reach > 0 ? params.reach : spacing;
  rate_ = params.multiplier_rate;

  // each vertex's share of its triangles' area, and its body's Young's modulus (its first point's)
  std::vector<double> area(static_cast<std::size_t>(nv), 0.0);
  for (const auto& t : mesh_.F) {
    const double a = 0.5 * (mesh_.V.col(t[1]) - mesh_.V.col(t[0])).cross(mesh_.V.col(t[2]) - mesh_.V.col(t[0])).norm();
    for (index_t v : t) area[static_cast<std::size_t>(v)] += a / 3;
  }
  vertex_stiffness_.resize(static_cast<std::size_t>(nv));
  std::vector<double> point_stiffness(static_cast<std::size_t>(model.n_points), 0.0);
  for (index_t v = 0; v < nv; ++v) {
    const double young =
        map_.points.row_size(v) ? model.young_at(map_.points.index[map_.points.begin(v)]) : model.material.young;
    const double penalty = params.penalty > 0 ? params.penalty : 1e3 * young / spacing;
    const double k = penalty * area[static_cast<std::size_t>(v)];
    vertex_stiffness_[static_cast<std::size_t>(v)] = k;
    for (index_t e = map_.points.begin(v); e < map_.points.end(v); ++e)
      point_stiffness[static_cast<std::size_t>(map_.points.index[e])] += k * map_.weight[e] * map_.weight[e];
  }
  // a point is pressed through its own vertices and through the triangles other vertices press on: twice its
  // own share at most (the explicit stable step's bound)
  double largest = 2 * *std::max_element(point_stiffness.begin(), point_stiffness.end());
  if (params.max_point_stiffness > 0 && largest > params.max_point_stiffness) {
    const double scale = params.max_point_stiffness / largest;
    for (double& k : vertex_stiffness_) k *= scale;
    largest = params.max_point_stiffness;
  }
  max_point_stiffness_ = largest;
  grid_ = SpatialGrid(2 * reach_);
}

index_t BodyContact::body_of_vertex(index_t v) const {
  return static_cast<index_t>(std::upper_bound(vertex_start_.begin(), vertex_start_.end(), v) - vertex_start_.begin()) -
         1;
}
index_t BodyContact::body_of_face(index_t t) const {
  return static_cast<index_t>(std::upper_bound(face_start_.begin(), face_start_.end(), t) - face_start_.begin()) - 1;
}

void BodyContact::refresh(const Model& model, const Points& u) {
  refreshed_ = true;
  const index_t nv = static_cast<index_t>(mesh_.V.cols()), nf = static_cast<index_t>(mesh_.F.size());
  carry_surface(map_, mesh_.V, u, y_);
  // the multipliers of the vertices paired now, kept for those paired again
  previous_multiplier_.assign(static_cast<std::size_t>(nv), 0.0);
  for (const Pair& p : pairs_) previous_multiplier_[static_cast<std::size_t>(p.vertex)] = p.multiplier;

  // the deformed triangles' centroids, reach and normals; the vertices' normals (area-weighted)
  centroid_.resize(3, nf);
  vertex_normal_.setZero(3, nv);
  max_circumradius_ = 0;
  for (index_t t = 0; t < nf; ++t) {
    const auto& f = mesh_.F[static_cast<std::size_t>(t)];
    const Vec3 a = y_.col(f[0]), b = y_.col(f[1]), c = y_.col(f[2]);
    const Vec3 centre = (a + b + c) / 3;
    centroid_.col(t) = centre;
    max_circumradius_ = std::max({max_circumradius_, (a - centre).norm(), (b - centre).norm(), (c - centre).norm()});
    const Vec3 twice_area = (b - a).cross(c - a);
    for (index_t v : f) vertex_normal_.col(v) += twice_area;
  }
  grid_.rebuild(centroid_);

  pairs_.clear();
  coefficient_.clear();
  for (index_t v = 0; v < nv; ++v) {
    const index_t body = body_of_vertex(v);
    const Vec3 y = y_.col(v), vertex_normal = vertex_normal_.col(v);
    double best = std::numeric_limits<double>::infinity();
    index_t nearest = -1;
    Vec3 nearest_point = Vec3::Zero(), nearest_normal = Vec3::Zero();
    grid_.for_each_within(centroid_, y, reach_ + max_circumradius_, [&](index_t t) {
      if (body_of_face(t) == body) return;
      const auto& f = mesh_.F[static_cast<std::size_t>(t)];
      const Vec3 a = y_.col(f[0]), b = y_.col(f[1]), c = y_.col(f[2]);
      const Vec3 normal = (b - a).cross(c - a).normalized();
      // surfaces that face each other only (not the far side of a thin body, nor a side face met edge on)
      if (!(normal.dot(vertex_normal) < 0)) return;
      const Vec3 point = closest_on_triangle(y, a, b, c).first;
      const double d = (y - point).norm();
      if (d <= reach_ && d < best) {
        best = d;
        nearest = t;
        nearest_point = point;
        nearest_normal = normal;
      }
    });
    if (nearest < 0) continue;
    const auto& f = mesh_.F[static_cast<std::size_t>(nearest)];
    const std::array<double, 3> beta = barycentric(nearest_point, y_.col(f[0]), y_.col(f[1]), y_.col(f[2]));
    Pair p;
    p.vertex = v;
    p.triangle = nearest;
    p.normal = nearest_normal;
    p.stiffness = vertex_stiffness_[static_cast<std::size_t>(v)];
    p.multiplier = previous_multiplier_[static_cast<std::size_t>(v)];
    p.first = static_cast<index_t>(coefficient_.size());
    Vec3 reference = mesh_.V.col(v);
    for (index_t e = map_.points.begin(v); e < map_.points.end(v); ++e)
      coefficient_.emplace_back(map_.points.index[e], map_.weight[e]);
    const auto own_end = coefficient_.size();
    for (int b = 0; b < 3; ++b) {
      reference -= beta[static_cast<std::size_t>(b)] * mesh_.V.col(f[static_cast<std::size_t>(b)]);
      for (index_t e = map_.points.begin(f[static_cast<std::size_t>(b)]);
           e < map_.points.end(f[static_cast<std::size_t>(b)]); ++e) {
        const index_t j = map_.points.index[e];
        const double c = -beta[static_cast<std::size_t>(b)] * map_.weight[e];
        // the triangle's corners share points: one coefficient each
        const auto same = std::find_if(coefficient_.begin() + static_cast<std::ptrdiff_t>(own_end), coefficient_.end(),
                                       [&](const auto& jc) { return jc.first == j; });
        if (same != coefficient_.end()) same->second += c;
        else coefficient_.emplace_back(j, c);
      }
    }
    p.last = static_cast<index_t>(coefficient_.size());
    p.gap0 = p.normal.dot(reference);
    pairs_.push_back(p);
  }
  pressing_.assign(pairs_.size(), 0);
  (void)model;
}

double BodyContact::gap(const Pair& p, const Points& u) const {
  Vec3 moved = Vec3::Zero();
  for (index_t e = p.first; e < p.last; ++e)
    moved += coefficient_[static_cast<std::size_t>(e)].second * u.col(coefficient_[static_cast<std::size_t>(e)].first);
  return p.gap0 + p.normal.dot(moved);
}

double BodyContact::energy(const Model& model, const Points& u) {
  if (!refreshed_) refresh(model, u);
  double e = 0;
  for (const Pair& p : pairs_) {
    const double f = pressing(p, gap(p, u));
    e += (f * f - p.multiplier * p.multiplier) / (2 * p.stiffness);
  }
  return e;
}

void BodyContact::add_forces(const Model& model, const Points& u, Points& f) {
  if (!refreshed_) refresh(model, u);
  for (const Pair& p : pairs_) {
    const double force = pressing(p, gap(p, u));
    if (force <= 0) continue;
    const Vec3 along = force * p.normal;
    for (index_t e = p.first; e < p.last; ++e)
      f.col(coefficient_[static_cast<std::size_t>(e)].first) +=
          coefficient_[static_cast<std::size_t>(e)].second * along;
  }
}

void BodyContact::linearise(const Model& model, const Points& u, TangentMode) {
  if (!refreshed_) refresh(model, u);
  for (std::size_t k = 0; k < pairs_.size(); ++k)
    pressing_[k] = pairs_[k].multiplier - pairs_[k].stiffness * gap(pairs_[k], u) > 0;
}

void BodyContact::add_tangent_product(const Points& dx, Points& out) const {
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    if (!pressing_[k]) continue;
    const Pair& p = pairs_[k];
    Vec3 moved = Vec3::Zero();
    for (index_t e = p.first; e < p.last; ++e)
      moved +=
          coefficient_[static_cast<std::size_t>(e)].second * dx.col(coefficient_[static_cast<std::size_t>(e)].first);
    const Vec3 h = p.stiffness * p.normal.dot(moved) * p.normal;
    for (index_t e = p.first; e < p.last; ++e)
      out.col(coefficient_[static_cast<std::size_t>(e)].first) += coefficient_[static_cast<std::size_t>(e)].second * h;
  }
}

void BodyContact::add_diagonal_blocks(Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks) const {
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    if (!pressing_[k]) continue;
    const Pair& p = pairs_[k];
    const Mat3 nn = p.stiffness * p.normal * p.normal.transpose();
    for (index_t e = p.first; e < p.last; ++e) {
      const auto& [j, c] = coefficient_[static_cast<std::size_t>(e)];
      Eigen::Map<Mat3>(blocks.col(j).data()) += c * c * nn;
    }
  }
}

bool BodyContact::add_to_matrix(TangentMatrix& K) const {
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    if (!pressing_[k]) continue;
    const Pair& p = pairs_[k];
    const Mat3 nn = p.stiffness * p.normal * p.normal.transpose();
    for (index_t e = p.first; e < p.last; ++e)
      for (index_t f = e; f < p.last; ++f) {
        const auto& [i, ci] = coefficient_[static_cast<std::size_t>(e)];
        const auto& [j, cj] = coefficient_[static_cast<std::size_t>(f)];
        add_coupling(K, i, j, ci * cj, nn);
      }
  }
  return true;
}

bool BodyContact::update_multipliers(const Model& model, const Points& u) {
  // pair again where the bodies are now (keeping the multipliers), then check
  refresh(model, u);
  double deepest = 0;
  for (const Pair& p : pairs_) deepest = std::max(deepest, -gap(p, u));
  if (deepest <= tolerance_) return true;
  for (Pair& p : pairs_) p.multiplier = pressing(p, gap(p, u));
  return false;
}

void BodyContact::add(const Model& model, const State& state, Points& f) { add_forces(model, state.u, f); }

void BodyContact::after_step(const Model& model, const State& state, Workspace&) {
  // Uzawa's update spread over the steps: each multiplier moves by a share of the way to its pair's force
  for (Pair& p : pairs_) p.multiplier += rate_ * (pressing(p, gap(p, state.u)) - p.multiplier);
  refresh(model, state.u);
}

BodyLoads BodyContact::loads(const Model&, const Points& u) const {
  BodyLoads out;
  out.force.assign(vertex_start_.size() - 1, Vec3::Zero());
  for (const Pair& p : pairs_) {
    const double g = gap(p, u), force = pressing(p, g);
    out.penetration = std::max(out.penetration, -g);
    if (force <= 0) continue;
    ++out.contacts;
    out.force[static_cast<std::size_t>(body_of_vertex(p.vertex))] += force * p.normal;
    out.force[static_cast<std::size_t>(body_of_face(p.triangle))] -= force * p.normal;
  }
  return out;
}

}  // namespace pointhaptics
