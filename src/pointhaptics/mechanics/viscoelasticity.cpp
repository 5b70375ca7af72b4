#include <pointhaptics/mechanics/viscoelasticity.hpp>

#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/energies/hessian.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>

#include <cmath>

namespace pointhaptics {

PronyStep prony_step(const std::vector<PronyTerm>& series, double dt) {
  PronyStep step;
  step.terms = std::min(series.size(), max_prony_terms);
  for (std::size_t k = 0; k < step.terms; ++k) {
    const double g = series[k].g, x = dt / series[k].tau;
    const double a = std::exp(-x);
    // (1 - a) / x - a and 1 - (1 - a) / x cancel for short steps: their series there
    double phi_minus_a, one_minus_phi;
    if (x < 1e-3) {
      phi_minus_a = x * (0.5 - x * (1.0 / 3.0 - x * (1.0 / 8.0 - x / 30.0)));
      one_minus_phi = x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0)));
    } else {
      const double phi = -std::expm1(-x) / x;
      phi_minus_a = phi - a;
      one_minus_phi = 1 - phi;
    }
    step.a[k] = a;
    step.b[k] = g * phi_minus_a;
    step.c[k] = g * one_minus_phi;
    step.c_sum += step.c[k];
  }
  return step;
}

namespace {

/// S_s = F^-1 P_s with P_s the material's stress at zero bulk modulus (F^-1 = cof F^T / J), symmetrised
/// against round-off; false where the neighbourhood is too degenerate to invert F.
template <class ShearEnergy>
bool shear_stress_of(const ShearEnergy& shear, index_t i, const Mat3& G, Mat3& S) {
  const Mat3 F = Mat3::Identity() + G;
  const double J = F.determinant();
  if (!(J >= PowerOfJ::j_floor)) return false;
  const Mat3 Ss = cofactor(F).transpose() * shear.material_stress(i, G) / J;
  S = 0.5 * (Ss + Ss.transpose());
  return true;
}

bool has_history(const Model& model, const State& state) {
  return state.viscous.rows() == State::viscous_rows(model) && state.viscous.cols() == model.n_points;
}

template <class Fn>
decltype(auto) with_shear_part(const Model& model, Fn&& fn) {
  return with_material(model, ViscousStep{}, std::forward<Fn>(fn), /*bulk_factor=*/0.0);
}

}  // namespace

Mat3 shear_stress(const Model& model, index_t i, const Mat3& G) {
  return with_shear_part(model, [&](const auto& shear) {
    Mat3 S = Mat3::Constant(std::numeric_limits<double>::quiet_NaN());
    shear_stress_of(shear, i, G, S);
    return S;
  });
}

void begin_viscous_step(const Model& model, const State& state, double dt, Workspace& ws) {
  if (model.material.prony.empty()) return;
  const PronyStep step = prony_step(model.material.prony, dt);
  const auto terms = static_cast<Eigen::Index>(step.terms);
  ws.viscous_shear_factor = 1 - step.c_sum;
  ws.overstress_active = true;
  if (!has_history(model, state)) {  // a state made without one (not State::at_rest's): at rest
    ws.overstress.setZero();
    return;
  }
  ws.for_each_chunk([&](int chunk) {
    for (index_t i = ws.chunk_begin(chunk); i < ws.chunk_end(chunk); ++i) {
      const auto history = state.viscous.col(i);
      const auto S = history.segment<6>(6 * terms);
      Voigt6 H = Voigt6::Zero();
      for (Eigen::Index k = 0; k < terms; ++k) H += step.a[k] * history.segment<6>(6 * k) + step.b[k] * S;
      ws.overstress.col(i) = H;
    }
  });
}

void end_viscous_step(const Model& model, double dt, State& state, Workspace& ws) {
  if (model.material.prony.empty()) return;
  const PronyStep step = prony_step(model.material.prony, dt);
  const auto terms = static_cast<Eigen::Index>(step.terms);
  if (!has_history(model, state)) state.viscous = Eigen::MatrixXd::Zero(State::viscous_rows(model), model.n_points);
  with_shear_part(model, [&](const auto& shear) {
    ws.for_each_chunk([&](int chunk) {
      const index_t end = std::min(ws.chunk_end(chunk), model.stencil_end());
      for (index_t i = ws.chunk_begin(chunk); i < end; ++i) {
        auto history = state.viscous.col(i);
        const Voigt6 S_before = history.segment<6>(6 * terms);
        Mat3 S_now;
        const Mat3 G = displacement_gradient(model, state.u, i);  // seed Eq. 10
        const Voigt6 S = shear_stress_of(shear, i, G, S_now) ? to_voigt(S_now) : S_before;
        for (Eigen::Index k = 0; k < terms; ++k)
          history.segment<6>(6 * k) = step.a[k] * history.segment<6>(6 * k) + step.b[k] * S_before + step.c[k] * S;
        history.segment<6>(6 * terms) = S;
      }
    });
  });
}

void viscous_stress_at_state(const Model& model, const State& state, Workspace& ws, bool relaxed) {
  if (model.material.prony.empty()) return;
  if (relaxed) {
    relaxed_material(model, ws);
    return;
  }
  ws.viscous_shear_factor = 1;
  ws.overstress_active = true;
  if (!has_history(model, state)) {
    ws.overstress.setZero();
    return;
  }
  const auto terms = static_cast<Eigen::Index>(std::min(model.material.prony.size(), max_prony_terms));
  ws.for_each_chunk([&](int chunk) {
    for (index_t i = ws.chunk_begin(chunk); i < ws.chunk_end(chunk); ++i) {
      Voigt6 Q = Voigt6::Zero();
      for (Eigen::Index k = 0; k < terms; ++k) Q += state.viscous.col(i).segment<6>(6 * k);
      ws.overstress.col(i) = Q;
    }
  });
}

void relaxed_material(const Model& model, Workspace& ws) {
  ws.viscous_shear_factor = 1 - model.material.prony_total();
  ws.overstress_active = false;
}

}  // namespace pointhaptics
