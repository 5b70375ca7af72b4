#include <pointhaptics/geometry/neighbour_search.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/run_control.hpp>

#include <pointhaptics/geometry/kd_tree.hpp>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <utility>

namespace pointhaptics {
namespace {

// (each row is freed once copied: freeing them all at the end took most of a second at the widest support)
Csr rows_to_csr(std::vector<std::vector<index_t>>&& rows) {
  std::vector<index_t> offset(rows.size() + 1, 0);
  for (size_t i = 0; i < rows.size(); ++i) offset[i + 1] = offset[i] + static_cast<index_t>(rows[i].size());
  std::vector<index_t> index;
  index.reserve(offset.back());
  for (auto& row : rows) {
    throw_if_stop_requested("the neighbour lists");
    index.insert(index.end(), row.begin(), row.end());
    std::vector<index_t>().swap(row);
  }
  return Csr{std::move(offset), std::move(index)};
}

// The k-d tree search shared by both supports: row i holds the points j != i within radius(i) of
// point i (unsorted).
template <class Radius>
std::vector<std::vector<index_t>> search_rows(const Points& X, Radius&& radius) {
  const index_t n = static_cast<index_t>(X.cols());
  const KdTree tree(X);
  std::vector<std::vector<index_t>> rows(n);
  Progress progress("the neighbour search", n);
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n, 256), [&](const tbb::blocked_range<index_t>& range) {
    std::vector<std::pair<index_t, double>> found;
    nanoflann::SearchParams params;
    params.sorted = false;
    for (index_t i = range.begin(); i != range.end(); ++i) {
      throw_if_stop_requested("the neighbour search");  // a wide support finds 10^4 neighbours per point
      found.clear();
      const Vec3 q = X.col(i);
      const double r = radius(i);
      tree.index().radiusSearch(q.data(), r * r * (1.0 + 1e-6), found, params);
      for (const auto& [j, r2] : found)
        if (static_cast<index_t>(j) != i && within_support((X.col(j) - q).squaredNorm(), r)) rows[i].push_back(j);
    }
    progress.advance(static_cast<double>(range.size()));
  });
  return rows;
}

void sort_rows(std::vector<std::vector<index_t>>& rows) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        throw_if_stop_requested("the neighbour lists");
                        std::sort(rows[i].begin(), rows[i].end());
                      }
                    });
}

}  // namespace

Csr radius_neighbours(const Points& X, double h) {
  std::vector<std::vector<index_t>> rows = search_rows(X, [h](index_t) { return h; });
  sort_rows(rows);
  return rows_to_csr(std::move(rows));
}

Csr radius_neighbours(const Points& X, const Eigen::VectorXd& support) {
  const index_t n = static_cast<index_t>(X.cols());
  if (support.size() != n) throw Error("neighbour search: one support radius per point is needed");
  // symmetric: i and j are neighbours when either one's support reaches the other. Each point searches
  // its own support only (searching the largest one from every point would cost (h_max / h_i)^3 more
  // candidates in a dense core); a pair only the wider side reaches is added to the other side's row after
  std::vector<std::vector<index_t>> rows = search_rows(X, [&support](index_t i) { return support[i]; });
  std::vector<std::vector<index_t>> extra(n);
  for (index_t i = 0; i < n; ++i) {
    throw_if_stop_requested("the neighbour lists");
    for (index_t j : rows[i])
      if (!within_support((X.col(j) - X.col(i)).squaredNorm(), support[j])) extra[j].push_back(i);
  }
  for (index_t i = 0; i < n; ++i) rows[i].insert(rows[i].end(), extra[i].begin(), extra[i].end());
  sort_rows(rows);
  return rows_to_csr(std::move(rows));
}

Csr radius_neighbours_brute_force(const Points& X, double h) {
  const index_t n = static_cast<index_t>(X.cols());
  std::vector<std::vector<index_t>> rows(n);
  for (index_t i = 0; i < n; ++i)
    for (index_t j = 0; j < n; ++j)
      if (j != i && within_support((X.col(j) - X.col(i)).squaredNorm(), h)) rows[i].push_back(j);
  return rows_to_csr(std::move(rows));
}

std::vector<index_t> nearest_neighbour(const Points& X) {
  const index_t n = static_cast<index_t>(X.cols());
  std::vector<index_t> nearest(n, -1);
  if (n < 2) return nearest;
  const KdTree tree(X);
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n, 256), [&](const tbb::blocked_range<index_t>& range) {
    for (index_t i = range.begin(); i != range.end(); ++i) {
      index_t idx[2];
      double d2[2];
      const Vec3 q = X.col(i);
      const size_t found = tree.index().knnSearch(q.data(), 2, idx, d2);
      for (size_t k = 0; k < found; ++k)
        if (idx[k] != i) {
          nearest[i] = idx[k];
          break;
        }
    }
  });
  return nearest;
}

}  // namespace pointhaptics
