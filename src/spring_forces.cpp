#include "spring_forces.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace jello {

std::vector<SpringGroup> latticeSpringGroups(const Lattice& lat, double stiffness,
                                             double damping) {
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
  std::size_t longest = 0;
  for (const SpringGroup& g : groups_) {
    assert(g.delta > 0 && g.first >= 0);
    assert(g.first + static_cast<int>(g.mask.size()) + g.delta <= n_);
    numSprings_ += g.numSprings;
    longest = std::max(longest, g.mask.size());
  }
  gx_.resize(longest);
  gy_.resize(longest);
  gz_.resize(longest);
}

void SpringForces::accumulate(const double* x, const double* v, double* f) const {
  const int n = n_;
  const double* __restrict X = x;
  const double* __restrict Y = x + n;
  const double* __restrict Z = x + 2 * n;
  const double* __restrict VX = v;
  const double* __restrict VY = v + n;
  const double* __restrict VZ = v + 2 * n;
  double* __restrict FX = f;
  double* __restrict FY = f + n;
  double* __restrict FZ = f + 2 * n;
  double* __restrict gx = gx_.data();
  double* __restrict gy = gy_.data();
  double* __restrict gz = gz_.data();

  for (const SpringGroup& g : groups_) {
    const int count = static_cast<int>(g.mask.size());
    const int p0 = g.first;
    const int q0 = g.first + g.delta;
    const double k = g.stiffness, c = g.damping, L0 = g.rest;
    const double* __restrict mask = g.mask.data();
    // Pass 1: the force on each base point; it can be added in place since p runs unit-stride.
    for (int s = 0; s < count; ++s) {
      const int p = p0 + s, q = q0 + s;
      const double dx = X[q] - X[p], dy = Y[q] - Y[p], dz = Z[q] - Z[p];
      const double wx = VX[q] - VX[p], wy = VY[q] - VY[p], wz = VZ[q] - VZ[p];
      const double l2 = dx * dx + dy * dy + dz * dz;
      const double inv = 1.0 / std::sqrt(l2);
      double scale = k * (1.0 - L0 * inv) + c * (dx * wx + dy * wy + dz * wz) * (inv * inv);
      scale = mask[s] != 0.0 ? scale : 0.0;  // a select, so 0 * inf never makes a NaN
      gx[s] = scale * dx;
      gy[s] = scale * dy;
      gz[s] = scale * dz;
      FX[p] += gx[s];
      FY[p] += gy[s];
      FZ[p] += gz[s];
    }
    // Pass 2: the opposite force on the partners (a separate loop: p + delta may alias p + 1).
    for (int s = 0; s < count; ++s) {
      FX[q0 + s] -= gx[s];
      FY[q0 + s] -= gy[s];
      FZ[q0 + s] -= gz[s];
    }
  }
}

double SpringForces::energy(const double* x) const {
  const int n = n_;
  double e = 0.0;
  for (const SpringGroup& g : groups_) {
    double eg = 0.0;
    for (int s = 0; s < static_cast<int>(g.mask.size()); ++s) {
      if (g.mask[s] == 0.0) continue;
      const int p = g.first + s, q = p + g.delta;
      const double dx = x[q] - x[p], dy = x[n + q] - x[n + p], dz = x[2 * n + q] - x[2 * n + p];
      const double stretch = std::sqrt(dx * dx + dy * dy + dz * dz) - g.rest;
      eg += stretch * stretch;
    }
    e += 0.5 * g.stiffness * eg;
  }
  return e;
}

std::vector<Spring> SpringForces::springs() const {
  std::vector<Spring> list;
  list.reserve(static_cast<std::size_t>(numSprings_));
  for (const SpringGroup& g : groups_) {
    for (int s = 0; s < static_cast<int>(g.mask.size()); ++s) {
      if (g.mask[s] != 0.0) list.push_back({g.first + s, g.first + s + g.delta, g.rest, g.kind});
    }
  }
  return list;
}

}  // namespace jello
