#include "solvers/linalg/diagonal_correction.h"

#include <algorithm>
#include <cstddef>
#include <string>

namespace jello {

void DiagonalCorrection::clear() {
  points_.clear();
  deltas_.clear();
  Z_.resize(0, 0);
}

StepResult DiagonalCorrection::add(const std::vector<std::pair<int, double>>& changes, int n,
                                   const Solve& solveA) {
  if (Z_.rows() != n) {  // a first change, or a new size (its factor cleared the rest)
    clear();
    Z_.resize(n, 0);
  }
  const int old = size();  // the points before, with their columns of Z; the joined after
  for (const auto& [point, delta] : changes) {  // a few dozen points: a linear search
    if (delta == 0.0) continue;
    const auto at = std::find(points_.begin(), points_.end(), point);
    if (at == points_.end()) {
      points_.push_back(point);
      deltas_.push_back(delta);
    } else {
      deltas_[static_cast<std::size_t>(at - points_.begin())] += delta;
    }
  }
  // Points whose changes cancelled (a contact that came and went) leave, with their columns.
  // Weights are sums and differences of the same few stiffnesses: they cancel exactly.
  int kept = 0, keptBefore = 0;
  for (int j = 0; j < size(); ++j) {
    if (deltas_[j] == 0.0) continue;
    if (j < old) {
      if (j != kept) Z_.col(kept) = Z_.col(j);
      ++keptBefore;
    }
    points_[kept] = points_[j];
    deltas_[kept] = deltas_[j];
    ++kept;
  }
  points_.resize(kept);
  deltas_.resize(kept);
  // The joined points' columns, three at a time.
  Z_.conservativeResize(n, kept);
  for (int j = keptBefore; j < kept; j += 3) {
    const int columns = std::min(3, kept - j);
    auto block = Z_.middleCols(j, columns);
    block.setZero();
    for (int c = 0; c < columns; ++c) block(points_[j + c], c) = 1.0;
    if (StepResult solved = solveA(block.data(), columns); !solved.ok) {
      clear();
      return solved;
    }
  }
  return factorSmallSystem();
}

StepResult DiagonalCorrection::factorSmallSystem() {
  const int k = size();
  if (k == 0) return StepResult::success();
  Eigen::MatrixXd system(k, k);  // I + U' Z D
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) system(i, j) = (i == j) + Z_(points_[i], j) * deltas_[j];
  lu_.compute(system);
  const double rcond = lu_.rcond();
  if (!(rcond > 1e-12)) {
    clear();
    return StepResult::failure("the corrected matrix is singular (reciprocal condition " +
                               std::to_string(rcond) + " of its capacitance system)");
  }
  return StepResult::success();
}

void DiagonalCorrection::apply(double* x) const {
  const int k = size();
  if (k == 0) return;
  s_.resize(k);
  for (int i = 0; i < k; ++i) s_[i] = x[points_[i]];
  s_ = lu_.solve(s_);
  for (int j = 0; j < k; ++j) s_[j] *= deltas_[j];
  Eigen::Map<Eigen::VectorXd>(x, Z_.rows()).noalias() -= Z_ * s_;
}

}  // namespace jello
