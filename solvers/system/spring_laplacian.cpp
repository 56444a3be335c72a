#include "solvers/system/spring_laplacian.h"

#include <algorithm>

#include "src/base/assertions.h"

namespace jello {

SpringLaplacian::SpringLaplacian(const Model& model) {
  const int n = model.numPoints();
  const std::vector<Spring> springs = model.springs().springs();
  // Stiffness and damping summed over the same triplets, so the two share one pattern.
  std::vector<Eigen::Triplet<double, int>> k, c;
  k.reserve(static_cast<std::size_t>(n) + 4 * springs.size());
  c.reserve(k.capacity());
  for (int p = 0; p < n; ++p) {
    k.emplace_back(p, p, 0.0);
    c.emplace_back(p, p, 0.0);
  }
  for (const Spring& s : springs) {
    for (auto [list, w] : {std::pair{&k, s.stiffness}, std::pair{&c, s.damping}}) {
      list->emplace_back(s.a, s.a, w);
      list->emplace_back(s.b, s.b, w);
      list->emplace_back(s.a, s.b, -w);
      list->emplace_back(s.b, s.a, -w);
    }
  }
  stiffness_.resize(n, n);
  stiffness_.setFromTriplets(k.begin(), k.end());  // sums duplicates
  stiffness_.makeCompressed();
  SparseMatrix damping(n, n);
  damping.setFromTriplets(c.begin(), c.end());
  damping.makeCompressed();
  JELLO_ASSERT(damping.nonZeros() == stiffness_.nonZeros(), "one pattern for k and c");
  damping_.assign(damping.valuePtr(), damping.valuePtr() + damping.nonZeros());
  diagonal_.assign(static_cast<std::size_t>(n), -1);
  for (int col = 0; col < n; ++col) {
    for (int i = stiffness_.outerIndexPtr()[col]; i < stiffness_.outerIndexPtr()[col + 1]; ++i) {
      if (stiffness_.innerIndexPtr()[i] == col) diagonal_[static_cast<std::size_t>(col)] = i;
    }
  }
}

void SpringLaplacian::form(double d, double a, double b, const double* extra,
                           SparseMatrix& out) const {
  if (out.nonZeros() != stiffness_.nonZeros() || out.rows() != stiffness_.rows()) {
    out = stiffness_;
  }
  const double* k = stiffness_.valuePtr();
  double* v = out.valuePtr();
  const std::size_t nnz = damping_.size();
  for (std::size_t i = 0; i < nnz; ++i) v[i] = a * damping_[i] + b * k[i];
  const std::size_t n = diagonal_.size();
  for (std::size_t p = 0; p < n; ++p) v[diagonal_[p]] += d + (extra ? extra[p] : 0.0);
}

double SpringLaplacian::dampingRatio(double d, double a, double b) const {
  const double* k = stiffness_.valuePtr();
  double ratio = 0.0;
  for (const int i : diagonal_) ratio = std::max(ratio, a * damping_[i] / (d + b * k[i]));
  return ratio;
}

}  // namespace jello
