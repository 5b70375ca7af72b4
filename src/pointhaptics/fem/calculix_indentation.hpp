#pragma once
/// @file CalculiX reference for a rigid sphere pressed into a block: an axisymmetric model (CAX8 quadratic
/// quadrilaterals) of a cylinder held at its bottom, indented on its axis by a frictionless sphere, the contact
/// solved by CalculiX (surface-to-surface, penalty), the force read at every depth. It is the independent
/// check of the force the device renders (issue 16, `pointhaptics experiment contact`).
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

}  // namespace pointhaptics::fem
