#include <pointhaptics/reduction/modal_basis.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/mechanics/tangent_matrix.hpp>
#include <pointhaptics/solvers/sparse_cholesky.hpp>

#include <Spectra/SymGEigsShiftSolver.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <tuple>

namespace pointhaptics {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Eigen::Map<const Eigen::VectorXd> flat(const Points& p) { return {p.data(), p.size()}; }

/// (K - sigma M)^-1 on the free degrees of freedom through the rest tangent's factor (sigma is always 0 here:
/// the lowest modes of a held object), as Spectra's shift-invert mode wants it.
class InverseTangent {
 public:
  using Scalar = double;
  InverseTangent(const Model& model, SparseCholesky& factor, const std::vector<index_t>& free_points)
      : factor_(factor), free_(free_points), r_(Points::Zero(3, model.n_points)), z_(3, model.n_points) {}
  Eigen::Index rows() const { return 3 * static_cast<Eigen::Index>(free_.size()); }
  Eigen::Index cols() const { return rows(); }
  void set_shift(double sigma) {
    if (sigma != 0) throw Error("modal basis: only a shift of zero is factorised (a bug)");
  }
  void perform_op(const double* x, double* y) {
    throw_if_stop_requested("modal basis (the vibration modes)");
    for (std::size_t k = 0; k < free_.size(); ++k)
      for (int a = 0; a < 3; ++a) r_(a, free_[k]) = x[3 * k + a];
    factor_.solve(r_, z_);
    for (std::size_t k = 0; k < free_.size(); ++k)
      for (int a = 0; a < 3; ++a) y[3 * k + a] = z_(a, free_[k]);
    ++solves;
  }
  int solves = 0;

 private:
  SparseCholesky& factor_;
  const std::vector<index_t>& free_;
  Points r_, z_;
};

/// The lumped mass matrix on the free degrees of freedom.
class FreeMass {
 public:
  using Scalar = double;
  FreeMass(const Model& model, const std::vector<index_t>& free_points) : mass_(3 * free_points.size()) {
    for (std::size_t k = 0; k < free_points.size(); ++k)
      mass_.segment<3>(3 * k).setConstant(model.mass[free_points[k]]);
  }
  Eigen::Index rows() const { return mass_.size(); }
  Eigen::Index cols() const { return mass_.size(); }
  void perform_op(const double* x, double* y) const {
    for (Eigen::Index k = 0; k < mass_.size(); ++k) y[k] = mass_[k] * x[k];
  }

 private:
  Eigen::VectorXd mass_;
};

}  // namespace

Points displacement_of(const Eigen::MatrixXd& U, const Eigen::VectorXd& q, index_t n_points) {
  Points u(3, n_points);
  Eigen::Map<Eigen::VectorXd>(u.data(), u.size()).noalias() = U * q;
  return u;
}

ModalBasis build_modal_basis(const Model& model, const ModalBasisSettings& settings, Workspace& ws) {
  const auto start = std::chrono::steady_clock::now();
  const int r = settings.size;
  std::vector<index_t> free_points;
  for (index_t i = 0; i < model.n_points; ++i)
    if (!model.fixed[static_cast<std::size_t>(i)]) free_points.push_back(i);
  const Eigen::Index n_free = 3 * static_cast<Eigen::Index>(free_points.size());
  if (r < 1) throw Error(fmt::format("reduction.modes: {} must be at least 1", r));
  if (free_points.size() == static_cast<std::size_t>(model.n_points))
    throw Error(
        "reduction: nothing is held ([[fixed]]): a free object's rest tangent is singular, and its rigid "
        "motions are not in a modal basis");
  if (n_free < r + 2)
    throw Error(
        fmt::format("reduction.modes: {} basis vectors asked for, but the object has only {} free degrees of "
                    "freedom",
                    r, n_free));
  int m = settings.linear_modes;
  if (m <= 0)
    for (m = 1; m + m * (m + 1) / 2 < static_cast<int>(std::ceil(1.3 * r));) ++m;
  m = static_cast<int>(std::min<Eigen::Index>(m, n_free - 2));

  ModalBasis basis;
  // the rest tangent, assembled and factorised once
  Tangent tangent;
  const Points rest = Points::Zero(3, model.n_points);
  tangent.linearise(model, rest, TangentMode::EXACT, &ws);
  TangentMatrix K;
  assemble_tangent(model, tangent, K, &ws);
  SparseCholesky factor;
  factor.analyse(model, K);
  if (!factor.factorise(K))
    throw Error(
        "reduction: the rest tangent is not positive definite over the free points (is every part of the "
        "object held?)");
  basis.factor_bytes = factor.stats().factor_bytes;
  basis.factorise_s = seconds_since(start);

  // the lowest modes: K phi = omega^2 M phi, shift-invert about zero
  const auto modes_start = std::chrono::steady_clock::now();
  InverseTangent inverse(model, factor, free_points);
  FreeMass mass(model, free_points);
  const Eigen::Index ncv = std::min<Eigen::Index>(n_free, std::max(2 * m + 1, m + 20));
  Spectra::SymGEigsShiftSolver<InverseTangent, FreeMass, Spectra::GEigsMode::ShiftInvert> eigen(inverse, mass, m, ncv,
                                                                                                0.0);
  eigen.init();
  const Eigen::Index converged = eigen.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10);
  if (eigen.info() != Spectra::CompInfo::Successful)
    throw Error(
        fmt::format("reduction: the eigen-solver converged on {} of the {} lowest vibration modes", converged, m));
  // ascending (Spectra gives them back transformed from 1 / omega^2, highest first)
  const Eigen::VectorXd values = eigen.eigenvalues();
  const Eigen::MatrixXd vectors = eigen.eigenvectors();  // M-orthonormal on the free dofs
  std::vector<Eigen::Index> order(static_cast<std::size_t>(values.size()));
  for (Eigen::Index k = 0; k < values.size(); ++k) order[static_cast<std::size_t>(k)] = k;
  std::sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return values[a] < values[b]; });
  basis.eigenvalues.resize(values.size());
  Eigen::MatrixXd phi_free(vectors.rows(), vectors.cols());
  for (Eigen::Index k = 0; k < values.size(); ++k) {
    basis.eigenvalues[k] = values[order[static_cast<std::size_t>(k)]];
    phi_free.col(k) = vectors.col(order[static_cast<std::size_t>(k)]);
  }
  basis.linear_modes = m;
  basis.modes_s = seconds_since(modes_start);

  // candidates in the full layout: modes, derivatives, load responses
  const auto scatter = [&](const Eigen::VectorXd& free, Points& out) {
    out.setZero(3, model.n_points);
    for (std::size_t k = 0; k < free_points.size(); ++k)
      out.col(free_points[k]) = free.segment<3>(3 * static_cast<Eigen::Index>(k));
  };
  const int n_derivatives = m * (m + 1) / 2;
  const int n_loads = static_cast<int>(settings.loads.size());
  Eigen::MatrixXd candidates(3 * model.n_points, m + n_derivatives + n_loads);
  std::vector<double> weights;  // the principal components' weights (Barbic & James: modes by omega_1^2 / omega_i^2)
  const double lowest = basis.eigenvalues[0];
  std::vector<Points> phi(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) {
    scatter(phi_free.col(i), phi[static_cast<std::size_t>(i)]);
    candidates.col(i) = flat(phi[static_cast<std::size_t>(i)]);
    weights.push_back(lowest / basis.eigenvalues[i]);
  }

  // modal derivatives: K Psi_ij = -H(phi_i, phi_j), H(a, b) = d/de [K(e b) a] at e = 0 by central differences
  const auto derivatives_start = std::chrono::steady_clock::now();
  Points plus(3, model.n_points), minus(3, model.n_points), rhs(3, model.n_points), psi(3, model.n_points);
  Tangent at_plus, at_minus;
  int column = m;
  for (int j = 0; j < m; ++j) {
    throw_if_stop_requested("modal basis (the modal derivatives)");
    const Points& b = phi[static_cast<std::size_t>(j)];
    // a step small against the mode's size but far above round-off: the tangent is quadratic in u, so the
    // central difference is exact up to it
    const double step = 1e-3 * model.spacing / std::max(b.cwiseAbs().maxCoeff(), 1e-300);
    at_plus.linearise(model, step * b, TangentMode::EXACT, &ws);
    at_minus.linearise(model, -step * b, TangentMode::EXACT, &ws);
    for (int i = 0; i <= j; ++i) {
      const Points& a = phi[static_cast<std::size_t>(i)];
      at_plus.apply(model, a, ws, plus);
      at_minus.apply(model, a, ws, minus);
      rhs = -(plus - minus) / (2 * step);
      for (index_t p = 0; p < model.n_points; ++p)
        if (model.fixed[static_cast<std::size_t>(p)]) rhs.col(p).setZero();
      factor.solve(rhs, psi);
      candidates.col(column++) = flat(psi);
      weights.push_back(lowest * lowest / (basis.eigenvalues[i] * basis.eigenvalues[j]));
    }
  }
  basis.derivatives = n_derivatives;
  basis.derivatives_s = seconds_since(derivatives_start);
  // static responses to the dead loads, weighted above every mode so that they are kept whole
  for (const Points& load : settings.loads) {
    rhs = load;
    for (index_t p = 0; p < model.n_points; ++p)
      if (model.fixed[static_cast<std::size_t>(p)]) rhs.col(p).setZero();
    factor.solve(rhs, psi);
    candidates.col(column++) = flat(psi);
    weights.push_back(10.0);
  }
  basis.load_vectors = n_loads;

  // mass-weighted principal components: the candidates made mass-unit and weighted, then the leading left
  // singular vectors of M^1/2 V, mapped back by M^-1/2 (mass-orthonormal)
  Eigen::VectorXd sqrt_mass(3 * model.n_points);
  for (index_t p = 0; p < model.n_points; ++p) {
    if (!(model.mass[p] > 0) && !model.fixed[static_cast<std::size_t>(p)])
      throw Error(
          fmt::format("reduction: point {} has no mass (a mass-orthonormal basis needs every free point's)", p));
    sqrt_mass.segment<3>(3 * p).setConstant(model.mass[p] > 0 ? std::sqrt(model.mass[p]) : 1.0);
  }
  Eigen::MatrixXd weighted = sqrt_mass.asDiagonal() * candidates;
  for (Eigen::Index k = 0; k < weighted.cols(); ++k) {
    const double norm = weighted.col(k).norm();
    if (norm > 0) weighted.col(k) *= weights[static_cast<std::size_t>(k)] / norm;
  }
  Eigen::BDCSVD<Eigen::MatrixXd> svd(weighted, Eigen::ComputeThinU);
  const int kept = static_cast<int>(std::min<Eigen::Index>(r, svd.rank()));
  if (kept < r)
    throw Error(
        fmt::format("reduction.modes: only {} independent basis vectors came out of {} modes and their "
                    "derivatives (ask for fewer, or for more linear_modes)",
                    kept, m));
  basis.U = sqrt_mass.cwiseInverse().asDiagonal() * svd.matrixU().leftCols(r);
  for (index_t p = 0; p < model.n_points; ++p)
    if (model.fixed[static_cast<std::size_t>(p)]) basis.U.middleRows<3>(3 * p).setZero();
  basis.total_s = seconds_since(start);
  return basis;
}

Model coarse_model(const Model& model, double spacing) {
  if (!(spacing > model.spacing))
    throw Error(fmt::format("reduction.basis_spacing: {} m must be coarser than the object's spacing ({} m)", spacing,
                            model.spacing));
  const Vec3 lowest = model.X.rowwise().minCoeff(), extent = model.X.rowwise().maxCoeff() - lowest;
  // per axis, a whole number of cubes across the points' extent (about `spacing` each), so that the first and last
  // layers of cubes are centred on the faces, as a sampling that includes its faces is
  Vec3 cube_size;
  for (int a = 0; a < 3; ++a) {
    const double cubes_across = std::max(1.0, std::round(extent[a] / spacing));
    cube_size[a] = extent[a] > 0 ? extent[a] / cubes_across : spacing;
  }
  // the cube of each point, and each cube's chosen point and sums
  struct Cube {
    index_t chosen = -1;
    double distance = 0, volume = 0;
    Vec3 load = Vec3::Zero(), centroid = Vec3::Zero();
    bool held = false;
  };
  std::map<std::tuple<long long, long long, long long>, Cube> cubes;
  for (index_t i = 0; i < model.n_points; ++i) {
    const Vec3 at = (model.X.col(i) - lowest).cwiseQuotient(cube_size);
    const auto key = std::tuple{std::llround(at.x()), std::llround(at.y()), std::llround(at.z())};
    const Vec3 centre(static_cast<double>(std::get<0>(key)), static_cast<double>(std::get<1>(key)),
                      static_cast<double>(std::get<2>(key)));
    Cube& cube = cubes[key];
    const double distance = (at - centre).norm();
    if (cube.chosen < 0 || distance < cube.distance - 1e-9) {
      cube.chosen = i;
      cube.distance = distance;
    }
    cube.volume += model.volume[i];
    cube.centroid += model.volume[i] * model.X.col(i);
    cube.held = cube.held || model.fixed[static_cast<std::size_t>(i)];
    if (model.f_ext.size() == 3 * model.n_points) cube.load += model.f_ext.col(i);
  }
  PointCloud cloud;
  cloud.X.resize(3, static_cast<Eigen::Index>(cubes.size()));
  cloud.volume.resize(static_cast<Eigen::Index>(cubes.size()));
  cloud.surface.assign(cubes.size(), 0);
  cloud.spacing = spacing;
  std::vector<unsigned char> held;
  Points loads(3, static_cast<Eigen::Index>(cubes.size()));
  Eigen::Index k = 0;
  for (const auto& [key, cube] : cubes) {
    cloud.X.col(k) = cube.centroid / cube.volume;
    cloud.volume[k] = cube.volume;
    loads.col(k) = cube.load;
    held.push_back(cube.held);
    ++k;
  }
  KernelParams kernel = model.kernel;
  if (kernel.support > 0) kernel.support *= spacing / model.spacing;
  Model coarse = build_model(cloud, model.material, kernel);
  coarse.fixed = held;
  coarse.f_ext = loads;
  return coarse;
}

ModalBasis carry_basis(const ModalBasis& basis, const Model& coarse, const Model& model) {
  const auto start = std::chrono::steady_clock::now();
  if (basis.U.rows() != 3 * coarse.n_points)
    throw Error(
        fmt::format("reduction: a basis of {} rows for a coarse model of {} points", basis.U.rows(), coarse.n_points));
  const SurfaceMap map = build_surface_map(coarse, model.X);
  const Eigen::Index r = basis.U.cols();
  Eigen::MatrixXd carried(3 * model.n_points, r);
  Eigen::MatrixXd at_points;
  for (Eigen::Index k = 0; k < r; ++k) {
    interpolate_at_surface(map, Eigen::Map<const Eigen::MatrixXd>(basis.U.col(k).data(), 3, coarse.n_points),
                           at_points);
    carried.col(k) = Eigen::Map<const Eigen::VectorXd>(at_points.data(), at_points.size());
  }
  Eigen::VectorXd mass(3 * model.n_points);
  for (index_t p = 0; p < model.n_points; ++p) {
    mass.segment<3>(3 * p).setConstant(model.mass[p]);
    if (model.fixed[static_cast<std::size_t>(p)]) carried.middleRows<3>(3 * p).setZero();
  }
  // mass-orthonormal: U = V L^-T with L L^T = V^T M V
  const Eigen::MatrixXd gram = carried.transpose() * mass.asDiagonal() * carried;
  const Eigen::LLT<Eigen::MatrixXd> llt(gram);
  if (llt.info() != Eigen::Success || !(llt.matrixL().toDenseMatrix().diagonal().minCoeff() >
                                        1e-8 * llt.matrixL().toDenseMatrix().diagonal().maxCoeff()))
    throw Error(
        "reduction: the basis carried from the coarse points lost its independence (a coarser "
        "basis_spacing than the object's features?)");
  ModalBasis out = basis;
  out.U = llt.matrixU().solve<Eigen::OnTheRight>(carried);
  out.total_s = basis.total_s + seconds_since(start);
  return out;
}

}  // namespace pointhaptics
