#include "solvers/system/system_operator.h"

#include <algorithm>
#include <cmath>

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
    group.rest = g.rest;
    group.stiffness = g.stiffness;
    group.damping = g.damping;
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

JELLO_VECTOR_CLONES long SystemOperator::fill(const double* x, double mass, double a, double b,
                                              bool clamp, const double* diagK,
                                              const double* diagD) {
  const std::ptrdiff_t n = n_;
  for (std::ptrdiff_t p = 0; p < n; ++p) {
    for (int e = 0; e < 6; ++e) {
      const std::ptrdiff_t i = 9 * p + kUpper[e];
      diag_[e][p] = (e == 0 || e == 3 || e == 5 ? mass : 0.0) - a * diagD[i] - b * diagK[i];
    }
  }
  long clamps = 0;
  for (Group& g : groups_) {
    const double* __restrict mask = g.mask.data();
    const double *xp = x + g.first, *yp = x + n + g.first, *zp = x + 2 * n + g.first;
    const double *xq = xp + g.delta, *yq = yp + g.delta, *zq = zp + g.delta;
    double* __restrict cxx = g.c[0].data();
    double* __restrict cxy = g.c[1].data();
    double* __restrict cxz = g.c[2].data();
    double* __restrict cyy = g.c[3].data();
    double* __restrict cyz = g.c[4].data();
    double* __restrict czz = g.c[5].data();
    const double kb = b * g.stiffness, ca = a * g.damping, rest = g.rest;
    long groupClamps = 0;
    // The block is -(a c + b k (1 - alpha)) P - b k alpha I: unit stride, no branch (a missing
    // spring's mask is 0, its block selected to 0), so the loop vectorizes.
#pragma omp simd reduction(+ : groupClamps)
    for (std::ptrdiff_t s = 0; s < g.count; ++s) {
      const double dx = xq[s] - xp[s], dy = yq[s] - yp[s], dz = zq[s] - zp[s];
      const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
      const bool spring = mask[s] != 0.0;
      const double inv = spring ? 1.0 / length : 0.0;
      double alpha = 1.0 - rest * inv;
      const bool clamped = clamp && spring && alpha < 0.0;
      groupClamps += clamped ? 1 : 0;
      alpha = clamped ? 0.0 : alpha;
      const double ux = dx * inv, uy = dy * inv, uz = dz * inv;
      const double beta = spring ? -(ca + kb * (1.0 - alpha)) : 0.0;
      const double iso = spring ? -kb * alpha : 0.0;
      cxx[s] = beta * ux * ux + iso;
      cxy[s] = beta * ux * uy;
      cxz[s] = beta * ux * uz;
      cyy[s] = beta * uy * uy + iso;
      cyz[s] = beta * uy * uz;
      czz[s] = beta * uz * uz + iso;
    }
    clamps += groupClamps;
    // Each spring's block, negated, on both ends' diagonal blocks (two loops: the ends of one
    // group never alias within a loop).
    for (std::ptrdiff_t end : {g.first, g.first + g.delta}) {
      for (int e = 0; e < 6; ++e) {
        double* __restrict d = diag_[e].data() + end;
        const double* __restrict c = g.c[e].data();
#pragma omp simd
        for (std::ptrdiff_t s = 0; s < g.count; ++s) d[s] -= c[s];
      }
    }
  }
  return clamps;
}

JELLO_VECTOR_CLONES double SystemOperator::springDampingQuadratic(const double* x,
                                                                  const double* v) const {
  const std::ptrdiff_t n = n_;
  double sum = 0.0;
  for (const Group& g : groups_) {
    const double* __restrict mask = g.mask.data();
    const double *xp = x + g.first, *yp = x + n + g.first, *zp = x + 2 * n + g.first;
    const double *xq = xp + g.delta, *yq = yp + g.delta, *zq = zp + g.delta;
    const double *vxp = v + g.first, *vyp = v + n + g.first, *vzp = v + 2 * n + g.first;
    const double *vxq = vxp + g.delta, *vyq = vyp + g.delta, *vzq = vzp + g.delta;
    double groupSum = 0.0;
#pragma omp simd reduction(+ : groupSum)
    for (std::ptrdiff_t s = 0; s < g.count; ++s) {
      const double dx = xq[s] - xp[s], dy = yq[s] - yp[s], dz = zq[s] - zp[s];
      const double dv = dx * (vxq[s] - vxp[s]) + dy * (vyq[s] - vyp[s]) + dz * (vzq[s] - vzp[s]);
      const double length2 = dx * dx + dy * dy + dz * dz;
      groupSum += mask[s] != 0.0 ? dv * dv / length2 : 0.0;
    }
    sum -= g.damping * groupSum;
  }
  return sum;
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
