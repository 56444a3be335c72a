// A Cholesky factor for many cheap solves with up to three right-hand sides: the matrices whose
// factor is kept for hundreds of solves (projective's M/h^2 + L, the projective preconditioner
// of CG). CHOLMOD factors (supernodal, the best ordering of three); the solves then run over
// a copy of the factor, in one of two forms by its size:
// - up to copyLimit entries, the supernodes before the tail as dense blocks by rows (explicit
//   zeros included; solvers/linalg/supernode_blocks.h), the three right-hand sides side by side in
//   one 4-wide vector per point; the substitutions hold eight of a supernode's columns in registers
//   while they run over its rows, so an entry of L costs one load and one multiply-add for all
//   three columns; the factor's last supernodes (at 8^3 263 of 512 columns, 61% of L) as one dense
//   triangle (solvers/linalg/dense_tail.h), read eight entries to a vector. BM_KeptFactorSolve
//   measures it against CHOLMOD's own solve (experiments/results/kept_factor.json, the table in
//   solvers/README.md).
// - above (10^3 points and more: the copy and its indices no longer stay in cache), CHOLMOD's
//   dense supernodes copied in single precision and solved by our own blocked substitutions
//   (solvers/linalg/single_supernodes.h),
//   every product and sum in double: these solves are bound by memory traffic, which the floats
//   halve (BM_KeptFactorSolve/single against /cholmod). The
//   answer is that of a factor rounded to single precision (about 1e-7 relative times the
//   condition number): what a preconditioner or projective's fixed-point iterations need, whose
//   residuals are evaluated in double. singlePrecision = false solves these by CHOLMOD.
// After addToDiagonal, single-precision factors are solved with a low-rank correction, the others
// over CHOLMOD's updates of a simplicial copy (copied again, the dense tail too; large ones by
// CHOLMOD) until the next factorize.
// Solves allocate nothing after the first.
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "solvers/linalg/sparse_matrix.h"
#include "solvers/step_result.h"

namespace jello {

class PrefactoredCholesky {
 public:
  // Factors with more entries than copyLimit are solved by CHOLMOD (the default: measured).
  static constexpr long kDefaultCopyLimit = 100000;
  // singlePrecision: larger factors are solved over a single-precision copy of CHOLMOD's
  // supernodes (every operation in double) instead of by CHOLMOD itself.
  explicit PrefactoredCholesky(long copyLimit = kDefaultCopyLimit, bool singlePrecision = true);
  ~PrefactoredCholesky();
  PrefactoredCholesky(const PrefactoredCholesky&) = delete;
  PrefactoredCholesky& operator=(const PrefactoredCholesky&) = delete;

  // Factors the symmetric positive definite A (its lower triangle is read). The ordering is
  // computed on the first call and kept: every later A must have the same pattern until
  // forgetPattern(). A failure (not positive definite, out of memory) leaves no factor.
  // samePattern, a factored PrefactoredCholesky of a matrix with A's pattern, lends its
  // analysis to a first call instead of a new one (projective's three coordinates: at 16^3 an
  // analysis costs about six factorizations).
  StepResult factorize(const SparseMatrix& A, const PrefactoredCholesky* samePattern = nullptr);
  void forgetPattern();
  bool factored() const { return n_ > 0; }
  int size() const { return n_; }
  long nonZeros() const;  // entries of L, diagonal included

  // A + diag(delta) in place of A, for the (point, delta) pairs given (a point at most once),
  // instead of a new factorization: CHOLMOD's rank-one updates (delta > 0) and downdates
  // (delta < 0) of a simplicial copy of the factor (cholmod_updown); for the single-precision
  // supernodes a low-rank correction solved through the unchanged factor
  // (solvers/linalg/diagonal_correction.h: one solve for each point that joins it). The matrix must
  // stay positive definite; a failure leaves no factor.
  StepResult addToDiagonal(const std::vector<std::pair<int, double>>& changes);
  // The points whose diagonal differs from the factored matrix's by a low-rank correction (0
  // when updates went into the factor itself): each costs every solve a gather and an axpy.
  int correctedPoints() const;

  // Solves A X = B in place: b holds `columns` (1 to 3) right-hand sides of size() entries one
  // after the other, and receives the solutions. Fails only when CHOLMOD's own solve does
  // (large factors), with its status.
  StepResult solve(double* b, int columns) const;

 private:
  struct Impl;  // CHOLMOD's common and symbolic factor, the solves' work vectors
  std::unique_ptr<Impl> impl_;
  long copyLimit_;
  bool singlePrecision_;
  StepResult solveFactored(double* b, int columns) const;  // the factor, without corrections
  StepResult solveByCholmod(double* b, int columns) const;
  // The supernodes before the tail as dense blocks, from L by columns; samePattern: into the
  // blocks of the last call when every entry falls in them (after an update).
  void blockCopy(bool samePattern);
  int n_ = 0;
  long nonZeros_ = 0;
  std::vector<int> perm_;  // row k of the factor is point perm_[k]
  int tailStart_ = 0;      // the copy's columns from here on are the dense tail's
  std::vector<double> inverseDiagonal_;
  // Strictly lower L by columns, the columns before the tail (blockCopy's source).
  std::vector<int> colStart_, colRow_;
  std::vector<double> colValue_;
};

}  // namespace jello
