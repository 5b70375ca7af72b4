#include <pointhaptics/haptics/surface_contact.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/segment_crossing.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace pointhaptics {

namespace {
double largest(const std::vector<double>& x) { return x.empty() ? 0.0 : *std::max_element(x.begin(), x.end()); }

/// The map the contact carries its vertices by: the surface's, checked against it first (the samples index it)
SurfaceMap contact_map(const TriangleMesh& mesh, SurfaceMap map, const SurfaceContactParams& params) {
  if (map.n_vertices() != mesh.V.cols()) throw Error("tool: the surface map is for another surface");
  return params.non_negative_weights ? without_negative_weights(std::move(map)) : map;
}

std::vector<std::uint64_t> identity_ids(index_t n) {
  std::vector<std::uint64_t> ids(static_cast<std::size_t>(n));
  for (index_t v = 0; v < n; ++v) ids[static_cast<std::size_t>(v)] = static_cast<std::uint64_t>(v);
  return ids;
}
}  // namespace

SurfaceContact::SurfaceContact(const Model& model, const TriangleMesh& mesh, SurfaceMap map, const ToolShape& shape,
                               const SurfaceContactParams& params)
    : SurfaceContact(model, mesh, contact_map(mesh, std::move(map), params),
                     contact_samples(mesh, params.sample_spacing != 0 ? params.sample_spacing
                                                                      : default_sample_spacing * shape.radius),
                     shape, params) {}

SurfaceContact::SurfaceContact(const Model& model, const TriangleMesh& surface, SurfaceMap map, ContactSamples samples,
                               const ToolShape& shape, const SurfaceContactParams& params)
    : Y_(3, surface.V.cols() + samples.Y.cols()),
      triangles_(surface.F),
      samples_(std::move(samples.samples)),
      parents_(std::move(samples.parents)),
      keys_(contact_sample_keys(identity_ids(static_cast<index_t>(surface.V.cols())), parents_)),
      n_surface_(static_cast<index_t>(surface.V.cols())),
      sample_levels_(samples.levels),
      map_(std::move(map)),
      shape_(shape) {
  Y_.leftCols(n_surface_) = surface.V;
  Y_.rightCols(samples.Y.cols()) = samples.Y;
  y_ = Y_;
  if (!(shape.radius > 0) || !std::isfinite(shape.radius)) throw Error("tool: radius must be positive (m)");
  if (!(shape.length >= 0) || !std::isfinite(shape.length)) throw Error("tool: length must be >= 0 (m)");
  const index_t m = static_cast<index_t>(Y_.cols());
  // a vertex stands for a third of its triangles' area (the split ones, samples included): the penalty is a
  // pressure per unit penetration
  std::vector<double> area(static_cast<std::size_t>(m), 0.0);
  for (const auto& t : samples.triangles) {
    const double a = 0.5 * (Y_.col(t[1]) - Y_.col(t[0])).cross(Y_.col(t[2]) - Y_.col(t[0])).norm();
    for (const index_t v : t) area[static_cast<std::size_t>(v)] += a / 3.0;
  }
  const double per_area = params.penalty > 0 ? params.penalty : 1000.0 * model.material.young / model.spacing;
  penalty_.resize(area.size());
  for (std::size_t v = 0; v < area.size(); ++v) penalty_[v] = per_area * std::max(area[v], 1e-30);
  lambda_.assign(area.size(), 0.0);
  if (!(params.friction >= 0) || !std::isfinite(params.friction)) throw Error("tool: friction must be >= 0");
  friction_ = params.friction;
  if (!(params.tangential_share > 0) || !(params.tangential_share <= 1))
    throw Error("tool: the friction's penalty share must be in (0, 1]");
  tangential_share_ = params.tangential_share;
  if (friction_ > 0) anchors_.assign(area.size(), Anchor{});
  tolerance_ = params.tolerance > 0 ? params.tolerance : 1e-4 * shape.radius;
  per_area_penalty_ = per_area;
  // the explicit stable step's bound: a point's contact stiffness is at most sum_v k_v w_vj^2
  max_point_stiffness_ = largest(point_stiffness(model.n_points));
  if (params.max_point_stiffness > 0 && max_point_stiffness_ > params.max_point_stiffness) {
    const double scale = params.max_point_stiffness / max_point_stiffness_;
    for (double& k : penalty_) k *= scale;
    per_area_penalty_ *= scale;
    max_point_stiffness_ = params.max_point_stiffness;
  }
  cull_ = params.cull_far_vertices;
  cull_margin_ = std::max(0.0, params.cull_margin);
  if (cull_) {
    // how far a vertex can be from where the displacement's largest point moved it, per unit of that: sum |w|
    weight_l1_.assign(static_cast<std::size_t>(m), 0.0);
    for (index_t v = 0; v < n_surface_; ++v)
      for (index_t e = map_.points.begin(v); e < map_.points.end(v); ++e)
        weight_l1_[static_cast<std::size_t>(v)] += std::abs(map_.weight[static_cast<std::size_t>(e)]);
    for (std::size_t k = 0; k < samples_.size(); ++k)
      for (int b = 0; b < 3; ++b)
        weight_l1_[static_cast<std::size_t>(n_surface_) + k] +=
            std::abs(samples_[k].weight[b]) * weight_l1_[static_cast<std::size_t>(samples_[k].vertex[b])];
    carried_.assign(static_cast<std::size_t>(m), 1);
    max_weight_l1_ = weight_l1_.empty() ? 0.0 : *std::max_element(weight_l1_.begin(), weight_l1_.end());
    // a skin of half the tool's reach (a plane's: a spacing): the candidates chosen again once the tool, or the
    // displacement's bound, has moved that far
    candidate_skin_ = shape.kind == ToolKind::PLANE ? model.spacing : 0.5 * tool_reach(shape);
    candidates_.reserve(static_cast<std::size_t>(m));
    near_triangles_.reserve(triangles_.size());
    candidate_points_.reserve(static_cast<std::size_t>(model.n_points));
    candidate_u_.resize(3, model.n_points);
    point_marked_.assign(static_cast<std::size_t>(model.n_points), 0);
  }
}

template <class Fn>
void SurfaceContact::for_each_surface_vertex(index_t v, const Fn& fn) const {
  if (v < n_surface_) return fn(v, 1.0);
  const ContactSample& sample = samples_[static_cast<std::size_t>(v - n_surface_)];
  for (int k = 0; k < 3; ++k)
    if (sample.weight[k] != 0) fn(sample.vertex[k], sample.weight[k]);
}

template <class Fn>
void SurfaceContact::for_each_weight(index_t v, const Fn& fn) const {
  for_each_surface_vertex(v, [&](index_t vertex, double b) {
    for (index_t e = map_.points.begin(vertex); e < map_.points.end(vertex); ++e)
      fn(map_.points.index[e], b * map_.weight[e]);
  });
}

template <class Fn>
void SurfaceContact::for_each_squared_weight(index_t v, const Fn& fn) const {
  for_each_surface_vertex(v, [&](index_t vertex, double b) {
    for (index_t e = map_.points.begin(vertex); e < map_.points.end(vertex); ++e)
      fn(map_.points.index[e], b * map_.weight[e] * map_.weight[e]);
  });
}

std::vector<double> SurfaceContact::point_stiffness(index_t n_points) const {
  std::vector<double> stiffness(static_cast<std::size_t>(n_points), 0.0);
  for (index_t v = 0; v < static_cast<index_t>(Y_.cols()); ++v)
    for_each_squared_weight(v, [&](index_t j, double w2) {
      stiffness[static_cast<std::size_t>(j)] += penalty_[static_cast<std::size_t>(v)] * w2;
    });
  return stiffness;
}

void SurfaceContact::limit_point_stiffness(std::span<const double> limit, double cap) {
  const std::vector<double> stiffness = point_stiffness(static_cast<index_t>(limit.size()));
  const double stiffest = largest(stiffness);
  // the uniform scale that brings the stiffest point to the cap: no vertex is lowered further, so no part of
  // the surface is softer than a uniformly lowered penalty made it (no cap: nothing is lowered)
  const double uniform = cap > 0 && stiffest > cap ? cap / stiffest : 1.0;
  for (index_t v = 0; v < static_cast<index_t>(Y_.cols()); ++v) {
    double scale = 1.0;
    for_each_weight(v, [&](index_t point, double w) {
      const auto j = static_cast<std::size_t>(point);
      if (w != 0 && stiffness[j] > limit[j]) scale = std::min(scale, limit[j] / stiffness[j]);
    });
    penalty_[static_cast<std::size_t>(v)] *= std::max(scale, uniform);
  }
  // each point now presses at most max(limit_j, uniform x its stiffness) <= max(limit_j, cap)
  max_point_stiffness_ = largest(point_stiffness(static_cast<index_t>(limit.size())));
}

void SurfaceContact::evaluate(const Points& u) {
  if (cull_) return evaluate_near(u);
  // the surface's vertices by the map, then each sample as its combination of them
  carry_surface_into(map_, Y_, u, y_.leftCols(n_surface_));
  for (std::size_t k = 0; k < samples_.size(); ++k) {
    const ContactSample& s = samples_[k];
    y_.col(n_surface_ + static_cast<index_t>(k)) =
        s.weight[0] * y_.col(s.vertex[0]) + s.weight[1] * y_.col(s.vertex[1]) + s.weight[2] * y_.col(s.vertex[2]);
  }
}

void SurfaceContact::evaluate_near(const Points& u) {
  // the largest point displacement bounds how far each vertex moved: |y_v - Y_v| <= sum |w| max_j |u_j|
  double largest = 0;
  for (Eigen::Index j = 0; j < u.cols(); ++j) largest = std::max(largest, u.col(j).squaredNorm());
  largest = std::sqrt(largest);
  // the candidates stand while neither the tool nor that bound has moved by more than their skin (a Verlet list)
  const double moved =
      (pose_.position - candidate_position_).norm() + max_weight_l1_ * std::max(0.0, largest - candidate_largest_);
  if (!(moved <= candidate_skin_)) select_candidates(largest);
  // the candidates' vertices stand when the points their maps read have not moved since they were carried (a step
  // evaluates the surface at one u three or four times: where the tool is placed, its forces, its springs and the
  // step's end, which is the next one's start)
  const bool known = u.cols() == static_cast<Eigen::Index>(point_marked_.size());
  if (known && candidate_u_current_) {
    bool same = true;
    for (std::size_t k = 0; k < candidate_points_.size() && same; ++k)
      same = u.col(candidate_points_[k]) == candidate_u_.col(static_cast<Eigen::Index>(k));
    if (same) return;
  }
  for (const index_t v : candidates_) {
    if (v >= n_surface_) continue;
    Vec3 y = Y_.col(v);
    for (index_t e = map_.points.begin(v); e < map_.points.end(v); ++e)
      y += map_.weight[static_cast<std::size_t>(e)] * u.col(map_.points.index[static_cast<std::size_t>(e)]);
    y_.col(v) = y;
  }
  for (const index_t v : candidates_) {
    if (v < n_surface_) continue;
    const ContactSample& s = samples_[static_cast<std::size_t>(v - n_surface_)];
    y_.col(v) =
        s.weight[0] * y_.col(s.vertex[0]) + s.weight[1] * y_.col(s.vertex[1]) + s.weight[2] * y_.col(s.vertex[2]);
  }
  if (!known) return;
  for (std::size_t k = 0; k < candidate_points_.size(); ++k)
    candidate_u_.col(static_cast<Eigen::Index>(k)) = u.col(candidate_points_[k]);
  candidate_u_current_ = true;
}

void SurfaceContact::select_candidates(double largest) {
  const bool plane = shape_.kind == ToolKind::PLANE;
  const Vec3 normal = pose_.orientation * Vec3::UnitZ();
  const double reach = tool_reach(shape_) + cull_margin_ + candidate_skin_;
  const index_t m = static_cast<index_t>(Y_.cols());
  for (index_t v = 0; v < m; ++v) {
    const auto i = static_cast<std::size_t>(v);
    const double slack = weight_l1_[i] * largest + tolerance_ + candidate_skin_;
    const Vec3 from_tool = Y_.col(v) - pose_.position;
    carried_[i] = lambda_[i] != 0 || (!anchors_.empty() && anchors_[i].held) ||
                  (plane ? normal.dot(from_tool) <= slack : from_tool.norm() <= reach + slack);
  }
  // a sample carried needs its vertices
  for (std::size_t k = 0; k < samples_.size(); ++k)
    if (carried_[static_cast<std::size_t>(n_surface_) + k])
      for (int b = 0; b < 3; ++b) carried_[static_cast<std::size_t>(samples_[k].vertex[b])] = 1;
  // the others far outside the tool (beyond its reach, above a plane), where every evaluation skips them; the
  // candidates in order, vertices first (a sample is carried after its vertices)
  const Vec3 at = pose_.position.allFinite() ? pose_.position : Vec3::Zero();
  const Vec3 outside = at + (plane ? Vec3(1e6 * normal) : Vec3((reach + 1e6) * Vec3::UnitX()));
  candidates_.clear();  // (their capacities kept: no allocation after the constructor's)
  for (index_t v = 0; v < m; ++v) {
    if (carried_[static_cast<std::size_t>(v)]) candidates_.push_back(v);
    else y_.col(v) = outside;
  }
  near_triangles_.clear();
  for (const auto& t : triangles_)
    if (carried_[static_cast<std::size_t>(t[0])] && carried_[static_cast<std::size_t>(t[1])] &&
        carried_[static_cast<std::size_t>(t[2])])
      near_triangles_.push_back(t);
  candidate_position_ = pose_.position;
  candidate_largest_ = largest;
  // the points the candidates' maps read, once each
  for (const index_t p : candidate_points_) point_marked_[static_cast<std::size_t>(p)] = 0;
  candidate_points_.clear();
  for (const index_t v : candidates_) {
    if (v >= n_surface_) continue;
    for (index_t e = map_.points.begin(v); e < map_.points.end(v); ++e) {
      const index_t p = map_.points.index[static_cast<std::size_t>(e)];
      if (static_cast<std::size_t>(p) >= point_marked_.size() || point_marked_[static_cast<std::size_t>(p)]) continue;
      point_marked_[static_cast<std::size_t>(p)] = 1;
      candidate_points_.push_back(p);
    }
  }
  candidate_u_current_ = false;
}

void SurfaceContact::set_vertex_ids(const std::vector<index_t>& ids) {
  if (static_cast<index_t>(ids.size()) != n_surface_) throw Error("tool: one id per vertex of the surface");
  keys_ = contact_sample_keys(std::vector<std::uint64_t>(ids.begin(), ids.end()), parents_);
}

double SurfaceContact::energy(const Model&, const Points& u) {
  evaluate(u);
  double e = 0;
  const double far = tool_reach(shape_);
  for_each_candidate([&](index_t v) {
    const double lambda = lambda_[static_cast<std::size_t>(v)], k = penalty_[static_cast<std::size_t>(v)];
    if (lambda == 0 && (y_.col(v) - pose_.position).squaredNorm() > far * far) return;
    const double t = std::max(lambda + k * tool_distance(shape_, pose_, y_.col(v)).penetration, 0.0);
    e += (t * t - lambda * lambda) / (2 * k);
  });
  // friction: quadratic in the trial force inside the cone, linear beyond it (so a slide is one minimisation,
  // not one multiplier update per penalty's worth of slip)
  if (!anchors_.empty())
    for_each_candidate([&](index_t v) {
      const Anchor& a = anchors_[static_cast<std::size_t>(v)];
      if (!a.held) return;
      const double k = tangential_penalty(v), cone = friction_cone(v), t = friction_trial(v).norm();
      e += (t <= cone ? t * t : 2 * cone * t - cone * cone) / (2 * k) - a.tau.squaredNorm() / (2 * k);
    });
  return e;
}

Vec3 SurfaceContact::friction_trial(index_t v) const {
  const Anchor& a = anchors_[static_cast<std::size_t>(v)];
  const Vec3 slip = a.tangent * (y_.col(v) - (pose_.position + pose_.orientation * a.local));
  return a.tau + tangential_penalty(v) * slip;
}

double SurfaceContact::tangential_penalty(index_t v) const {
  return tangential_share_ * penalty_[static_cast<std::size_t>(v)];
}

double SurfaceContact::friction_cone(index_t v) const {
  if (anchors_[static_cast<std::size_t>(v)].fresh) return std::numeric_limits<double>::infinity();
  return friction_ * lambda_[static_cast<std::size_t>(v)];
}

void SurfaceContact::begin_static_solve(const Points& u) {
  kink_tangent_ = true;
  if (anchors_.empty()) return;
  evaluate(u);
  for (index_t v = 0; v < y_.cols(); ++v) {
    Anchor& a = anchors_[static_cast<std::size_t>(v)];
    if (a.held) continue;
    const ToolDistance d = tool_distance(shape_, pose_, y_.col(v));
    if (!(d.penetration > 0)) continue;
    a.local = pose_.orientation.conjugate() * (y_.col(v) - pose_.position);
    a.tangent = Mat3::Identity() - d.normal * d.normal.transpose();
    a.tau.setZero();
    a.held = a.fresh = true;
  }
}

Mat3 SurfaceContact::friction_hessian(index_t v) const {
  const Anchor& a = anchors_[static_cast<std::size_t>(v)];
  const Vec3 t = friction_trial(v);
  const double k = tangential_penalty(v), cone = friction_cone(v), norm = t.norm();
  // inside the cone k P; beyond it the clamped force's derivative, (cone k / |t|) (P - t^ t^T)
  return norm <= cone ? Mat3(k * a.tangent) : Mat3(cone * k / norm * (a.tangent - t * t.transpose() / (norm * norm)));
}

Vec3 SurfaceContact::friction_force(index_t v) const {
  const Vec3 t = friction_trial(v);
  const double cone = friction_cone(v), norm = t.norm();
  return norm > cone ? Vec3(cone / norm * t) : t;
}

template <class Pressing>
ToolLoad SurfaceContact::for_each_pressing(const Pressing& pressing, bool touching) const {
  ToolLoad out;
  const double far = tool_reach(shape_);
  for_each_candidate([&](index_t v) {
    const double lambda = lambda_[static_cast<std::size_t>(v)], k = penalty_[static_cast<std::size_t>(v)];
    if (lambda == 0 && (y_.col(v) - pose_.position).squaredNorm() > far * far) return;
    const ToolDistance d = tool_distance(shape_, pose_, y_.col(v));
    out.penetration = std::max(out.penetration, d.penetration);
    const double pressure = lambda + k * d.penetration;
    if (!(pressure > 0 || (touching && lambda == 0 && d.penetration > -1e-3 * tolerance_))) return;
    const Vec3 on_tool = -pressure * d.normal;
    out.force += on_tool;
    out.torque += (d.core - pose_.position).cross(on_tool);  // the force acts along the normal through the core
    out.stiffness -= k * d.normal * d.normal.transpose();
    ++out.contacts;
    pressing(v, d, pressure);
  });
  // friction: the anchored vertices drag the tool (acting where they are)
  if (!anchors_.empty())
    for_each_candidate([&](index_t v) {
      if (!anchors_[static_cast<std::size_t>(v)].held) return;
      const Vec3 on_tool = friction_force(v);
      out.force += on_tool;
      out.friction += on_tool;
      out.torque += (y_.col(v) - pose_.position).cross(on_tool);
      out.stiffness -= friction_hessian(v);  // the anchor moves with the tool: its slip by minus the tool's motion
    });
  return out;
}

void SurfaceContact::add_forces(const Model&, const Points& u, Points& f) {
  evaluate(u);
  last_load_ = for_each_pressing([&](index_t v, const ToolDistance& d, double pressure) {
    const Vec3 force = pressure * d.normal;  // on the vertex, out of the tool
    for_each_weight(v, [&](index_t j, double w) { f.col(j) += w * force; });
  });
  if (!anchors_.empty())
    for_each_candidate([&](index_t v) {
      if (!anchors_[static_cast<std::size_t>(v)].held) return;
      const Vec3 force = -friction_force(v);  // on the vertex, toward its anchor
      for_each_weight(v, [&](index_t j, double w) { f.col(j) += w * force; });
    });
}

void SurfaceContact::linearise(const Model&, const Points& u, TangentMode mode) {
  evaluate(u);
  active_.clear();
  for_each_pressing(
      [&](index_t v, const ToolDistance& d, double pressure) {
        // d2E/dy2 = k n n^T - p dn/dy: the second part (the tool's curvature, negative) only in the exact tangent
        Mat3 hessian = penalty_[static_cast<std::size_t>(v)] * d.normal * d.normal.transpose();
        if (mode == TangentMode::EXACT && d.curvature > 0) {
          const Mat3 off_normal = Mat3::Identity() - d.normal * d.normal.transpose();
          const Mat3 along = Mat3::Identity() - d.axis * d.axis.transpose();
          hessian -= (pressure * d.curvature) * off_normal * along;
        }
        active_.push_back(
            {v, d.normal, pressure, hessian, penalty_[static_cast<std::size_t>(v)] * d.normal * d.normal.transpose()});
      },
      kink_tangent_);
  kink_tangent_ = false;
  if (!anchors_.empty())
    for_each_candidate([&](index_t v) {
      if (!anchors_[static_cast<std::size_t>(v)].held) return;
      const Mat3 hessian = friction_hessian(v);
      active_.push_back({v, Vec3::Zero(), 0.0, hessian, hessian});
    });
}

void SurfaceContact::add_tangent_product(const Points& dx, Points& out) const {
  for (const Active& a : active_) {
    Vec3 dy = Vec3::Zero();
    for_each_weight(a.vertex, [&](index_t j, double w) { dy += w * dx.col(j); });
    const Vec3 h = a.hessian * dy;
    for_each_weight(a.vertex, [&](index_t j, double w) { out.col(j) += w * h; });
  }
}

Mat3 SurfaceContact::add_tool_load(const Vec3& e, Points& b) const {
  Mat3 sum = Mat3::Zero();
  for (const Active& a : active_) {
    sum += a.preconditioner;
    const Vec3 h = a.preconditioner * e;
    for_each_weight(a.vertex, [&](index_t j, double w) { b.col(j) += w * h; });
  }
  return sum;
}

Vec3 SurfaceContact::tool_response(const Points& x) const {
  Vec3 f = Vec3::Zero();
  for (const Active& a : active_) {
    Vec3 y = Vec3::Zero();
    for_each_weight(a.vertex, [&](index_t j, double w) { y += w * x.col(j); });
    f += a.preconditioner * y;
  }
  return f;
}

void SurfaceContact::add_diagonal_blocks(Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks) const {
  // the positive parts only (the normal and the friction's stiffness): the preconditioner wants positive blocks
  // (at a sample a bound of its squared weights: for_each_squared_weight)
  for (const Active& a : active_)
    for_each_squared_weight(
        a.vertex, [&](index_t j, double w2) { Eigen::Map<Mat3>(blocks.col(j).data()) += w2 * a.preconditioner; });
}

bool SurfaceContact::add_to_matrix(TangentMatrix& K) const {
  for (const Active& a : active_)
    for_each_surface_vertex(a.vertex, [&](index_t vertex, double b) {
      for (index_t e = map_.points.begin(vertex); e < map_.points.end(vertex); ++e)
        for (index_t f = e; f < map_.points.end(vertex); ++f)
          add_coupling(K, map_.points.index[e], map_.points.index[f], b * map_.weight[e] * map_.weight[f],
                       a.preconditioner);
    });
  return true;
}

bool SurfaceContact::update_multipliers(const Model& model, const Points& u) {
  bool met = load(model, u).penetration <= tolerance_;
  double penalty_pressure = 0, anchored_lambda = 0;  // over the anchored vertices, N
  for (index_t v = 0; v < static_cast<index_t>(anchors_.size()); ++v) {
    Anchor& a = anchors_[static_cast<std::size_t>(v)];
    if (!a.held) {
      // pressing without an anchor (a multiplier, or only the penalty at the contact's rim): anchor it first
      met = met && lambda_[static_cast<std::size_t>(v)] == 0 &&
            !(tool_distance(shape_, pose_, y_.col(v)).penetration > 0);
      continue;
    }
    met = met && !a.fresh;  // a fresh anchor's force is not yet on its cone
    const double k = tangential_penalty(v);
    const Vec3 t = friction_trial(v), clamped = friction_force(v);
    // a sticking vertex is done on its anchor, a sliding one when its force stopped changing; and the cones,
    // friction x lambda, are the pressure to 1% together (lambda + k g: a penetration within the tolerance
    // still made the penalty's part of the pressure as large as lambda, and the friction 5% short of mu x
    // pressure). Together, not each: at the rim of a resting body's base a vertex's lambda is small, and
    // its own 1% took Uzawa's updates past their limit (issue 47: a block resting on a table)
    const double g = std::max(tool_distance(shape_, pose_, y_.col(v)).penetration, 0.0);
    met = met && (clamped - a.tau).norm() <= k * tolerance_;
    penalty_pressure += penalty_[static_cast<std::size_t>(v)] * g;
    anchored_lambda += lambda_[static_cast<std::size_t>(v)];
    // beyond the cone the anchor follows the vertex (the slide so far), the force unchanged
    if ((t - clamped).squaredNorm() > 0) a.local += pose_.orientation.conjugate() * Vec3((t - clamped) / k);
  }
  met = met && penalty_pressure <= 0.01 * anchored_lambda;
  if (met) return true;
  for (index_t v = 0; v < y_.cols(); ++v) {
    double& lambda = lambda_[static_cast<std::size_t>(v)];
    const double k = penalty_[static_cast<std::size_t>(v)];
    const ToolDistance d = tool_distance(shape_, pose_, y_.col(v));
    lambda = std::max(lambda + k * d.penetration, 0.0);
    advance_anchor(v, d);
  }
  return false;
}

void SurfaceContact::advance_anchor(index_t v, const ToolDistance& d) {
  if (anchors_.empty()) return;
  Anchor& a = anchors_[static_cast<std::size_t>(v)];
  const double lambda = lambda_[static_cast<std::size_t>(v)];
  if (lambda == 0) {
    a = Anchor{};  // lifted off: free again
    return;
  }
  const Mat3 tangent = Mat3::Identity() - d.normal * d.normal.transpose();
  if (!a.held) {
    // touches: anchored where it is as seen by the tool before its last move (so in a quasi-static step
    // it slides at once, as it would have under the moving tool)
    a.local = previous_pose_.orientation.conjugate() * (y_.col(v) - previous_pose_.position);
    a.tangent = tangent;
    a.held = true;
  }
  // the trial force on the new tangent plane, put on the new cone if beyond it (the anchor then follows)
  a.fresh = false;
  const Vec3 t = tangent * friction_trial(v);
  const double cone = friction_ * lambda;
  a.tau = t.norm() > cone ? Vec3(cone / t.norm() * t) : t;
  if (t.norm() > cone) a.local = pose_.orientation.conjugate() * (y_.col(v) - pose_.position);
  a.tangent = tangent;
}

bool SurfaceContact::enters(const Vec3& from, const Vec3& to) const {
  const Vec3 low = from.cwiseMin(to), high = from.cwiseMax(to);
  for (const auto& t : cull_ ? near_triangles_ : triangles_) {
    const Vec3 a = y_.col(t[0]), b = y_.col(t[1]), c = y_.col(t[2]);
    // most triangles are far from a move of a fraction of the tool's radius: their boxes miss the move's
    if ((a.cwiseMax(b).cwiseMax(c).array() < low.array()).any() ||
        (a.cwiseMin(b).cwiseMin(c).array() > high.array()).any())
      continue;
    const CrossingTriangle triangle(a, b, c);
    const double side_from = triangle.side(from), side_to = triangle.side(to);
    if (side_from >= 0 && side_to < 0 && triangle.crossing(from, to, side_from, side_to)) return true;
  }
  return false;
}

void SurfaceContact::pressing_points(std::vector<index_t>& out) const {
  out.clear();
  for_each_pressing([&](index_t v, const ToolDistance&, double) {
    index_t best = -1;
    double most = 0;
    for_each_weight(v, [&](index_t j, double w) {
      if (best < 0 || w > most) best = j, most = w;
    });
    if (best >= 0) out.push_back(best);
  });
}

ToolLoad SurfaceContact::load(const Model&, const Points& u, bool same_u) {
  if (!same_u) evaluate(u);
  return for_each_pressing([](index_t, const ToolDistance&, double) {});
}

ToolLoad SurfaceContact::advance_multipliers(double rate, double max_force) {
  const double far = tool_reach(shape_);
  Vec3 pressing = Vec3::Zero();
  for_each_candidate([&](index_t v) {
    double& lambda = lambda_[static_cast<std::size_t>(v)];
    if (lambda == 0 && (y_.col(v) - pose_.position).squaredNorm() > far * far) return;
    const ToolDistance d = tool_distance(shape_, pose_, y_.col(v));
    lambda = std::max(lambda + rate * penalty_[static_cast<std::size_t>(v)] * d.penetration, 0.0);
    pressing += lambda * d.normal;
  });
  if (pressing.norm() > max_force)
    for (double& lambda : lambda_) lambda *= max_force / pressing.norm();
  // the friction's anchors and forces, on the multipliers just made
  if (!anchors_.empty())
    for_each_candidate([&](index_t v) {
      if (lambda_[static_cast<std::size_t>(v)] > 0 || anchors_[static_cast<std::size_t>(v)].held)
        advance_anchor(v, tool_distance(shape_, pose_, y_.col(v)));
    });
  return for_each_pressing([](index_t, const ToolDistance&, double) {});
}

void SurfaceContact::take_multipliers(const SurfaceContact& other) {
  std::unordered_map<std::uint64_t, index_t> of_key;  // a vertex's or sample's key -> the other's vertex
  of_key.reserve(other.keys_.size());
  for (std::size_t v = 0; v < other.keys_.size(); ++v) of_key.emplace(other.keys_[v], static_cast<index_t>(v));
  for (std::size_t v = 0; v < keys_.size(); ++v) {
    const auto found = of_key.find(keys_[v]);
    const index_t o = found == of_key.end() ? -1 : found->second;
    lambda_[v] = o < 0 ? 0.0 : other.lambda_[static_cast<std::size_t>(o)];
    if (!anchors_.empty())
      anchors_[v] = o < 0 || other.anchors_.empty() ? Anchor{} : other.anchors_[static_cast<std::size_t>(o)];
  }
}

void SurfaceContact::reset_multipliers() {
  std::fill(lambda_.begin(), lambda_.end(), 0.0);
  std::fill(anchors_.begin(), anchors_.end(), Anchor{});
}

}  // namespace pointhaptics
