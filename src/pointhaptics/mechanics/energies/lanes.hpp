#pragma once
/// @file Matrix3<T>: a 3x3 matrix over a double or over Lanes, four points' values in one SIMD register, so
/// that a material writes its stress once and the force loop evaluates it for four points at a time.
/// Vectorising across points is what pays for the hyperelastic models: a point's 3x3 algebra is too small
/// for SIMD within it, and the force loop's gradients are already in registers when the stress is formed
/// (the gathers that made vectorising across the pairs of a stencil lose, docs/performance.md, are not
/// needed: four gradients are 36 loads).
///
/// GCC builds without AVX (the sanitizer presets) warn that Lanes in a signature change the ABI; everything
/// here is inline and never crosses a library boundary. No pop: GCC warns for always-inlined functions at
/// the end of the translation unit (as stencil_loop.hpp).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
#include <pointhaptics/core/types.hpp>

#include <cmath>
#include <cstring>
#include <type_traits>
#include <utility>

namespace pointhaptics {

#if !defined(__GNUC__)
#error "lanes.hpp uses GCC/Clang vector extensions"
#endif
/// Four doubles, one per point (or x, y, z and a zero pad in the stencil loop); arithmetic with a double
/// broadcasts it.
typedef double Lanes __attribute__((vector_size(4 * sizeof(double))));
/// The result of comparing Lanes: all bits set in the lanes where the comparison holds.
using LaneMask = decltype(Lanes{} < Lanes{});
inline constexpr int lane_count = 4;

PH_ALWAYS_INLINE inline bool any_lane(const LaneMask& mask) {
  for (int k = 0; k < lane_count; ++k)
    if (mask[k]) return true;
  return false;
}
/// Where `mask` holds, `if_true`, else `if_false`: for one point (a bool) or lane by lane.
PH_ALWAYS_INLINE inline double where(bool mask, double if_true, double if_false) { return mask ? if_true : if_false; }
PH_ALWAYS_INLINE inline Lanes where(const LaneMask& mask, const Lanes& if_true, const Lanes& if_false) {
  return mask ? if_true : if_false;
}
PH_ALWAYS_INLINE inline bool none(bool mask) { return !mask; }
PH_ALWAYS_INLINE inline bool none(const LaneMask& mask) { return !any_lane(mask); }
/// What comparing two T gives: a bool for a double, a LaneMask for Lanes.
template <class T>
using MaskOf = decltype(std::declval<T>() < std::declval<T>());

/// A 3x3 matrix of T, by columns as Eigen's Mat3 (entry (r, c) is m[r + 3 c]).
template <class T>
struct Matrix3 {
  T m[9];
  PH_ALWAYS_INLINE T& operator()(int r, int c) { return m[r + 3 * c]; }
  PH_ALWAYS_INLINE const T& operator()(int r, int c) const { return m[r + 3 * c]; }
};

/// A double or the matrix's own scalar: what scales a Matrix3<T>.
template <class S, class T>
concept ScalarOf = std::is_same_v<S, T> || std::is_same_v<S, double>;

PH_ALWAYS_INLINE inline Matrix3<double> to_matrix3(const Mat3& A) {
  Matrix3<double> M;
  std::memcpy(M.m, A.data(), sizeof M.m);
  return M;
}
PH_ALWAYS_INLINE inline Mat3 to_eigen(const Matrix3<double>& M) {
  Mat3 A;
  std::memcpy(A.data(), M.m, sizeof M.m);
  return A;
}

template <class T>
PH_ALWAYS_INLINE inline Matrix3<T> operator+(const Matrix3<T>& a, const Matrix3<T>& b) {
  Matrix3<T> r;
  for (int k = 0; k < 9; ++k) r.m[k] = a.m[k] + b.m[k];
  return r;
}
template <class T>
PH_ALWAYS_INLINE inline Matrix3<T> operator-(const Matrix3<T>& a, const Matrix3<T>& b) {
  Matrix3<T> r;
  for (int k = 0; k < 9; ++k) r.m[k] = a.m[k] - b.m[k];
  return r;
}
template <class T, ScalarOf<T> S>
PH_ALWAYS_INLINE inline Matrix3<T> operator*(const S& s, const Matrix3<T>& a) {
  Matrix3<T> r;
  for (int k = 0; k < 9; ++k) r.m[k] = s * a.m[k];
  return r;
}
template <class T>
PH_ALWAYS_INLINE inline Matrix3<T> operator*(const Matrix3<T>& a, const Matrix3<T>& b) {
  Matrix3<T> r;
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i) r(i, c) = a(i, 0) * b(0, c) + a(i, 1) * b(1, c) + a(i, 2) * b(2, c);
  return r;
}
template <class T>
PH_ALWAYS_INLINE inline T trace(const Matrix3<T>& a) {
  return a.m[0] + a.m[4] + a.m[8];
}
/// a + s I.
template <class T, ScalarOf<T> S>
PH_ALWAYS_INLINE inline Matrix3<T> plus_identity(Matrix3<T> a, const S& s) {
  a.m[0] += s, a.m[4] += s, a.m[8] += s;
  return a;
}
/// The deviatoric part.
template <class T>
PH_ALWAYS_INLINE inline Matrix3<T> deviator(const Matrix3<T>& a) {
  return plus_identity(a, T(-trace(a) / 3.0));
}
/// Green strain E = 0.5 (G + G^T + G^T G), formed from G (deformation.hpp's green_strain).
template <class T>
PH_ALWAYS_INLINE inline Matrix3<T> green_strain(const Matrix3<T>& G) {
  Matrix3<T> E;
  for (int c = 0; c < 3; ++c)
    for (int r = c; r < 3; ++r)
      E(r, c) = E(c, r) = 0.5 * (G(r, c) + G(c, r) + G(0, r) * G(0, c) + G(1, r) * G(1, c) + G(2, r) * G(2, c));
  return E;
}
/// cof F: rows are the cross products of F's rows (deformation.hpp's cofactor).
template <class T>
PH_ALWAYS_INLINE inline Matrix3<T> cofactor(const Matrix3<T>& F) {
  Matrix3<T> C;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    C(a, 0) = F(b, 1) * F(c, 2) - F(b, 2) * F(c, 1);
    C(a, 1) = F(b, 2) * F(c, 0) - F(b, 0) * F(c, 2);
    C(a, 2) = F(b, 0) * F(c, 1) - F(b, 1) * F(c, 0);
  }
  return C;
}
/// det F from its cofactor (row 0 of F against row 0 of cof F).
template <class T>
PH_ALWAYS_INLINE inline T determinant(const Matrix3<T>& F, const Matrix3<T>& cof) {
  return F(0, 0) * cof(0, 0) + F(0, 1) * cof(0, 1) + F(0, 2) * cof(0, 2);
}
/// J - 1 = det(I + G) - 1 = tr G + I2(G) + det G, written in G (hessian.hpp's volume_change).
template <class T>
PH_ALWAYS_INLINE inline T volume_change(const Matrix3<T>& G) {
  const T t = trace(G);
  const T trace_of_square = G(0, 0) * G(0, 0) + G(1, 1) * G(1, 1) + G(2, 2) * G(2, 2) +
                            2 * (G(0, 1) * G(1, 0) + G(0, 2) * G(2, 0) + G(1, 2) * G(2, 1));
  return t + 0.5 * (t * t - trace_of_square) + determinant(G, cofactor(G));
}
/// S^2 of a symmetric S from its six distinct entries (18 products instead of 27).
template <class T>
PH_ALWAYS_INLINE inline Matrix3<T> symmetric_square(const Matrix3<T>& S) {
  const T a = S(0, 0), b = S(1, 1), c = S(2, 2), d = S(1, 2), e = S(0, 2), f = S(0, 1);
  Matrix3<T> Q;
  Q(0, 0) = a * a + f * f + e * e;
  Q(1, 1) = f * f + b * b + d * d;
  Q(2, 2) = e * e + d * d + c * c;
  Q(0, 1) = Q(1, 0) = a * f + f * b + e * d;
  Q(0, 2) = Q(2, 0) = a * e + f * d + e * c;
  Q(1, 2) = Q(2, 1) = f * e + b * d + d * c;
  return Q;
}
template <class T>
PH_ALWAYS_INLINE inline Matrix3<T> where(const MaskOf<T>& mask, const Matrix3<T>& if_true, const Matrix3<T>& if_false) {
  Matrix3<T> r;
  for (int k = 0; k < 9; ++k) r.m[k] = where(mask, if_true.m[k], if_false.m[k]);
  return r;
}
/// sum_ab A_ab B_ab = tr(A^T B).
template <class T>
PH_ALWAYS_INLINE inline T inner(const Matrix3<T>& a, const Matrix3<T>& b) {
  T r = a.m[0] * b.m[0];
  for (int k = 1; k < 9; ++k) r += a.m[k] * b.m[k];
  return r;
}
/// The largest |entry|.
PH_ALWAYS_INLINE inline double max_abs(const Matrix3<double>& a) {
  double r = 0;
  for (int k = 0; k < 9; ++k) r = std::max(r, std::abs(a.m[k]));
  return r;
}
PH_ALWAYS_INLINE inline Lanes max_abs(const Matrix3<Lanes>& a) {
  Lanes r = {};
  for (int k = 0; k < 9; ++k) {
    const Lanes v = a.m[k] < 0 ? -a.m[k] : a.m[k];
    r = v > r ? v : r;
  }
  return r;
}

/// sqrt, |x| and max for one point or lane by lane (the lanes' sqrt is one vector instruction).
PH_ALWAYS_INLINE inline double square_root(double x) { return std::sqrt(x); }
PH_ALWAYS_INLINE inline Lanes square_root(const Lanes& x) {
  Lanes r;
  for (int k = 0; k < lane_count; ++k) r[k] = __builtin_sqrt(x[k]);
  return r;
}
template <class T>
PH_ALWAYS_INLINE inline T absolute(const T& x) {
  return where(x < 0, T(-x), x);
}
template <class T>
PH_ALWAYS_INLINE inline T larger(const T& a, const T& b) {
  return where(a < b, b, a);
}

/// The four points i .. i + count - 1 (count <= 4) of gradients stored by columns with a pad (12 doubles a
/// point, Workspace::gradients); lanes past `count` stay zero, a rest state.
PH_ALWAYS_INLINE inline Matrix3<Lanes> four_gradients(const double* padded_gradients, std::ptrdiff_t i, int count) {
  Matrix3<Lanes> G{};
  for (int p = 0; p < count; ++p) {
    const double* g = padded_gradients + 12 * (i + p);
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) G.m[r + 3 * c][p] = g[4 * c + r];
  }
  return G;
}

/// J^-1/3 for J > 0.
PH_ALWAYS_INLINE inline double inverse_cube_root(double J) { return 1 / std::cbrt(J); }
/// J^-1/3 in each lane (J > 0), to a few ulps, without a division or a call: a quartic in J - 1 (relative
/// error 2.7e-3 on [0.5, 2]; an exact start outside, lane by lane) and three Newton steps y <- y (4 - J y^3) / 3,
/// each squaring the error (1.5e-5, 4.5e-10, 4e-16). std::cbrt lane by lane cost as much as the rest of a
/// neo-Hookean stress.
PH_ALWAYS_INLINE inline Lanes inverse_cube_root(const Lanes& J) {
  const Lanes x = J - 1;
  Lanes y =
      0.99931112135651146 +
      x * (-0.33390365079123296 + x * (0.24391399229695226 + x * (-0.19397435934763865 + x * 0.079520639421947842)));
  const LaneMask outside = (J < 0.5) | (J > 2.0);
  if (any_lane(outside)) [[unlikely]]
    for (int k = 0; k < lane_count; ++k)
      if (outside[k]) y[k] = inverse_cube_root(J[k]);
  for (int step = 0; step < 3; ++step) y = y * (4 - J * (y * y * y)) * (1.0 / 3.0);
  return y;
}

}  // namespace pointhaptics
