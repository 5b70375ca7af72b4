#pragma once
/// @file The static model: everything precomputed once and never written during a run.
#include <pointhaptics/core/csr.hpp>
#include <pointhaptics/core/diagnostics.hpp>
#include <pointhaptics/core/parameters.hpp>
#include <pointhaptics/core/types.hpp>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace pointhaptics {

/// A set of held points (one `[[fixed]]` table): at zero or at a prescribed displacement.
struct FixedGroup {
  std::string name;                  ///< for messages, e.g. "fixed #1"
  Vec3 displacement = Vec3::Zero();  ///< prescribed displacement, m
  double ramp = 0.0;                 ///< ramp-in time of the prescribed displacement, s
  std::vector<index_t> points;       ///< held points
};

/// Static, precomputed data of a point-based object (MuJoCo's mjModel). Built by build_model()
/// and then only read: the solvers take it by const reference.
struct Model {
  index_t n_points = 0;
  Points X;                 ///< reference positions, m  (3 x n)
  Eigen::VectorXd volume;   ///< v_i, m^3  (n)
  Eigen::VectorXd mass;     ///< m_i, kg  (n)
  double spacing = 0;       ///< nominal sample spacing, m
  double h = 0;             ///< kernel support radius, m (the base one when `support` is set)
  Eigen::VectorXd support;  ///< per-point support h_i, m, when they differ (levels of detail); else empty
  double extent = 0;        ///< diagonal of the reference bounding box plus h, m (scale for divergence checks)
  KernelParams kernel;
  MaterialParams material;    ///< the object's material (its points' unless material_of says otherwise)
  double lambda = 0, mu = 0;  ///< Lame parameters of `material`, Pa
  /// per-point materials ([[region]] tables, a stiffness map): the point i has point_materials[material_of[i]]
  /// (point_materials[0] is `material`); both empty when every point has `material`
  std::vector<MaterialParams> point_materials;
  std::vector<std::uint8_t> material_of;
  /// E_i / E per point from a stiffness map (empty: 1): at a fixed Poisson's ratio every model's stress is
  /// proportional to E, so the point's stress is its material's times this
  Eigen::VectorXd stiffness_scale;
  /// v_i times stiffness_scale_i, the weight of stencil i's stress (its energy, forces and tangent), m^3  (n)
  Eigen::VectorXd stiffness_volume;

  /// stencils: the neighbours j != i with |X_j - X_i| < h of each point i, as CSR (pairs e = (i, j)),
  /// each row sorted; symmetric (j is in i's row when i is in j's)
  Csr neighbours;
  std::vector<index_t> reverse_pair;  ///< for each pair e = (i, j), the pair (j, i)  (n_pairs)
  // per-pair data, aligned with neighbours.index
  Points d;                 ///< d_ij = M_i^-1 X_ij w_ij, 1/m  (3 x n_pairs), seed Eq. 10-11
  Eigen::VectorXd hg_coef;  ///< k_ij = (alpha E / 2) (v_i w^_ij + v_j w^_ji) / |X_ij|^2, symmetric, N/m  (n_pairs)
  /// 1 where a cut severed the pair (mechanics/cut.hpp): it stays in the lists, with d_ij = 0 and k_ij = 0, so
  /// it carries nothing; empty while nothing was cut  (n_pairs)
  std::vector<std::uint8_t> severed;
  // per-point data
  Points d_self;                ///< d_ii = -sum_j d_ij, 1/m  (3 x n)
  Eigen::VectorXd hg_diagonal;  ///< diagonal of the (constant) hourglass Hessian per point, N/m  (n)

  // boundary conditions and constant external loads
  std::vector<unsigned char> fixed;  ///< 1 where the point is held  (n)
  std::vector<FixedGroup> fixed_groups;
  Points f_ext;  ///< constant external force per point (gravity, tractions, point loads), N  (3 x n)

  ModelDiagnostics diagnostics;

  /// The last n_passive points are held, carry no stencil (no strain energy, no force of their own) and
  /// are there only as neighbours of the others: the outer frozen ring of a level-of-detail active set,
  /// which completes the neighbourhoods (M_i, d_ij) of the held points next to the simulated ones.
  index_t n_passive = 0;

  /// Several deformable bodies in one model (issue 47; bodies/join_models.hpp): body k's points are
  /// [body_start[k], body_start[k + 1]) and no neighbour list leaves a body. Both empty: one body.
  std::vector<index_t> body_start;
  std::vector<std::string> body_names;
  index_t n_bodies() const { return body_start.empty() ? 1 : static_cast<index_t>(body_start.size()) - 1; }
  /// The body point i belongs to (0 with one body).
  index_t body_of(index_t i) const {
    if (body_start.empty()) return 0;
    return static_cast<index_t>(std::upper_bound(body_start.begin(), body_start.end(), i) - body_start.begin()) - 1;
  }

  /// The material of point i.
  const MaterialParams& material_at(index_t i) const {
    return material_of.empty() ? material : point_materials[material_of[i]];
  }
  /// Young's modulus of point i, Pa (its material's, times its stiffness scale).
  double young_at(index_t i) const {
    return material_at(i).young * (stiffness_scale.size() ? stiffness_scale[i] : 1.0);
  }
  /// The largest P-wave modulus lambda + 2 mu over the object's materials and stiffness scales, Pa (the explicit
  /// stable step).
  double max_p_wave_modulus() const {
    double m = material.lambda() + 2 * material.mu();
    for (const MaterialParams& p : point_materials) m = std::max(m, p.lambda() + 2 * p.mu());
    return m * (stiffness_scale.size() ? std::max(1.0, stiffness_scale.maxCoeff()) : 1.0);
  }
  /// The largest Young's modulus of any point, Pa.
  double max_young() const {
    double e = material.young;
    for (const MaterialParams& p : point_materials) e = std::max(e, p.young);
    return e * (stiffness_scale.size() ? std::max(1.0, stiffness_scale.maxCoeff()) : 1.0);
  }

  index_t n_pairs() const { return neighbours.n_entries(); }
  /// Points [0, stencil_end()) carry a stencil.
  index_t stencil_end() const { return n_points - n_passive; }
};

}  // namespace pointhaptics
