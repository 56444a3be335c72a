#include "solvers/linalg/dense_tail.h"

#include <cholmod.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "src/base/assertions.h"
#include "src/base/vector_clones.h"

// Without AVX-512 (a generic build) GCC warns that passing these vectors by value changes the
// ABI: they never leave this file.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace jello {
namespace {

constexpr int kPanel = DenseTail::kPanel;
using Lanes = double __attribute__((vector_size(kPanel * sizeof(double))));

// A tail spans at least this many columns.
constexpr int kMinTailWidth = 2 * kPanel;
// What an entry of the dense tail costs against one of the sparse copy, in a solve: the tail
// grows over the supernodes before it while the entries it adds (zeros included) cost less than
// those it takes from the sparse copy. Measured (BM_KeptFactorSolve at 8^3, three columns; the
// copy alone 31.6 us): the last supernode alone as the tail (197 columns, 19,500 entries) 23.9
// us; tails of 245, 263, 278 and 290 columns (costs 0.7, 0.4-0.5, 0.3 and 0.2) 21.3, 20.1, 20.0
// and 22.4 us.
constexpr double kTailEntryCost = 0.4;

inline Lanes load(const double* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store(double* p, Lanes v) {
  std::memcpy(p, &v, sizeof v);
}

// x = A v for an 8 x 8 A by columns, v the kPanel entries at each right-hand side's `at`.
template <int C>
inline void multiplyPanel(const double* a, double* const* y, long at) {
  Lanes x[C] = {};
  for (int q = 0; q < kPanel; ++q) {
    const Lanes column = load(a + q * kPanel);
    for (int c = 0; c < C; ++c) x[c] += column * y[c][at + q];
  }
  for (int c = 0; c < C; ++c) store(y[c] + at, x[c]);
}

template <int C>
void forwardPanels(const DenseTail::Data& f, int width, double* y0) {
  double* y[C];
  for (int c = 0; c < C; ++c) y[c] = y0 + static_cast<long>(c) * width;
  for (int p = 0; p < width; p += kPanel) {
    multiplyPanel<C>(f.inverse + static_cast<long>(p) * kPanel, y, p);
    const double* l = f.byColumn + static_cast<long>(p) * width;  // column p
    for (int r = p + kPanel; r < width; r += kPanel) {
      Lanes sum[C];
      for (int c = 0; c < C; ++c) sum[c] = load(y[c] + r);
      for (int q = 0; q < kPanel; ++q) {
        const Lanes lq = load(l + static_cast<long>(q) * width + r);
        for (int c = 0; c < C; ++c) sum[c] -= lq * y[c][p + q];
      }
      for (int c = 0; c < C; ++c) store(y[c] + r, sum[c]);
    }
  }
}

template <int C>
void backwardPanels(const DenseTail::Data& f, int width, double* y0) {
  double* y[C];
  for (int c = 0; c < C; ++c) y[c] = y0 + static_cast<long>(c) * width;
  for (int p = width - kPanel; p >= 0; p -= kPanel) {
    // The panel's values are final (the panels after it have pushed theirs): solve its
    // transposed diagonal block, then push its solved values into the rows above it through
    // L's rows p .. p + 7 (by rows: eight of their columns to a vector), the values held in
    // registers while the columns go by.
    multiplyPanel<C>(f.inverseTransposed + static_cast<long>(p) * kPanel, y, p);
    Lanes z[C][kPanel];
    for (int c = 0; c < C; ++c)
      for (int q = 0; q < kPanel; ++q) z[c][q] = Lanes{} + y[c][p + q];
    const double* l = f.byRow + static_cast<long>(p) * width;  // row p
    for (int j = 0; j < p; j += kPanel) {
      Lanes sum[C];
      for (int c = 0; c < C; ++c) sum[c] = load(y[c] + j);
      for (int q = 0; q < kPanel; ++q) {
        const Lanes lq = load(l + static_cast<long>(q) * width + j);
        for (int c = 0; c < C; ++c) sum[c] -= lq * z[c][q];
      }
      for (int c = 0; c < C; ++c) store(y[c] + j, sum[c]);
    }
  }
}

}  // namespace

void DenseTail::copy(const double* block, int width) {
  const int wp = paddedWidth_ = (width + kPanel - 1) / kPanel * kPanel;
  const auto size = static_cast<std::size_t>(wp) * static_cast<std::size_t>(wp);
  Data& f = data_;
  const std::size_t panels = static_cast<std::size_t>(wp) * kPanel, work = 3 * std::size_t(wp);
  // Zeros where no entry is written below (a new size only: the kernels read no other place).
  if (f.storage.size() != 2 * size + 2 * panels + work + kPanel) {
    f.storage.assign(2 * size + 2 * panels + work + kPanel, 0.0);
  }
  auto* at = reinterpret_cast<double*>((reinterpret_cast<std::uintptr_t>(f.storage.data()) + 63) &
                                       ~std::uintptr_t{63});
  for (double** array : {&f.byColumn, &f.byRow}) {
    *array = at;
    at += size;
  }
  for (double** array : {&f.inverse, &f.inverseTransposed}) {
    *array = at;
    at += panels;
  }
  f.work = at;
  // The padded matrix: L's entries, then the identity on the padding's diagonal.
  const auto entry = [&](int r, int j) {
    if (r >= width || j >= width) return r == j ? 1.0 : 0.0;
    return block[static_cast<long>(j) * width + r];
  };
  for (int p = 0; p < wp; p += kPanel) {
    // Entries below the panel's diagonal block.
    for (int j = p; j < p + kPanel; ++j) {
      for (int r = p + kPanel; r < wp; ++r) {
        const double v = entry(r, j);
        f.byColumn[static_cast<std::size_t>(j) * wp + r] = v;
        f.byRow[static_cast<std::size_t>(r) * wp + j] = v;
      }
    }
    // The diagonal block's inverse by rows (the transpose's by columns), then by columns.
    double* transposed = f.inverseTransposed + static_cast<long>(p) * kPanel;
    invertLowerTriangle(
        kPanel, [&](int i, int j) { return entry(p + i, p + j); },
        [&](int i) { return entry(p + i, p + i); }, transposed);
    double* inverse = f.inverse + static_cast<long>(p) * kPanel;
    for (int i = 0; i < kPanel; ++i)
      for (int k = 0; k < kPanel; ++k) inverse[i * kPanel + k] = transposed[k * kPanel + i];
  }
}

long supernodeEntries(const cholmod_factor& L, std::size_t sn) {
  const auto* super = static_cast<const int*>(L.super);
  const auto* pi = static_cast<const int*>(L.pi);
  const long width = super[sn + 1] - super[sn], height = pi[sn + 1] - pi[sn];
  return width * height - width * (width - 1) / 2;
}

int DenseTail::copyTail(const cholmod_factor& L, int n) {
  clear();
  const auto* super = static_cast<const int*>(L.super);
  const auto* pi = static_cast<const int*>(L.pi);
  const auto* px = static_cast<const int*>(L.px);
  const auto* rows = static_cast<const int*>(L.s);
  const auto* values = static_cast<const double*>(L.x);
  const auto triangle = [n, super](std::size_t sn) {  // entries of a tail from supernode sn
    const long width = n - super[sn];
    return width * (width + 1) / 2;
  };
  std::size_t first = L.nsuper - 1;  // the tail's first supernode
  while (first > 0 && kTailEntryCost * double(triangle(first - 1) - triangle(first)) <
                          double(supernodeEntries(L, first - 1))) {
    --first;
  }
  const int start = super[first], width = n - start;
  if (width < kMinTailWidth) return n;
  // The supernodes' rows from `start` on are all the tail's own: none lies below it.
  std::vector<double> block(static_cast<std::size_t>(width) * width, 0.0);
  for (std::size_t sn = first; sn < L.nsuper; ++sn) {
    const int height = pi[sn + 1] - pi[sn];
    for (int j = super[sn]; j < super[sn + 1]; ++j) {
      const int jj = j - super[sn];
      const double* column = values + px[sn] + static_cast<std::ptrdiff_t>(jj) * height;
      for (int ii = jj; ii < height; ++ii) {
        block[static_cast<std::size_t>(j - start) * width + (rows[pi[sn] + ii] - start)] =
            column[ii];
      }
    }
  }
  copy(block.data(), width);
  return start;
}

JELLO_VECTOR_CLONES void DenseTail::forward(double* y, int columns) const {
  JELLO_ASSERT(columns >= 1 && columns <= 3, "one to three right-hand sides");
  if (columns == 1) return forwardPanels<1>(data_, paddedWidth_, y);
  if (columns == 2) return forwardPanels<2>(data_, paddedWidth_, y);
  forwardPanels<3>(data_, paddedWidth_, y);
}

JELLO_VECTOR_CLONES void DenseTail::backward(double* y, int columns) const {
  JELLO_ASSERT(columns >= 1 && columns <= 3, "one to three right-hand sides");
  if (columns == 1) return backwardPanels<1>(data_, paddedWidth_, y);
  if (columns == 2) return backwardPanels<2>(data_, paddedWidth_, y);
  backwardPanels<3>(data_, paddedWidth_, y);
}

}  // namespace jello
