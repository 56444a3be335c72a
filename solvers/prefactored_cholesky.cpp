#include "solvers/prefactored_cholesky.h"

#include <cholmod.h>
#ifdef __AVX__
#include <immintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "solvers/blas_headroom.h"

namespace jello {
namespace {

// Three right-hand sides and a pad, one vector register (AVX) per point.
using Lanes = double __attribute__((vector_size(32)));

// Forward substitution L y = y by rows, then backward L^T z = y by columns, in place; T is one
// double or four lanes. Each row's sum runs over four accumulators: the additions of one row
// are independent, so the loop is bound by loads, not by the adder's latency.
template <typename T>
void substitute(int n, const std::vector<int>& rowStart, const std::vector<int>& rowColumn,
                const std::vector<double>& rowValue, const std::vector<int>& colStart,
                const std::vector<int>& colRow, const std::vector<double>& colValue,
                const std::vector<double>& inverseDiagonal, T* y) {
  const auto sweep = [y](const int* index, const double* value, int begin, int end, T sum) {
    T s1 = sum - sum, s2 = s1, s3 = s1;  // zero, for both T
    int q = begin;
    for (; q + 4 <= end; q += 4) {
      sum -= value[q] * y[index[q]];
      s1 -= value[q + 1] * y[index[q + 1]];
      s2 -= value[q + 2] * y[index[q + 2]];
      s3 -= value[q + 3] * y[index[q + 3]];
    }
    for (; q < end; ++q) sum -= value[q] * y[index[q]];
    return (sum + s1) + (s2 + s3);
  };
  for (int i = 0; i < n; ++i) {
    y[i] = sweep(rowColumn.data(), rowValue.data(), rowStart[i], rowStart[i + 1], y[i]) *
           inverseDiagonal[i];
  }
  for (int j = n - 1; j >= 0; --j) {
    y[j] = sweep(colRow.data(), colValue.data(), colStart[j], colStart[j + 1], y[j]) *
           inverseDiagonal[j];
  }
}

// The supernodal substitutions over the single-precision copy: supernode k holds columns
// first[k] .. first[k+1]-1 of L, dense and by columns, over the rows rows[rowStart[k]] ..
// (the first `width` of which are its own columns), at values[valueStart[k]]. Entries are read
// as floats (half the memory traffic of CHOLMOD's doubles: these solves are bound by it) and
// every product and sum is in double. The right-hand sides are solved side by side, each
// contiguous, four rows to a vector.
struct Supernodes {
  std::vector<int> first, rowStart, rows;
  std::vector<long> valueStart;
  std::vector<float> values;
  std::vector<double> inverseDiagonal;
  int tallest = 0;           // the most rows of a supernode
  std::vector<double> work;  // a supernode's rows per right-hand side, gathered
  std::vector<double> y;     // the permuted right-hand sides
};

using Floats4 = float __attribute__((vector_size(16)));
using Doubles4 = double __attribute__((vector_size(32)));

inline Doubles4 widen(const float* p) {
#ifdef __AVX__
  return Doubles4(_mm256_cvtps_pd(_mm_loadu_ps(p)));  // one instruction, where the generic
#else                                                 // conversion below compiles to four
  Floats4 f;
  std::memcpy(&f, p, sizeof f);
  return __builtin_convertvector(f, Doubles4);
#endif
}
inline Doubles4 load(const double* p) {
  Doubles4 d;
  std::memcpy(&d, p, sizeof d);
  return d;
}
inline void store(double* p, Doubles4 d) {
  std::memcpy(p, &d, sizeof d);
}
inline double total(Doubles4 v) {
  return (v[0] + v[1]) + (v[2] + v[3]);
}

// y[i] -= sum over the q < B columns of l[q][i] a[q], i < count.
template <int B>
void subtractColumns(double* y, const float* const* l, const double* a, int count) {
  int i = 0;
  for (; i + 4 <= count; i += 4) {
    Doubles4 sum = widen(l[0] + i) * a[0];
    for (int q = 1; q < B; ++q) sum += widen(l[q] + i) * a[q];
    store(y + i, load(y + i) - sum);
  }
  for (; i < count; ++i) {
    double sum = 0.0;
    for (int q = 0; q < B; ++q) sum += double(l[q][i]) * a[q];
    y[i] -= sum;
  }
}

// out[q] = sum over i < count of l[q][i] x[i], for the q < B columns. One column runs over four
// accumulators: a single one would wait on the adder's latency at every step.
template <int B>
void dotColumns(const float* const* l, const double* x, int count, double* out) {
  constexpr int kChains = B == 1 ? 4 : 1;
  Doubles4 sum[B][kChains] = {};
  int i = 0;
  for (; i + 4 * kChains <= count; i += 4 * kChains) {
    for (int u = 0; u < kChains; ++u) {
      const Doubles4 xi = load(x + i + 4 * u);
      for (int q = 0; q < B; ++q) sum[q][u] += widen(l[q] + i + 4 * u) * xi;
    }
  }
  for (; i + 4 <= count; i += 4) {
    const Doubles4 xi = load(x + i);
    for (int q = 0; q < B; ++q) sum[q][0] += widen(l[q] + i) * xi;
  }
  for (int q = 0; q < B; ++q) {
    Doubles4 all = sum[q][0];
    for (int u = 1; u < kChains; ++u) all += sum[q][u];
    double rest = 0.0;
    for (int r = i; r < count; ++r) rest += double(l[q][r]) * x[r];
    out[q] = total(all) + rest;
  }
}

// Forward substitution L y = y; y holds `columns` right-hand sides of n entries. Each block
// of L is read once for all of them (the loops over right-hand sides are innermost but one).
void forwardSupernodal(Supernodes& f, int n, int columns) {
  const int count = static_cast<int>(f.first.size()) - 1;
  const long stride = f.tallest;
  for (int k = 0; k < count; ++k) {
    const int first = f.first[k], width = f.first[k + 1] - first;
    const int height = f.rowStart[k + 1] - f.rowStart[k], below = height - width;
    const float* L = f.values.data() + f.valueStart[k];
    const int* rows = f.rows.data() + f.rowStart[k] + width;
    const auto own = [&](int c) { return f.y.data() + static_cast<long>(c) * n + first; };
    const auto work = [&](int c) { return f.work.data() + c * stride; };
    for (int j = 0; j < width; ++j) {  // the diagonal block's triangle
      // From a multiple of four (the block's upper triangle and diagonal are stored as zeros):
      // each step then stores the very vectors the next one loads, which the processor
      // forwards; shifted by one entry a step, every load would wait for the stores.
      const int from = j & ~3;
      const float* column = L + static_cast<long>(j) * height + from;
      for (int c = 0; c < columns; ++c) {
        double* y = own(c);
        y[j] *= f.inverseDiagonal[first + j];
        const double yj = y[j];
        subtractColumns<1>(y + from, &column, &yj, width - from);
      }
    }
    for (int c = 0; c < columns; ++c) std::fill_n(work(c), below, 0.0);
    int j = 0;
    for (; j + 4 <= width; j += 4) {  // the rows below, four columns at a time
      const float* l[4];
      for (int q = 0; q < 4; ++q) l[q] = L + static_cast<long>(j + q) * height + width;
      for (int c = 0; c < columns; ++c) subtractColumns<4>(work(c), l, own(c) + j, below);
    }
    for (; j < width; ++j) {
      const float* l = L + static_cast<long>(j) * height + width;
      for (int c = 0; c < columns; ++c) subtractColumns<1>(work(c), &l, own(c) + j, below);
    }
    for (int c = 0; c < columns; ++c) {
      double* y = f.y.data() + static_cast<long>(c) * n;
      const double* t = work(c);
      for (int i = 0; i < below; ++i) y[rows[i]] += t[i];  // t holds minus the sums
    }
  }
}

// Backward substitution L' y = y, as forwardSupernodal.
void backwardSupernodal(Supernodes& f, int n, int columns) {
  const int count = static_cast<int>(f.first.size()) - 1;
  const long stride = f.tallest;
  for (int k = count - 1; k >= 0; --k) {
    const int first = f.first[k], width = f.first[k + 1] - first;
    const int height = f.rowStart[k + 1] - f.rowStart[k], below = height - width;
    const float* L = f.values.data() + f.valueStart[k];
    const int* rows = f.rows.data() + f.rowStart[k] + width;
    const auto own = [&](int c) { return f.y.data() + static_cast<long>(c) * n + first; };
    const auto work = [&](int c) { return f.work.data() + c * stride; };
    for (int c = 0; c < columns; ++c) {
      const double* y = f.y.data() + static_cast<long>(c) * n;
      double* t = work(c);
      for (int i = 0; i < below; ++i) t[i] = y[rows[i]];
    }
    double sums[4];
    int j = 0;
    for (; j + 4 <= width; j += 4) {  // the rows below, four columns at a time
      const float* l[4];
      for (int q = 0; q < 4; ++q) l[q] = L + static_cast<long>(j + q) * height + width;
      for (int c = 0; c < columns; ++c) {
        dotColumns<4>(l, work(c), below, sums);
        for (int q = 0; q < 4; ++q) own(c)[j + q] -= sums[q];
      }
    }
    for (; j < width; ++j) {
      const float* l = L + static_cast<long>(j) * height + width;
      for (int c = 0; c < columns; ++c) {
        dotColumns<1>(&l, work(c), below, sums);
        own(c)[j] -= sums[0];
      }
    }
    for (int jj = width - 1; jj >= 0; --jj) {  // the diagonal block's triangle, transposed
      const int from = jj & ~3;                // as in forwardSupernodal
      const float* column = L + static_cast<long>(jj) * height + from;
      for (int c = 0; c < columns; ++c) {
        double* y = own(c);
        dotColumns<1>(&column, y + from, width - from, sums);
        y[jj] = (y[jj] - sums[0]) * f.inverseDiagonal[first + jj];
      }
    }
  }
}

}  // namespace

// Above this many entries in L the copy and its indices no longer stay in cache, and supernodal
// solves (dense blocks) win: measured over three right-hand sides at 512, 1,000, 1,728 and 4,096
// points (L of 48,000, 139,000, 340,000 and 1.1 million entries), the copy solved in 0.45, 0.65,
// 0.8 and 1.6 times CHOLMOD's time (kDefaultCopyLimit); the single-precision supernodes in 0.65,
// -, 0.6 and 0.6 (BM_KeptFactorSolve: 50, 307 and 975 us at 8^3, 12^3, 16^3 against the copy's
// 33, 287 and 2,100).
struct PrefactoredCholesky::Impl {
  cholmod_common common{};
  cholmod_factor* symbolic = nullptr;  // analysis of the pattern, factored in place
  // After update(): a simplicial LDL' copy of the factor, modified by cholmod_updown (which
  // needs that form); the supernodal one stays for the next full factorization.
  cholmod_factor* updated = nullptr;
  bool copied = false;      // solves run over the copy, not through CHOLMOD
  bool singleCopy = false;  // solves run over the single-precision supernodes
  Supernodes supernodes;
  std::vector<int> inversePerm;
  std::vector<Lanes> lanes;
  std::vector<double> single;
  cholmod_dense* solution = nullptr;  // cholmod_solve2's outputs and work, kept between solves
  cholmod_dense* work1 = nullptr;
  cholmod_dense* work2 = nullptr;

  Impl() {
    cholmod_start(&common);
    common.print = 0;                        // failures are reported as StepResults
    common.supernodal = CHOLMOD_SUPERNODAL;  // measured: factors 3x faster than simplicial
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
  n_ = 0;
}

long PrefactoredCholesky::nonZeros() const {
  return nonZeros_;
}

StepResult PrefactoredCholesky::factorize(const SparseMatrix& A) {
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
  if (!s.symbolic) {
    s.symbolic = cholmod_analyze(&view, &s.common);
    if (!s.symbolic || s.common.status != CHOLMOD_OK) {
      cholmod_free_factor(&s.symbolic, &s.common);
      return StepResult::failure("CHOLMOD could not analyse the matrix (status " +
                                 std::to_string(s.common.status) + ")");
    }
  }
  cholmod_free_factor(&s.updated, &s.common);  // a fresh factor: earlier updates are moot
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
  for (std::size_t sn = 0; sn < L->nsuper; ++sn) {
    const long width = super[sn + 1] - super[sn], height = pi[sn + 1] - pi[sn];
    nonZeros_ += width * height - width * (width - 1) / 2;
  }
  s.copied = nonZeros_ <= copyLimit_;
  s.singleCopy = !s.copied && singlePrecision_;
  n_ = n;
  const auto* rows = static_cast<const int*>(L->s);
  const auto* perm = static_cast<const int*>(L->Perm);
  perm_.assign(perm, perm + n);
  if (s.singleCopy) {
    copySupernodes(*L);
    return StepResult::success();
  }
  if (!s.copied) return StepResult::success();
  // Copy the supernodes' dense column blocks into L by columns, dropping the explicit zeros
  // of merged supernodes; then transpose into L by rows.
  inverseDiagonal_.assign(static_cast<std::size_t>(n), 0.0);
  colStart_.assign(static_cast<std::size_t>(n) + 1, 0);
  colRow_.clear();
  colValue_.clear();
  for (std::size_t sn = 0; sn < L->nsuper; ++sn) {
    const int first = super[sn], last = super[sn + 1];
    const int height = pi[sn + 1] - pi[sn];
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
  transposeCopy();
  return StepResult::success();
}

void PrefactoredCholesky::copySupernodes(const cholmod_factor& L) {
  Supernodes& f = impl_->supernodes;
  const auto count = static_cast<std::size_t>(L.nsuper);
  const auto* super = static_cast<const int*>(L.super);
  const auto* pi = static_cast<const int*>(L.pi);
  const auto* px = static_cast<const int*>(L.px);
  const auto* rows = static_cast<const int*>(L.s);
  const auto* values = static_cast<const double*>(L.x);
  f.first.assign(super, super + count + 1);
  f.rowStart.assign(pi, pi + count + 1);
  f.rows.assign(rows, rows + pi[count]);
  f.valueStart.assign(px, px + count);
  const long size = px[count];
  f.values.resize(static_cast<std::size_t>(size));
  for (long q = 0; q < size; ++q)
    f.values[static_cast<std::size_t>(q)] = static_cast<float>(values[q]);
  f.inverseDiagonal.resize(static_cast<std::size_t>(n_));
  int tallest = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const int height = pi[k + 1] - pi[k];
    tallest = std::max(tallest, height);
    for (int j = super[k]; j < super[k + 1]; ++j) {
      const long column = px[k] + static_cast<long>(j - super[k]) * height;
      const long at = column + (j - super[k]);  // (j, j)
      f.inverseDiagonal[static_cast<std::size_t>(j)] = 1.0 / values[at];
      // The diagonal and above read as zeros (the solves run over them; CHOLMOD leaves the
      // entries above undefined).
      std::fill(f.values.begin() + column, f.values.begin() + at + 1, 0.0f);
    }
  }
  f.tallest = tallest;
  f.work.resize(3 * static_cast<std::size_t>(tallest));
  f.y.resize(3 * static_cast<std::size_t>(n_));
}

void PrefactoredCholesky::transposeCopy() {
  const int n = n_;
  rowStart_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (int r : colRow_) ++rowStart_[static_cast<std::size_t>(r) + 1];
  for (int i = 0; i < n; ++i) rowStart_[i + 1] += rowStart_[i];
  rowColumn_.resize(colRow_.size());
  rowValue_.resize(colRow_.size());
  std::vector<int> next(rowStart_.begin(), rowStart_.end() - 1);
  for (int j = 0; j < n; ++j) {
    for (int q = colStart_[j]; q < colStart_[j + 1]; ++q) {
      const int at = next[static_cast<std::size_t>(colRow_[q])]++;
      rowColumn_[at] = j;
      rowValue_[at] = colValue_[q];
    }
  }
  impl_->lanes.resize(static_cast<std::size_t>(n));
  impl_->single.resize(static_cast<std::size_t>(n));
}

StepResult PrefactoredCholesky::addToDiagonal(const std::vector<std::pair<int, double>>& changes) {
  Impl& s = *impl_;
  if (!factored()) return StepResult::failure("prefactored Cholesky: no factor to update");
  if (changes.empty()) return StepResult::success();
  const int n = n_;
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
  // The copy from the simplicial LDL' factor, as LL': column j scaled by sqrt(D_j).
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
    for (int q = Lp[j] + 1; q < Lp[j] + Lnz[j]; ++q) {
      if (Lx[q] == 0.0) continue;
      colRow_.push_back(Li[q]);
      colValue_.push_back(Lx[q] * root);
    }
    colStart_[static_cast<std::size_t>(j) + 1] = static_cast<int>(colRow_.size());
  }
  transposeCopy();
  return StepResult::success();
}

StepResult PrefactoredCholesky::solve(double* b, int columns) const {
  Impl& s = *impl_;
  const int n = n_;
  if (s.singleCopy && !s.updated) {
    double* y = s.supernodes.y.data();
    for (int c = 0; c < columns; ++c) {
      for (int k = 0; k < n; ++k) y[c * n + k] = b[c * n + perm_[k]];
    }
    forwardSupernodal(s.supernodes, n, columns);
    backwardSupernodal(s.supernodes, n, columns);
    for (int c = 0; c < columns; ++c) {
      for (int k = 0; k < n; ++k) b[c * n + perm_[k]] = y[c * n + k];
    }
    return StepResult::success();
  }
  if (!s.copied) return solveByCholmod(b, columns);
  if (columns == 1) {
    double* y = s.single.data();
    for (int k = 0; k < n; ++k) y[k] = b[perm_[k]];
    substitute(n, rowStart_, rowColumn_, rowValue_, colStart_, colRow_, colValue_, inverseDiagonal_,
               y);
    for (int k = 0; k < n; ++k) b[perm_[k]] = y[k];
    return StepResult::success();
  }
  Lanes* y = s.lanes.data();
  for (int k = 0; k < n; ++k) {
    const int p = perm_[k];
    y[k] = Lanes{b[p], columns > 1 ? b[n + p] : 0.0, columns > 2 ? b[2 * n + p] : 0.0, 0.0};
  }
  substitute(n, rowStart_, rowColumn_, rowValue_, colStart_, colRow_, colValue_, inverseDiagonal_,
             y);
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
