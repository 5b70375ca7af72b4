#pragma once
/// @file CalculiX adapter: an independent FEM solution of a box-shaped body (structured mesh of 20-node
/// hexahedra), written as a .inp deck, solved by the `ccx` program, and read back.
#include <pointhaptics/core/parameters.hpp>
#include <pointhaptics/core/types.hpp>

#include <pointhaptics/core/error.hpp>

#include <filesystem>
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

namespace pointhaptics::fem {

/// An axis-aligned box (faces included).
struct Box {
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();
  bool contains(const Vec3& p, double tol) const {
    return (p.array() >= min.array() - tol).all() && (p.array() <= max.array() + tol).all();
  }
};

/// A total force spread as a uniform traction over the mesh's boundary faces that lie inside `region`
/// (as consistent nodal forces of the quadratic faces: corners -1/12, mid-sides +1/3 of a face's share).
struct Traction {
  Box region;
  Vec3 total = Vec3::Zero();  ///< N
};

/// Nodes moved by a prescribed displacement (all three components), ramped in over the step: those in
/// `region` and, when radius > 0, within `radius` of `centre` measured across `axis` (a punch's footprint).
/// The total reaction force on them is printed at every increment (Solution::reactions).
struct Prescribed {
  Box region;
  Vec3 centre = Vec3::Zero(), axis = Vec3::UnitY();
  double radius = 0;                 ///< m; 0: the whole box
  Vec3 displacement = Vec3::Zero();  ///< m, at the end of the step

  bool holds(const Vec3& p, double tol) const {
    if (!region.contains(p, tol)) return false;
    if (radius <= 0) return true;
    const Vec3 d = p - centre;
    return (d - d.dot(axis) * axis).norm() <= radius + tol;
  }
};

/// A plane of mirror symmetry: the nodes on X[axis] = at hold that component of their displacement (zero), so
/// that a quarter or half of a symmetric problem gives the whole one's solution at a fraction of the cost.
struct Symmetry {
  int axis = 0;   ///< 0, 1, 2: x, y, z
  double at = 0;  ///< m
};

/// The constitutive card: *ELASTIC (St. Venant-Kirchhoff with NLGEOM), or *HYPERELASTIC NEO HOOKE
/// (W = C10 (I1bar - 3) + (J - 1)^2 / D1) or MOONEY-RIVLIN (+ C01 (I2bar - 3)).
enum class FemMaterial { ELASTIC, NEO_HOOKE, MOONEY_RIVLIN };

/// A ball of another material (a stiff nodule): the elements whose centre lies inside take it.
struct Inclusion {
  Vec3 centre = Vec3::Zero();
  double radius = 0;        ///< m
  MaterialParams material;  ///< its model and moduli (set_material's mapping)
};

/// A box body [origin, origin + size] meshed with nx x ny x nz quadratic hexahedra.
struct BoxProblem {
  Vec3 origin = Vec3::Zero();
  Vec3 size = Vec3(0.15, 0.03, 0.03);  ///< m
  int nx = 20, ny = 4, nz = 4;         ///< elements per direction
  double young = 1e5, poisson = 0.4, density = 1000.0;
  std::vector<Box> clamps;  ///< nodes inside are held (all three components)
  std::vector<Traction> tractions;
  std::vector<Prescribed> prescribed;  ///< moved nodes (after the clamps: a node in both is held)
  std::vector<Symmetry> symmetry;      ///< mirror planes (their nodes not held or moved otherwise)
  Vec3 gravity = Vec3::Zero();         ///< m/s^2
  FemMaterial material = FemMaterial::ELASTIC;
  double c10 = 0, c01 = 0, d1 = 0;  ///< hyperelastic constants (Pa, Pa, 1/Pa)
  /// NLGEOM increments: 0 lets ccx choose them (from 5% of the step); n > 0: n fixed increments of 1/n (the
  /// reactions are then printed at each 1/n of the step)
  int fixed_increments = 0;
  std::vector<Inclusion> inclusions;  ///< later ones win where they overlap
  bool nlgeom = false;                ///< geometrically nonlinear (*ELASTIC is then St. Venant-Kirchhoff)
  bool reduced_integration = true;    ///< C3D20R, else C3D20
};

/// The material card's constants for one of our materials: St. Venant-Kirchhoff as *ELASTIC (young,
/// poisson), neo-Hookean as NEO HOOKE with C10 = mu / 2, D1 = 2 / K, Mooney-Rivlin as MOONEY-RIVLIN with its
/// C10, C01 and D1 = 2 / K (mechanics/energies/). Throws Error for a model CalculiX does not have (corotated).
void set_material(BoxProblem& problem, const MaterialParams& material);

/// The total reaction force on one Prescribed set at one step time (0..1].
struct Reaction {
  double time = 0;
  Vec3 force = Vec3::Zero();  ///< N: what the moving nodes exert on the body is minus this
};

/// Nodes of the structured mesh and a displacement per node.
struct Solution {
  Points nodes;         ///< reference positions (3 x n_nodes), node k has CalculiX id k + 1
  Points displacement;  ///< (3 x n_nodes), m
  /// per Prescribed set, the reaction totals at every printed increment, in time order
  std::vector<std::vector<Reaction>> reactions;
  double wall_s = 0;  ///< ccx run time, s
  /// solve(..., partial = true) of a run ccx stopped (e.g. diverged): why, and the reactions are those of the
  /// increments it finished (displacements empty); empty for a complete run
  std::string failure;
};

/// The mesh's node positions, in id order (id = column + 1).
Points mesh_nodes(const BoxProblem& problem);
/// The complete input deck. Throws Error when the problem is malformed (no clamp, a traction region
/// that holds no boundary face, a symmetry plane with no node, non-positive sizes).
std::string write_inp(const BoxProblem& problem);
/// Displacements of nodes 1..n_nodes from the text of a ccx .dat file (the last "displacements" block
/// of *NODE PRINT). Throws Error naming `source` on a missing block, a missing or repeated node, a
/// malformed line or a non-finite value.
Points read_dat_displacements(std::istream& dat, index_t n_nodes, const std::string& source);
/// The "total force" blocks of *NODE PRINT, TOTALS=ONLY for the set named `set` (upper case), in file order.
/// Throws Error naming `source` on a malformed block.
std::vector<Reaction> read_dat_totals(std::istream& dat, const std::string& set, const std::string& source);
/// The displacement of the first node of the set named `set` (upper case) in every "displacements" block of *NODE
/// PRINT for that set, with its step time, in file order. Throws Error naming `source` on a malformed block.
std::vector<std::pair<double, Vec3>> read_dat_set_displacements(std::istream& dat, const std::string& set,
                                                                const std::string& source);
/// *MATERIAL, NAME=name with the problem's constitutive card and density (13 significant digits: they fit ccx's
/// 20-character fields).
std::string material_card(const std::string& name, const BoxProblem& problem);
/// The `ccx` program: $PH_CCX if set, else `ccx` on PATH; throws Error saying how to install it if absent.
std::string find_ccx();
/// A deck run by ccx in a fresh temporary folder (job.inp, job.dat, ccx.log).
struct CcxRun {
  std::filesystem::path dir;
  int status = 0;  ///< ccx's exit status
  double wall_s = 0;
  /// An error naming the folder (kept for a look), `what` went wrong and the end of ccx.log.
  Error failure(const std::string& what) const;
  void remove() const;
};
/// Write `deck` into a fresh temporary folder and run ccx there with `threads` threads.
CcxRun run_ccx(const std::string& deck, int threads);
/// Write the deck into a fresh temporary folder, run ccx there (threads = OMP_NUM_THREADS), read the
/// displacements, remove the folder (kept, and named in the error, when ccx fails). `partial`: a run ccx
/// stopped returns the reactions of the increments it finished, with Solution::failure, instead of throwing.
Solution solve(const BoxProblem& problem, int threads = 1, bool partial = false);

}  // namespace pointhaptics::fem
