// PrefactoredCholesky (solvers/linalg/prefactored_cholesky.h): its own substitutions over CHOLMOD's
// factor solve the system, for one to three right-hand sides, after refactoring with new
// values, and refuse a matrix that is not positive definite.
#include "solvers/linalg/prefactored_cholesky.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "solvers/linalg/dense_tail.h"
#include "solvers/linalg/linear_solver.h"
#include "src/model.h"
#include "src/world/scene_builder.h"
#include "tests/test_support.h"

namespace jello {
namespace {

// diag + the springs' weighted Laplacian of a 6^3 jello cube, weights varied per spring.
SparseMatrix laplacianSystem(const Model& model, double diagonal, double spread) {
  std::vector<Eigen::Triplet<double, int>> entries;
  const int n = model.numPoints();
  for (int p = 0; p < n; ++p) entries.emplace_back(p, p, diagonal * (1.0 + 0.01 * p));
  int i = 0;
  for (const Spring& s : model.springs().springs()) {
    const double w = s.stiffness * (1.0 + spread * ((i++ % 7) - 3));
    entries.emplace_back(s.a, s.a, w);
    entries.emplace_back(s.b, s.b, w);
    entries.emplace_back(s.a, s.b, -w);
    entries.emplace_back(s.b, s.a, -w);
  }
  SparseMatrix A(n, n);
  A.setFromTriplets(entries.begin(), entries.end());
  A.makeCompressed();
  return A;
}

// The three ways a factor is solved: over the double-precision copy (small factors), over the
// single-precision supernodes (large ones: copyLimit 0), by CHOLMOD itself (large ones without
// single precision, and any factor after addToDiagonal while large). Single precision answers
// to about 1e-7 relative (the factor's rounding times A's condition number, which is modest
// here), and its solves are checked to that.
struct Way {
  long copyLimit;
  bool single;
  double tolerance;  // of the relative residual
};
class PrefactoredCholeskyBothWays : public testing::TestWithParam<Way> {
 protected:
  double tolerance() const { return GetParam().tolerance; }
};

TEST_P(PrefactoredCholeskyBothWays, SolvesOneTwoAndThreeRightHandSides) {
  const Model model(resampleCube(test::loadWorld("jello.w"), 6));
  const int n = model.numPoints();
  PrefactoredCholesky factor(GetParam().copyLimit, GetParam().single);
  EXPECT_FALSE(factor.factored());
  for (double spread : {0.0, 0.2}) {  // the second: new values in the same pattern
    const SparseMatrix A = laplacianSystem(model, 3.0, spread);
    ASSERT_TRUE(factor.factorize(A).ok);
    EXPECT_EQ(factor.size(), n);
    EXPECT_GE(factor.nonZeros(), (A.nonZeros() + n) / 2);  // at least A's lower triangle
    const Eigen::MatrixXd dense(A);
    for (int columns = 1; columns <= 3; ++columns) {
      SCOPED_TRACE(columns);
      const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, columns);
      Eigen::MatrixXd X = B;
      ASSERT_TRUE(factor.solve(X.data(), columns).ok);
      EXPECT_LT((dense * X - B).norm(), tolerance() * B.norm() * dense.norm());
      const Eigen::MatrixXd expected = dense.llt().solve(B);
      EXPECT_LT((X - expected).norm(), 100 * tolerance() * expected.norm());
    }
  }
}

// A factor that borrows another's analysis (projective's coordinates share one pattern) gives
// the answer of its own: the same entries in L, the same solutions to round-off; and the lender
// is left as it was.
TEST_P(PrefactoredCholeskyBothWays, BorrowsAnotherFactorsAnalysis) {
  const Model model(resampleCube(test::loadWorld("jello.w"), 6));
  const int n = model.numPoints();
  const SparseMatrix A = laplacianSystem(model, 3.0, 0.0);
  SparseMatrix B = laplacianSystem(model, 3.0, 0.2);        // same pattern, other values
  for (int p = 0; p < n; p += 5) B.coeffRef(p, p) += 50.0;  // as contact weights
  PrefactoredCholesky lender(GetParam().copyLimit, GetParam().single);
  PrefactoredCholesky borrower(GetParam().copyLimit, GetParam().single);
  PrefactoredCholesky own(GetParam().copyLimit, GetParam().single);
  ASSERT_TRUE(lender.factorize(A).ok);
  ASSERT_TRUE(borrower.factorize(B, &lender).ok);
  ASSERT_TRUE(own.factorize(B).ok);
  EXPECT_EQ(borrower.nonZeros(), own.nonZeros());
  const Eigen::MatrixXd R = Eigen::MatrixXd::Random(n, 3);
  Eigen::MatrixXd borrowed = R, fresh = R, lent = R;
  ASSERT_TRUE(borrower.solve(borrowed.data(), 3).ok);
  ASSERT_TRUE(own.solve(fresh.data(), 3).ok);
  ASSERT_TRUE(lender.solve(lent.data(), 3).ok);
  const Eigen::MatrixXd denseB(B), denseA(A);
  EXPECT_LT((denseB * borrowed - R).norm(), tolerance() * R.norm() * denseB.norm());
  EXPECT_LT((borrowed - fresh).norm(), 10 * tolerance() * fresh.norm());
  EXPECT_LT((denseA * lent - R).norm(), tolerance() * R.norm() * denseA.norm());
  EXPECT_GT((borrowed - lent).norm(), 1e-3 * lent.norm());  // two matrices, two answers
}

TEST_P(PrefactoredCholeskyBothWays, RefusesAMatrixThatIsNotPositiveDefinite) {
  const Model model(resampleCube(test::loadWorld("jello.w"), 4));
  PrefactoredCholesky factor(GetParam().copyLimit, GetParam().single);
  ASSERT_TRUE(factor.factorize(laplacianSystem(model, 1.0, 0.0)).ok);
  // A Laplacian alone is singular; minus the identity it is indefinite.
  const StepResult result = factor.factorize(laplacianSystem(model, -1.0, 0.0));
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.message.find("not positive definite"), std::string::npos) << result.message;
  EXPECT_FALSE(factor.factored());
  // and recovers: the same pattern factors again, as does another size.
  EXPECT_TRUE(factor.factorize(laplacianSystem(model, 1.0, 0.0)).ok);
  const Model bigger(resampleCube(test::loadWorld("jello.w"), 5));
  ASSERT_TRUE(factor.factorize(laplacianSystem(bigger, 1.0, 0.0)).ok);
  EXPECT_EQ(factor.size(), bigger.numPoints());
}

// Rank-one updates and downdates of the diagonal (cholmod_updown) solve A + diag(delta) as a new
// factorization would, over several rounds, and a full factorization afterwards starts afresh.
TEST_P(PrefactoredCholeskyBothWays, UpdatesAndDowndatesTheDiagonal) {
  const Model model(resampleCube(test::loadWorld("jello.w"), 6));
  const int n = model.numPoints();
  const SparseMatrix A = laplacianSystem(model, 3.0, 0.1);
  PrefactoredCholesky factor(GetParam().copyLimit, GetParam().single);
  ASSERT_TRUE(factor.factorize(A).ok);
  Eigen::MatrixXd dense(A);
  for (int round = 0; round < 3; ++round) {
    SCOPED_TRACE(round);
    std::vector<std::pair<int, double>> changes;
    for (int p = round; p < n; p += 17) {
      const double delta = (p % 2 == 0) ? 50.0 : -1.0;  // stays positive definite
      changes.emplace_back(p, delta);
      dense(p, p) += delta;
    }
    ASSERT_TRUE(factor.addToDiagonal(changes).ok);
    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, 3);
    Eigen::MatrixXd X = B;
    ASSERT_TRUE(factor.solve(X.data(), 3).ok);
    // Each way to its own precision (a fixed 1e-11 let single precision pass where double was
    // asked for), and to the dense factorization's answer.
    EXPECT_LT((dense * X - B).norm(), tolerance() * B.norm() * dense.norm());
    const Eigen::MatrixXd expected = dense.llt().solve(B);
    EXPECT_LT((X - expected).norm(), 100 * tolerance() * expected.norm());
  }
  ASSERT_TRUE(factor.factorize(A).ok);  // the original again, from scratch
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, 1);
  Eigen::MatrixXd X = B;
  ASSERT_TRUE(factor.solve(X.data(), 1).ok);
  EXPECT_LT((Eigen::MatrixXd(A) * X - B).norm(), 10 * tolerance() * B.norm() * dense.norm());
}

// The dense tail (solvers/linalg/dense_tail.h) on its own: a lower triangle of 21 columns (two
// whole panels and a padded one) solves L y = b and L' y = b like Eigen's triangular solves, one to
// three right-hand sides at once.
// Issue 41 (low): a failed solve said "relative residual -nan".
TEST(LinearSolverMessages, AResidualIsDescribedOrWhyItCannotBe) {
  EXPECT_EQ(describeResidual(1e-3, 10.0), "relative residual 0.0001");
  EXPECT_EQ(describeResidual(std::nan(""), 1.0),
            "the residual is not finite: the solution holds NaN or infinity");
  EXPECT_EQ(describeResidual(2.0, 0.0), "residual 2 against a right-hand side of norm 0");
  EXPECT_EQ(describeResidual(std::numeric_limits<double>::infinity(), 0.0).find("nan"),
            std::string::npos);
}

TEST(DenseTail, SolvesBothTrianglesLikeEigen) {
  const int w = 21;
  Eigen::MatrixXd L = Eigen::MatrixXd::Random(w, w).triangularView<Eigen::StrictlyLower>();
  L.diagonal() = Eigen::VectorXd::LinSpaced(w, 2.0, 5.0);
  DenseTail tail;
  tail.copy(L.data(), w);
  ASSERT_EQ(tail.paddedWidth(), 24);
  for (int columns = 1; columns <= 3; ++columns) {
    SCOPED_TRACE(columns);
    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(w, columns);
    Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(tail.paddedWidth(), columns);
    Y.topRows(w) = B;
    tail.forward(Y.data(), columns);
    const Eigen::MatrixXd forward = L.triangularView<Eigen::Lower>().solve(B);
    EXPECT_LE((Y.topRows(w) - forward).cwiseAbs().maxCoeff(),
              1e-12 * forward.cwiseAbs().maxCoeff());
    EXPECT_EQ(Y.bottomRows(3).cwiseAbs().maxCoeff(), 0.0);  // the padding stays zero
    Y.topRows(w) = B;
    tail.backward(Y.data(), columns);
    const Eigen::MatrixXd backward = L.transpose().triangularView<Eigen::Upper>().solve(B);
    EXPECT_LE((Y.topRows(w) - backward).cwiseAbs().maxCoeff(),
              1e-12 * backward.cwiseAbs().maxCoeff());
  }
}

// The single-precision factor takes diagonal changes as a low-rank correction solved through
// it (solvers/linalg/diagonal_correction.h): as close to a factorization of the changed matrix as
// the factor itself is to the original, over rounds that add points, change them again and take
// some back out (the correction then shrinks), and cleared by the next factorization.
TEST(PrefactoredCholesky, SinglePrecisionFactorsSolveDiagonalChangesThroughACorrection) {
  const Model model(resampleCube(test::loadWorld("jello.w"), 6));
  const int n = model.numPoints();
  const SparseMatrix A = laplacianSystem(model, 3.0, 0.1);
  PrefactoredCholesky factor(0, true);  // single precision at any size
  ASSERT_TRUE(factor.factorize(A).ok);
  Eigen::MatrixXd dense(A);
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, 3);
  const auto relativeError = [&](int columns) {
    Eigen::MatrixXd X = B.leftCols(columns);
    EXPECT_TRUE(factor.solve(X.data(), columns).ok);
    const Eigen::MatrixXd exact = dense.llt().solve(B.leftCols(columns));
    return (X - exact).norm() / exact.norm();
  };
  const double unchanged = relativeError(3);
  EXPECT_LT(unchanged, 1e-6);
  const std::vector<std::vector<std::pair<int, double>>> rounds = {
      {{3, 5e3}, {40, 5e3}, {41, 5e3}, {100, 2e4}, {215, 5e3}},  // contacts arrive
      {{40, -5e3}, {7, 1e4}, {100, 3e3}, {41, -2.0}},            // one leaves, one more
      {{3, -5e3}, {7, -1e4}, {215, -5e3}},                       // three leave
  };
  const int sizes[] = {5, 5, 2};  // points corrected after each round (41 and 100 at the end)
  for (std::size_t r = 0; r < rounds.size(); ++r) {
    SCOPED_TRACE(r);
    ASSERT_TRUE(factor.addToDiagonal(rounds[r]).ok);
    for (const auto& [p, delta] : rounds[r]) dense(p, p) += delta;
    EXPECT_EQ(factor.correctedPoints(), sizes[r]);
    for (int columns = 1; columns <= 3; ++columns) {
      EXPECT_LT(relativeError(columns), std::max(1e-7, 3 * unchanged)) << columns;
    }
  }
  dense = Eigen::MatrixXd(A);
  ASSERT_TRUE(factor.factorize(A).ok);  // from scratch: the correction goes
  EXPECT_EQ(factor.correctedPoints(), 0);
  EXPECT_LT(relativeError(3), std::max(1e-7, 3 * unchanged));
}

INSTANTIATE_TEST_SUITE_P(CopySingleAndCholmod, PrefactoredCholeskyBothWays,
                         testing::Values(Way{PrefactoredCholesky::kDefaultCopyLimit, true, 1e-12},
                                         Way{0, true, 1e-7}, Way{0, false, 1e-12}));

// projective's own matrix at 12^3 (supernodes up to hundreds of columns wide, the blocked
// loops and their remainders all run): the single-precision supernodes solve one to three
// right-hand sides as CHOLMOD does, to single precision, and the residual is that small.
TEST(PrefactoredCholesky, SinglePrecisionSupernodesAgreeWithCholmod) {
  const Model model(resampleCube(test::loadWorld("jello.w"), 12));
  const int n = model.numPoints();
  const SparseMatrix A = laplacianSystem(model, model.mass() / 1e-4, 0.2);
  PrefactoredCholesky single(0, true), cholmod(0, false);
  ASSERT_TRUE(single.factorize(A).ok);
  ASSERT_TRUE(cholmod.factorize(A).ok);
  for (int columns = 1; columns <= 3; ++columns) {
    SCOPED_TRACE(columns);
    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, columns);
    Eigen::MatrixXd X = B, Y = B;
    ASSERT_TRUE(single.solve(X.data(), columns).ok);
    ASSERT_TRUE(cholmod.solve(Y.data(), columns).ok);
    EXPECT_LT((X - Y).norm(), 1e-6 * Y.norm());
    EXPECT_GT((X - Y).norm(), 0.0);  // not CHOLMOD's answer passed through
    EXPECT_LT((A * X - B).norm(), 1e-6 * B.norm());
  }
}

}  // namespace
}  // namespace jello
