// A few changed diagonal entries of a factored matrix, solved through the unchanged factor
// (the Sherman-Morrison-Woodbury identity): A + U D U' with U the unit columns of k points and D
// their changes. With Z = A^-1 U (one solve per point, once, when it joins) and x0 = A^-1 b,
//   x = x0 - Z D s,   (I + U' Z D) s = U' x0,
// a k x k system (LU: D may hold decreases). PrefactoredCholesky uses it for its large factors
// (projective's contacts at 10^3 points and up), whose single-precision supernodal solves
// cholmod_updown cannot modify: an updated factor was solved by CHOLMOD in double instead, at
// four times the cost.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <utility>
#include <vector>

#include "solvers/step_result.h"

namespace jello {

class DiagonalCorrection {
 public:
  // Solves A X = B in place for 1 to 3 columns of n entries (the unchanged factor's solve).
  using Solve = std::function<StepResult(double* b, int columns)>;

  void clear();
  int size() const { return static_cast<int>(points_.size()); }  // points changed, k

  // Adds delta to the diagonal at each (point, delta) given (a point at most once), on top of
  // the changes added since clear(): a point whose changes sum to zero leaves. Solves A for each
  // point that joins. Fails (the correction then cleared) when a solve fails or the k x k
  // system is singular: A plus the changes is.
  StepResult add(const std::vector<std::pair<int, double>>& changes, int n, const Solve& solveA);

  // x0 = A^-1 b in, (A + U D U')^-1 b out: one column of n entries.
  void apply(double* x) const;

 private:
  StepResult factorSmallSystem();

  std::vector<int> points_;     // the changed points
  std::vector<double> deltas_;  // their changes
  Eigen::MatrixXd Z_;           // n x k: column j is A^-1 at points_[j]
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  mutable Eigen::VectorXd s_;
};

}  // namespace jello
