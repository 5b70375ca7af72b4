#include <pointhaptics/contact/body_contact.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/mechanics/tangent_matrix.hpp>

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
  if (map_.n_vertices() != nv || vertex_start_.size() < 2 || vertex_start_.size() != face_start_.size() ||
      vertex_start_.back() != nv || face_start_.back() != static_cast<index_t>(mesh_.F.size()) ||
      static_cast<index_t>(vertex_start_.size()) - 1 != model.n_bodies())
    throw Error("body contact: the surface's bodies do not match its vertices and triangles, or the model's bodies");
  std::vector<index_t> piece_of;
  connected_pieces(model, piece_of);
  vertex_piece_.assign(static_cast<std::size_t>(nv), -1);
  for (index_t v = 0; v < nv; ++v)
    if (map_.points.row_size(v) > 0)
      vertex_piece_[static_cast<std::size_t>(v)] =
          piece_of[static_cast<std::size_t>(map_.points.index[map_.points.begin(v)])];
  face_piece_.reserve(mesh_.F.size());
  for (const auto& f : mesh_.F) face_piece_.push_back(vertex_piece_[static_cast<std::size_t>(f[0])]);
  piece_box_.resize(static_cast<std::size_t>(*std::max_element(piece_of.begin(), piece_of.end())) + 1);
  const double spacing = model.spacing;
  tolerance_ = params.tolerance > 0 ? params.tolerance : 1e-3 * spacing;
  reach_ = params.reach > 0 ? params.reach : spacing;
  rate_ = params.multiplier_rate;
  friction_rate_ = params.friction_rate;
  if (!(rate_ > 0 && rate_ <= 1) || !(friction_rate_ > 0 && friction_rate_ <= 1))
    throw Error("body contact: the multipliers' rates must lie in (0, 1]");
  const std::size_t bodies = vertex_start_.size() - 1;
  if (!(params.friction >= 0) || !(params.tangential_share > 0 && params.tangential_share <= 1) ||
      (!params.pair_friction.empty() && params.pair_friction.size() != bodies * bodies))
    throw Error("body contact: friction must be >= 0, one per pair of bodies, and the tangential share in (0, 1]");
  tangential_share_ = params.tangential_share;
  update_after_step_ = params.update_after_step;
  pair_friction_ =
      params.pair_friction.empty() ? std::vector<double>(bodies * bodies, params.friction) : params.pair_friction;
  anchors_.assign(static_cast<std::size_t>(nv), Anchor{});

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

namespace {

// the range k with starts[k] <= i < starts[k + 1]
index_t range_of(const std::vector<index_t>& starts, index_t i) {
  return static_cast<index_t>(std::upper_bound(starts.begin(), starts.end(), i) - starts.begin()) - 1;
}

}  // namespace

index_t BodyContact::body_of_vertex(index_t v) const { return range_of(vertex_start_, v); }
index_t BodyContact::body_of_face(index_t t) const { return range_of(face_start_, t); }

void BodyContact::carry_multipliers(const BodyContact& from, std::span<const index_t> from_vertex) {
  if (refreshed_ || from_vertex.size() != static_cast<std::size_t>(mesh_.V.cols()))
    throw Error("body contact: multipliers are carried over before the first refresh, one source per vertex");
  std::vector<double> multiplier(static_cast<std::size_t>(from.mesh_.V.cols()), 0.0);
  for (const Pair& p : from.pairs_) multiplier[static_cast<std::size_t>(p.vertex)] = p.multiplier;
  previous_multiplier_.assign(from_vertex.size(), 0.0);
  for (std::size_t v = 0; v < from_vertex.size(); ++v)
    if (from_vertex[v] >= 0) previous_multiplier_[v] = multiplier[static_cast<std::size_t>(from_vertex[v])];
}

void BodyContact::refresh(const Model& model, const Points& u) {
  const index_t nv = static_cast<index_t>(mesh_.V.cols()), nf = static_cast<index_t>(mesh_.F.size());
  carry_surface(map_, mesh_.V, u, y_);
  // the multipliers of the vertices paired now, kept for those paired again (at the first refresh, those
  // carry_multipliers() gave, if any)
  if (refreshed_ || previous_multiplier_.size() != static_cast<std::size_t>(nv)) {
    previous_multiplier_.assign(static_cast<std::size_t>(nv), 0.0);
    for (const Pair& p : pairs_) previous_multiplier_[static_cast<std::size_t>(p.vertex)] = p.multiplier;
  }
  previous_triangle_.assign(static_cast<std::size_t>(nv), -1);
  for (const Pair& p : pairs_) previous_triangle_[static_cast<std::size_t>(p.vertex)] = p.triangle;
  refreshed_ = true;

  // the deformed triangles' centroids, reach and unit normals, and each piece's box; the vertices' normals
  // (area-weighted)
  centroid_.resize(3, nf);
  face_normal_.resize(3, nf);
  vertex_normal_.setZero(3, nv);
  for (Eigen::AlignedBox3d& box : piece_box_) box.setEmpty();  // (one per piece, sized with them by the constructor)
  max_circumradius_ = 0;
  for (index_t t = 0; t < nf; ++t) {
    const auto& f = mesh_.F[static_cast<std::size_t>(t)];
    const Vec3 a = y_.col(f[0]), b = y_.col(f[1]), c = y_.col(f[2]);
    const Vec3 centre = (a + b + c) / 3;
    centroid_.col(t) = centre;
    max_circumradius_ = std::max({max_circumradius_, (a - centre).norm(), (b - centre).norm(), (c - centre).norm()});
    const Vec3 twice_area = (b - a).cross(c - a);
    face_normal_.col(t) = twice_area.normalized();
    for (index_t v : f) vertex_normal_.col(v) += twice_area;
    const index_t piece = face_piece_[static_cast<std::size_t>(t)];
    if (piece < 0) continue;
    for (const Vec3& corner : {a, b, c}) piece_box_[static_cast<std::size_t>(piece)].extend(corner);
  }
  grid_.rebuild(centroid_);
  // a vertex farther than the reach from every other piece's box meets no face of it: no grid search (most of a
  // body's surface, away from the others)
  const auto near_another_piece = [&](const Vec3& y, index_t own) {
    for (std::size_t q = 0; q < piece_box_.size(); ++q)
      if (static_cast<index_t>(q) != own && piece_box_[q].exteriorDistance(y) <= reach_) return true;
    return false;
  };

  pairs_.clear();
  coefficient_.clear();
  for (index_t v = 0; v < nv; ++v) {
    const index_t body = body_of_vertex(v);
    const Vec3 y = y_.col(v), vertex_normal = vertex_normal_.col(v);
    double best = std::numeric_limits<double>::infinity();
    index_t nearest = -1;
    Vec3 nearest_normal = Vec3::Zero();
    double nearest_distance = 0;
    std::array<double, 3> beta{0, 0, 0};
    const index_t piece = vertex_piece_[static_cast<std::size_t>(v)];
    Anchor& anchor = anchors_[static_cast<std::size_t>(v)];
    if (piece < 0 || !near_another_piece(y, piece)) {
      anchor = Anchor{};
      continue;
    }
    // face t, if it may take vertex v: nearer than the best so far
    const auto consider = [&](index_t t) {
      if (face_piece_[static_cast<std::size_t>(t)] == piece) return;
      const auto& f = mesh_.F[static_cast<std::size_t>(t)];
      const Vec3 a = y_.col(f[0]), b = y_.col(f[1]), c = y_.col(f[2]);
      const Vec3 normal = face_normal_.col(t);
      // surfaces that face each other only, within 60 degrees: not the far side of a thin body, nor a side face
      // met edge on (a base's vertex beside a block standing on it, paired with the block's side, held the block
      // from sliding as the side's plane came to it)
      if (!(normal.dot(vertex_normal) < -0.5 * vertex_normal.norm())) return;
      // the face covers the vertex: its projection on the face's plane lies in the triangle (a hundredth of it
      // beyond, where two triangles meet). Not the face's plane beyond the body's edge: a vertex beside a body's
      // base is below that plane but outside the body
      const double distance = normal.dot(y - a);
      const std::array<double, 3> coordinates = barycentric(y - distance * normal, a, b, c);
      if (std::min({coordinates[0], coordinates[1], coordinates[2]}) < -0.01) return;
      if (std::abs(distance) <= reach_ && std::abs(distance) < best) {
        best = std::abs(distance);
        nearest = t;
        nearest_normal = normal;
        nearest_distance = distance;
        beta = coordinates;
      }
    };
    // a vertex keeps its triangle while that still covers it. Two triangles of a faceted curved surface that meet
    // at a kink give a vertex by their edge gaps that differ by the kink's angle times its distance from the
    // edge, and the stiff penalty makes that a force: two elastic spheres pressed together statically flipped
    // between two pairings at the same displacement, their force changing by 0.6% and 4% by turns, and never
    // converged ("not met after 50 updates"). Kept, a vertex changes triangle only once it has moved past the
    // overlap where both cover it
    if (const index_t kept = previous_triangle_[static_cast<std::size_t>(v)]; kept >= 0) consider(kept);
    if (nearest < 0) grid_.for_each_within(centroid_, y, reach_ + max_circumradius_, consider);
    if (nearest < 0) {
      anchor = Anchor{};
      continue;
    }
    Pair p;
    p.vertex = v;
    p.triangle = nearest;
    p.normal = nearest_normal;
    p.stiffness = vertex_stiffness_[static_cast<std::size_t>(v)];
    p.multiplier = previous_multiplier_[static_cast<std::size_t>(v)];
    p.friction = pair_friction_[static_cast<std::size_t>(body) * (vertex_start_.size() - 1) +
                                static_cast<std::size_t>(body_of_face(nearest))];
    p.first = static_cast<index_t>(coefficient_.size());
    p.gap0 = p.normal.dot(append_difference(v, nearest, beta));
    p.last = static_cast<index_t>(coefficient_.size());
    // friction holds a vertex where it was anchored while it is in force; a vertex paired afresh sticks where it
    // touches, and one that slid or began to press is anchored where it is now (a slide keeps its force)
    const bool new_pair = anchor.triangle < 0;
    if (new_pair || anchor.afresh) {
      if (new_pair) {
        anchor.state = nearest_distance <= tolerance_ ? Friction::FRESH : Friction::FREE;
        anchor.tau.setZero();
      }
      anchor.triangle = nearest;
      anchor.beta = beta;
      anchor.afresh = false;
    }
    anchor.tau -= anchor.tau.dot(p.normal) * p.normal;  // in the tangent plane of this pairing
    p.slip_first = static_cast<index_t>(coefficient_.size());
    p.slip0 = append_difference(v, anchor.triangle, anchor.beta);
    p.slip_last = static_cast<index_t>(coefficient_.size());
    pairs_.push_back(p);
  }
  (void)model;
}

Vec3 BodyContact::append_difference(index_t v, index_t triangle, const std::array<double, 3>& beta) {
  const auto own_end =
      static_cast<std::ptrdiff_t>(coefficient_.size()) + static_cast<std::ptrdiff_t>(map_.points.row_size(v));
  for (index_t e = map_.points.begin(v); e < map_.points.end(v); ++e)
    coefficient_.emplace_back(map_.points.index[e], map_.weight[e]);
  Vec3 reference = mesh_.V.col(v);
  const auto& f = mesh_.F[static_cast<std::size_t>(triangle)];
  for (std::size_t b = 0; b < 3; ++b) {
    reference -= beta[b] * mesh_.V.col(f[b]);
    for (index_t e = map_.points.begin(f[b]); e < map_.points.end(f[b]); ++e) {
      const index_t j = map_.points.index[e];
      const double c = -beta[b] * map_.weight[e];
      // the triangle's corners share points: one coefficient each
      const auto same = std::find_if(coefficient_.begin() + own_end, coefficient_.end(),
                                     [&](const auto& jc) { return jc.first == j; });
      if (same != coefficient_.end()) same->second += c;
      else coefficient_.emplace_back(j, c);
    }
  }
  return reference;
}

Vec3 BodyContact::gather(index_t first, index_t last, const Points& y) const {
  Vec3 sum = Vec3::Zero();
  for (index_t e = first; e < last; ++e) {
    const auto& [j, c] = coefficient_[static_cast<std::size_t>(e)];
    sum += c * y.col(j);
  }
  return sum;
}

void BodyContact::spread(index_t first, index_t last, const Vec3& along, Points& f) const {
  for (index_t e = first; e < last; ++e) {
    const auto& [j, c] = coefficient_[static_cast<std::size_t>(e)];
    f.col(j) += c * along;
  }
}

double BodyContact::gap(const Pair& p, const Points& u) const {
  return p.gap0 + p.normal.dot(gather(p.first, p.last, u));
}

Vec3 BodyContact::slip(const Pair& p, const Points& u) const {
  const Vec3 d = p.slip0 + gather(p.slip_first, p.slip_last, u);
  return d - d.dot(p.normal) * p.normal;
}

Vec3 BodyContact::trial(const Pair& p, const Vec3& s) const {
  return anchors_[static_cast<std::size_t>(p.vertex)].tau + tangential_stiffness(p) * s;
}

Vec3 BodyContact::friction_force(const Pair& p, const Vec3& s) const {
  const Vec3 t = trial(p, s);
  const double c = cone(p), norm = t.norm();
  return norm > c ? Vec3(c / norm * t) : t;
}

double BodyContact::energy(const Model& model, const Points& u) {
  if (!refreshed_) refresh(model, u);
  double e = 0;
  for (const Pair& p : pairs_) {
    const double f = pressing(p, gap(p, u));
    e += (f * f - p.multiplier * p.multiplier) / (2 * p.stiffness);
    // friction: quadratic in the trial force inside the cone, linear beyond it
    const double c = cone(p);
    if (c <= 0) continue;
    const double k = tangential_stiffness(p), t = trial(p, slip(p, u)).norm();
    e += ((t <= c ? t * t : 2 * c * t - c * c) - anchors_[static_cast<std::size_t>(p.vertex)].tau.squaredNorm()) /
         (2 * k);
  }
  return e;
}

void BodyContact::add_forces(const Model& model, const Points& u, Points& f) {
  if (!refreshed_) refresh(model, u);
  for (const Pair& p : pairs_) {
    const double force = pressing(p, gap(p, u));
    if (force > 0) spread(p.first, p.last, force * p.normal, f);
    // the friction's force on the vertex is minus its trial force (clamped), against the slip
    if (cone(p) > 0) spread(p.slip_first, p.slip_last, -friction_force(p, slip(p, u)), f);
  }
}

void BodyContact::linearise(const Model& model, const Points& u, TangentMode) {
  if (!refreshed_) refresh(model, u);
  for (Pair& p : pairs_) {
    // at the kink too (a vertex touching with no multiplier yet): the tangent's pressing side there, so that a
    // body resting exactly on another has its weight's stiffness from the first iteration (with only the side
    // that has none, its fall is singular and conjugate gradients ran out in the ASan build)
    p.pressing = p.multiplier - p.stiffness * gap(p, u) >= 0;
    p.friction_hessian.setZero();
    const double c = cone(p);
    if (c <= 0) continue;
    const Mat3 tangent_plane = Mat3::Identity() - p.normal * p.normal.transpose();
    const double k = tangential_stiffness(p);
    const Vec3 t = trial(p, slip(p, u));
    const double norm = t.norm();
    // inside the cone k P; beyond it the clamped force's derivative, (c k / |t|) P (I - t^ t^T) P
    p.friction_hessian = norm <= c ? Mat3(k * tangent_plane)
                                   : Mat3(c * k / norm * tangent_plane *
                                          (Mat3::Identity() - t * t.transpose() / (norm * norm)) * tangent_plane);
  }
}

template <class Visit>
void BodyContact::for_each_block(const Visit& visit) const {
  for (const Pair& p : pairs_) {
    if (p.pressing) visit(p.first, p.last, Mat3(p.stiffness * p.normal * p.normal.transpose()));
    if (cone(p) > 0) visit(p.slip_first, p.slip_last, p.friction_hessian);
  }
}

void BodyContact::add_tangent_product(const Points& dx, Points& out) const {
  for_each_block([&](index_t first, index_t last, const Mat3& block) {
    spread(first, last, block * gather(first, last, dx), out);
  });
}

void BodyContact::add_diagonal_blocks(Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks) const {
  for_each_block([&](index_t first, index_t last, const Mat3& block) {
    for (index_t e = first; e < last; ++e) {
      const auto& [j, c] = coefficient_[static_cast<std::size_t>(e)];
      Eigen::Map<Mat3>(blocks.col(j).data()) += c * c * block;
    }
  });
}

bool BodyContact::add_to_matrix(TangentMatrix& K) const {
  for_each_block([&](index_t first, index_t last, const Mat3& block) {
    for (index_t e = first; e < last; ++e)
      for (index_t f = e; f < last; ++f) {
        const auto& [i, ci] = coefficient_[static_cast<std::size_t>(e)];
        const auto& [j, cj] = coefficient_[static_cast<std::size_t>(f)];
        add_coupling(K, i, j, ci * cj, block);
      }
  });
  return true;
}

bool BodyContact::friction_met(const Points& u) const {
  for (const Pair& p : pairs_) {
    if (p.friction <= 0) continue;
    const Anchor& a = anchors_[static_cast<std::size_t>(p.vertex)];
    const bool presses = pressing(p, gap(p, u)) > 0;
    if (a.state != Friction::HELD) {
      if (presses) return false;  // its friction is to be put in force
      continue;
    }
    const double c = cone(p);
    const Vec3 s = slip(p, u), t = trial(p, s);
    // a sticking vertex is done on its anchor, a sliding one when its force stopped changing
    if (t.norm() <= c ? s.norm() > tolerance_
                      : (c / t.norm() * t - a.tau).norm() > tangential_stiffness(p) * tolerance_)
      return false;
  }
  return true;
}

void BodyContact::update_friction(const Points& u, double rate) {
  for (const Pair& p : pairs_) {
    if (p.friction <= 0) continue;
    Anchor& a = anchors_[static_cast<std::size_t>(p.vertex)];
    if (!(pressing(p, gap(p, u)) > 0)) {  // no friction without pressure
      a.state = Friction::FREE;
      a.tau.setZero();
      continue;
    }
    if (a.state == Friction::FREE) {  // pressing now: anchored where it is at the next refresh
      a.state = Friction::HELD;
      a.afresh = true;
      continue;
    }
    const double c = cone(p);
    const Vec3 t = trial(p, slip(p, u));
    if (t.norm() <= c) {
      a.tau += rate * (t - a.tau);
    } else {
      a.tau = c / t.norm() * t;  // on the cone; the anchor moves to where the vertex is at the next refresh
      a.afresh = true;
    }
    a.state = Friction::HELD;
  }
}

bool BodyContact::update_multipliers(const Model& model, const Points& u) {
  // met when no vertex is deeper in another body than the tolerance and friction's stick and slide are met, with
  // the pairs the solve had and with those at u (a vertex that came near another body during it is paired now);
  // else the multipliers and anchors are updated at u and the vertices paired again where the bodies are now
  if (!refreshed_) refresh(model, u);
  const auto deepest = [&] {
    double d = 0;
    for (const Pair& p : pairs_) d = std::max(d, -gap(p, u));
    return d;
  };
  if (deepest() <= tolerance_ && friction_met(u)) {
    // met with the pairs the solve had; also with those at u, or minimised again with them (a pairing made far
    // from the minimiser is a linearisation of another geometry)
    const BodyLoads before = loads(model, u);
    refresh(model, u);
    const BodyLoads after = loads(model, u);
    double change = 0, scale = 0;
    for (std::size_t k = 0; k < before.force.size(); ++k) {
      change = std::max(change, (after.force[k] - before.force[k]).norm());
      scale = std::max(scale, before.force[k].norm());
    }
    return deepest() <= tolerance_ && change <= 1e-3 * scale;
  }
  update_friction(u, 1.0);
  for (Pair& p : pairs_) p.multiplier = pressing(p, gap(p, u));
  refresh(model, u);
  return false;
}

void BodyContact::add(const Model& model, const State& state, Points& f) { add_forces(model, state.u, f); }

void BodyContact::after_step(const Model& model, const State& state, Workspace&) {
  if (!update_after_step_) return;
  // Uzawa's update spread over the steps: each multiplier moves by a share of the way to its pair's force, and
  // the friction takes its trial force (on the cone)
  update_friction(state.u, friction_rate_);
  for (Pair& p : pairs_) p.multiplier += rate_ * (pressing(p, gap(p, state.u)) - p.multiplier);
  refresh(model, state.u);
}

BodyLoads BodyContact::loads(const Model&, const Points& u) const {
  BodyLoads out;
  out.force.assign(vertex_start_.size() - 1, Vec3::Zero());
  out.friction = out.force;
  for (const Pair& p : pairs_) {
    const double g = gap(p, u), force = pressing(p, g);
    out.penetration = std::max(out.penetration, -g);
    out.contacts += force > 0;
    const Vec3 friction = cone(p) > 0 ? Vec3(-friction_force(p, slip(p, u))) : Vec3::Zero();
    const Anchor& a = anchors_[static_cast<std::size_t>(p.vertex)];
    const auto vertex_body = static_cast<std::size_t>(body_of_vertex(p.vertex));
    // the friction's reaction is on the anchor's body (the normal force's on the paired triangle's)
    const auto anchor_body = static_cast<std::size_t>(body_of_face(a.triangle >= 0 ? a.triangle : p.triangle));
    out.force[vertex_body] += force * p.normal + friction;
    out.force[static_cast<std::size_t>(body_of_face(p.triangle))] -= force * p.normal;
    out.force[anchor_body] -= friction;
    out.friction[vertex_body] += friction;
    out.friction[anchor_body] -= friction;
  }
  return out;
}

}  // namespace pointhaptics
