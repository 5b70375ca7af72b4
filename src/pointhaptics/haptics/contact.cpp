#include <pointhaptics/haptics/contact.hpp>

#include <pointhaptics/core/error.hpp>

#include <algorithm>
#include <cmath>

namespace pointhaptics {
namespace {

ProbeParams resolved(const Model& model, ProbeParams p) {
  if (!(p.radius > 0) || !std::isfinite(p.radius)) throw Error("probe.radius must be positive (m)");
  if (p.point_radius <= 0) p.point_radius = 0.5 * model.spacing;
  if (p.stiffness <= 0) p.stiffness = model.material.young * model.spacing;
  return p;
}

}  // namespace

ProbeContact::ProbeContact(const Model& model, const ProbeParams& params)
    : params_(resolved(model, params)), grid_(params_.radius + params_.point_radius), x_(model.X) {}

void ProbeContact::remap(const Model& model, const std::vector<index_t>& new_index) {
  x_ = model.X;
  positions_valid_ = false;
  std::size_t kept = 0;
  for (std::size_t g = 0; g < grabbed_.size(); ++g) {
    const index_t old = grabbed_[g];
    const index_t now = old < static_cast<index_t>(new_index.size()) ? new_index[old] : -1;
    if (now < 0 || model.fixed[now]) continue;
    grabbed_[kept] = now;
    offsets_[kept] = offsets_[g];
    ++kept;
  }
  grabbed_.resize(kept);
  offsets_.resize(kept);
  touched_.clear();
  normals_.clear();
}

ContactModel ProbeContact::apply(const Model& model, const Points& u, const Vec3& probe, bool button, double time,
                                 Points& forces, bool same_u) {
  ContactModel out;
  out.time = time;
  out.p0 = probe;
  if (!probe.allFinite()) return out;
  const double k = params_.stiffness;
  grabbing_ = params_.mode == ProbeMode::GRAB || (params_.mode == ProbeMode::PUSH_GRAB && button);
  if (grabbing_) {
    touched_.clear();
    normals_.clear();
    if (button && !was_pressed_) {
      // press: grab the points under the probe, keeping their offsets
      x_ = model.X + u;
      grid_.rebuild(x_);
      positions_valid_ = true;
      grabbed_.clear();
      offsets_.clear();
      grid_.for_each_within(x_, probe, params_.radius + params_.point_radius, [&](index_t i) {
        if (model.fixed[i]) return;
        grabbed_.push_back(i);
        offsets_.push_back(x_.col(i) - probe);
      });
    }
    if (!button) grabbed_.clear();
    was_pressed_ = button;
    for (size_t g = 0; g < grabbed_.size(); ++g) {
      const index_t i = grabbed_[g];
      const Vec3 f = k * (probe + offsets_[g] - (model.X.col(i) + u.col(i)));  // seed: the dragged point
      forces.col(i) += f;
      out.f0 -= f;
    }
    out.K = -k * static_cast<double>(grabbed_.size()) * Mat3::Identity();
    out.contacts = static_cast<int>(grabbed_.size());
    out.grabbing = !grabbed_.empty();
    return out;
  }
  // push: sphere-sphere overlap (seed Fig. 5)
  grabbed_.clear();
  was_pressed_ = false;
  touched_.clear();
  normals_.clear();
  if (!same_u || !positions_valid_ || x_.cols() != model.n_points) {
    x_ = model.X + u;
    grid_.rebuild(x_);
    positions_valid_ = true;
  }
  const double reach = params_.radius + params_.point_radius;
  grid_.for_each_within(x_, probe, reach, [&](index_t i) {
    const Vec3 r = x_.col(i) - probe;
    const double d = r.norm();
    // a point at the probe's centre has no direction: push it up, as good as any
    const Vec3 n = d > 1e-12 * reach ? Vec3(r / d) : Vec3::UnitY();
    const Vec3 f = k * (reach - d) * n;
    if (!model.fixed[i]) {
      forces.col(i) += f;
      touched_.push_back(i);
      normals_.push_back(n);
    }
    out.f0 -= f;
    // the normal part of dF/dp; the tangential part (which would make K indefinite) is left out
    out.K -= k * n * n.transpose();
    ++out.contacts;
  });
  return out;
}

void ProbeContact::add_stiffness(Eigen::Matrix<double, 9, Eigen::Dynamic>& springs) const {
  const double k = params_.stiffness;
  if (grabbing_) {
    for (index_t i : grabbed_) Eigen::Map<Mat3>(springs.col(i).data()).diagonal().array() += k;
    return;
  }
  for (std::size_t c = 0; c < touched_.size(); ++c)
    Eigen::Map<Mat3>(springs.col(touched_[c]).data()) += k * normals_[c] * normals_[c].transpose();
}

}  // namespace pointhaptics
