#pragma once
/// @file CalculiX references for contact of a sphere, axisymmetric (CAX8 quadratic quadrilaterals), the contact
/// solved by CalculiX (surface-to-surface, penalty, frictionless), the force read at every increment:
/// - a rigid sphere pressed into a cylinder held at its bottom: the independent check of the force the device
///   renders (issue 16, `pointhaptics experiment contact`);
/// - an elastic sphere held at its cap pressed onto a rigid plane: by symmetry, half of two equal spheres pressed
///   together, the check of body-body contact beside Hertz's two-body law (issue 47, `experiment contact-pairs`).
#include <pointhaptics/core/parameters.hpp>

#include <string>
#include <vector>

namespace pointhaptics::fem {

struct IndentationProblem {
  double sphere_radius = 0.01;  ///< R, m
  double block_radius = 0.04;   ///< the cylinder's radius, m
  double height = 0.04;         ///< the cylinder's height, m (its bottom is held)
  MaterialParams material;      ///< set_material's mapping (St. Venant-Kirchhoff, neo-Hookean, Mooney-Rivlin)
  double max_depth = 0.003;     ///< m, reached in `increments` equal steps
  int increments = 6;           ///< the force is read after each: at depths k max_depth / increments
  /// element size in the contact zone: R / elements_per_radius (graded by 1.4 per element away from it)
  int elements_per_radius = 10;
  /// contact pressure per unit of overclosure, Pa/m; 0: 100 E / element size (the sphere then sinks into the
  /// block by about 1% of an element at a contact pressure of E)
  double penalty = 0;
  bool nlgeom = true;  ///< geometrically nonlinear (as the point-based model)
};

struct IndentationPoint {
  double depth = 0;  ///< m, the sphere's travel from first touch
  double force = 0;  ///< N, the whole ring's (ccx prints a 2 degree segment's)
};

struct IndentationSolution {
  std::vector<IndentationPoint> curve;  ///< one per increment (ccx's cut ones too), in depth order
  /// The force at `depth` (linear between increments; exact at k max_depth / increments). Throws Error past
  /// the curve's end.
  double force_at(double depth) const;
  int nodes = 0, elements = 0;
  double wall_s = 0;
};

/// The input deck. The sphere is a layer of elements 10^4 times stiffer than the block whose inner nodes are
/// moved (so it is rigid for the contact); the block's top face near the axis is the contact's dependent
/// surface. Throws Error on non-positive sizes, a depth beyond the sphere's radius or a material ccx lacks.
std::string write_indentation_inp(const IndentationProblem& problem, int* nodes = nullptr, int* elements = nullptr);
/// Runs ccx on the deck (threads) and reads the reaction on the sphere at every increment. Throws Error
/// (naming the kept run folder and the end of ccx's log) when ccx fails or stops early.
IndentationSolution solve_indentation(const IndentationProblem& problem, int threads = 1);

/// An elastic sphere (centre at the origin) whose cap above `cap_from` is moved down by `max_travel` (held
/// radially), pressed onto a rigid frictionless plane touching its lowest point. Two equal spheres held at their
/// caps and pressed together deform as this one does against their plane of symmetry: their centres approach by
/// twice this one's centre's travel towards the plane, under the same force.
struct SphereOnPlaneProblem {
  double radius = 0.01;          ///< R, m
  double cap_from = 0.007;       ///< the held cap: every node with y >= cap_from, m
  MaterialParams material;       ///< as IndentationProblem's
  double max_travel = 0.0006;    ///< the cap's travel, m, reached in `increments` equal steps
  int increments = 8;            ///< the force and the centre's travel are read after each
  int elements_per_radius = 40;  ///< element size R / elements_per_radius where the sphere meets the plane
  double penalty = 0;            ///< contact pressure per unit of overclosure, Pa/m; 0: 100 E / element size
};

struct SphereOnPlanePoint {
  double cap_travel = 0;     ///< m, the held cap's
  double centre_travel = 0;  ///< m, the centre's travel towards the plane (half the two spheres' approach)
  double force = 0;          ///< N, on the plane
};

struct SphereOnPlaneSolution {
  std::vector<SphereOnPlanePoint> curve;  ///< one per increment, in travel order
  /// The force when the cap has travelled `cap_travel` (linear between increments; exact at k max_travel /
  /// increments). Throws Error outside the curve.
  double force_at_cap(double cap_travel) const;
  int nodes = 0, elements = 0;
  double wall_s = 0;
};

/// The input deck: the half disc of the sphere's meridian meshed as an O-grid (a square core and three blocks out
/// to the circle, fine where it meets the plane), the plane a layer of elements 10^4 times stiffer held at its
/// bottom. Throws Error on non-positive sizes, a cap that does not cut the sphere's upper half, a travel beyond
/// R/4, or a material ccx lacks.
std::string write_sphere_on_plane_inp(const SphereOnPlaneProblem& problem, int* nodes = nullptr,
                                      int* elements = nullptr);
/// Runs ccx on the deck (threads); reads the force on the cap and the centre's travel at every increment. Throws
/// Error (naming the kept run folder and the end of ccx's log) when ccx fails or stops early.
SphereOnPlaneSolution solve_sphere_on_plane(const SphereOnPlaneProblem& problem, int threads = 1);

}  // namespace pointhaptics::fem
