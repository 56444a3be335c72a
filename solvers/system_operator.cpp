#include "solvers/system_operator.h"

#include <algorithm>

#include "src/assertions.h"

namespace jello {

namespace {

// Row-major indices of the upper triangle of a symmetric 3x3 block: xx, xy, xz, yy, yz, zz.
constexpr int kUpper[6] = {0, 1, 2, 4, 5, 8};

// y[s] += C[s] p[s] over a run of symmetric blocks (a group's springs, seen from one end, or the
// points' diagonal blocks): unit stride, no dependence between iterations.
void addBlockProducts(std::ptrdiff_t count, const std::array<std::vector<double>, 6>& c,
                      const double* __restrict px, const double* __restrict py,
                      const double* __restrict pz, double* __restrict yx, double* __restrict yy,
                      double* __restrict yz) {
  const double* __restrict cxx = c[0].data();
  const double* __restrict cxy = c[1].data();
  const double* __restrict cxz = c[2].data();
  const double* __restrict cyy = c[3].data();
  const double* __restrict cyz = c[4].data();
  const double* __restrict czz = c[5].data();
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
  const std::ptrdiff_t n = n_;
  const double *px = p, *py = p + n, *pz = p + 2 * n;
  double *yx = y, *yy = y + n, *yz = y + 2 * n;
  // The points' own blocks first (y = G p), then every spring's, both ends.
  std::fill(y, y + 3 * n, 0.0);
  addBlockProducts(n, diag_, px, py, pz, yx, yy, yz);
  for (const Group& g : groups_) {
    const std::ptrdiff_t a = g.first, b = g.first + g.delta;
    // Base points take their partners' values, then partners take the base points'.
    addBlockProducts(g.count, g.c, px + b, py + b, pz + b, yx + a, yy + a, yz + a);
    addBlockProducts(g.count, g.c, px + a, py + a, pz + a, yx + b, yy + b, yz + b);
  }
}

}  // namespace jello
