#include "solvers/system/lattice_spectral.h"

#include <cmath>
#include <unsupported/Eigen/KroneckerProduct>
#include <vector>

#include "solvers/system/spring_laplacian.h"
#include "src/base/assertions.h"
#include "src/base/parallel.h"

namespace jello {
namespace {

// The offsets of each kind, and the springs each has on a lattice of n.
std::array<int, kSpringKinds> offsetsPerKind() {
  std::array<int, kSpringKinds> count{};
  for (const LatticeOffset& o : latticeOffsets()) ++count[std::size_t(o.kind)];
  return count;
}

}  // namespace

bool LatticeSpectral::fits(const Model& model) {
  const int n = model.latticeResolution();
  if (n < 2 || model.numPoints() != n * n * n) return false;
  const std::array<long, kSpringKinds> expected = springCountFormula(n);
  const std::array<int, kSpringKinds> offsets = offsetsPerKind();
  std::array<long, kSpringKinds> springs{};
  std::array<int, kSpringKinds> groups{};
  std::array<double, kSpringKinds> k{}, c{};
  for (const SpringGroup& g : model.springs().groups()) {
    const auto kind = std::size_t(g.kind);
    if (groups[kind] > 0 && (g.stiffness != k[kind] || g.damping != c[kind])) return false;
    k[kind] = g.stiffness;
    c[kind] = g.damping;
    ++groups[kind];
    springs[kind] += g.numSprings;
  }
  for (std::size_t kind = 0; kind < std::size_t(kSpringKinds); ++kind) {
    if (springs[kind] != expected[kind]) return false;
    if (springs[kind] > 0 && groups[kind] != offsets[kind]) return false;
  }
  return true;
}

LatticeSpectral::LatticeSpectral(const Model& model)
    : n_(model.latticeResolution()), solver_(model.latticeResolution()) {
  JELLO_ASSERT(fits(model), "the springs are the whole lattice, one stiffness per kind");
  for (const SpringGroup& g : model.springs().groups()) {
    stiffness_[std::size_t(g.kind)] = g.stiffness;
    damping_[std::size_t(g.kind)] = g.damping;
  }
}

StepResult LatticeSpectral::form(double d, double a, double b, const SpringLaplacian* laplacian) {
  std::array<double, kSpringKinds> w{};
  for (std::size_t kind = 0; kind < w.size(); ++kind) {
    w[kind] = a * damping_[kind] + b * stiffness_[kind];
  }
  const double structural = w[std::size_t(SpringKind::Structural)];
  const double face = w[std::size_t(SpringKind::FaceShear)];
  const double body = w[std::size_t(SpringKind::BodyShear)];
  const double bend = w[std::size_t(SpringKind::Bend)];
  std::vector<double> cosine(std::size_t(n_), 0.0);
  for (int i = 0; i < n_; ++i) cosine[std::size_t(i)] = std::cos(M_PI * i / n_);
  std::vector<double> lambda(std::size_t(n_) * n_ * n_);
  std::size_t p = 0;
  for (int i = 0; i < n_; ++i) {
    for (int j = 0; j < n_; ++j) {
      for (int k = 0; k < n_; ++k, ++p) {
        const double ci = cosine[std::size_t(i)], cj = cosine[std::size_t(j)],
                     ck = cosine[std::size_t(k)];
        lambda[p] = d + structural * (6.0 - 2.0 * (ci + cj + ck)) +
                    face * 4.0 * (3.0 - ci * cj - ci * ck - cj * ck) +
                    body * 8.0 * (1.0 - ci * cj * ck) +
                    bend * 4.0 * (3.0 - ci * ci - cj * cj - ck * ck);
      }
    }
  }
  if (StepResult set = solver_.setEigenvalues(lambda); !set.ok) return set;
  if (!laplacian) return StepResult::success();
  // P' in space: the Kronecker products of the path's I, L1, C and C^2 (i the slowest index).
  const int n = n_;
  SparseMatrix I(n, n), L1(n, n);
  I.setIdentity();
  for (int i = 0; i + 1 < n; ++i) {
    L1.coeffRef(i, i) += 1.0;
    L1.coeffRef(i + 1, i + 1) += 1.0;
    L1.coeffRef(i, i + 1) -= 1.0;
    L1.coeffRef(i + 1, i) -= 1.0;
  }
  const SparseMatrix C = SparseMatrix(I - 0.5 * L1), C2 = SparseMatrix(C * C);
  auto kron = [](const SparseMatrix& x, const SparseMatrix& y, const SparseMatrix& z) {
    return SparseMatrix(Eigen::kroneckerProduct(x, SparseMatrix(Eigen::kroneckerProduct(y, z))));
  };
  SparseMatrix I3(n * n * n, n * n * n);
  I3.setIdentity();
  SparseMatrix bound = d * I3;
  bound += structural * (kron(L1, I, I) + kron(I, L1, I) + kron(I, I, L1));
  bound += face * (12.0 * I3 - 4.0 * (kron(C, C, I) + kron(C, I, C) + kron(I, C, C)));
  bound += body * (8.0 * I3 - 8.0 * kron(C, C, C));
  bound += bend * (12.0 * I3 - 4.0 * (kron(C2, I, I) + kron(I, C2, I) + kron(I, I, C2)));
  SparseMatrix exact;
  laplacian->form(d, a, b, nullptr, exact);
  boundary_ = bound - exact;
  const double scale = exact.coeffs().abs().maxCoeff();
  boundary_.prune(1e-12 * scale, 1.0);
  boundary_.makeCompressed();
  return StepResult::success();
}

void LatticeSpectral::solve(double* x, int columns, int corrections) {
  const std::ptrdiff_t size = numPoints();
  solver_.solve(x, columns);
  if (corrections <= 0) return;
  first_.resize(size, columns);
  work_.resize(size, columns);
  const int* outer = boundary_.outerIndexPtr();
  const int* inner = boundary_.innerIndexPtr();
  const double* value = boundary_.valuePtr();
  // Over the points, split over the threads: each pass touches only its own rows.
  const int threads = threadsFor(size);
  auto rows = [&](const auto& body) {
    if (threads <= 1) return body(std::ptrdiff_t(0), size);
    runParallel(threads, [&](int t) { body(size * t / threads, size * (t + 1) / threads); });
  };
  for (int correction = 0; correction < corrections; ++correction) {
    // work = (P' - P) x by rows (symmetric: row p is column p), x kept as x0 on the first.
    rows([&](std::ptrdiff_t lo, std::ptrdiff_t hi) {
      for (int c = 0; c < columns; ++c) {
        const double* xc = x + c * size;
        double* out = work_.col(c).data();
        double* keep = first_.col(c).data();
        for (std::ptrdiff_t p = lo; p < hi; ++p) {
          double sum = 0.0;
          for (int i = outer[p]; i < outer[p + 1]; ++i) sum += value[i] * xc[inner[i]];
          out[p] = sum;
          if (correction == 0) keep[p] = xc[p];
        }
      }
    });
    solver_.solve(work_.data(), columns);
    rows([&](std::ptrdiff_t lo, std::ptrdiff_t hi) {  // x = x0 + P'^-1 (P' - P) x
      for (int c = 0; c < columns; ++c) {
        const double* keep = first_.col(c).data();
        const double* w = work_.col(c).data();
        double* xc = x + c * size;
        for (std::ptrdiff_t p = lo; p < hi; ++p) xc[p] = keep[p] + w[p];
      }
    });
  }
}

}  // namespace jello
