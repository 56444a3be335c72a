#include "src/effects/spring_forces.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "src/base/assertions.h"
#include "src/base/parallel.h"
#include "src/base/vector_clones.h"

namespace jello {

std::vector<SpringGroup> latticeSpringGroups(const Lattice& lat, double stiffness, double damping) {
  std::vector<SpringGroup> groups;
  const int n = lat.n;
  for (const LatticeOffset& o : latticeOffsets()) {
    SpringGroup g;
    g.kind = o.kind;
    g.delta = lat.index(o.di, o.dj, o.dk) - lat.index(0, 0, 0);
    g.rest = std::sqrt(double(o.di * o.di + o.dj * o.dj + o.dk * o.dk)) * lat.spacing();
    g.stiffness = stiffness;
    g.damping = damping;
    // Base points p = (i,j,k) with p + offset inside the lattice; their flat indices span
    // [first, last]. In between lie a few non-springs (wrapping rows), masked out.
    int first = lat.numPoints(), last = -1;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
          if (lat.contains(i + o.di, j + o.dj, k + o.dk)) {
            first = std::min(first, lat.index(i, j, k));
            last = std::max(last, lat.index(i, j, k));
          }
    if (last < first) continue;  // offset longer than the lattice (bend springs at N = 2)
    g.first = first;
    g.mask.assign(static_cast<std::size_t>(last - first + 1), 0.0);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
          if (lat.contains(i + o.di, j + o.dj, k + o.dk)) {
            g.mask[lat.index(i, j, k) - first] = 1.0;
            ++g.numSprings;
          }
    groups.push_back(std::move(g));
  }
  return groups;
}

SpringForces::SpringForces(std::vector<SpringGroup> groups, int numPoints)
    : groups_(std::move(groups)), n_(numPoints) {
  for (const SpringGroup& g : groups_) {
    JELLO_ASSERT(g.delta > 0 && g.first >= 0, "a spring group links a point to a later one");
    JELLO_ASSERT(g.first + static_cast<int>(g.mask.size()) + g.delta <= n_,
                 "a spring group reaches past the last point");
    numSprings_ += g.numSprings;
    maxDelta_ = std::max(maxDelta_, g.delta);
  }
}

namespace {

// Partners at least this far apart can be updated in the same vectorized pass: within 8
// consecutive springs no point is both a base and a partner.
constexpr int kFusedMinDelta = 8;

// The scalar the force on the base point is d times (see the header).
inline double springScale(double dx, double dy, double dz, double wx, double wy, double wz,
                          double k, double c, double L0, double mask) {
  // A missing spring's (mask 0) squared length is taken as 1, so its scale is finite and times
  // its mask is 0: 0 * inf never makes a NaN; a spring's (mask 1) is its own, exactly. Written
  // as arithmetic, not a select: GCC sank a select's arms into a branch (floating-point
  // operations may trap), which only AVX-512's masks vectorize; on AVX2 (Zen 3, and the
  // portable build's x86-64-v3 clone) these loops ran scalar, several times slower.
  const double l2 = mask * (dx * dx + dy * dy + dz * dz) + (1.0 - mask);
  const double inv = 1.0 / std::sqrt(l2);
  return mask * (k * (1.0 - L0 * inv) + c * (dx * wx + dy * wy + dz * wz) * (inv * inv));
}

// A group with delta >= kFusedMinDelta: one pass adds the force to both ends. Arrays are
// component arrays offset to the group's first base point.
void accumulateGroupFused(const SpringGroup& g, std::ptrdiff_t offset, std::ptrdiff_t count,
                          const double* __restrict x, const double* __restrict y,
                          const double* __restrict z, const double* __restrict vx,
                          const double* __restrict vy, const double* __restrict vz, double* fx,
                          double* fy, double* fz) {
  const double k = g.stiffness, c = g.damping, L0 = g.rest;
  const double* __restrict mask = g.mask.data() + offset;
  const std::ptrdiff_t d = g.delta;
#pragma omp simd safelen(kFusedMinDelta)
  for (std::ptrdiff_t s = 0; s < count; ++s) {
    const double dx = x[s + d] - x[s], dy = y[s + d] - y[s], dz = z[s + d] - z[s];
    const double scale = springScale(dx, dy, dz, vx[s + d] - vx[s], vy[s + d] - vy[s],
                                     vz[s + d] - vz[s], k, c, L0, mask[s]);
    fx[s] += scale * dx;
    fy[s] += scale * dy;
    fz[s] += scale * dz;
    fx[s + d] -= scale * dx;
    fy[s + d] -= scale * dy;
    fz[s + d] -= scale * dz;
  }
}

// One group: springs p -> p + delta for the base points p = first .. first + count - 1. The
// arrays are passed as separate restrict pointers, offset to the group's base and partner
// points, so the compiler sees unit-stride loops without aliasing and vectorizes them.
void accumulateGroup(const SpringGroup& g, std::ptrdiff_t first, std::ptrdiff_t count,
                     const double* __restrict xp, const double* __restrict yp,
                     const double* __restrict zp, const double* __restrict xq,
                     const double* __restrict yq, const double* __restrict zq,
                     const double* __restrict vxp, const double* __restrict vyp,
                     const double* __restrict vzp, const double* __restrict vxq,
                     const double* __restrict vyq, const double* __restrict vzq,
                     double* __restrict fxp, double* __restrict fyp, double* __restrict fzp,
                     double* __restrict gx, double* __restrict gy, double* __restrict gz) {
  const double k = g.stiffness, c = g.damping, L0 = g.rest;
  const double* __restrict mask = g.mask.data() + first;
  // Pass 1: the force on each base point, added in place (base points run unit-stride).
  for (std::ptrdiff_t s = 0; s < count; ++s) {
    const double dx = xq[s] - xp[s], dy = yq[s] - yp[s], dz = zq[s] - zp[s];
    const double scale = springScale(dx, dy, dz, vxq[s] - vxp[s], vyq[s] - vyp[s], vzq[s] - vzp[s],
                                     k, c, L0, mask[s]);
    gx[s] = scale * dx;
    gy[s] = scale * dy;
    gz[s] = scale * dz;
    fxp[s] += gx[s];
    fyp[s] += gy[s];
    fzp[s] += gz[s];
  }
}

// Pass 2: the opposite force on the partners, in its own loop since q may alias p + 1.
void subtractFromPartners(std::ptrdiff_t count, const double* __restrict gx,
                          const double* __restrict gy, const double* __restrict gz,
                          double* __restrict fxq, double* __restrict fyq, double* __restrict fzq) {
  for (std::ptrdiff_t s = 0; s < count; ++s) {
    fxq[s] -= gx[s];
    fyq[s] -= gy[s];
    fzq[s] -= gz[s];
  }
}

}  // namespace

void SpringForces::accumulate(const double* x, const double* v, double* f) const {
  // Each thread's block of base points in two halves (src/base/parallel.h): the sums differ from
  // the serial ones only in the order in which points receive their terms (round-off).
  runOverPointBlocks(
      splitPointBlocks(n_, maxDelta_, threads()),
      [&](std::ptrdiff_t, std::ptrdiff_t, std::ptrdiff_t lo, std::ptrdiff_t hi) {
        accumulateRange(x, v, f, lo, hi);
      },
      [](std::ptrdiff_t, std::ptrdiff_t) {});
}

int SpringForces::threads() const {
  return threadsFor(n_);
}

JELLO_VECTOR_CLONES void SpringForces::accumulateRange(const double* x, const double* v, double* f,
                                                       std::ptrdiff_t lo, std::ptrdiff_t hi) const {
  const int n = n_;
  // The base points' forces of a group with a short offset are kept for the partners' pass in
  // two chunk buffers on the stack (no state in the object, so threads may share it). The
  // partners' pass of a chunk runs after the next chunk's base pass: a partner q = p + delta
  // (delta < kChunk) is a base point of the same or the next chunk, so every point receives its
  // base force before its partner force, the order of a single pass over the whole group, and
  // the sums are bit for bit those of the unchunked loop.
  constexpr std::ptrdiff_t kChunk = 128;
  static_assert(kChunk >= kFusedMinDelta);
  alignas(64) double buffer[2][3][kChunk];
  for (const SpringGroup& g : groups_) {
    const std::ptrdiff_t size = static_cast<std::ptrdiff_t>(g.mask.size());
    // This call's springs: base points in [lo, hi).
    const std::ptrdiff_t begin = std::clamp<std::ptrdiff_t>(lo - g.first, 0, size);
    const std::ptrdiff_t count = std::clamp<std::ptrdiff_t>(hi - g.first, 0, size) - begin;
    if (count <= 0) continue;
    const std::ptrdiff_t p = g.first + begin, q = p + g.delta;
    if (g.delta >= kFusedMinDelta) {
      accumulateGroupFused(g, begin, count, x + p, x + n + p, x + 2 * n + p, v + p, v + n + p,
                           v + 2 * n + p, f + p, f + n + p, f + 2 * n + p);
      continue;
    }
    const auto partners = [&](std::ptrdiff_t s0, int b) {
      const std::ptrdiff_t len = std::min(kChunk, count - s0), o = q + s0;
      subtractFromPartners(len, buffer[b][0], buffer[b][1], buffer[b][2], f + o, f + n + o,
                           f + 2 * n + o);
    };
    int b = 0;
    for (std::ptrdiff_t s0 = 0; s0 < count; s0 += kChunk, b ^= 1) {
      const std::ptrdiff_t len = std::min(kChunk, count - s0), a = p + s0, c = q + s0;
      accumulateGroup(g, begin + s0, len, x + a, x + n + a, x + 2 * n + a, x + c, x + n + c,
                      x + 2 * n + c, v + a, v + n + a, v + 2 * n + a, v + c, v + n + c,
                      v + 2 * n + c, f + a, f + n + a, f + 2 * n + a, buffer[b][0], buffer[b][1],
                      buffer[b][2]);
      if (s0 > 0) partners(s0 - kChunk, b ^ 1);
    }
    partners((count - 1) / kChunk * kChunk, b ^ 1);
  }
}

double SpringForces::energy(const double* x) const {
  const int threads = this->threads();
  if (threads <= 1) return energyRange(x, 0, 1);
  // Both cores from kParallelMinPoints (the divergence check's energy is as long as a force
  // evaluation): each part sums every group over its share of the base points; the parts' sums are
  // then added in order (round-off apart from the serial sum). No allocation: the divergence check
  // calls it step after step.
  std::array<double, kMaxParallelThreads> parts{};
  runParallel(threads,
              [&](int t) { parts[static_cast<std::size_t>(t)] = energyRange(x, t, threads); });
  double e = 0.0;
  for (int t = 0; t < threads; ++t) e += parts[static_cast<std::size_t>(t)];
  return e;
}

JELLO_VECTOR_CLONES double SpringForces::energyRange(const double* x, int part, int parts) const {
  const int n = n_;
  double e = 0.0;
  for (const SpringGroup& g : groups_) {
    double eg = 0.0;
    const auto count = static_cast<long>(g.mask.size());
    const int lo = static_cast<int>(count * part / parts),
              hi = static_cast<int>(count * (part + 1) / parts);
    // Unit stride and no branch (a missing spring's mask is 0, selected away), so the loop
    // vectorizes.
    const double* __restrict mask = g.mask.data();
    const double *xp = x + g.first, *yp = x + n + g.first, *zp = x + 2 * n + g.first;
    const double *xq = xp + g.delta, *yq = yp + g.delta, *zq = zp + g.delta;
#pragma omp simd reduction(+ : eg)
    for (int s = lo; s < hi; ++s) {
      const double dx = xq[s] - xp[s], dy = yq[s] - yp[s], dz = zq[s] - zp[s];
      const double stretch = std::sqrt(dx * dx + dy * dy + dz * dz) - g.rest;
      eg += mask[s] != 0.0 ? stretch * stretch : 0.0;  // a blend: no 0 * inf far from it
    }
    e += 0.5 * g.stiffness * eg;
  }
  return e;
}

JELLO_VECTOR_CLONES void SpringForces::addJacobian(const double* x, JacobianBlocks& out) const {
  const int n = n_;
  const int* slot = out.springSlots;  // in the order of springs(): groups, then base points
  long clamps = 0;
  for (const SpringGroup& g : groups_) {
    const double k = g.stiffness, c = g.damping;
    for (int i = 0; i < static_cast<int>(g.mask.size()); ++i) {
      if (g.mask[i] == 0.0) continue;
      const int a = g.first + i, b = a + g.delta;
      const double d[3] = {x[b] - x[a], x[n + b] - x[n + a], x[2 * n + b] - x[2 * n + a]};
      const double inv = 1.0 / std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      const double u[3] = {d[0] * inv, d[1] * inv, d[2] * inv};
      double alpha = 1.0 - g.rest * inv;
      if (out.clampCompression && alpha < 0.0) {
        alpha = 0.0;
        ++clamps;
      }
      double* Ka = out.diagK + 9 * static_cast<std::ptrdiff_t>(a);
      double* Kb = out.diagK + 9 * static_cast<std::ptrdiff_t>(b);
      double* Da = out.diagD + 9 * static_cast<std::ptrdiff_t>(a);
      double* Db = out.diagD + 9 * static_cast<std::ptrdiff_t>(b);
      for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q) {
          const int e = 3 * r + q;
          const double P = u[r] * u[q];
          const double Ke = -k * (P + alpha * ((r == q ? 1.0 : 0.0) - P));
          const double De = -c * P;
          Ka[e] += Ke;
          Kb[e] += Ke;
          Da[e] += De;
          Db[e] += De;
          out.K[slot[e]] = -Ke;      // (a,b)
          out.K[slot[9 + e]] = -Ke;  // (b,a)
          out.D[slot[e]] = -De;
          out.D[slot[9 + e]] = -De;
        }
      slot += 18;
    }
  }
  out.clamps += clamps;
}

std::vector<Spring> SpringForces::springs() const {
  std::vector<Spring> list;
  list.reserve(static_cast<std::size_t>(numSprings_));
  for (const SpringGroup& g : groups_) {
    for (int s = 0; s < static_cast<int>(g.mask.size()); ++s) {
      if (g.mask[s] != 0.0) {
        list.push_back(
            {g.first + s, g.first + s + g.delta, g.rest, g.kind, g.stiffness, g.damping});
      }
    }
  }
  return list;
}

}  // namespace jello
