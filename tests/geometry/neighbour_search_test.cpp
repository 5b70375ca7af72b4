// Tests for geometry/neighbour_search.
#include <pointhaptics/geometry/neighbour_search.hpp>
#include <pointhaptics/geometry/sampling.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

void expect_same(const Csr& a, const Csr& b) {
  ASSERT_EQ(a.offset, b.offset);
  ASSERT_EQ(a.index, b.index);
}

TEST(RadiusNeighbours, MatchesBruteForceOnRandomPoints) {
  const Points X = test::random_field(1500, 0.05, 11);
  for (double h : {0.005, 0.02, 0.06}) expect_same(radius_neighbours(X, h), radius_neighbours_brute_force(X, h));
}

TEST(RadiusNeighbours, MatchesBruteForceOnAGrid) {
  const PointCloud c = sample_box(Vec3(0.3, -0.1, 0.7), Vec3(0.1, 0.05, 0.04), 0.005);
  for (double factor : {1.5, 2.0, 2.5, 3.0}) {
    const Csr a = radius_neighbours(c.X, factor * 0.005);
    expect_same(a, radius_neighbours_brute_force(c.X, factor * 0.005));
  }
}

TEST(RadiusNeighbours, PerPointSupportsAreSymmetricAndMatchBruteForce) {
  // supports from h to 3h: i and j are neighbours when max(h_i, h_j) reaches
  const Points X = test::random_field(1200, 0.05, 4);
  Eigen::VectorXd support(X.cols());
  for (Eigen::Index i = 0; i < X.cols(); ++i) support[i] = 0.01 * (1.0 + 2.0 * (i % 7) / 6.0);
  const Csr a = radius_neighbours(X, support);
  std::vector<index_t> offset{0}, index;
  for (index_t i = 0; i < X.cols(); ++i) {
    for (index_t j = 0; j < X.cols(); ++j)
      if (j != i && within_support((X.col(j) - X.col(i)).squaredNorm(), std::max(support[i], support[j])))
        index.push_back(j);
    offset.push_back(static_cast<index_t>(index.size()));
  }
  EXPECT_EQ(a.offset, offset);
  EXPECT_EQ(a.index, index);
}

TEST(RadiusNeighbours, GridStencilAtTwiceTheSpacingHas26Points) {
  // points exactly h apart are not neighbours (every kernel is zero there), whatever the round-off
  const PointCloud c = sample_box(Vec3(0.013, 0.0, 0.0), Vec3::Constant(0.06), 0.0075);
  const Csr nbr = radius_neighbours(c.X, 2 * 0.0075);
  index_t max_row = 0;
  for (index_t i = 0; i < nbr.n_rows(); ++i) max_row = std::max(max_row, nbr.row_size(i));
  EXPECT_EQ(max_row, 26);
  // symmetric
  for (index_t i = 0; i < nbr.n_rows(); ++i)
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
      const index_t j = nbr.index[e];
      EXPECT_TRUE(std::binary_search(nbr.index.begin() + nbr.begin(j), nbr.index.begin() + nbr.end(j), i));
    }
}

TEST(NearestNeighbour, FindsTheClosestOtherPoint) {
  const Points X = test::random_field(300, 1.0, 5);
  const std::vector<index_t> nearest = nearest_neighbour(X);
  for (index_t i = 0; i < 300; ++i) {
    double best = 1e300;
    for (index_t j = 0; j < 300; ++j)
      if (j != i) best = std::min(best, (X.col(j) - X.col(i)).norm());
    EXPECT_DOUBLE_EQ((X.col(nearest[i]) - X.col(i)).norm(), best);
  }
}

}  // namespace
}  // namespace pointhaptics
