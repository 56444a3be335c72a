#include "solvers/linalg/prefactored_cholesky.h"

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "solvers/linalg/blas_headroom.h"
#include "solvers/linalg/dense_tail.h"
#include "solvers/linalg/diagonal_correction.h"
#include "solvers/linalg/single_supernodes.h"
#include "solvers/linalg/supernode_blocks.h"

namespace jello {
namespace {

// Three right-hand sides and a pad, one vector register (AVX) per point.
using Lanes = SubstitutionLanes;
// Their storage: 32-byte aligned (vector<Lanes> cannot carry Lanes' reduced alignment).
using AlignedLanes = double __attribute__((vector_size(32)));

// Doubles from one point's entries to the next in the substitutions: one right-hand side
// (T = double) uses the first, three the first three.
constexpr int kStride = kSubstitutionStride;

// Forward substitution L y = y, then backward L^T z = y, in place (point i's entries at
// yd + kStride i, `columns` of them): the supernodes before the tail push their solved values
// into the rows after them (the tail's rows included), the tail solves both triangles over
// `work` (its rows side by side), and the supernodes, last first, pull the solved values of the
// rows after them.
void substitute(int n, const SupernodeBlocks& b, int tailStart, const DenseTail& tail, int columns,
                double* work, double* yd) {
  b.forward(columns, yd);
  if (tailStart < n) {
    const int width = tail.paddedWidth();
    std::fill_n(work, static_cast<long>(columns) * width, 0.0);
    for (int i = tailStart; i < n; ++i)
      for (int c = 0; c < columns; ++c) work[c * width + i - tailStart] = yd[kStride * i + c];
    tail.forward(work, columns);
    tail.backward(work, columns);
    for (int i = tailStart; i < n; ++i)
      for (int c = 0; c < columns; ++c) yd[kStride * i + c] = work[c * width + i - tailStart];
  }
  b.backward(columns, yd);
}

}  // namespace

// Above this many entries in L the copy and its indices no longer stay in cache, and supernodal
// solves (dense blocks) win: measured over three right-hand sides at 512, 1,000, 1,728 and 4,096
// points (L of 48,000, 139,000, 340,000 and 1.1 million entries), the copy solved in 0.45, 0.65,
// 0.8 and 1.6 times CHOLMOD's time (kDefaultCopyLimit); the single-precision supernodes
// (BM_KeptFactorSolve, 2026-12-03): 38, 94 and 194 us at 8^3, 10^3 and 12^3 against the copy's
// 33, 110 and 283. The copy by supernode blocks then solved 10^3 and 12^3 in 61 and 136 us
// (single precision 89 and 181), but jello.w's contact changes, which the copy takes as
// cholmod_updown's updates copied again and the single-precision factor as a low-rank
// correction, made a projective run at 10^3 and 12^3 1.6x and 2.2x slower with the copy: the
// limit stays.
constexpr int kOrderingsMinSize = 1000;

struct PrefactoredCholesky::Impl {
  cholmod_common common{};
  cholmod_factor* symbolic = nullptr;  // analysis of the pattern, factored in place
  // After update(): a simplicial LDL' copy of the factor, modified by cholmod_updown (which
  // needs that form); the supernodal one stays for the next full factorization.
  cholmod_factor* updated = nullptr;
  bool copied = false;      // solves run over the copy, not through CHOLMOD
  bool singleCopy = false;  // solves run over the single-precision supernodes
  SingleSupernodes supernodes;
  DiagonalCorrection correction;  // the diagonal's changes on top of the single-precision factor
  std::vector<int> inversePerm;
  std::vector<AlignedLanes> lanes;
  SupernodeBlocks blocks;             // the copy's supernodes before the tail
  DenseTail tail;                     // the copy's last supernodes, when it pays (dense_tail.h)
  std::vector<double> tailBlock;      // its triangle from an updated factor, by columns
  int defaultOrderings[3] = {};       // cholmod_start's, restored for small matrices
  cholmod_dense* solution = nullptr;  // cholmod_solve2's outputs and work, kept between solves
  cholmod_dense* work1 = nullptr;
  cholmod_dense* work2 = nullptr;

  Impl() {
    cholmod_start(&common);
    common.print = 0;                        // failures are reported as StepResults
    common.supernodal = CHOLMOD_SUPERNODAL;  // measured: factors 3x faster than simplicial
    for (int m = 0; m < 3; ++m) defaultOrderings[m] = common.method[m].ordering;
  }
  ~Impl() {
    cholmod_free_dense(&solution, &common);
    cholmod_free_dense(&work1, &common);
    cholmod_free_dense(&work2, &common);
    cholmod_free_factor(&updated, &common);
    cholmod_free_factor(&symbolic, &common);
    cholmod_finish(&common);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

PrefactoredCholesky::PrefactoredCholesky(long copyLimit, bool singlePrecision)
    : impl_(std::make_unique<Impl>()), copyLimit_(copyLimit), singlePrecision_(singlePrecision) {}
PrefactoredCholesky::~PrefactoredCholesky() = default;

void PrefactoredCholesky::forgetPattern() {
  cholmod_free_factor(&impl_->updated, &impl_->common);
  cholmod_free_factor(&impl_->symbolic, &impl_->common);
  impl_->correction.clear();
  n_ = 0;
}

long PrefactoredCholesky::nonZeros() const {
  return nonZeros_;
}

// Long: CHOLMOD's analysis, the factorization and the choice of copy in the order CHOLMOD needs
// them, each return code checked.
StepResult PrefactoredCholesky::factorize(const SparseMatrix& A,
                                          const PrefactoredCholesky* samePattern) {
  Impl& s = *impl_;
  const int n = static_cast<int>(A.rows());
  n_ = 0;  // no factor until this one succeeds
  if (!A.isCompressed() || A.cols() != n) {
    return StepResult::failure("prefactored Cholesky: the matrix is not square and compressed");
  }
  cholmod_sparse view{};
  view.nrow = view.ncol = static_cast<size_t>(n);
  view.nzmax = static_cast<size_t>(A.nonZeros());
  view.p = const_cast<int*>(A.outerIndexPtr());
  view.i = const_cast<int*>(A.innerIndexPtr());
  view.x = const_cast<double*>(A.valuePtr());
  view.stype = -1;  // the lower triangle
  view.itype = CHOLMOD_INT;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = 1;
  view.packed = 1;
  if (s.symbolic && static_cast<int>(s.symbolic->n) != n) forgetPattern();
  const cholmod_factor* lent = samePattern ? samePattern->impl_->symbolic : nullptr;
  if (!s.symbolic && lent && static_cast<int>(lent->n) == n) {
    // Its ordering and supernodes (and values, overwritten below).
    s.symbolic = cholmod_copy_factor(const_cast<cholmod_factor*>(lent), &s.common);
    if (!s.symbolic || s.common.status != CHOLMOD_OK) {
      cholmod_free_factor(&s.symbolic, &s.common);
      return StepResult::failure("CHOLMOD could not copy an analysis (status " +
                                 std::to_string(s.common.status) + ")");
    }
  }
  if (!s.symbolic) {
    // From kOrderingsMinSize the ordering with the fewest entries in L of AMD, METIS and
    // CHOLMOD's nested dissection, instead of CHOLMOD's default (AMD, and METIS only when AMD
    // fills in badly): for projective's M/h^2 + L the default kept AMD at 10^3 and 12^3, whose
    // factors METIS makes 12% and 18% smaller (12^3: factorization 6.3 -> 4.0 ms), and METIS at
    // 16^3, where nested dissection factors in 18 ms against 27-30 (6% fewer entries). The
    // analysis costs about twice the default's (16^3: 70 against 38 ms; 32^3: 0.8 against
    // 0.4 s, beside 1.7 s a factorization); at 8^3, 5 against 1 ms for 7% fewer entries, more
    // than a second of projective's solves saves: the default there.
    cholmod_common& c = s.common;
    if (n >= kOrderingsMinSize) {
      c.nmethods = 3;
      c.method[0].ordering = CHOLMOD_AMD;
      c.method[1].ordering = CHOLMOD_METIS;
      c.method[2].ordering = CHOLMOD_NESDIS;
    } else {
      c.nmethods = 0;  // the default, which reads the default entries of c.method
      for (int m = 0; m < 3; ++m) c.method[m].ordering = s.defaultOrderings[m];
    }
    s.symbolic = cholmod_analyze(&view, &c);
    if (!s.symbolic || s.common.status != CHOLMOD_OK) {
      cholmod_free_factor(&s.symbolic, &s.common);
      return StepResult::failure("CHOLMOD could not analyse the matrix (status " +
                                 std::to_string(s.common.status) + ")");
    }
  }
  cholmod_free_factor(&s.updated, &s.common);  // a fresh factor: earlier updates are moot
  s.correction.clear();
  s.singleCopy = false;
  cholmod_factor* L = s.symbolic;
  if (const std::string why = blasHeadroomProblem(); !why.empty()) {
    return StepResult::resourceFailure(why);
  }
  if (!cholmod_factorize(&view, L, &s.common) || s.common.status != CHOLMOD_OK) {
    // CHOLMOD_NOT_POSDEF is a warning: the call "succeeds" with a partial factor.
    const int status = s.common.status;
    forgetPattern();
    return StepResult::failure(status == CHOLMOD_NOT_POSDEF
                                   ? "CHOLMOD: the matrix is not positive definite"
                                   : "CHOLMOD could not factor the matrix (status " +
                                         std::to_string(status) + ")");
  }
  if (!L->is_super || L->xtype != CHOLMOD_REAL) {
    forgetPattern();
    return StepResult::failure("CHOLMOD returned a factor of an unexpected kind");
  }
  const auto* super = static_cast<const int*>(L->super);
  const auto* pi = static_cast<const int*>(L->pi);
  const auto* px = static_cast<const int*>(L->px);
  const auto* values = static_cast<const double*>(L->x);
  nonZeros_ = 0;
  for (std::size_t sn = 0; sn < L->nsuper; ++sn) nonZeros_ += supernodeEntries(*L, sn);
  s.copied = nonZeros_ <= copyLimit_;
  s.singleCopy = !s.copied && singlePrecision_;
  n_ = n;
  const auto* rows = static_cast<const int*>(L->s);
  const auto* perm = static_cast<const int*>(L->Perm);
  perm_.assign(perm, perm + n);
  if (s.singleCopy) {
    s.supernodes.copy(*L, n);
    return StepResult::success();
  }
  if (!s.copied) return StepResult::success();
  // Copy the supernodes' dense column blocks into L by columns, dropping the explicit zeros
  // of merged supernodes; then transpose into L by rows. The last supernodes go to the dense
  // tail instead, when it pays.
  inverseDiagonal_.assign(static_cast<std::size_t>(n), 0.0);
  colStart_.assign(static_cast<std::size_t>(n) + 1, 0);
  colRow_.clear();
  colValue_.clear();
  tailStart_ = s.tail.copyTail(*L, n);
  s.blocks.start.clear();
  for (std::size_t sn = 0; sn < L->nsuper && super[sn] < tailStart_; ++sn) {
    s.blocks.start.push_back(super[sn]);
  }
  s.blocks.start.push_back(tailStart_);
  for (std::size_t sn = 0; sn < L->nsuper; ++sn) {
    const int first = super[sn], last = super[sn + 1];
    const int height = pi[sn + 1] - pi[sn];
    if (first >= tailStart_) {
      for (int j = first; j < last; ++j) colStart_[static_cast<std::size_t>(j) + 1] = colStart_[j];
      continue;
    }
    for (int j = first; j < last; ++j) {
      const int jj = j - first;
      const double* column = values + px[sn] + static_cast<std::ptrdiff_t>(jj) * height;
      inverseDiagonal_[static_cast<std::size_t>(j)] = 1.0 / column[jj];
      for (int ii = jj + 1; ii < height; ++ii) {
        if (column[ii] == 0.0) continue;
        colRow_.push_back(rows[pi[sn] + ii]);
        colValue_.push_back(column[ii]);
      }
      colStart_[static_cast<std::size_t>(j) + 1] = static_cast<int>(colRow_.size());
    }
  }
  blockCopy(false);
  return StepResult::success();
}

void PrefactoredCholesky::blockCopy(bool samePattern) {
  impl_->blocks.copy(n_, colStart_, colRow_, colValue_, inverseDiagonal_, samePattern);
  impl_->lanes.resize(static_cast<std::size_t>(n_));
}

// Long: the rank update by cholmod_updown and the refill of every copy of the factor it changed,
// in one transaction.
StepResult PrefactoredCholesky::addToDiagonal(const std::vector<std::pair<int, double>>& changes) {
  Impl& s = *impl_;
  if (!factored()) return StepResult::failure("prefactored Cholesky: no factor to update");
  if (changes.empty()) return StepResult::success();
  const int n = n_;
  if (s.singleCopy) {
    // Solved through the single-precision factor, unchanged (cholmod_updown would leave a
    // double simplicial factor for CHOLMOD to solve, at four times the cost).
    const StepResult added = s.correction.add(
        changes, n, [this](double* b, int columns) { return solveFactored(b, columns); });
    if (!added.ok) forgetPattern();
    return added;
  }
  if (!s.updated) {
    // A simplicial LDL' copy of the supernodal factor: the form cholmod_updown works on.
    s.updated = cholmod_copy_factor(s.symbolic, &s.common);
    if (!s.updated || s.common.status != CHOLMOD_OK ||
        !cholmod_change_factor(CHOLMOD_REAL, false, false, false, true, s.updated, &s.common) ||
        s.common.status != CHOLMOD_OK) {
      cholmod_free_factor(&s.updated, &s.common);
      return StepResult::failure("CHOLMOD could not convert the factor for an update");
    }
    const auto* perm = static_cast<const int*>(s.updated->Perm);
    s.inversePerm.assign(static_cast<std::size_t>(n), 0);
    for (int k = 0; k < n; ++k) s.inversePerm[static_cast<std::size_t>(perm[k])] = k;
  }
  // One column per changed point, sqrt(|delta|) at the point's row of the permuted matrix;
  // the increases are an update, the decreases a downdate. Columns in row order, each sorted.
  for (const bool increase : {true, false}) {
    std::vector<std::pair<int, double>> entries;
    for (const auto& [point, delta] : changes) {
      if (delta == 0.0 || (delta > 0.0) != increase) continue;
      entries.emplace_back(s.inversePerm[static_cast<std::size_t>(point)],
                           std::sqrt(std::abs(delta)));
    }
    if (entries.empty()) continue;
    std::sort(entries.begin(), entries.end());
    const auto k = static_cast<int>(entries.size());
    std::vector<int> columnStart(static_cast<std::size_t>(k) + 1),
        rowIndex(static_cast<std::size_t>(k));
    std::vector<double> value(static_cast<std::size_t>(k));
    for (int c = 0; c < k; ++c) {
      columnStart[static_cast<std::size_t>(c) + 1] = c + 1;
      rowIndex[static_cast<std::size_t>(c)] = entries[static_cast<std::size_t>(c)].first;
      value[static_cast<std::size_t>(c)] = entries[static_cast<std::size_t>(c)].second;
    }
    cholmod_sparse C{};
    C.nrow = static_cast<size_t>(n);
    C.ncol = static_cast<size_t>(k);
    C.nzmax = static_cast<size_t>(k);
    C.p = columnStart.data();
    C.i = rowIndex.data();
    C.x = value.data();
    C.stype = 0;
    C.itype = CHOLMOD_INT;
    C.xtype = CHOLMOD_REAL;
    C.dtype = CHOLMOD_DOUBLE;
    C.sorted = 1;
    C.packed = 1;
    if (!cholmod_updown(increase, &C, s.updated, &s.common) || s.common.status != CHOLMOD_OK) {
      const int status = s.common.status;
      forgetPattern();
      return StepResult::failure(status == CHOLMOD_NOT_POSDEF
                                     ? "CHOLMOD: the downdated matrix is not positive definite"
                                     : "CHOLMOD could not update the factor (status " +
                                           std::to_string(status) + ")");
    }
  }
  if (!s.copied) return StepResult::success();
  // The copy from the simplicial LDL' factor, as LL': column j scaled by sqrt(D_j); the columns
  // of the dense tail (chosen at the factorization: same ordering, and no entry of theirs lies
  // above it) into its triangle.
  const int tail = tailStart_, width = n - tail;
  s.tailBlock.assign(static_cast<std::size_t>(width) * width, 0.0);
  const cholmod_factor& L = *s.updated;
  const auto* Lp = static_cast<const int*>(L.p);
  const auto* Li = static_cast<const int*>(L.i);
  const auto* Lnz = static_cast<const int*>(L.nz);
  const auto* Lx = static_cast<const double*>(L.x);
  colStart_.assign(static_cast<std::size_t>(n) + 1, 0);
  colRow_.clear();
  colValue_.clear();
  for (int j = 0; j < n; ++j) {
    const double d = Lx[Lp[j]];
    if (!(d > 0.0)) {
      forgetPattern();
      return StepResult::failure("CHOLMOD: the updated matrix is not positive definite");
    }
    const double root = std::sqrt(d);
    inverseDiagonal_[static_cast<std::size_t>(j)] = 1.0 / root;
    if (j >= tail) {
      double* column = s.tailBlock.data() + static_cast<std::ptrdiff_t>(j - tail) * width;
      column[j - tail] = root;
      for (int q = Lp[j] + 1; q < Lp[j] + Lnz[j]; ++q) column[Li[q] - tail] = Lx[q] * root;
    } else {
      for (int q = Lp[j] + 1; q < Lp[j] + Lnz[j]; ++q) {
        if (Lx[q] == 0.0) continue;
        colRow_.push_back(Li[q]);
        colValue_.push_back(Lx[q] * root);
      }
    }
    colStart_[static_cast<std::size_t>(j) + 1] = static_cast<int>(colRow_.size());
  }
  if (tail < n) s.tail.copy(s.tailBlock.data(), width);
  blockCopy(true);  // same ordering and supernodes: the values into the blocks
  return StepResult::success();
}

StepResult PrefactoredCholesky::solve(double* b, int columns) const {
  const StepResult solved = solveFactored(b, columns);
  if (!solved.ok || impl_->correction.size() == 0) return solved;
  for (int c = 0; c < columns; ++c) impl_->correction.apply(b + static_cast<long>(c) * n_);
  return solved;
}

int PrefactoredCholesky::correctedPoints() const {
  return impl_->correction.size();
}

StepResult PrefactoredCholesky::solveFactored(double* b, int columns) const {
  Impl& s = *impl_;
  const int n = n_;
  if (s.singleCopy) {
    double* y = s.supernodes.workspace();
    for (int c = 0; c < columns; ++c) {
      for (int k = 0; k < n; ++k) y[c * n + k] = b[c * n + perm_[k]];
    }
    s.supernodes.solve(columns);
    for (int c = 0; c < columns; ++c) {
      for (int k = 0; k < n; ++k) b[c * n + perm_[k]] = y[c * n + k];
    }
    return StepResult::success();
  }
  if (!s.copied) return solveByCholmod(b, columns);
  if (columns == 1) {
    auto* y = reinterpret_cast<double*>(s.lanes.data());
    for (int k = 0; k < n; ++k) y[kStride * k] = b[perm_[k]];
    substitute(n, s.blocks, tailStart_, s.tail, 1, s.tail.workspace(), y);
    for (int k = 0; k < n; ++k) b[perm_[k]] = y[kStride * k];
    return StepResult::success();
  }
  Lanes* y = reinterpret_cast<Lanes*>(s.lanes.data());
  for (int k = 0; k < n; ++k) {
    const int p = perm_[k];
    y[k] = Lanes{b[p], columns > 1 ? b[n + p] : 0.0, columns > 2 ? b[2 * n + p] : 0.0, 0.0};
  }
  substitute(n, s.blocks, tailStart_, s.tail, columns, s.tail.workspace(),
             reinterpret_cast<double*>(y));
  for (int k = 0; k < n; ++k) {
    const int p = perm_[k];
    b[p] = y[k][0];
    if (columns > 1) b[n + p] = y[k][1];
    if (columns > 2) b[2 * n + p] = y[k][2];
  }
  return StepResult::success();
}

StepResult PrefactoredCholesky::solveByCholmod(double* b, int columns) const {
  Impl& s = *impl_;
  cholmod_dense rhs{};
  rhs.nrow = rhs.d = static_cast<size_t>(n_);
  rhs.ncol = static_cast<size_t>(columns);
  rhs.nzmax = rhs.nrow * rhs.ncol;
  rhs.x = b;
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;
  // cholmod_solve2 reuses its output and work vectors once they have the right size.
  if (!cholmod_solve2(CHOLMOD_A, s.updated ? s.updated : s.symbolic, &rhs, nullptr, &s.solution,
                      nullptr, &s.work1, &s.work2, &s.common) ||
      s.common.status != CHOLMOD_OK) {
    return StepResult::failure("the CHOLMOD solve failed (status " +
                               std::to_string(s.common.status) + ")");
  }
  const auto* x = static_cast<const double*>(s.solution->x);
  std::copy(x, x + rhs.nzmax, b);
  return StepResult::success();
}

}  // namespace jello
