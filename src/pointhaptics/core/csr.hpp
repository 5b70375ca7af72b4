#pragma once
/// @file Compressed sparse rows: the neighbour lists of every point in two flat arrays.
#include <pointhaptics/core/types.hpp>

#include <vector>

namespace pointhaptics {

/// Row i holds entries index[offset[i] .. offset[i+1]); entry positions are "pair" ids.
struct Csr {
  std::vector<index_t> offset{0};  ///< (n_rows + 1)
  std::vector<index_t> index;      ///< (n_entries)

  index_t n_rows() const { return static_cast<index_t>(offset.size()) - 1; }
  index_t n_entries() const { return static_cast<index_t>(index.size()); }
  index_t row_size(index_t i) const { return offset[i + 1] - offset[i]; }
  index_t begin(index_t i) const { return offset[i]; }
  index_t end(index_t i) const { return offset[i + 1]; }
};

}  // namespace pointhaptics
