#include "solvers/linalg/supernode_blocks.h"

#include <algorithm>
#include <cstddef>

#include "solvers/linalg/dense_tail.h"
#include "src/base/assertions.h"
#include "src/base/vector_clones.h"

namespace jello {
namespace {

using Lanes = SubstitutionLanes;
constexpr int kStride = kSubstitutionStride;
constexpr int kChunk = DenseTail::kPanel;  // what invertLowerTriangle writes

// One chunk of W <= 8 of a supernode's columns, their values y_c in `chunk` (held in
// registers meanwhile), and the block's rows after the chunk's own. Forward: y_c = D^-1 y_c
// with D the chunk's triangle, then for each row r, y_r -= L_rc y_c. Backward: y_c -= (sum over
// the rows of L_rc' y_r), then y_c = D^-T y_c. `v` is the chunk's first column in its first
// row, `stride` the block's width, `inverse` D^-1 (8 x 8 by rows): a product, its eight sums
// independent and each in two halves, where substituting through D chained every column's
// value to the one before; T one double or four lanes.
template <typename T, int W>
void forwardChunk(const int* rows, int count, const double* v, int stride, const double* inverse,
                  T* chunk, double* yd) {
  T yc[W];
  for (int k = W - 1; k >= 0; --k) {
    T even = inverse[k * kChunk] * chunk[0], odd{};
    for (int m = 1; m <= k; ++m) (m % 2 ? odd : even) += inverse[k * kChunk + m] * chunk[m];
    yc[k] = even + odd;
  }
  for (int k = 0; k < W; ++k) chunk[k] = yc[k];
  v += W * stride;
  for (int q = 0; q < count; ++q, v += stride) {
    T& yr = *reinterpret_cast<T*>(yd + rows[q]);
    T sum = yr;
    for (int k = 0; k < W; ++k) sum -= v[k] * yc[k];
    yr = sum;
  }
}
template <typename T, int W>
void backwardChunk(const int* rows, int count, const double* v, int stride, const double* inverse,
                   T* chunk, const double* yd) {
  T acc[W] = {};
  const double* below = v + W * stride;
  for (int q = 0; q < count; ++q, below += stride) {
    const T yr = *reinterpret_cast<const T*>(yd + rows[q]);
    for (int k = 0; k < W; ++k) acc[k] += below[k] * yr;
  }
  T yc[W];
  for (int k = 0; k < W; ++k) yc[k] = chunk[k] - acc[k];
  for (int j = 0; j < W; ++j) {
    T even = inverse[(W - 1) * kChunk + j] * yc[W - 1], odd{};
    for (int k = W - 2; k >= j; --k) {
      (k % 2 ? odd : even) += inverse[k * kChunk + j] * yc[k];
    }
    chunk[j] = even + odd;
  }
}
template <typename T, bool Forward, int W = 8>
void chunk(int width, const int* rows, int count, const double* v, int stride,
           const double* inverse, T* values, double* yd) {
  if constexpr (W > 1) {
    if (width < W) {
      return chunk<T, Forward, W - 1>(width, rows, count, v, stride, inverse, values, yd);
    }
  }
  if constexpr (Forward) {
    forwardChunk<T, W>(rows, count, v, stride, inverse, values, yd);
  } else {
    backwardChunk<T, W>(rows, count, v, stride, inverse, values, yd);
  }
}

}  // namespace

template <typename T, bool Forward>
void SupernodeBlocks::sweep(int sn, double* yd) const {
  const auto at = [yd](int point) -> T& { return *reinterpret_cast<T*>(yd + kStride * point); };
  const int c0 = start[sn], width = start[sn + 1] - c0;
  const int* rows = rows_.data() + rowStart_[sn];
  const int height = rowStart_[sn + 1] - rowStart_[sn];
  const double* v = values_.data() + valueStart_[sn];
  const int last = (width - 1) / kChunk * kChunk;
  for (int i = 0; i <= last; i += kChunk) {
    const int j = Forward ? i : last - i;  // forward first chunk first, backward last first
    T values[kChunk];
    const int w = std::min(kChunk, width - j);
    for (int k = 0; k < w; ++k) values[k] = at(c0 + j + k);
    chunk<T, Forward>(w, rows + j + w, height - j - w, v + static_cast<long>(j) * width + j, width,
                      inverses_.data() + static_cast<long>(kChunk) * (c0 + j), values, yd);
    for (int k = 0; k < w; ++k) at(c0 + j + k) = values[k];
  }
}

JELLO_VECTOR_CLONES void SupernodeBlocks::forward(int columns, double* yd) const {
  const int supernodes = static_cast<int>(start.size()) - 1;
  for (int sn = 0; sn < supernodes; ++sn) {
    if (columns == 1) {
      sweep<double, true>(sn, yd);
    } else {
      sweep<Lanes, true>(sn, yd);
    }
  }
}

JELLO_VECTOR_CLONES void SupernodeBlocks::backward(int columns, double* yd) const {
  for (int sn = static_cast<int>(start.size()) - 2; sn >= 0; --sn) {
    if (columns == 1) {
      sweep<double, false>(sn, yd);
    } else {
      sweep<Lanes, false>(sn, yd);
    }
  }
}

void SupernodeBlocks::copy(int n, const std::vector<int>& colStart, const std::vector<int>& colRow,
                           const std::vector<double>& colValue,
                           const std::vector<double>& inverseDiagonal, bool samePattern) {
  const int supernodes = static_cast<int>(start.size()) - 1;
  std::vector<int>& local = local_;  // a row's place in the block being filled; -1: none
  local.assign(static_cast<std::size_t>(n), -1);
  // The values into the blocks' pattern, supernode by supernode; false when an entry lies
  // outside it (a new pattern).
  const auto fill = [&] {
    std::fill(values_.begin(), values_.end(), 0.0);
    for (int sn = 0; sn < supernodes; ++sn) {
      const int c0 = start[sn], c1 = start[sn + 1], width = c1 - c0;
      const int first = rowStart_[sn], height = rowStart_[sn + 1] - first;
      for (int q = 0; q < height; ++q) local[rows_[first + q] / kStride] = q;
      double* block = values_.data() + valueStart_[sn];
      for (int j = c0; j < c1; ++j) {
        for (int q = colStart[j]; q < colStart[j + 1]; ++q) {
          const int row = local[static_cast<std::size_t>(colRow[q])];
          if (row < 0) return false;
          block[static_cast<std::ptrdiff_t>(row) * width + (j - c0)] = colValue[q];
        }
      }
      for (int q = 0; q < height; ++q) local[rows_[first + q] / kStride] = -1;
    }
    return true;
  };
  if (samePattern && fill()) return invertChunks(inverseDiagonal);
  // The pattern: each supernode's own columns, then every row of its columns' entries from c1
  // on (CHOLMOD's supernodes share them; the copy dropped explicit zeros, so the union is
  // taken).
  std::fill(local.begin(), local.end(), -1);
  rowStart_.assign(1, 0);
  rows_.clear();
  valueStart_.assign(1, 0);
  for (int sn = 0; sn < supernodes; ++sn) {
    const int c0 = start[sn], c1 = start[sn + 1], width = c1 - c0;
    const std::size_t first = rows_.size();
    for (int j = c0; j < c1; ++j) rows_.push_back(j);
    for (int j = c0; j < c1; ++j)
      for (int q = colStart[j]; q < colStart[j + 1]; ++q)
        if (colRow[q] >= c1) rows_.push_back(colRow[q]);
    const auto below = rows_.begin() + static_cast<std::ptrdiff_t>(first) + width;
    std::sort(below, rows_.end());
    rows_.erase(std::unique(below, rows_.end()), rows_.end());
    for (std::size_t q = first; q < rows_.size(); ++q) rows_[q] *= kStride;  // as read
    rowStart_.push_back(static_cast<int>(rows_.size()));
    valueStart_.push_back(valueStart_.back() + static_cast<int>(rows_.size() - first) * width);
  }
  values_.assign(static_cast<std::size_t>(valueStart_.back()), 0.0);
  const bool filled = fill();
  JELLO_ASSERT(filled, "every entry lies in the blocks' pattern made from them");
  invertChunks(inverseDiagonal);
}

void SupernodeBlocks::invertChunks(const std::vector<double>& inverseDiagonal) {
  const int supernodes = static_cast<int>(start.size()) - 1;
  inverses_.assign(static_cast<std::size_t>(kChunk) * static_cast<std::size_t>(start.back()), 0.0);
  for (int sn = 0; sn < supernodes; ++sn) {
    const int c0 = start[sn], width = start[sn + 1] - c0;
    const double* v = values_.data() + valueStart_[sn];
    for (int j = 0; j < width; j += kChunk) {
      const double* d = v + static_cast<long>(j) * width + j;  // D, the chunk's triangle
      invertLowerTriangle(
          std::min(kChunk, width - j), [&](int i, int m) { return d[i * width + m]; },
          [&](int i) { return 1.0 / inverseDiagonal[static_cast<std::size_t>(c0 + j + i)]; },
          inverses_.data() + static_cast<long>(kChunk) * (c0 + j));
    }
  }
}

}  // namespace jello
