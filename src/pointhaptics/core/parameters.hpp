#pragma once
/// @file Plain parameter structs: material, kernel and volume choices (all SI units).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pointhaptics {

/// Weighting kernels of the seed paper.
enum class KernelType {
  POLY6,      ///< seed Eq. 3
  SPIKY,      ///< seed Eq. 4
  VISCOSITY,  ///< seed Eq. 5
  QUADRATIC,  ///< seed Eq. 6 (with r^2/h^2)
};

/// How point volumes are obtained.
enum class VolumeMode {
  CELL,    ///< tributary cell volume of the sampling (default; volumes sum to the body's volume)
  KERNEL,  ///< the seed's m_i = total mass / N, rho_i = sum_j m_j w_ij (Eq. 7), v_i = m_i / rho_i (Eq. 8)
};

/// The constitutive models (mechanics/energies/: one file each, and a line in material.hpp's registry).
enum class MaterialModel {
  SVK,            ///< St. Venant-Kirchhoff, the seed's (Green strain, seed Eq. 2)
  NEO_HOOKEAN,    ///< compressible neo-Hookean, CalculiX's NEO HOOKE (energies/neo_hookean.hpp)
  MOONEY_RIVLIN,  ///< compressible Mooney-Rivlin, CalculiX's MOONEY-RIVLIN (energies/mooney_rivlin.hpp)
  COROTATED,      ///< linear corotated (energies/corotated.hpp)
};

/// One term of a Prony series: the share g of the instantaneous shear stiffness that relaxes with time
/// constant tau (mechanics/viscoelasticity.hpp).
struct PronyTerm {
  double g = 0;    ///< relaxing share of the shear modulus, in (0, 1); the terms' sum stays below 1
  double tau = 1;  ///< relaxation time, s
};

struct MaterialParams {
  MaterialModel model = MaterialModel::SVK;
  double young = 1e5;             ///< Young's modulus E, Pa
  double poisson = 0.4;           ///< Poisson ratio nu, in (-1, 0.5)
  double density = 1000.0;        ///< rho, kg/m^3
  double volume_stiffness = 0.0;  ///< k_v of the volume term 0.5 k_v v (det F - 1)^2, Pa
  double damping = 0.0;           ///< mass-proportional damping, 1/s
  double hourglass =
      0.3;  ///< alpha of the zero-energy-mode penalty (averaged-gradient form, docs/mechanics.md); 0: off
  VolumeMode volume = VolumeMode::CELL;
  /// Mooney-Rivlin's split of the shear modulus mu = 2 (c10 + c01), Pa: when given (the scene's c10, c01 and
  /// bulk), young and poisson are set from them; otherwise both are mu / 4
  double c10 = 0, c01 = 0;
  /// Viscoelasticity: the Prony series of the deviatoric (shear) part, the object's for all its points.
  /// young and poisson are then the instantaneous moduli; the long-term shear modulus is mu (1 - sum g).
  std::vector<PronyTerm> prony;

  /// sum_k g_k of the Prony series (0: elastic).
  double prony_total() const {
    double g = 0;
    for (const PronyTerm& t : prony) g += t.g;
    return g;
  }
  /// Lame's first parameter lambda = E nu / ((1 + nu)(1 - 2 nu)), Pa.
  double lambda() const { return young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)); }
  /// Shear modulus mu = E / (2 (1 + nu)), Pa.
  double mu() const { return young / (2.0 * (1.0 + poisson)); }
  /// Bulk modulus K = E / (3 (1 - 2 nu)), Pa.
  double bulk_modulus() const { return young / (3.0 * (1.0 - 2.0 * poisson)); }
  /// P-wave speed sqrt((lambda + 2 mu + k_v) / rho), m/s: sets the explicit stable step.
  double p_wave_speed() const;
};

/// The most terms a Prony series may have.
inline constexpr std::size_t max_prony_terms = 8;
/// What a Prony series must be (scene files and Python say it the same way).
inline constexpr const char* prony_rule =
    "expected [[g, tau], ...] with 1 to 8 terms, each g in (0, 1) and tau in [1e-6, 1e6] s, the g summing below 1";
/// Whether `series` follows prony_rule.
bool valid_prony(const std::vector<PronyTerm>& series);

struct KernelParams {
  KernelType type = KernelType::POLY6;
  double support_factor = 2.0;  ///< h = support_factor * spacing, unless `support` is set
  double support = 0.0;         ///< h in m; 0 means "use support_factor"
};

/// How points in the thinned bands are chosen (design.md, "Levels of detail").
enum class LodScheme {
  RANDOM,  ///< the seed's: a uniform draw Ran in [0, 10) per point (seeded; a point keeps its draw)
  DITHER,  ///< ours: Ran from a 4x4x4 ordered-dither matrix over the sampling lattice, so that every band's
           ///< selected points are spread evenly (same weights as the seed's, no clusters or holes)
};

/// A propagation level: the points with P_(i-1) < d <= P_i are selected with probability (10 - K) / 10.
struct LodLevel {
  double distance = 2.5;  ///< P_i, in units of h, increasing with i and beyond k2
  int K = 6;              ///< in [0, 10], non-decreasing with i
};

/// Levels of detail (seed §3): which points are simulated around the contact point, and how.
struct LodParams {
  double k1 = 1.0;               ///< T_r1 = k1 h: every point within is selected
  double k2 = 1.5;               ///< T_r2 = k2 h: points within (T_r1, T_r2] are selected if Ran > 2
  std::vector<LodLevel> levels;  ///< propagation levels beyond T_r2 (none: nothing beyond T_r2)
  std::uint64_t seed = 1;        ///< of the random generator, so that runs are reproducible
  LodScheme scheme = LodScheme::RANDOM;
  double reselect = 0.5;  ///< re-select when the contact point moved farther than this (units of h)
  /// no re-selection sooner than this after the last one (s of simulated time; contact onset excepted): a
  /// take-over is a small shock, and a slow real-time session that re-selected every few milliseconds
  /// diverged (issue 21)
  double reselect_interval = 0.05;
  int min_neighbours = 12;    ///< a selected point's support widens until it reaches this many points
                              ///< (or as many as it had in the full model, if fewer) ...
  double max_widening = 3.0;  ///< ... but never beyond this multiple of h
};

enum class SolverKind { STATIC, EXPLICIT, IMPLICIT };

/// What preconditions Newton's conjugate gradients (static and implicit solvers).
enum class Preconditioner {
  BLOCK_JACOBI,  ///< the tangent's inverted 3x3 diagonal blocks: cheap, many iterations on stiff problems
  CHOLESKY,      ///< a sparse Cholesky factor of the assembled tangent, reused across iterations and steps
                 ///< while CG converges in few iterations (lagged), refactorised when it no longer does
  TWO_LEVEL,     ///< block-Jacobi plus a coarse model's factorised correction (every other point, twice the
                 ///< spacing): the smooth, global modes in a few iterations; lags like block-Jacobi
};

/// Where the Cholesky preconditioner's refactorisations run once its first factor is made (that one always
/// in place: there is nothing to precondition with before it).
enum class Refactorisation {
  AUTO,        ///< in the background in real-time sessions (a probe on the wall clock), else in place
  IN_PLACE,    ///< on the simulation's thread, within the step that needs it
  BACKGROUND,  ///< on a worker thread while the old factor serves: taken up as soon as it is ready in real
               ///< time, at the next step's start otherwise (waiting for it there, so a run is reproducible)
};

/// [reduction]: the object stepped in a reduced basis of `modes` vectors (issue 49; docs/reduction.md): linear
/// vibration modes, their modal derivatives and the loads' static responses (reduction/modal_basis.hpp), St.
/// Venant-Kirchhoff's reduced energy as an exact polynomial (reduction/svk_polynomial.hpp).
struct ReductionSpec {
  int modes = 0;             ///< r; 0: the full model
  double basis_spacing = 0;  ///< m: the basis made on a sampling this coarse and carried to the points (0: on them)
  /// the folder the basis is kept in and read back from (reduction/basis_cache.hpp): "auto" for the user's cache
  /// folder, empty for none (a scene's default is "auto")
  std::string cache;
  /// a tool's contact region in full resolution (reduction/contact_patch.hpp): the points the tools act on grown by
  /// this many neighbour rings
  int contact_rings = 3;
  int line = 0;  ///< the table's line in the scene file (0: none), for errors
};

/// [solver]: which solver advances the object, and how far.
struct SolverSpec {
  SolverKind kind = SolverKind::EXPLICIT;
  double dt = 1e-3;              ///< s
  double duration = 1.0;         ///< s
  double tolerance = 0;          ///< static, implicit: relative residual; 0 = default (1e-8 static, 1e-6 implicit)
  int max_iterations = 50;       ///< static, implicit: Newton iterations per solve
  int max_cg_iterations = 2000;  ///< static, implicit: CG iterations per Newton iteration
  int iteration_budget = 0;      ///< implicit: Newton iterations per step in real time, keeping the iterate (0 = off)
  Preconditioner preconditioner = Preconditioner::BLOCK_JACOBI;  ///< static, implicit
  int refactor_iterations = 8;  ///< cholesky: refactorise after a CG solve of more iterations than this
  Refactorisation refactorisation = Refactorisation::AUTO;  ///< cholesky: where refactorisations run
  /// explicit, several bodies: a body at rest that nothing touches sleeps (its stencils are not evaluated, its
  /// points not moved) until something touches it (world/model_simulation.hpp)
  bool sleep = true;
  ReductionSpec reduction{};  ///< [reduction]: static and implicit solves in a reduced basis
};

/// The one table per enum of the names the scene file, the command line and Python use: to_string(),
/// parse_enum() and enum_choices() all read it, so a new value is one new line here.
template <class E>
struct EnumNames;
template <>
struct EnumNames<KernelType> {
  static constexpr std::array<std::pair<KernelType, std::string_view>, 4> table{{{KernelType::POLY6, "poly6"},
                                                                                 {KernelType::SPIKY, "spiky"},
                                                                                 {KernelType::VISCOSITY, "viscosity"},
                                                                                 {KernelType::QUADRATIC, "quadratic"}}};
};
template <>
struct EnumNames<MaterialModel> {
  static constexpr std::array<std::pair<MaterialModel, std::string_view>, 4> table{
      {{MaterialModel::SVK, "svk"},
       {MaterialModel::NEO_HOOKEAN, "neo_hookean"},
       {MaterialModel::MOONEY_RIVLIN, "mooney_rivlin"},
       {MaterialModel::COROTATED, "corotated"}}};
};
template <>
struct EnumNames<VolumeMode> {
  static constexpr std::array<std::pair<VolumeMode, std::string_view>, 2> table{
      {{VolumeMode::CELL, "cell"}, {VolumeMode::KERNEL, "kernel"}}};
};
template <>
struct EnumNames<LodScheme> {
  static constexpr std::array<std::pair<LodScheme, std::string_view>, 2> table{
      {{LodScheme::RANDOM, "random"}, {LodScheme::DITHER, "dither"}}};
};
template <>
struct EnumNames<Preconditioner> {
  static constexpr std::array<std::pair<Preconditioner, std::string_view>, 3> table{
      {{Preconditioner::BLOCK_JACOBI, "block_jacobi"},
       {Preconditioner::CHOLESKY, "cholesky"},
       {Preconditioner::TWO_LEVEL, "two_level"}}};
};
template <>
struct EnumNames<Refactorisation> {
  static constexpr std::array<std::pair<Refactorisation, std::string_view>, 3> table{
      {{Refactorisation::AUTO, "auto"},
       {Refactorisation::IN_PLACE, "in_place"},
       {Refactorisation::BACKGROUND, "background"}}};
};
template <>
struct EnumNames<SolverKind> {
  static constexpr std::array<std::pair<SolverKind, std::string_view>, 3> table{
      {{SolverKind::STATIC, "static"}, {SolverKind::EXPLICIT, "explicit"}, {SolverKind::IMPLICIT, "implicit"}}};
};

/// The name of an enum value ("?" for a value outside the table).
template <class E>
constexpr std::string_view enum_name(E value) {
  for (const auto& [v, name] : EnumNames<E>::table)
    if (v == value) return name;
  return "?";
}
/// The value of a name, if it is one.
template <class E>
std::optional<E> parse_enum(std::string_view name) {
  for (const auto& [v, n] : EnumNames<E>::table)
    if (n == name) return v;
  return std::nullopt;
}
/// "a | b | c": the names, for messages.
template <class E>
std::string enum_choices() {
  std::string list;
  for (const auto& [v, name] : EnumNames<E>::table) list += (list.empty() ? "" : " | ") + std::string(name);
  return list;
}

inline std::string_view to_string(KernelType type) { return enum_name(type); }
inline std::string_view to_string(LodScheme scheme) { return enum_name(scheme); }
inline std::string_view to_string(VolumeMode mode) { return enum_name(mode); }
inline std::string_view to_string(MaterialModel model) { return enum_name(model); }
inline std::string_view to_string(SolverKind kind) { return enum_name(kind); }

}  // namespace pointhaptics
