#pragma once
/// @file The map that carries an object's surface with its points: each vertex moves with the first-order
/// moving least squares interpolant of the points' displacements around it (the mechanics' kernel and
/// support), a sparse linear map W built once: y = Y + W u. Forces on the surface reach the points by W^T,
/// so that the virtual work is the same on both sides.
#include <pointhaptics/core/csr.hpp>
#include <pointhaptics/core/model.hpp>

#include <functional>
#include <vector>

namespace pointhaptics {

struct SurfaceMap {
  Csr points;                  ///< row v: the points that carry vertex v
  std::vector<double> weight;  ///< phi_j(Y_v), by the entries of `points`; each row sums to 1
  index_t widened = 0;  ///< vertices whose neighbourhood was widened (too few points, or too flat, within the support)

  index_t n_vertices() const { return points.n_rows(); }
};

/// W for the vertices Y (3 x m) over `model`'s points: phi_j(Y) = w_j p(0)^T M(Y)^-1 p(X_j - Y), M(Y) =
/// sum_j w_j p(X_j - Y) p(X_j - Y)^T with the linear basis p(x) = (1, x / h) and w_j = w(|X_j - Y|, h) the
/// model's kernel (h: the model's support, or with per-point supports the nearest point's). So W reproduces
/// every affine displacement exactly, rigid motions among them. A vertex whose points within h are too few
/// or too flat for M (condition number above 1e8) takes them within 1.5 h, then 2.25 h, ... (counted in
/// `widened`); after five widenings it is an Error naming the vertex, unless `uncarried` is given: then such a
/// vertex gets an empty row and uncarried[v] = 1 (the others 0).
/// With `sees`, a vertex is carried only by the points it sees: sees(v, j) false leaves point j out of vertex
/// v's neighbourhood (a cut object's vertex, carried by the points on its side of the cuts: cut_surface.hpp).
using VertexSees = std::function<bool(index_t vertex, index_t point)>;
SurfaceMap build_surface_map(const Model& model, const Points& Y, std::vector<char>* uncarried = nullptr,
                             const VertexSees& sees = {});

/// The map with each vertex's negative weights left out and the rest scaled to sum to 1 (a vertex without
/// points keeps its empty row): a partition of unity of non-negative weights, so a force on a vertex pushes
/// every point that carries it the same way. It carries translations exactly; under an affine displacement
/// u = A X a vertex moves by A X_v (X_v: its points' weighted centre, inside the object by about half a
/// spacing) instead of A Y_v, so a rotation slides it along the surface (first order) and a stretch across the
/// surface moves it by the strain times that depth. (The contact's map: SurfaceContact says why.)
SurfaceMap without_negative_weights(SurfaceMap map);

/// W f: a field of the points (k x n, e.g. k = 1 von Mises stress, 9 a stress tensor) at the vertices (k x m),
/// into `out` (resized once).
void interpolate_at_surface(const SurfaceMap& map, const Eigen::Ref<const Eigen::MatrixXd>& field,
                            Eigen::MatrixXd& out);

/// y = Y + W u (3 x m), into `y` (resized once; no allocation after).
void carry_surface(const SurfaceMap& map, const Points& Y, const Points& u, Points& y);
/// The same into the first m columns of `y` (which has at least m; Y too): a contact's vertices before its
/// samples (haptics/contact_samples.hpp).
void carry_surface_into(const SurfaceMap& map, const Points& Y, const Points& u, Eigen::Ref<Points> y);

/// f_points += W^T f_vertices: forces on the vertices onto the points, with the same virtual work
/// (f_vertices . W du = (W^T f_vertices) . du).
void spread_surface_forces(const SurfaceMap& map, const Points& f_vertices, Points& f_points);

}  // namespace pointhaptics
