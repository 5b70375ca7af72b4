#pragma once
/// @file The surface of a cut object (issue 18): the object's surface split where a blade's sheets cross it,
/// and the two faces of every sheet inside the object, one for the material on each side. Every vertex is
/// carried only by the points it sees, the segment between them crossing no sheet (the visibility criterion
/// that severed the points' pairs, mechanics/cut.hpp), so the faces part as the material parts: the gap is
/// seen, written out and touched.
///
/// The sheets are kept in the reference configuration, where the surface is defined (ModelSimulation maps
/// each blade step's new strip back by the displacement around it).
#include <pointhaptics/surface/object_surface.hpp>

#include <array>
#include <optional>
#include <span>

namespace pointhaptics {

/// A triangle of a blade's swept surface, in the reference configuration, m.
using SheetTriangle = std::array<Vec3, 3>;

/// The sheets a blade's cuts swept, in the reference configuration.
struct CutSheets {
  std::vector<SheetTriangle> triangles;
  long long revision = 0;  ///< counts the changes: a strip added or extended

  /// Add the strip the edge A0-B0 swept moving to A1-B1, as the triangles (A0, B0, B1) and (A0, B1, A1). With
  /// `continues` (it starts on the last strip's end edge), a strip that goes on straight from the last one,
  /// within `tolerance` (m), extends it instead: a straight cut stays one quad however many steps it took, and
  /// a curved one takes a quad per bend of that size.
  void add_strip(const Vec3& A0, const Vec3& B0, const Vec3& A1, const Vec3& B1, bool continues, double tolerance);
};

/// `whole`, the uncut object's surface (closed), split by `sheets` over the cut `model`:
/// - an edge of the surface that crosses a sheet gets a vertex where it crosses, once for each side; a
///   triangle with two such edges is split into the part on its lone corner's side and the part on the
///   other (three: its three corners); a triangle the sheet ends in (one such edge) is kept, the crack's tip;
/// - each sheet, cut into triangles of about the surface's edge and clipped to the inside of `whole` (its
///   signed distance), gives two faces, oriented away from the material they bound (the last `cut_faces`
///   triangles);
/// - the map carries the vertices near the sheets by the points they see (a vertex on a sheet looks from
///   just off it, on its side); the others keep their rows of whole.map. A vertex that sees too few points to
///   be carried is dropped with its triangles.
/// Without sheets, `whole` itself. The sheets need not be closed, disjoint or inside the object.
ObjectSurface split_surface(const ObjectSurface& whole, const Model& model, std::span<const SheetTriangle> sheets);

/// An object's surface as its cuts so far leave it: split_surface() again only when the cuts have added sheets
/// since the last call (they only add).
class CutSurface {
 public:
  explicit CutSurface(ObjectSurface whole) : whole_(std::move(whole)) {}
  /// The surface split along `sheets` (the whole one without).
  const ObjectSurface& at(const Model& model, const CutSheets& sheets) {
    if (sheets.triangles.empty()) return whole_;
    if (!split_ || sheets.revision != split_revision_) {
      split_ = split_surface(whole_, model, sheets.triangles);
      split_revision_ = sheets.revision;
    }
    return *split_;
  }
  const ObjectSurface& whole() const { return whole_; }

 private:
  ObjectSurface whole_;
  std::optional<ObjectSurface> split_;
  long long split_revision_ = 0;
};

}  // namespace pointhaptics
