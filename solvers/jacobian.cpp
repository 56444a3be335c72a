#include "jacobian.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace jello {
namespace {

// Value index of entry (row, col) in a compressed column-major matrix that holds it.
int slotOf(const SparseMatrix& m, int row, int col) {
  const int* begin = m.innerIndexPtr() + m.outerIndexPtr()[col];
  const int* end = m.innerIndexPtr() + m.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  assert(it != end && *it == row);
  return static_cast<int>(it - m.innerIndexPtr());
}

// Adds sign * B (3x3, row-major) into the 9 slots starting at `slots`.
inline void addBlock(double* values, const int* slots, const double B[9], double sign) {
  for (int e = 0; e < 9; ++e) values[slots[e]] += sign * B[e];
}

}  // namespace

JacobianAssembler::JacobianAssembler(const Model& model) : model_(model) {
  const int n = model.numPoints();
  for (const SpringGroup& g : model.springs().groups()) {
    for (int s = 0; s < static_cast<int>(g.mask.size()); ++s) {
      if (g.mask[s] == 0.0) continue;
      springs_.push_back({g.first + s, g.first + s + g.delta, g.rest, g.kind});
      stiffness_.push_back(g.stiffness);
      damping_.push_back(g.damping);
    }
  }
  // The pattern: every point's diagonal block and both off-diagonal blocks of every spring.
  std::vector<Eigen::Triplet<double, int>> entries;
  entries.reserve(9 * (static_cast<std::size_t>(n) + 2 * springs_.size()));
  auto block = [&](int p, int q) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) entries.emplace_back(r * n + p, c * n + q, 0.0);
  };
  for (int p = 0; p < n; ++p) block(p, p);
  for (const Spring& s : springs_) {
    block(s.a, s.b);
    block(s.b, s.a);
  }
  K_.resize(3 * n, 3 * n);
  K_.setFromTriplets(entries.begin(), entries.end());
  K_.makeCompressed();
  D_ = K_;

  auto slots = [&](std::vector<int>& out, int p, int q) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) out.push_back(slotOf(K_, r * n + p, c * n + q));
  };
  springSlots_.reserve(36 * springs_.size());
  for (const Spring& s : springs_) {
    slots(springSlots_, s.a, s.a);
    slots(springSlots_, s.b, s.b);
    slots(springSlots_, s.a, s.b);
    slots(springSlots_, s.b, s.a);
  }
  diagSlots_.reserve(9 * static_cast<std::size_t>(n));
  for (int p = 0; p < n; ++p) slots(diagSlots_, p, p);
  for (int i = 0; i < 3 * n; ++i) diagonal_.push_back(slotOf(K_, i, i));
}

void JacobianAssembler::assemble(const double* x, const double* v,
                                 const JacobianOptions& options) {
  (void)v;  // D does not depend on v: the forces are linear in v
  const int n = model_.numPoints();
  double* Kv = K_.valuePtr();
  double* Dv = D_.valuePtr();
  std::fill(Kv, Kv + K_.nonZeros(), 0.0);
  std::fill(Dv, Dv + D_.nonZeros(), 0.0);

  long clamps = 0;
  for (std::size_t s = 0; s < springs_.size(); ++s) {
    const int a = springs_[s].a, b = springs_[s].b;
    const double d[3] = {x[b] - x[a], x[n + b] - x[n + a], x[2 * n + b] - x[2 * n + a]};
    const double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const double u[3] = {d[0] / l, d[1] / l, d[2] / l};
    double alpha = 1.0 - springs_[s].rest / l;
    if (options.clampCompression && alpha < 0.0) {
      alpha = 0.0;
      ++clamps;
    }
    const double k = stiffness_[s], c = damping_[s];
    double Ke[9], De[9];
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) {
        const double P = u[r] * u[q];
        Ke[3 * r + q] = -k * (P + alpha * ((r == q ? 1.0 : 0.0) - P));
        De[3 * r + q] = -c * P;
      }
    const int* slot = &springSlots_[36 * s];
    addBlock(Kv, slot, Ke, 1.0);
    addBlock(Kv, slot + 9, Ke, 1.0);
    addBlock(Kv, slot + 18, Ke, -1.0);
    addBlock(Kv, slot + 27, Ke, -1.0);
    addBlock(Dv, slot, De, 1.0);
    addBlock(Dv, slot + 9, De, 1.0);
    addBlock(Dv, slot + 18, De, -1.0);
    addBlock(Dv, slot + 27, De, -1.0);
  }
  lastClamps_ = clamps;
  totalClamps_ += clamps;

  // Contact and field: the point's own diagonal block.
  auto normalBlock = [](const Vec3& nrm, double scale, double out[9]) {
    const double u[3] = {nrm.x, nrm.y, nrm.z};
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) out[3 * r + q] = scale * u[r] * u[q];
  };
  double B[9];
  for (int p = 0; p < n; ++p) {
    const Vec3 xp{x[p], x[n + p], x[2 * n + p]};
    const int* slot = &diagSlots_[9 * p];
    if (const auto& walls = model_.walls()) {
      const ContactConstants& kc = walls->constants();
      const double coord[3] = {xp.x, xp.y, xp.z};
      for (int axis = 0; axis < 3; ++axis) {
        if (std::abs(coord[axis]) <= kBoxHalfSize) continue;
        Kv[slot[4 * axis]] -= kc.stiffness;  // entry (axis, axis) of the block
        Dv[slot[4 * axis]] -= kc.damping;
      }
    }
    if (const auto& plane = model_.plane()) {
      const Vec3 nrm = plane->normal();
      if (dot(nrm, xp) + plane->offset() < 0.0) {
        normalBlock(nrm, -plane->constants().stiffness, B);
        addBlock(Kv, slot, B, 1.0);
        normalBlock(nrm, -plane->constants().damping, B);
        addBlock(Dv, slot, B, 1.0);
      }
    }
    if (const auto& sphere = model_.sphere()) {
      const Vec3 r = xp - sphere->sphere().center;
      const double l = norm(r), R = sphere->sphere().radius;
      if (l < R && l > 0.0) {
        const Vec3 nrm = r * (1.0 / l);
        const ContactConstants& kc = sphere->constants();
        // -kc n n^T, plus (unclamped only) the curvature term kc (R/l - 1)(I - n n^T).
        const double t = options.clampCompression ? 0.0 : kc.stiffness * (R / l - 1.0);
        normalBlock(nrm, -kc.stiffness - t, B);
        for (int e = 0; e < 3; ++e) B[4 * e] += t;
        addBlock(Kv, slot, B, 1.0);
        normalBlock(nrm, -kc.damping, B);
        addBlock(Dv, slot, B, 1.0);
      }
    }
    if (options.includeField && model_.field()) {
      double G[3][3];
      model_.field()->gradient(xp, G);
      addBlock(Kv, slot, &G[0][0], 1.0);
    }
  }
}

void JacobianAssembler::combine(double alpha, double beta, SparseMatrix& A) const {
  assert(A.nonZeros() == K_.nonZeros());
  const double* Kv = K_.valuePtr();
  const double* Dv = D_.valuePtr();
  double* Av = A.valuePtr();
  const Eigen::Index nnz = K_.nonZeros();
  for (Eigen::Index i = 0; i < nnz; ++i) Av[i] = -alpha * Dv[i] - beta * Kv[i];
  const double m = model_.mass();
  for (int i : diagonal_) Av[i] += m;
}

}  // namespace jello
