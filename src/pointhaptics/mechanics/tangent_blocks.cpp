#include <pointhaptics/mechanics/tangent.hpp>

#include <pointhaptics/mechanics/detail/linearisation_store.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>

// The tangent's per-point moduli and diagonal blocks, for the preconditioners (block-Jacobi, the assembled
// matrix): a file apart from the product K du, so that neither instantiates every material's linearisation
// for all four loops (each half compiles in under 20 s at -O3).
namespace pointhaptics {

using detail::for_each_point;
using detail::load_linearisation;

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

void Tangent::diagonal_blocks(const Model& model, Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks,
                              Workspace* ws) const {
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
        K += model.stiffness_volume[i] *
             energy.stiffness_block(i, load_linearisation<L>(base, i), model.d.col(model.reverse_pair[e]));
      }
      blocks.col(j) = K.reshaped();
    });
  });
}

}  // namespace pointhaptics
