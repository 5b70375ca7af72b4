#pragma once
/// @file CalculiX adapter: an independent FEM solution of a box-shaped body (structured mesh of 20-node
/// hexahedra), written as a .inp deck, solved by the `ccx` program, and read back.
#include <pointhaptics/core/types.hpp>

#include <iosfwd>
#include <string>
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

/// A box body [origin, origin + size] meshed with nx x ny x nz quadratic hexahedra.
struct BoxProblem {
  Vec3 origin = Vec3::Zero();
  Vec3 size = Vec3(0.15, 0.03, 0.03);  ///< m
  int nx = 20, ny = 4, nz = 4;          ///< elements per direction
  double young = 1e5, poisson = 0.4, density = 1000.0;
  std::vector<Box> clamps;              ///< nodes inside are held (all three components)
  std::vector<Traction> tractions;
  Vec3 gravity = Vec3::Zero();          ///< m/s^2
  bool nlgeom = false;                  ///< geometrically nonlinear (*ELASTIC is then St. Venant-Kirchhoff)
  bool reduced_integration = true;      ///< C3D20R, else C3D20
};

/// Nodes of the structured mesh and a displacement per node.
struct Solution {
  Points nodes;         ///< reference positions (3 x n_nodes), node k has CalculiX id k + 1
  Points displacement;  ///< (3 x n_nodes), m
  double wall_s = 0;    ///< ccx run time, s
};

/// The mesh's node positions, in id order (id = column + 1).
Points mesh_nodes(const BoxProblem& problem);
/// The complete input deck. Throws Error when the problem is malformed (no clamp, a traction region
/// that holds no boundary face, non-positive sizes).
std::string write_inp(const BoxProblem& problem);
/// Displacements of nodes 1..n_nodes from the text of a ccx .dat file (the last "displacements" block
/// of *NODE PRINT). Throws Error naming `source` on a missing block, a missing or repeated node, a
/// malformed line or a non-finite value.
Points read_dat_displacements(std::istream& dat, index_t n_nodes, const std::string& source);
/// The `ccx` program: $PH_CCX if set, else `ccx` on PATH; throws Error saying how to install it if absent.
std::string find_ccx();
/// Write the deck into a fresh temporary folder, run ccx there (threads = OMP_NUM_THREADS), read the
/// displacements, remove the folder (kept, and named in the error, when ccx fails).
Solution solve(const BoxProblem& problem, int threads = 1);

}  // namespace pointhaptics::fem
