#include <pointhaptics/mechanics/forces.hpp>

#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/detail/stencil_loop.hpp>

namespace pointhaptics {

void compute_internal_forces(const Model& model, const Points& u, Workspace& ws) {
  const double lambda = model.lambda, mu = model.mu, kv = model.material.volume_stiffness;
  // seed Eq. 12-13 in exact form: A_i = v_i P_i = v_i (F_i S_i + k_v (J_i - 1) cof F_i), F = I + G (Eq. 2)
  detail::stencil_sum(model, u, ws, ws.f_int, 1.0, [lambda, mu, kv, volume = model.volume.data()](index_t i, const Mat3& G) PH_ALWAYS_INLINE -> Mat3 {
    const Mat3 F = Mat3::Identity() + G;
    const Mat3 E = 0.5 * (G + G.transpose() + G.transpose() * G);  // Green strain, cancellation-free
    const Mat3 S = lambda * E.trace() * Mat3::Identity() + 2.0 * mu * E;
    const double v = volume[i];
    Mat3 A = v * (F * S);
    if (kv > 0) A += v * kv * (F.determinant() - 1.0) * cofactor(F);
    return A;
  });
}

}  // namespace pointhaptics
