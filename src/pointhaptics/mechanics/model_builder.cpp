#include <pointhaptics/mechanics/model_builder.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/polled_loop.hpp>
#include <pointhaptics/geometry/neighbour_search.hpp>
#include <pointhaptics/mechanics/energies/hourglass.hpp>
#include <pointhaptics/mechanics/kernels.hpp>
#include <pointhaptics/mechanics/stencil.hpp>

#include <fmt/format.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace pointhaptics {

void validate_material(const MaterialParams& m) {
  auto bad = [](const char* key, double value, const char* rule) {
    throw Error(fmt::format("material: {} = {} is out of range: {}", key, value, rule));
  };
  if (!(m.young > 0) || !std::isfinite(m.young)) bad("young", m.young, "must be positive and finite (Pa)");
  if (!(m.poisson > -1 && m.poisson < 0.5)) bad("poisson", m.poisson, "must lie in (-1, 0.5)");
  if (!(m.density > 0) || !std::isfinite(m.density)) bad("density", m.density, "must be positive and finite (kg/m^3)");
  if (!(m.volume_stiffness >= 0) || !std::isfinite(m.volume_stiffness))
    bad("volume_stiffness", m.volume_stiffness, "must be >= 0 and finite (Pa)");
  if (!(m.damping >= 0) || !std::isfinite(m.damping)) bad("damping", m.damping, "must be >= 0 and finite (1/s)");
  if (!(m.hourglass >= 0) || !std::isfinite(m.hourglass)) bad("hourglass", m.hourglass, "must be >= 0 and finite");
  if (!m.prony.empty() && !valid_prony(m.prony)) throw Error(fmt::format("material: prony: {}", prony_rule));
}

namespace {

double support_radius(const PointCloud& cloud, const KernelParams& kernel) {
  if (kernel.support > 0) {
    if (!std::isfinite(kernel.support)) throw Error("kernel: support must be finite");
    return kernel.support;
  }
  if (!(kernel.support_factor > 0) || !std::isfinite(kernel.support_factor))
    throw Error(fmt::format("kernel: support_factor = {} must be positive", kernel.support_factor));
  if (!(cloud.spacing > 0)) throw Error("kernel: the point cloud has no spacing; give kernel.support in m");
  return kernel.support_factor * cloud.spacing;
}

}  // namespace

Model build_model(const PointCloud& cloud, const MaterialParams& material, const KernelParams& kernel,
                  std::vector<MaterialParams> point_materials, std::vector<std::uint8_t> material_of) {
  validate_material(material);
  const index_t n = cloud.size();
  if (n == 0) throw Error("model: the object has no points");
  if (!material_of.empty()) {
    if (static_cast<index_t>(material_of.size()) != n)
      throw Error("model: per-point materials must give one per point");
    if (point_materials.empty() || point_materials.size() > max_point_materials)
      throw Error(fmt::format("model: {} materials in one object; at most {} (the object's and its regions')",
                              point_materials.size(), max_point_materials));
    for (const MaterialParams& p : point_materials) {
      validate_material(p);
      if (p.volume_stiffness != material.volume_stiffness || p.hourglass != material.hourglass ||
          p.volume != material.volume)
        throw Error(
            "model: regions may change young, poisson, density and model; volume_stiffness, hourglass and volume are the object's");
    }
    for (const std::uint8_t k : material_of)
      if (k >= point_materials.size()) throw Error(fmt::format("model: per-point material {} does not exist", int{k}));
  }
  if (!cloud.X.allFinite()) throw Error("model: the point positions contain NaN or infinity");

  Model model;
  model.n_points = n;
  model.X = cloud.X;
  model.spacing = cloud.spacing;
  model.kernel = kernel;
  model.material = material;
  model.point_materials = std::move(point_materials);
  model.material_of = std::move(material_of);
  model.lambda = material.lambda();
  model.mu = material.mu();
  model.h = support_radius(cloud, kernel);
  const double h = model.h;
  model.extent = (model.X.rowwise().maxCoeff() - model.X.rowwise().minCoeff()).norm() + h;

  // neighbours in the reference configuration
  const bool per_point = cloud.support.size() > 0;
  if (per_point) {
    if (cloud.support.size() != n || !(cloud.support.array() > 0).all() || !cloud.support.allFinite())
      throw Error("model: per-point supports must be positive, one per point");
    model.support = cloud.support;
  }
  model.neighbours = per_point ? radius_neighbours(model.X, cloud.support) : radius_neighbours(model.X, h);
  const Csr& nbr = model.neighbours;
  const index_t n_pairs = nbr.n_entries();
  // each pair's reverse; the forces and the tangent rely on the lists being symmetric (and sorted)
  resize_polled(model.reverse_pair, static_cast<std::size_t>(n_pairs), "the neighbour pairs");
  std::atomic<std::int64_t> one_sided{-1};
  parallel_for_polled("the neighbour pairs", n, [&](index_t i) {
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
      const index_t j = nbr.index[e];
      const index_t* row = nbr.index.data();
      const index_t back = static_cast<index_t>(std::lower_bound(row + nbr.begin(j), row + nbr.end(j), i) - row);
      if (back == nbr.end(j) || row[back] != i) one_sided = e;
      model.reverse_pair[e] = back;
    }
  });
  if (one_sided >= 0)
    throw Error(fmt::format("model: neighbour pair {} has no reverse (the neighbour search must be symmetric)",
                            one_sided.load()));

  // kernel weights per pair; coincident points would make w (and M_i) meaningless
  Eigen::VectorXd w(n_pairs);
  std::atomic<std::int64_t> coincident{-1};
  parallel_for_polled("the kernel weights", n, [&](index_t i) {
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
      if ((model.X.col(nbr.index[e]) - model.X.col(i)).norm() <= 1e-9 * h) coincident = i;
      // with per-point supports the stencil of i uses its own h_i (zero weight for the pairs only j reaches)
      w[e] = pair_weight(model, i, e);
    }
  });
  if (coincident >= 0) {
    const index_t i = static_cast<index_t>(coincident.load());
    index_t j = -1;
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e)
      if ((model.X.col(nbr.index[e]) - model.X.col(i)).norm() <= 1e-9 * h) j = nbr.index[e];
    throw Error(fmt::format("model: points {} and {} coincide at ({}, {}, {}); remove duplicate points", i, j,
                            model.X(0, i), model.X(1, i), model.X(2, i)));
  }

  // volumes and masses
  if (cloud.volume.size() != n || !(cloud.volume.array() > 0).all())
    throw Error("model: every point needs a positive sampling volume");
  if (material.volume == VolumeMode::CELL) {
    model.volume = cloud.volume;
    model.mass.resize(n);
    for (index_t i = 0; i < n; ++i) model.mass[i] = model.material_at(i).density * model.volume[i];
  } else {
    // seed Eq. 7-8: equal masses, kernel-summed density (self term included; the viscosity
    // kernel is infinite at r = 0, so it is left out there)
    double total_mass = 0;
    for (index_t i = 0; i < n; ++i) total_mass += model.material_at(i).density * cloud.volume[i];
    model.mass = Eigen::VectorXd::Constant(n, total_mass / n);
    model.volume.resize(n);
    for (index_t i = 0; i < n; ++i) {
      const double w0 =
          kernel.type == KernelType::VISCOSITY ? 0.0 : kernel_value(kernel.type, 0.0, per_point ? cloud.support[i] : h);
      double rho = model.mass[i] * w0;  // seed Eq. 7
      for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) rho += model.mass[nbr.index[e]] * w[e];
      model.volume[i] = rho > 0 ? model.mass[i] / rho : cloud.volume[i];  // seed Eq. 8
    }
  }

  // the weight of each stencil's stress: its volume, times its stiffness scale
  if (cloud.stiffness_scale.size()) {
    if (cloud.stiffness_scale.size() != n || !(cloud.stiffness_scale.array() > 0).all() ||
        !cloud.stiffness_scale.allFinite())
      throw Error("model: per-point stiffness scales must be positive and finite, one per point");
    model.stiffness_scale = cloud.stiffness_scale;
    model.stiffness_volume = model.volume.cwiseProduct(model.stiffness_scale);
  } else {
    model.stiffness_volume = model.volume;
  }

  // moment matrices (seed Eq. 11), their conditioning, d_ij and d_ii (seed Eq. 10)
  model.d.resize(3, n_pairs);
  model.d_self.resize(3, n);
  model.hg_coef.resize(n_pairs);
  std::vector<double> condition(n, 0.0), weight_sum(n, 0.0);
  std::vector<unsigned char> regularised(n, 0);
  parallel_for_polled("the stencils", n, [&](index_t i) {
    const StencilFit fit = fit_stencil(model, i, w.data() + nbr.begin(i));
    condition[i] = fit.condition;
    weight_sum[i] = fit.weight_sum;
    regularised[i] = fit.regularised;
  });
  build_hourglass(model, weight_sum);

  // diagnostics
  ModelDiagnostics& diag = model.diagnostics;
  index_t min_nbr = std::numeric_limits<index_t>::max();
  for (index_t i = 0; i < n; ++i) {
    min_nbr = std::min(min_nbr, nbr.row_size(i));
    diag.regularised_neighbourhoods += regularised[i];
    diag.isolated_points += weight_sum[i] == 0;  // no neighbour that weighs: G_i = 0
    if (std::isfinite(condition[i])) diag.worst_condition = std::max(diag.worst_condition, condition[i]);
    else diag.worst_condition = std::numeric_limits<double>::infinity();
  }
  diag.min_neighbours = min_nbr;
  diag.mean_neighbours = static_cast<double>(n_pairs) / n;

  // no boundary conditions or loads yet
  model.fixed.assign(n, 0);
  model.f_ext = Points::Zero(3, n);
  return model;
}

void check_every_free_point_has_neighbours(const Model& model, const std::string& name) {
  index_t alone = 0, first = -1;
  for (index_t i = 0; i < model.n_points; ++i)
    if (!model.fixed[i] && model.neighbours.row_size(i) == 0) {
      if (alone++ == 0) first = i;
    }
  if (alone > 0)
    throw Error(fmt::format(
        "{}: {} of {} points (the first: point {} at ({:.4g}, {:.4g}, {:.4g}) m) have no neighbour within the "
        "support h = {:.4g} m: the support is too small for the spacing, or the points too far apart",
        name, alone, model.n_points, first, model.X(0, first), model.X(1, first), model.X(2, first), model.h));
}

}  // namespace pointhaptics
