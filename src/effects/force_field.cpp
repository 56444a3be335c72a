#include "src/effects/force_field.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "src/base/assertions.h"
#include "src/effects/contact.h"

namespace jello {
namespace {

// Cell index and fraction along one axis for a coordinate clamped to the box. A NaN clamps to
// -2 (std::clamp would keep it, and casting it to int is undefined): a diverging state then
// reads a valid node, and the NaN reaches the divergence check through the other forces.
void locate(double coord, int res, int& cell, double& frac) {
  const double clamped = coord > kBoxHalfSize     ? kBoxHalfSize
                         : coord >= -kBoxHalfSize ? coord
                                                  : -kBoxHalfSize;
  const double s = (clamped + kBoxHalfSize) / (2.0 * kBoxHalfSize) * (res - 1);
  cell = std::min(static_cast<int>(s), res - 2);
  frac = s - cell;
}

}  // namespace

FieldForces::FieldForces(ForceField field) : field_(std::move(field)) {
  JELLO_ASSERT(field_.resolution >= 2, "a field has at least 2 nodes per axis");
  JELLO_ASSERT(field_.forces.size() == static_cast<std::size_t>(field_.resolution) *
                                           field_.resolution * field_.resolution,
               "a field holds res^3 forces");
  constant_ = field_.forces.front();
  uniform_ = std::all_of(field_.forces.begin(), field_.forces.end(),
                         [this](const Vec3& f) { return f == constant_; });
}

Vec3 FieldForces::sample(const Vec3& position) const {
  if (uniform_) return constant_;
  const int r = field_.resolution;
  int i, j, k;
  double fx, fy, fz;
  locate(position.x, r, i, fx);
  locate(position.y, r, j, fy);
  locate(position.z, r, k, fz);
  auto node = [&](int di, int dj, int dk) -> const Vec3& {
    return field_.forces[static_cast<std::size_t>(((i + di) * r + (j + dj)) * r + (k + dk))];
  };
  // Interpolate along z, then y, then x.
  auto lerp = [](const Vec3& a, const Vec3& b, double t) { return a * (1.0 - t) + b * t; };
  const Vec3 c00 = lerp(node(0, 0, 0), node(0, 0, 1), fz);
  const Vec3 c01 = lerp(node(0, 1, 0), node(0, 1, 1), fz);
  const Vec3 c10 = lerp(node(1, 0, 0), node(1, 0, 1), fz);
  const Vec3 c11 = lerp(node(1, 1, 0), node(1, 1, 1), fz);
  return lerp(lerp(c00, c01, fy), lerp(c10, c11, fy), fx);
}

void FieldForces::gradient(const Vec3& position, double out[3][3]) const {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) out[a][b] = 0.0;
  if (uniform_) return;
  const int r = field_.resolution;
  const double p[3] = {position.x, position.y, position.z};
  int cell[3];
  double frac[3];
  for (int b = 0; b < 3; ++b) locate(p[b], r, cell[b], frac[b]);
  const double perMetre = (r - 1) / (2.0 * kBoxHalfSize);  // d(frac)/d(position)
  for (int di = 0; di < 2; ++di)
    for (int dj = 0; dj < 2; ++dj)
      for (int dk = 0; dk < 2; ++dk) {
        const int corner[3] = {di, dj, dk};
        double w[3], dw[3];  // 1-D weights and their derivatives per axis
        for (int b = 0; b < 3; ++b) {
          w[b] = corner[b] ? frac[b] : 1.0 - frac[b];
          const bool clamped = p[b] < -kBoxHalfSize || p[b] > kBoxHalfSize;
          dw[b] = clamped ? 0.0 : (corner[b] ? perMetre : -perMetre);
        }
        const Vec3& F = field_.forces[static_cast<std::size_t>(
            ((cell[0] + di) * r + (cell[1] + dj)) * r + (cell[2] + dk))];
        const double grad[3] = {dw[0] * w[1] * w[2], w[0] * dw[1] * w[2], w[0] * w[1] * dw[2]};
        for (int b = 0; b < 3; ++b) {
          out[0][b] += F.x * grad[b];
          out[1][b] += F.y * grad[b];
          out[2][b] += F.z * grad[b];
        }
      }
}

void FieldForces::accumulate(const double* x, double* f, int n, int lo, int hi) const {
  if (uniform_) {
    for (int p = lo; p < hi; ++p) {
      f[p] += constant_.x;
      f[n + p] += constant_.y;
      f[2 * n + p] += constant_.z;
    }
    return;
  }
  for (int p = lo; p < hi; ++p) {
    const Vec3 F = sample({x[p], x[n + p], x[2 * n + p]});
    f[p] += F.x;
    f[n + p] += F.y;
    f[2 * n + p] += F.z;
  }
}

void FieldForces::addJacobian(const double* x, int n, JacobianBlocks& out) const {
  if (!out.includeField || uniform_) return;  // a uniform field has no gradient
  double G[3][3];
  for (int p = 0; p < n; ++p) {
    gradient(Vec3{x[p], x[n + p], x[2 * n + p]}, G);
    double* K = out.diagK + 9 * static_cast<std::ptrdiff_t>(p);
    for (int e = 0; e < 9; ++e) K[e] += G[e / 3][e % 3];
  }
}

}  // namespace jello
