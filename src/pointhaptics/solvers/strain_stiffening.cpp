#include <pointhaptics/solvers/explicit_solver.hpp>

#include <pointhaptics/mechanics/energies/material.hpp>

#include <algorithm>
#include <cmath>

// strain_stiffening() (explicit_solver.hpp), in a file of its own: it instantiates every material's four-lane
// stiffening, which doubled the explicit step's compile time.
namespace pointhaptics {

double strain_stiffening(const Model& model, Workspace& ws) {
  double* chunk_max = ws.chunk_scalars.data();
  with_material(model, [&](const auto& energy) {
    ws.for_each_chunk([&](int chunk) {
      double m = 1;
      const index_t end = std::min(ws.chunk_end(chunk), model.stencil_end());
      // four points at a time (the check runs over every point of every step)
      for (index_t i = ws.chunk_begin(chunk); i < end; i += lane_count) {
        const int count = static_cast<int>(std::min<index_t>(lane_count, end - i));
        const Lanes s = energy.stiffening(i, count, four_gradients(ws.gradients.data(), i, count));
        for (int k = 0; k < count; ++k) m = std::max(m, s[k]);
      }
      chunk_max[chunk] = m;
    });
  });
  double m = 1;
  for (int c = 0; c < ws.n_threads(); ++c) m = std::max(m, chunk_max[c]);
  return std::isfinite(m) ? m : 1.0;
}

}  // namespace pointhaptics
