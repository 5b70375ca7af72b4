#include <pointhaptics/lod/active_surface.hpp>

#include <algorithm>
#include <cmath>

namespace pointhaptics {

ActiveSurface restrict_surface(const TriangleMesh& mesh, const SurfaceMap& map, const ActiveSet& active, double reach) {
  ActiveSurface out;
  const index_t m = map.n_vertices();
  const double region = 2 * active.core_radius + 2 * reach;
  std::vector<index_t> kept(static_cast<std::size_t>(m), -1);
  for (index_t v = 0; v < m; ++v) {
    if (map.points.row_size(v) == 0) continue;
    if (std::isfinite(region) && (mesh.V.col(v) - active.centre).norm() > region) continue;
    // the point that carries most of the vertex in the object: simulated, held in the ring, or absorbed by
    // a simulated one (left out, the absorbed points of a thinned band made holes in the part a few
    // millimetres from the contact, through which the probe's centre passed unseen)
    const auto first = map.weight.begin() + map.points.begin(v), last = map.weight.begin() + map.points.end(v);
    const index_t nearest =
        map.points.index[static_cast<std::size_t>(std::max_element(first, last) - map.weight.begin())];
    if (active.active_of[static_cast<std::size_t>(nearest)] < 0 && active.followed.row_size(nearest) == 0) continue;
    kept[static_cast<std::size_t>(v)] = static_cast<index_t>(out.vertex_of.size());
    out.vertex_of.push_back(v);
  }
  // carried by the active model's points: a vertex at the active region's rim may find too few of them
  // (a thinned band, one side of the frozen ring), and is left out as the others are
  Points Y(3, static_cast<Eigen::Index>(out.vertex_of.size()));
  for (std::size_t k = 0; k < out.vertex_of.size(); ++k)
    Y.col(static_cast<Eigen::Index>(k)) = mesh.V.col(out.vertex_of[k]);
  std::vector<char> uncarried;
  const SurfaceMap map_all = build_surface_map(active.model, Y, &uncarried);
  std::vector<index_t> vertex_of;
  std::fill(kept.begin(), kept.end(), -1);
  for (std::size_t k = 0; k < out.vertex_of.size(); ++k) {
    if (uncarried[k]) continue;
    const index_t v = out.vertex_of[k];
    kept[static_cast<std::size_t>(v)] = static_cast<index_t>(vertex_of.size());
    vertex_of.push_back(v);
    const index_t row = static_cast<index_t>(k);
    for (index_t e = map_all.points.begin(row); e < map_all.points.end(row); ++e) {
      out.map.points.index.push_back(map_all.points.index[e]);
      out.map.weight.push_back(map_all.weight[static_cast<std::size_t>(e)]);
    }
    out.map.points.offset.push_back(out.map.points.n_entries());
  }
  out.vertex_of = std::move(vertex_of);
  out.mesh.V.resize(3, static_cast<Eigen::Index>(out.vertex_of.size()));
  for (std::size_t k = 0; k < out.vertex_of.size(); ++k)
    out.mesh.V.col(static_cast<Eigen::Index>(k)) = mesh.V.col(out.vertex_of[k]);
  for (const auto& t : mesh.F) {
    const std::array<index_t, 3> r{kept[static_cast<std::size_t>(t[0])], kept[static_cast<std::size_t>(t[1])],
                                   kept[static_cast<std::size_t>(t[2])]};
    if (r[0] >= 0 && r[1] >= 0 && r[2] >= 0) out.mesh.F.push_back(r);
  }
  return out;
}

}  // namespace pointhaptics
