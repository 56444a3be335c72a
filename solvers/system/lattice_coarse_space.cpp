#include "solvers/system/lattice_coarse_space.h"

#include <algorithm>
#include <cmath>

#include "src/base/assertions.h"
#include "src/world/lattice.h"

namespace jello {

namespace {

// Whether a coarse factor of the weights `factored` still serves `wanted` (correct's rule).
bool serves(const Eigen::VectorXd& factored, const Eigen::VectorXd& wanted) {
  if (factored.size() != wanted.size()) return false;
  const Eigen::Index n = wanted.size();
  const double *f = factored.data(), *w = wanted.data();
  long far = 0;  // counted without a branch: the loop vectorizes (a scan of every point)
#pragma omp simd reduction(+ : far)
  for (Eigen::Index p = 0; p < n; ++p) {
    far += long(std::abs(f[p] - w[p]) > 0.25 * std::max(f[p], w[p]));  // and 0 against > 0
  }
  return far == 0;
}

}  // namespace

LatticeCoarseSpace::LatticeCoarseSpace(int resolution, int nodes) {
  JELLO_ASSERT(resolution >= 2 && nodes >= 2 && nodes <= resolution,
               "a coarse space has 2 to resolution nodes per edge");
  const Lattice lattice{resolution};
  n_ = lattice.numPoints();
  node_.resize(8 * std::size_t(n_));
  weight_.resize(8 * std::size_t(n_));
  // Each lattice index's coarse cell and its place in it.
  const double scale = double(nodes - 1) / (resolution - 1);
  resolution_ = resolution;
  nodes_ = nodes;
  std::vector<int>& cell = cell_;
  std::vector<double>& place = place_;
  cell.resize(std::size_t(resolution));
  place.resize(std::size_t(resolution));
  for (int i = 0; i < resolution; ++i) {
    const double t = i * scale;
    cell[i] = std::min(static_cast<int>(t), nodes - 2);
    place[i] = t - cell[i];
  }
  for (int i = 0; i < resolution; ++i)
    for (int j = 0; j < resolution; ++j)
      for (int k = 0; k < resolution; ++k) {
        const std::size_t p = 8 * std::size_t(lattice.index(i, j, k));
        int corner = 0;
        for (int di = 0; di < 2; ++di)
          for (int dj = 0; dj < 2; ++dj)
            for (int dk = 0; dk < 2; ++dk, ++corner) {
              node_[p + corner] = ((cell[i] + di) * nodes + cell[j] + dj) * nodes + cell[k] + dk;
              weight_[p + corner] = (di ? place[i] : 1.0 - place[i]) *
                                    (dj ? place[j] : 1.0 - place[j]) *
                                    (dk ? place[k] : 1.0 - place[k]);
            }
      }
  const int size = nodes * nodes * nodes;
  base_.setZero(size, size);
  g_.setZero(size);
}

void LatticeCoarseSpace::setBase(const SparseMatrix& S) {
  JELLO_ASSERT(S.rows() == n_ && S.cols() == n_, "the coarse space's matrix has its points");
  diagonal_ = S.diagonal();
  kept_ = next_ = 0;
  base_.setZero();
  for (int j = 0; j < n_; ++j) {
    const int* nj = &node_[8 * std::size_t(j)];
    const double* wj = &weight_[8 * std::size_t(j)];
    for (SparseMatrix::InnerIterator it(S, j); it; ++it) {
      const int* ni = &node_[8 * std::size_t(it.row())];
      const double* wi = &weight_[8 * std::size_t(it.row())];
      for (int b = 0; b < 8; ++b) {
        const double s = it.value() * wj[b];
        for (int a = 0; a < 8; ++a) base_(ni[a], nj[b]) += s * wi[a];
      }
    }
  }
}

bool LatticeCoarseSpace::light(const Eigen::VectorXd& d) const {
  return (d.cwiseAbs().array() <= kLightContactRatio * diagonal_.array()).all();
}

StepResult LatticeCoarseSpace::factorFor(const Eigen::VectorXd& w, const Factor** out) {
  for (int i = 0; i < kept_; ++i) {
    if (serves(factors_[i].w, w)) {
      *out = &factors_[i];
      return StepResult::success();
    }
  }
  Factor& f = factors_[next_];
  next_ = (next_ + 1) % static_cast<int>(factors_.size());
  kept_ = std::min(kept_ + 1, static_cast<int>(factors_.size()));
  f.w.resize(0);  // no factor here until this one succeeds
  work_ = base_;
  for (int p = 0; p < n_; ++p) {
    if (w[p] == 0.0) continue;
    const int* np = &node_[8 * std::size_t(p)];
    const double* wp = &weight_[8 * std::size_t(p)];
    for (int b = 0; b < 8; ++b) {
      const double s = w[p] * wp[b];
      for (int a = 0; a < 8; ++a) work_(np[a], np[b]) += s * wp[a];
    }
  }
  f.llt.compute(work_);
  if (f.llt.info() != Eigen::Success) {
    return StepResult::failure("the coarse correction's matrix is not positive definite");
  }
  f.w = w;
  *out = &f;
  return StepResult::success();
}

StepResult LatticeCoarseSpace::correct(const Eigen::VectorXd& w, const double* d, double* delta) {
  const Factor* f = nullptr;
  if (StepResult res = factorFor(w, &f); !res.ok) return res;
  g_.setZero();
  for (int p = 0; p < n_; ++p) {
    if (d[p] == 0.0) continue;
    const double r = d[p] * delta[p];
    const int* np = &node_[8 * std::size_t(p)];
    const double* wp = &weight_[8 * std::size_t(p)];
    for (int a = 0; a < 8; ++a) g_[np[a]] -= r * wp[a];
  }
  f->llt.solveInPlace(g_);
  prolong(g_.data(), delta);
  return StepResult::success();
}

void LatticeCoarseSpace::prolong(const double* c, double* x) const {
  // P is the product of one hat-function matrix per axis (P1 (x) P1 (x) P1, each fine index on
  // its cell's two nodes), so x += P c is three one-axis passes, k, j, then i, of two
  // multiply-adds a value: at 32^3 a thirtieth of the eight gathers a point of the rows of P.
  const std::ptrdiff_t N = resolution_, g = nodes_;
  along_k_.assign(std::size_t(g * g * N), 0.0);  // [a][b][k]
  along_j_.assign(std::size_t(g * N * N), 0.0);  // [a][j][k]
  for (std::ptrdiff_t ab = 0; ab < g * g; ++ab) {
    for (std::ptrdiff_t k = 0; k < N; ++k) {
      const double* from = c + ab * g + cell_[std::size_t(k)];
      const double t = place_[std::size_t(k)];
      along_k_[std::size_t(ab * N + k)] = (1.0 - t) * from[0] + t * from[1];
    }
  }
  for (std::ptrdiff_t a = 0; a < g; ++a) {
    for (std::ptrdiff_t j = 0; j < N; ++j) {
      const double* b0 = &along_k_[std::size_t((a * g + cell_[std::size_t(j)]) * N)];
      const double* b1 = b0 + N;
      const double t = place_[std::size_t(j)];
      double* out = &along_j_[std::size_t((a * N + j) * N)];
#pragma omp simd
      for (std::ptrdiff_t k = 0; k < N; ++k) out[k] = (1.0 - t) * b0[k] + t * b1[k];
    }
  }
  for (std::ptrdiff_t i = 0; i < N; ++i) {
    const double* a0 = &along_j_[std::size_t(cell_[std::size_t(i)] * N * N)];
    const double* a1 = a0 + N * N;
    const double t = place_[std::size_t(i)];
    double* out = x + i * N * N;
#pragma omp simd
    for (std::ptrdiff_t jk = 0; jk < N * N; ++jk) out[jk] += (1.0 - t) * a0[jk] + t * a1[jk];
  }
}

}  // namespace jello
