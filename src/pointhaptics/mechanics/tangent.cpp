#include <pointhaptics/mechanics/tangent.hpp>

#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/detail/stencil_loop.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <cstring>
#include <type_traits>

namespace pointhaptics {
namespace {

/// fn(i) for i in [0, n): on ws's threads (even contiguous ranges) when given, else on TBB's.
template <class Fn>
void for_each_point(index_t n, Workspace* ws, Fn&& fn) {
  if (ws) {
    const int chunks = ws->n_threads();
    ws->for_each_chunk([&](int c) {
      const index_t first = static_cast<index_t>(std::int64_t{n} * c / chunks);
      const index_t last = static_cast<index_t>(std::int64_t{n} * (c + 1) / chunks);
      for (index_t i = first; i < last; ++i) fn(i);
    });
    return;
  }
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n, 256), [&](const tbb::blocked_range<index_t>& r) {
    for (index_t i = r.begin(); i != r.end(); ++i) fn(i);
  });
}

// A material's Linearisation per point, kept as plain doubles (so that Tangent is not a template).
template <class L>
constexpr std::size_t doubles_of = sizeof(L) / sizeof(double);

template <class L>
PH_ALWAYS_INLINE inline L load_linearisation(const double* base, index_t i) {
  // fixed-size Eigen matrices and doubles only: plain arrays of doubles
  static_assert(std::is_standard_layout_v<L> && sizeof(L) % sizeof(double) == 0);
  L at;
  std::memcpy(static_cast<void*>(&at), base + doubles_of<L> * static_cast<std::size_t>(i), sizeof(L));
  return at;
}

}  // namespace

void Tangent::linearise(const Model& model, const Points& u, TangentMode mode, Workspace* ws) {
  mode_ = mode;
  with_material(model, ws ? viscous_step(*ws) : ViscousStep{}, [&](const auto& energy) {
    using L = typename std::decay_t<decltype(energy)>::Linearisation;
    linearisation_.resize(doubles_of<L> * static_cast<std::size_t>(model.n_points));
    double* base = linearisation_.data();
    for_each_point(model.n_points, ws, [&](index_t i) {
      const L at = energy.linearise(i, displacement_gradient(model, u, i), mode == TangentMode::PROJECTED);  // seed Eq. 10
      std::memcpy(static_cast<void*>(base + doubles_of<L> * static_cast<std::size_t>(i)), &at, sizeof(L));
    });
  });
}

void Tangent::apply(const Model& model, const Points& du, Workspace& ws, Points& out) const {
  const bool projected = mode_ == TangentMode::PROJECTED;
  const double* volume = model.stiffness_volume.data();  // v_i, times E_i / E with a stiffness map
  const double* base = linearisation_.data();
  with_material(model, viscous_step(ws), [&](const auto& energy) {
    using L = typename std::decay_t<decltype(energy)>::Linearisation;
    // the force loop with the stress map linearised gives -K du; the hourglass part is linear already
    detail::stencil_sum(model, du, ws, out, -1.0, [energy, volume, base, projected](index_t i, const Mat3& dG) PH_ALWAYS_INLINE -> Mat3 {
      return volume[i] * energy.stress_derivative(i, load_linearisation<L>(base, i), dG, projected);
    });
  });
}

void Tangent::moduli(const Model& model, std::vector<double>& out, Workspace* ws) const {
  const index_t stencils = model.stencil_end();
  out.resize(81 * static_cast<std::size_t>(stencils));
  const double* base = linearisation_.data();
  const bool projected = mode_ == TangentMode::PROJECTED;
  with_material(model, ws ? viscous_step(*ws) : ViscousStep{}, [&](const auto& energy) {
    using L = typename std::decay_t<decltype(energy)>::Linearisation;
    for_each_point(stencils, ws, [&](index_t i) {
      const L at = load_linearisation<L>(base, i);
      double* C = out.data() + 81 * static_cast<std::size_t>(i);
      // column k of the moduli: dP for the unit dG with entry k (column-major) set
      for (int k = 0; k < 9; ++k) {
        Mat3 dG = Mat3::Zero();
        dG.data()[k] = 1.0;
        const Mat3 dP = model.stiffness_volume[i] * energy.stress_derivative(i, at, dG, projected);
        std::memcpy(C + 9 * k, dP.data(), 9 * sizeof(double));
      }
    });
  });
}

void Tangent::diagonal_blocks(const Model& model, Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks, Workspace* ws) const {
  const Csr& nbr = model.neighbours;
  const index_t n = model.n_points, stencil_end = model.stencil_end();
  blocks.resize(9, n);
  const double* base = linearisation_.data();
  // A unit displacement of point j along e_b changes stencil i's gradient by dG = e_b d^T (d = d_ij, or d_ii
  // for j = i), and j's force by -v_i dP(dG) d: the energy's stiffness_block. Gathered per j over the
  // stencils that reach it (neighbourhoods are symmetric), so no two threads write one block. The hourglass
  // part is constant and precomputed in the model (energies/hourglass.cpp).
  with_material(model, ws ? viscous_step(*ws) : ViscousStep{}, [&](const auto& energy) {
    using L = typename std::decay_t<decltype(energy)>::Linearisation;
    for_each_point(n, ws, [&](index_t j) {
      Mat3 K = Mat3::Zero();
      if (j < stencil_end) {
        K = model.stiffness_volume[j] * energy.stiffness_block(j, load_linearisation<L>(base, j), model.d_self.col(j));
        if (model.hg_diagonal.size()) K.diagonal().array() += model.hg_diagonal[j];
      }
      for (index_t e = nbr.begin(j); e < nbr.end(j); ++e) {
        const index_t i = nbr.index[e];
        if (i >= stencil_end) continue;
        // d_ij of the pair (i, j) in i's row
        K += model.stiffness_volume[i] * energy.stiffness_block(i, load_linearisation<L>(base, i), model.d.col(model.reverse_pair[e]));
      }
      blocks.col(j) = K.reshaped();
    });
  });
}

}  // namespace pointhaptics
