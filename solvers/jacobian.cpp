#include "solvers/jacobian.h"

#include <algorithm>
#include <cmath>

#include "src/assertions.h"

namespace jello {
namespace {

// Value index of entry (row, col) in a compressed column-major matrix that holds it.
int slotOf(const SparseMatrix& m, int row, int col) {
  const int* begin = m.innerIndexPtr() + m.outerIndexPtr()[col];
  const int* end = m.innerIndexPtr() + m.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  JELLO_ASSERT(it != end && *it == row, "the entry is in the Jacobian's pattern");
  return static_cast<int>(it - m.innerIndexPtr());
}

// block += B, both 3x3 row-major.
inline void addBlock(double* block, const double B[9]) {
  for (int e = 0; e < 9; ++e) block[e] += B[e];
}

// True when m equals its transpose to round-off (a costly check: JELLO_VALIDATE only). A matrix
// with a non-finite entry passes: that is a diverging state, which Simulation reports, not a
// structural error.
[[maybe_unused]] bool isSymmetric(const SparseMatrix& m) {
  const double scale = m.cwiseAbs().sum();
  if (!std::isfinite(scale)) return true;
  const SparseMatrix transposed = m.transpose();
  return (m - transposed).cwiseAbs().sum() <= 1e-12 * scale;
}

}  // namespace

JacobianAssembler::JacobianAssembler(const Model& model)
    : model_(model), springs_(model.springs().springs()) {
  const int n = model.numPoints();
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
  springSlots_.reserve(18 * springs_.size());
  for (const Spring& s : springs_) {
    slots(springSlots_, s.a, s.b);
    slots(springSlots_, s.b, s.a);
  }
  diagSlots_.reserve(9 * static_cast<std::size_t>(n));
  for (int p = 0; p < n; ++p) slots(diagSlots_, p, p);
  diagK_.resize(9 * static_cast<std::size_t>(n));
  diagD_.resize(9 * static_cast<std::size_t>(n));
  for (int i = 0; i < 3 * n; ++i) diagonal_.push_back(slotOf(K_, i, i));
}

void JacobianAssembler::assemble(const double* x, const double* v, const JacobianOptions& options) {
  (void)v;  // D does not depend on v: the forces are linear in v
  const int n = model_.numPoints();
  double* Kv = K_.valuePtr();
  double* Dv = D_.valuePtr();
  // Diagonal blocks gather from many springs and from contact: into dense per-point arrays,
  // scattered into the matrices once at the end. Each off-diagonal block belongs to exactly one
  // spring, which assigns it: no zeroing, no accumulation.
  std::fill(diagK_.begin(), diagK_.end(), 0.0);
  std::fill(diagD_.begin(), diagD_.end(), 0.0);

  long clamps = 0;
  for (std::size_t s = 0; s < springs_.size(); ++s) {
    const int a = springs_[s].a, b = springs_[s].b;
    const double d[3] = {x[b] - x[a], x[n + b] - x[n + a], x[2 * n + b] - x[2 * n + a]};
    const double inv = 1.0 / std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const double u[3] = {d[0] * inv, d[1] * inv, d[2] * inv};
    double alpha = 1.0 - springs_[s].rest * inv;
    if (options.clampCompression && alpha < 0.0) {
      alpha = 0.0;
      ++clamps;
    }
    const double k = springs_[s].stiffness, c = springs_[s].damping;
    const int* slot = &springSlots_[18 * s];
    double* Ka = &diagK_[9 * static_cast<std::size_t>(a)];
    double* Kb = &diagK_[9 * static_cast<std::size_t>(b)];
    double* Da = &diagD_[9 * static_cast<std::size_t>(a)];
    double* Db = &diagD_[9 * static_cast<std::size_t>(b)];
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
        Kv[slot[e]] = -Ke;      // (a,b)
        Kv[slot[9 + e]] = -Ke;  // (b,a)
        Dv[slot[e]] = -De;
        Dv[slot[9 + e]] = -De;
      }
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
    double* Kp = &diagK_[9 * static_cast<std::size_t>(p)];
    double* Dp = &diagD_[9 * static_cast<std::size_t>(p)];
    if (const auto& walls = model_.walls()) {
      const ContactConstants& kc = walls->constants();
      const double coord[3] = {xp.x, xp.y, xp.z};
      for (int axis = 0; axis < 3; ++axis) {
        if (std::abs(coord[axis]) <= kBoxHalfSize) continue;
        Kp[4 * axis] -= kc.stiffness;  // entry (axis, axis) of the block
        Dp[4 * axis] -= kc.damping;
      }
    }
    if (const auto& plane = model_.plane()) {
      const Vec3 nrm = plane->normal();
      if (dot(nrm, xp) + plane->offset() < 0.0) {
        normalBlock(nrm, -plane->constants().stiffness, B);
        addBlock(Kp, B);
        normalBlock(nrm, -plane->constants().damping, B);
        addBlock(Dp, B);
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
        addBlock(Kp, B);
        normalBlock(nrm, -kc.damping, B);
        addBlock(Dp, B);
      }
    }
    if (options.includeField && model_.field()) {
      double G[3][3];
      model_.field()->gradient(xp, G);
      addBlock(Kp, &G[0][0]);
    }
  }
  for (std::size_t i = 0; i < diagSlots_.size(); ++i) {
    Kv[diagSlots_[i]] = diagK_[i];
    Dv[diagSlots_[i]] = diagD_[i];
  }
  JELLO_VALIDATE(options.includeField || isSymmetric(K_), "K is symmetric without the field");
  JELLO_VALIDATE(isSymmetric(D_), "D is symmetric");
}

void JacobianAssembler::combine(double alpha, double beta, SparseMatrix& A) const {
  JELLO_ASSERT(A.nonZeros() == K_.nonZeros(), "A has the pattern of K");
  const double* Kv = K_.valuePtr();
  const double* Dv = D_.valuePtr();
  double* Av = A.valuePtr();
  const Eigen::Index nnz = K_.nonZeros();
  for (Eigen::Index i = 0; i < nnz; ++i) Av[i] = -alpha * Dv[i] - beta * Kv[i];
  const double m = model_.mass();
  for (int i : diagonal_) Av[i] += m;
}

}  // namespace jello
