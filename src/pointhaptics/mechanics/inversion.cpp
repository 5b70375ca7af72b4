#include <pointhaptics/mechanics/inversion.hpp>

#include <algorithm>

namespace pointhaptics {

index_t count_inverted(const Model& model, Workspace& ws) {
  double* per_chunk = ws.chunk_scalars.data();  // one count per chunk: no atomics
  ws.for_each_chunk([&](int chunk) {
    index_t inverted = 0;
    const index_t end = std::min(ws.chunk_end(chunk), model.stencil_end());
    for (index_t i = ws.chunk_begin(chunk); i < end; ++i) {
      inverted += !((Mat3::Identity() + ws.gradient(i)).determinant() > 0);  // NaN counts
    }
    per_chunk[chunk] = static_cast<double>(inverted);
  });
  double total = 0;
  for (int c = 0; c < ws.n_threads(); ++c) total += per_chunk[c];
  return static_cast<index_t>(total);
}

}  // namespace pointhaptics
