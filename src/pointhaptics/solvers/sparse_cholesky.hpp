#pragma once
/// @file A sparse Cholesky factorisation of an assembled tangent over the free points (SuiteSparse CHOLMOD,
/// supernodal): the fill-reducing ordering and symbolic factor once per model, the numeric factor whenever
/// the caller asks (Newton reuses it over many steps as a preconditioner: a "lagged" factorisation).
#include <pointhaptics/mechanics/tangent_matrix.hpp>

#include <memory>

namespace pointhaptics {

struct CholeskyStats {
  double factor_nonzeros = 0;  ///< entries of L
  double factor_bytes = 0;     ///< L's values and indices, bytes
  double analyse_s = 0;        ///< the ordering and symbolic factor, s
  double factorise_s = 0;      ///< the last numeric factorisation, s
  long long factorisations = 0;
};

class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;

  /// Order and analyse K's pattern over the points that are not held (Model::fixed). Call again when the model
  /// (its points, stencils or held points) changes.
  void analyse(const Model& model, const TangentMatrix& K);
  /// The model analyse() was called for (its address, points, pairs and free points), else false.
  bool analysed_for(const Model& model) const;
  /// Factorise K with its current values: false when K is not positive definite over the free points (then
  /// there is no factor until the next successful call).
  bool factorise(const TangentMatrix& K);
  bool factorised() const;
  /// z = K^-1 r on the free points (after a successful factorise()), zero at held points. Allocates only on the
  /// first call after analyse().
  void solve(const Points& r, Points& z);
  const CholeskyStats& stats() const { return stats_; }

 private:
  struct Factor;  // CHOLMOD's objects, kept out of this header
  std::unique_ptr<Factor> factor_;
  CholeskyStats stats_;
};

}  // namespace pointhaptics
