#include <pointhaptics/surface/cut_surface.hpp>

#include <pointhaptics/geometry/mesh_distance.hpp>
#include <pointhaptics/geometry/remesh.hpp>
#include <pointhaptics/geometry/segment_crossing.hpp>

#include <fmt/format.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

namespace pointhaptics {
namespace {

struct Box {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  void add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bool overlaps(const Box& o) const { return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all(); }
  Box inflated(double r) const { return Box{lo.array() - r, hi.array() + r}; }
};

Box box_of(const SheetTriangle& t) {
  Box b;
  for (const Vec3& p : t) b.add(p);
  return b;
}

std::uint64_t edge_key(index_t a, index_t b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(std::min(a, b))) << 32) |
         static_cast<std::uint32_t>(std::max(a, b));
}

/// The mesh being built: vertices, where each looks from for the points it sees, triangles.
struct Building {
  std::vector<Vec3> vertex;
  std::vector<Vec3> from;
  std::vector<std::array<index_t, 3>> faces;
  double min_area = 0;  // triangles below it (a sheet through a corner makes slivers of no area) are left out

  index_t add(const Vec3& position, const Vec3& looks_from) {
    vertex.push_back(position);
    from.push_back(looks_from);
    return static_cast<index_t>(vertex.size()) - 1;
  }
  void face(index_t a, index_t b, index_t c) {
    const Vec3 n = (vertex[static_cast<std::size_t>(b)] - vertex[static_cast<std::size_t>(a)])
                       .cross(vertex[static_cast<std::size_t>(c)] - vertex[static_cast<std::size_t>(a)]);
    if (0.5 * n.norm() > min_area) faces.push_back({a, b, c});
  }
};

/// The sheets by the cells of a uniform grid their boxes overlap, so that whether a segment crosses a sheet
/// is asked of the sheets near it only (a sawn object has hundreds of sheets within a support).
class SheetGrid {
 public:
  SheetGrid(std::span<const SheetTriangle> sheets, const std::vector<Box>& boxes, const Box& region, double cell)
      : sheets_(sheets), boxes_(boxes) {
    for (const Box& b : boxes) {
      bounds_.add(b.lo.cwiseMax(region.lo));
      bounds_.add(b.hi.cwiseMin(region.hi));
    }
    if (boxes.empty() || !(bounds_.lo.array() <= bounds_.hi.array()).all()) return;
    // (at most about a million cells: a coarser grid for a region far larger than the cell)
    const Vec3 extent = bounds_.hi - bounds_.lo;
    cell_ = std::max(cell, std::cbrt(extent.prod() / 1e6));
    for (int a = 0; a < 3; ++a) cells_[a] = std::max<index_t>(1, static_cast<index_t>(std::ceil(extent[a] / cell_)));
    offset_.assign(static_cast<std::size_t>(cells_[0] * cells_[1] * cells_[2]) + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {  // count, then fill
      for (std::size_t t = 0; t < boxes.size(); ++t)
        for_cells(boxes[t], [&](std::size_t c) {
          if (pass == 0) ++offset_[c + 1];
          else sheet_[static_cast<std::size_t>(fill_[c]++)] = static_cast<std::uint32_t>(t);
        });
      if (pass == 0) {
        for (std::size_t c = 1; c < offset_.size(); ++c) offset_[c] += offset_[c - 1];
        sheet_.resize(static_cast<std::size_t>(offset_.back()));
        fill_.assign(offset_.begin(), offset_.end() - 1);
      }
    }
  }

  /// Whether the segment p-q crosses a sheet.
  bool crosses(const Vec3& p, const Vec3& q) const {
    Box segment;
    segment.add(p);
    segment.add(q);
    if (offset_.empty() || !segment.overlaps(bounds_)) return false;
    // each sheet tested once per question, though it lies in several of the cells (a stamp per sheet and thread)
    thread_local std::vector<std::uint32_t> asked;
    thread_local std::uint32_t question = 0;
    if (asked.size() != boxes_.size() || ++question == 0) asked.assign(boxes_.size(), 0), question = 1;
    bool crossed = false;
    for_cells(segment, [&](std::size_t c) {
      for (std::int64_t k = offset_[c]; k < offset_[c + 1] && !crossed; ++k) {
        const std::uint32_t t = sheet_[static_cast<std::size_t>(k)];
        if (asked[t] == question) continue;
        asked[t] = question;
        crossed = segment.overlaps(boxes_[t]) &&
                  segment_crossing(p, q, sheets_[t][0], sheets_[t][1], sheets_[t][2]).has_value();
      }
    });
    return crossed;
  }

 private:
  std::size_t flat_index(index_t i, index_t j, index_t k) const {
    const auto size = [](index_t v) { return static_cast<std::size_t>(v); };
    return size(i) + size(cells_[0]) * (size(j) + size(cells_[1]) * size(k));
  }

  template <class Fn>
  void for_cells(const Box& b, Fn&& fn) const {
    index_t first[3], last[3];
    for (int a = 0; a < 3; ++a) {
      first[a] =
          std::clamp<index_t>(static_cast<index_t>(std::floor((b.lo[a] - bounds_.lo[a]) / cell_)), 0, cells_[a] - 1);
      last[a] =
          std::clamp<index_t>(static_cast<index_t>(std::floor((b.hi[a] - bounds_.lo[a]) / cell_)), 0, cells_[a] - 1);
    }
    for (index_t k = first[2]; k <= last[2]; ++k)
      for (index_t j = first[1]; j <= last[1]; ++j)
        for (index_t i = first[0]; i <= last[0]; ++i) fn(flat_index(i, j, k));
  }

  std::span<const SheetTriangle> sheets_;
  const std::vector<Box>& boxes_;
  Box bounds_;
  double cell_ = 1;
  index_t cells_[3] = {1, 1, 1};
  std::vector<std::int64_t> offset_, fill_;
  std::vector<std::uint32_t> sheet_;
};

/// Part 1: the surface's triangles, split where their edges cross a sheet.
void split_triangles(const TriangleMesh& mesh, std::span<const SheetTriangle> sheets, const std::vector<Box>& sheet_box,
                     double offset, Building& out) {
  // where each edge first crosses a sheet (from its lower-numbered end), and the crossing's two vertices:
  // [0] on the lower-numbered end's side, [1] on the other's
  struct Crossing {
    std::array<index_t, 2> copy{-1, -1};
  };
  std::unordered_map<std::uint64_t, Crossing> crossing;
  Box all;
  for (const Box& b : sheet_box) {
    all.add(b.lo);
    all.add(b.hi);
  }
  auto crossing_of = [&](index_t a, index_t b) -> const Crossing* {
    const std::uint64_t key = edge_key(a, b);
    if (const auto found = crossing.find(key); found != crossing.end())
      return found->second.copy[0] < 0 ? nullptr : &found->second;
    const index_t lo = std::min(a, b), hi = std::max(a, b);
    const Vec3 p = mesh.V.col(lo), q = mesh.V.col(hi);
    Box segment;
    segment.add(p);
    segment.add(q);
    Crossing& c = crossing[key];
    if (!segment.overlaps(all)) return nullptr;
    double nearest = std::numeric_limits<double>::infinity();
    Vec3 at = Vec3::Zero();
    for (std::size_t s = 0; s < sheets.size(); ++s) {
      if (!segment.overlaps(sheet_box[s])) continue;
      const std::optional<Vec3> x = segment_crossing(p, q, sheets[s][0], sheets[s][1], sheets[s][2]);
      if (x && (*x - p).squaredNorm() < nearest) {
        nearest = (*x - p).squaredNorm();
        at = *x;
      }
    }
    if (!std::isfinite(nearest)) return nullptr;
    // each copy looks from just off the crossing toward its own end (from the end itself if it is that close)
    auto toward = [&](const Vec3& end) {
      return (end - at).norm() > offset ? Vec3(at + offset * (end - at).normalized()) : end;
    };
    c.copy = {out.add(at, toward(p)), out.add(at, toward(q))};
    return &c;
  };
  // the copy of edge (a, b)'s crossing on vertex v's side
  auto copy_near = [](const Crossing* c, index_t a, index_t b, index_t v) {
    return c->copy[v == std::min(a, b) ? 0 : 1];
  };
  for (const auto& f : mesh.F) {
    const Crossing* edge[3];
    int crossed = 0;
    for (int k = 0; k < 3; ++k) crossed += (edge[k] = crossing_of(f[k], f[(k + 1) % 3])) != nullptr;
    if (crossed < 2) {  // whole, or the tip of a crack that ends inside it
      out.face(f[0], f[1], f[2]);
      continue;
    }
    if (crossed == 3) {  // each corner on its own
      for (int k = 0; k < 3; ++k) {
        const index_t v = f[k], next = f[(k + 1) % 3], previous = f[(k + 2) % 3];
        out.face(v, copy_near(edge[k], v, next, v), copy_near(edge[(k + 2) % 3], previous, v, v));
      }
      continue;
    }
    // two crossed edges: the corner they share is alone on its side
    int lone = 0;
    while (!(edge[lone] && edge[(lone + 2) % 3])) ++lone;
    const index_t L = f[lone], B = f[(lone + 1) % 3], C = f[(lone + 2) % 3];
    const Crossing* LB = edge[lone];
    const Crossing* CL = edge[(lone + 2) % 3];
    out.face(L, copy_near(LB, L, B, L), copy_near(CL, C, L, L));
    const index_t b_side = copy_near(LB, L, B, B), c_side = copy_near(CL, C, L, C);
    out.face(b_side, B, C);
    out.face(b_side, C, c_side);
  }
}

/// Where the signed distance is zero between p and q (of distances dp and dq, of opposite signs), to within
/// `tolerance`: regula falsi with the Illinois step (exact at once where the distance is affine, as beside a
/// face; a few steps where the closest feature is an edge or a corner).
Vec3 zero_between(const MeshDistance& distance, Vec3 p, double dp, Vec3 q, double dq, double tolerance) {
  Vec3 x = p + (dp / (dp - dq)) * (q - p);
  for (int iteration = 0; iteration < 40; ++iteration) {
    const double dx = distance.signed_distance(x);
    if (std::abs(dx) <= tolerance || (q - p).norm() <= tolerance) break;
    if ((dx <= 0) == (dp <= 0)) {
      p = x, dp = dx;
      dq *= 0.5;
    } else {
      q = x, dq = dx;
      dp *= 0.5;
    }
    x = p + (dp / (dp - dq)) * (q - p);
  }
  return x;
}

/// Part 2: each sheet's part inside the object, twice: cut into a triangle grid of about `edge`, clipped to
/// where the signed distance to the uncut surface is negative.
void add_sheet_faces(const TriangleMesh& mesh, std::span<const SheetTriangle> sheets, const std::vector<Box>& sheet_box,
                     double edge, double offset, Building& out) {
  const MeshDistance distance(mesh);
  Box object;
  for (Eigen::Index v = 0; v < mesh.V.cols(); ++v) object.add(mesh.V.col(v));
  std::vector<double> d;
  std::vector<std::array<index_t, 2>>
      grid_vertex;  // a grid vertex's two copies (material on the normal's side, on the other)
  std::unordered_map<std::uint64_t, std::array<index_t, 2>> edge_vertex;  // a grid edge's crossing of the surface
  for (std::size_t s = 0; s < sheets.size(); ++s) {
    const SheetTriangle& t = sheets[s];
    const Vec3 normal = (t[1] - t[0]).cross(t[2] - t[0]);
    if (!(normal.norm() > 0) || !sheet_box[s].overlaps(object)) continue;
    const Vec3 n = normal.normalized();
    const double longest = std::max({(t[1] - t[0]).norm(), (t[2] - t[1]).norm(), (t[0] - t[2]).norm()});
    // (bounded: a sheet far larger than the object is cut no finer than 512 x 512)
    const index_t k = std::clamp<index_t>(static_cast<index_t>(std::ceil(longest / edge)), 1, 512);
    const index_t row = k + 1;
    auto id = [row](index_t i, index_t j) { return i * row + j; };
    auto position = [&](index_t i, index_t j) -> Vec3 {
      return t[0] + (static_cast<double>(i) / static_cast<double>(k)) * (t[1] - t[0]) +
             (static_cast<double>(j) / static_cast<double>(k)) * (t[2] - t[0]);
    };
    d.assign(static_cast<std::size_t>(row) * static_cast<std::size_t>(row), 0.0);
    tbb::parallel_for(index_t{0}, row, [&](index_t i) {
      for (index_t j = 0; i + j <= k; ++j)
        d[static_cast<std::size_t>(id(i, j))] = distance.signed_distance(position(i, j));
    });
    grid_vertex.assign(static_cast<std::size_t>(row) * static_cast<std::size_t>(row), {-1, -1});
    edge_vertex.clear();
    auto pair_at = [&](const Vec3& p) -> std::array<index_t, 2> {
      return {out.add(p, p + offset * n), out.add(p, p - offset * n)};
    };
    auto vertex_of = [&](index_t g) -> std::array<index_t, 2> {
      auto& v = grid_vertex[static_cast<std::size_t>(g)];
      if (v[0] < 0) v = pair_at(position(g / row, g % row));
      return v;
    };
    auto crossing_of = [&](index_t g, index_t h) -> std::array<index_t, 2> {
      const std::uint64_t key = edge_key(g, h);
      if (const auto found = edge_vertex.find(key); found != edge_vertex.end()) return found->second;
      const index_t lo = std::min(g, h), hi = std::max(g, h);
      const double dl = d[static_cast<std::size_t>(lo)], dh = d[static_cast<std::size_t>(hi)];
      const Vec3 p = position(lo / row, lo % row), q = position(hi / row, hi % row);
      return edge_vertex[key] = pair_at(zero_between(distance, p, dl, q, dh, 1e-9 * edge));
    };
    auto clipped = [&](std::array<index_t, 3> g) {
      // Sutherland-Hodgman against d <= 0, on the grid's ids (a crossing is shared by the triangles on both sides)
      std::array<std::array<index_t, 2>, 4> polygon;
      int count = 0;
      for (int c = 0; c < 3; ++c) {
        const index_t here = g[c], next = g[(c + 1) % 3];
        const bool in = d[static_cast<std::size_t>(here)] <= 0, next_in = d[static_cast<std::size_t>(next)] <= 0;
        if (in) polygon[count++] = vertex_of(here);
        if (in != next_in) polygon[count++] = crossing_of(here, next);
      }
      // the copy for the material on the normal's side faces away from it (against the normal): reversed
      for (int c = 1; c + 1 < count; ++c) {
        out.face(polygon[0][0], polygon[c + 1][0], polygon[c][0]);
        out.face(polygon[0][1], polygon[c][1], polygon[c + 1][1]);
      }
    };
    for (index_t i = 0; i < k; ++i)
      for (index_t j = 0; i + j < k; ++j) {
        clipped({id(i, j), id(i + 1, j), id(i, j + 1)});
        if (i + j + 1 < k) clipped({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
  }
}

}  // namespace

void CutSheets::add_strip(const Vec3& A0, const Vec3& B0, const Vec3& A1, const Vec3& B1, bool continues,
                          double tolerance) {
  ++revision;
  const std::size_t n = triangles.size();
  if (continues && n >= 2) {
    // the last strip: (P0, Q0, Q1), (P0, Q1, P1), ending on P1-Q1, where this one starts
    const Vec3 P0 = triangles[n - 2][0], Q0 = triangles[n - 2][1], P1 = triangles[n - 1][2], Q1 = triangles[n - 2][2];
    const Vec3 normal = (Q0 - P0).cross(B1 - P0);
    const bool straight = distance_to_segment(P1, P0, A1) <= tolerance &&
                          distance_to_segment(Q1, Q0, B1) <= tolerance && normal.norm() > 0 &&
                          std::abs(normal.normalized().dot(A1 - P0)) <= tolerance;
    if (straight) {
      triangles[n - 2] = {P0, Q0, B1};
      triangles[n - 1] = {P0, B1, A1};
      return;
    }
  }
  triangles.push_back({A0, B0, B1});
  triangles.push_back({A0, B1, A1});
}

namespace {

// One body's surface split (`body`: its index, whose points alone carry it; -1: the model's one body)
ObjectSurface split_body_surface(const ObjectSurface& whole, const Model& model, std::span<const SheetTriangle> sheets,
                                 index_t body) {
  const TriangleMesh& mesh = whole.mesh;
  const index_t n_whole = static_cast<index_t>(mesh.V.cols());
  const double edge = mean_edge_length(mesh);
  const double h = model.support.size() == model.n_points && model.n_points > 0 ? model.support.maxCoeff() : model.h;
  // how far off a sheet a vertex on it looks from: far below the spacing, far above rounding
  const double offset = 1e-4 * h;
  std::vector<Box> sheet_box;
  sheet_box.reserve(sheets.size());
  for (const SheetTriangle& t : sheets) sheet_box.push_back(box_of(t));

  Building out;
  out.min_area = 1e-10 * edge * edge;
  for (index_t v = 0; v < n_whole; ++v) out.add(mesh.V.col(v), mesh.V.col(v));
  split_triangles(mesh, sheets, sheet_box, offset, out);
  const std::size_t n_split = out.faces.size();
  add_sheet_faces(mesh, sheets, sheet_box, edge, offset, out);
  const std::size_t n_vertices = out.vertex.size();

  // a vertex near a sheet sees points within two widenings of the support (1.5^2 h) at most: further widenings
  // cannot see round the sheets that hem it in (a vertex between two close sheets of a sawn object), and each
  // would test every point within 7.6 h against the sheets. A vertex with no sheet within that reach keeps its
  // row of the whole surface's map.
  const double reach = h * 1.5 * 1.5;
  std::vector<char> near(n_vertices, 0);
  tbb::parallel_for(std::size_t{0}, n_vertices, [&](std::size_t v) {
    Box at;
    at.add(out.vertex[v]);
    at = at.inflated(reach);
    for (std::size_t s = 0; s < sheets.size() && !near[v]; ++s) near[v] = at.overlaps(sheet_box[s]);
  });
  std::vector<index_t> remap;  // the vertices whose rows are built anew
  for (std::size_t v = 0; v < n_vertices; ++v)
    if (static_cast<index_t>(v) >= n_whole || near[v]) remap.push_back(static_cast<index_t>(v));
  Box region;  // where vertices and the points they see can be
  for (Eigen::Index j = 0; j < model.X.cols(); ++j) region.add(model.X.col(j));
  for (const Vec3& v : out.vertex) region.add(v);
  const SheetGrid grid(sheets, sheet_box, region.inflated(reach), 0.5 * h);
  Points Y(3, static_cast<Eigen::Index>(remap.size()));
  for (std::size_t r = 0; r < remap.size(); ++r)
    Y.col(static_cast<Eigen::Index>(r)) = out.vertex[static_cast<std::size_t>(remap[r])];
  const VertexSees sees = [&](index_t r, index_t j) {
    const std::size_t v = static_cast<std::size_t>(remap[static_cast<std::size_t>(r)]);
    return (body < 0 || model.body_of(j) == body) && (model.X.col(j) - out.vertex[v]).squaredNorm() <= reach * reach &&
           !grid.crosses(out.from[v], model.X.col(j));
  };
  std::vector<char> uncarried;
  const SurfaceMap fresh = build_surface_map(model, Y, &uncarried, sees);

  // the rows, in the new vertices' order: the whole map's, or the fresh ones
  std::vector<index_t> fresh_row(n_vertices, -1);
  for (std::size_t r = 0; r < remap.size(); ++r)
    fresh_row[static_cast<std::size_t>(remap[r])] = static_cast<index_t>(r);
  std::vector<char> dropped(n_vertices, 0);
  ObjectSurface split;
  SurfaceMap& map = split.map;
  map.points.offset.assign(1, 0);
  for (std::size_t v = 0; v < n_vertices; ++v) {
    const index_t r = fresh_row[v];
    const SurfaceMap& from_map = r >= 0 ? fresh : whole.map;
    const index_t row = r >= 0 ? r : static_cast<index_t>(v);
    if (r >= 0 && uncarried[static_cast<std::size_t>(r)]) dropped[v] = 1;
    for (index_t e = from_map.points.begin(row); e < from_map.points.end(row); ++e) {
      map.points.index.push_back(from_map.points.index[e]);
      map.weight.push_back(from_map.weight[e]);
    }
    map.points.offset.push_back(static_cast<index_t>(map.points.index.size()));
  }
  map.widened = whole.map.widened + fresh.widened;

  split.mesh.V.resize(3, static_cast<Eigen::Index>(n_vertices));
  for (std::size_t v = 0; v < n_vertices; ++v) split.mesh.V.col(static_cast<Eigen::Index>(v)) = out.vertex[v];
  index_t dropped_faces = 0;
  for (std::size_t t = 0; t < out.faces.size(); ++t) {
    const auto& f = out.faces[t];
    if (dropped[static_cast<std::size_t>(f[0])] || dropped[static_cast<std::size_t>(f[1])] ||
        dropped[static_cast<std::size_t>(f[2])]) {
      ++dropped_faces;
      continue;
    }
    split.mesh.F.push_back(f);
    if (t >= n_split) ++split.cut_faces;
  }
  split.source = fmt::format(
      "{}; split by {} cut sheet triangle{} ({} faces of cuts{})", whole.source, sheets.size(),
      sheets.size() == 1 ? "" : "s", split.cut_faces,
      dropped_faces ? fmt::format(", {} triangles dropped: too few points to carry them", dropped_faces) : "");
  return split;
}

// whether any of body k's pairs is severed
bool body_is_cut(const Model& model, index_t k) {
  if (model.severed.empty()) return false;
  const Csr& nbr = model.neighbours;
  const auto b = static_cast<std::size_t>(k);
  for (index_t i = model.body_start[b]; i < model.body_start[b + 1]; ++i)
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e)
      if (model.severed[static_cast<std::size_t>(e)]) return true;
  return false;
}

}  // namespace

ObjectSurface split_surface(const ObjectSurface& whole, const Model& model, std::span<const SheetTriangle> given) {
  // (a sheet that is not finite, from a state that was not, splits nothing)
  std::vector<SheetTriangle> finite;
  finite.reserve(given.size());
  for (const SheetTriangle& t : given)
    if (t[0].allFinite() && t[1].allFinite() && t[2].allFinite()) finite.push_back(t);
  const std::span<const SheetTriangle> sheets(finite);
  if (sheets.empty()) return whole;
  if (whole.body_vertex_start.size() < 3 || model.body_start.size() < 3)
    return split_body_surface(whole, model, sheets, -1);
  // several bodies: each split alone, carried by its own points. A cut names its body, and its sheet may pass
  // through others (a blade drawn through two layers to cut the upper one): a body none of whose pairs a cut
  // severed keeps its surface whole
  ObjectSurface joined;
  std::string split_bodies;
  for (index_t k = 0; k + 1 < static_cast<index_t>(whole.body_vertex_start.size()); ++k) {
    ObjectSurface part = body_surface(whole, k);
    if (body_is_cut(model, k)) {
      part.source = fmt::format("\"{}\"", model.body_names[static_cast<std::size_t>(k)]);
      part = split_body_surface(part, model, sheets, k);
      split_bodies += "; " + part.source;
    }
    append_body_surface(joined, part);
  }
  joined.source = whole.source + split_bodies;
  return joined;
}

}  // namespace pointhaptics
