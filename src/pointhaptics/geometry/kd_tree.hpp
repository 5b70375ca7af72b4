#pragma once
/// @file A nanoflann k-d tree over the columns of a 3 x n matrix (internal to the geometry module).
#include <pointhaptics/core/types.hpp>

#include <nanoflann.hpp>

namespace pointhaptics {

/// nanoflann's dataset interface over a 3 x n column-major matrix.
struct PointsAdaptor {
  const Points& X;
  size_t kdtree_get_point_count() const { return static_cast<size_t>(X.cols()); }
  double kdtree_get_pt(size_t i, size_t dim) const {
    return X(static_cast<Eigen::Index>(dim), static_cast<Eigen::Index>(i));
  }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};

/// A k-d tree over the points, built on construction; `X` must outlive it.
class KdTree {
 public:
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>, PointsAdaptor,
                                                    3, index_t>;
  explicit KdTree(const Points& X) : adaptor_{X}, index_(3, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {}
  KdTree(const KdTree&) = delete;
  KdTree& operator=(const KdTree&) = delete;

  const Index& index() const { return index_; }

 private:
  PointsAdaptor adaptor_;  // declared before index_, which reads it while building
  Index index_;
};

}  // namespace pointhaptics
