#include <pointhaptics/mechanics/inversion.hpp>

#include <pointhaptics/mechanics/deformation.hpp>

#include <algorithm>

namespace pointhaptics {

namespace {

bool inverted(const Mat3& G) { return !((Mat3::Identity() + G).determinant() > 0); }  // NaN counts

// the stencils whose gradient(i) is inverted, on ws's threads
template <class Gradient>
index_t count_where_inverted(const Model& model, Workspace& ws, const Gradient& gradient) {
  double* per_chunk = ws.chunk_scalars.data();  // one count per chunk: no atomics
  ws.for_each_chunk([&](int chunk) {
    index_t count = 0;
    const index_t end = std::min(ws.chunk_end(chunk), model.stencil_end());
    for (index_t i = ws.chunk_begin(chunk); i < end; ++i) count += inverted(gradient(i));
    per_chunk[chunk] = static_cast<double>(count);
  });
  double total = 0;
  for (int c = 0; c < ws.n_threads(); ++c) total += per_chunk[c];
  return static_cast<index_t>(total);
}

}  // namespace

index_t count_inverted(const Model& model, Workspace& ws) {
  return count_where_inverted(model, ws, [&](index_t i) { return ws.gradient(i); });
}

index_t count_inverted(const Model& model, const Points& u, Workspace& ws) {
  return count_where_inverted(model, ws, [&](index_t i) { return displacement_gradient(model, u, i); });
}

}  // namespace pointhaptics
