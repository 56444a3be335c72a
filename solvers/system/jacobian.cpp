#include "solvers/system/jacobian.h"

#include <algorithm>
#include <cmath>

#include "src/base/assertions.h"

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

JacobianAssembler::JacobianAssembler(const Model& model) : model_(model) {
  const int n = model.numPoints();
  const std::vector<Spring> springs = model.springs().springs();
  // The pattern: every point's diagonal block and both off-diagonal blocks of every spring.
  std::vector<Eigen::Triplet<double, int>> entries;
  entries.reserve(9 * (static_cast<std::size_t>(n) + 2 * springs.size()));
  auto block = [&](int p, int q) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) entries.emplace_back(r * n + p, c * n + q, 0.0);
  };
  for (int p = 0; p < n; ++p) block(p, p);
  for (const Spring& s : springs) {
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
  springSlots_.reserve(18 * springs.size());
  for (const Spring& s : springs) {
    slots(springSlots_, s.a, s.b);
    slots(springSlots_, s.b, s.a);
  }
  diagSlots_.reserve(9 * static_cast<std::size_t>(n));
  for (int p = 0; p < n; ++p) slots(diagSlots_, p, p);
  diagK_.resize(9 * static_cast<std::size_t>(n));
  diagD_.resize(9 * static_cast<std::size_t>(n));
  for (int i = 0; i < 3 * n; ++i) diagonal_.push_back(slotOf(K_, i, i));
}

void JacobianAssembler::assemble(const double* x, const JacobianOptions& options) {
  // Diagonal blocks gather from many springs and from contact: into dense per-point arrays,
  // scattered into the matrices once at the end. Each off-diagonal block belongs to exactly one
  // spring, which assigns it: no zeroing, no accumulation.
  std::fill(diagK_.begin(), diagK_.end(), 0.0);
  std::fill(diagD_.begin(), diagD_.end(), 0.0);
  double* Kv = K_.valuePtr();
  double* Dv = D_.valuePtr();
  JacobianBlocks blocks;
  blocks.diagK = diagK_.data();
  blocks.diagD = diagD_.data();
  blocks.K = Kv;
  blocks.D = Dv;
  blocks.springSlots = springSlots_.data();
  blocks.clampCompression = options.clampCompression;
  blocks.includeField = options.includeField;
  blocks.velocities = options.velocities;
  blocks.includeSprings = options.includeSprings;
  const bool friction = options.velocities && model_.hasFriction();
  diagFriction_.assign(friction ? diagD_.size() : 0, 0.0);
  if (friction) blocks.diagFriction = diagFriction_.data();
  model_.addJacobian(x, blocks);
  for (std::size_t i = 0; i < diagFriction_.size(); ++i) diagD_[i] += diagFriction_[i];
  lastClamps_ = blocks.clamps;
  totalClamps_ += blocks.clamps;
  if (!options.includeSprings) return;
  for (std::size_t i = 0; i < diagSlots_.size(); ++i) {
    Kv[diagSlots_[i]] = diagK_[i];
    Dv[diagSlots_[i]] = diagD_[i];
  }
  JELLO_VALIDATE(options.includeField || isSymmetric(K_), "K is symmetric without the field");
  JELLO_VALIDATE(isSymmetric(D_), "D is symmetric");
}

double JacobianAssembler::frictionQuadratic(const double* v) const {
  if (diagFriction_.empty()) return 0.0;
  const std::ptrdiff_t n = model_.numPoints();
  double sum = 0.0;
  for (std::ptrdiff_t p = 0; p < n; ++p) {
    const double* B = diagFriction_.data() + 9 * p;
    const double u[3] = {v[p], v[n + p], v[2 * n + p]};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) sum += u[r] * B[3 * r + c] * u[c];
  }
  return sum;
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
