#include "solvers/system/system_operator.h"

#include <algorithm>

#include "src/base/assertions.h"
#include "src/base/parallel.h"
#include "src/base/vector_clones.h"

namespace jello {

namespace {

// Row-major indices of the upper triangle of a symmetric 3x3 block: xx, xy, xz, yy, yz, zz.
constexpr int kUpper[6] = {0, 1, 2, 4, 5, 8};

// y[s] += C[s] p[s] over a run of symmetric blocks (a group's springs, seen from one end, or the
// points' diagonal blocks): unit stride, no dependence between iterations.
// The blocks are c's entries from `first` on.
void addBlockProducts(std::ptrdiff_t count, const std::array<std::vector<double>, 6>& c,
                      std::ptrdiff_t first, const double* __restrict px,
                      const double* __restrict py, const double* __restrict pz,
                      double* __restrict yx, double* __restrict yy, double* __restrict yz) {
  const double* __restrict cxx = c[0].data() + first;
  const double* __restrict cxy = c[1].data() + first;
  const double* __restrict cxz = c[2].data() + first;
  const double* __restrict cyy = c[3].data() + first;
  const double* __restrict cyz = c[4].data() + first;
  const double* __restrict czz = c[5].data() + first;
#pragma omp simd
  for (std::ptrdiff_t s = 0; s < count; ++s) {
    yx[s] += cxx[s] * px[s] + cxy[s] * py[s] + cxz[s] * pz[s];
    yy[s] += cxy[s] * px[s] + cyy[s] * py[s] + cyz[s] * pz[s];
    yz[s] += cxz[s] * px[s] + cyz[s] * py[s] + czz[s] * pz[s];
  }
}

}  // namespace

SystemOperator::SystemOperator(const SpringForces& springs, int numPoints) : n_(numPoints) {
  for (const SpringGroup& g : springs.groups()) {
    Group group;
    group.first = g.first;
    group.count = static_cast<std::ptrdiff_t>(g.mask.size());
    group.delta = g.delta;
    group.mask = g.mask;
    for (auto& c : group.c) c.assign(g.mask.size(), 0.0);
    maxDelta_ = std::max(maxDelta_, group.delta);
    groups_.push_back(std::move(group));
  }
  for (auto& d : diag_) d.assign(static_cast<std::size_t>(n_), 0.0);
}

void SystemOperator::gather(const SparseMatrix& A, const std::vector<int>& diagSlots,
                            const std::vector<int>& springSlots) {
  JELLO_ASSERT(diagSlots.size() == 9 * static_cast<std::size_t>(n_),
               "nine diagonal slots per point");
  const double* values = A.valuePtr();
  for (int p = 0; p < n_; ++p) {
    for (int e = 0; e < 6; ++e) diag_[e][p] = values[diagSlots[9 * std::size_t(p) + kUpper[e]]];
  }
  const int* slot = springSlots.data();  // 18 per spring, springs in group order
  for (Group& g : groups_) {
    for (std::ptrdiff_t s = 0; s < g.count; ++s) {
      if (g.mask[s] == 0.0) continue;  // stays 0: no spring, no product
      for (int e = 0; e < 6; ++e) g.c[e][s] = values[slot[kUpper[e]]];  // the (a, b) block
      slot += 18;
    }
  }
  JELLO_ASSERT(slot == springSlots.data() + springSlots.size(), "every spring's slots used");
}

void SystemOperator::apply(const double* p, double* y) const {
  // Split over threads as the spring forces are (src/base/parallel.h): every group's springs write
  // to their base points and partners at most maxDelta_ points further.
  runOverPointBlocks(
      splitPointBlocks(n_, maxDelta_, threadsFor(n_)),
      [&](std::ptrdiff_t setLo, std::ptrdiff_t setHi, std::ptrdiff_t lo, std::ptrdiff_t hi) {
        applyRange(p, y, setLo, setHi, lo, hi);
      },
      [](std::ptrdiff_t, std::ptrdiff_t) {});
}

JELLO_VECTOR_CLONES void SystemOperator::applyRange(const double* p, double* y,
                                                    std::ptrdiff_t setLo, std::ptrdiff_t setHi,
                                                    std::ptrdiff_t lo, std::ptrdiff_t hi) const {
  const std::ptrdiff_t n = n_;
  const double *px = p, *py = p + n, *pz = p + 2 * n;
  double *yx = y, *yy = y + n, *yz = y + 2 * n;
  // The points' own blocks first (y = G p) over the points this call sets, then every spring's
  // with a base point in [lo, hi), both ends.
  for (int c = 0; c < 3; ++c) std::fill(y + c * n + setLo, y + c * n + setHi, 0.0);
  if (setHi > setLo) {
    addBlockProducts(setHi - setLo, diag_, setLo, px + setLo, py + setLo, pz + setLo, yx + setLo,
                     yy + setLo, yz + setLo);
  }
  for (const Group& g : groups_) {
    const std::ptrdiff_t begin = std::clamp<std::ptrdiff_t>(lo - g.first, 0, g.count);
    const std::ptrdiff_t count = std::clamp<std::ptrdiff_t>(hi - g.first, 0, g.count) - begin;
    if (count <= 0) continue;
    const std::ptrdiff_t a = g.first + begin, b = a + g.delta;
    // Base points take their partners' values, then partners take the base points'.
    addBlockProducts(count, g.c, begin, px + b, py + b, pz + b, yx + a, yy + a, yz + a);
    addBlockProducts(count, g.c, begin, px + a, py + a, pz + a, yx + b, yy + b, yz + b);
  }
}

}  // namespace jello
