// Solves with a symmetric matrix that the three-dimensional cosine transform (DCT-II on each
// axis of an N x N x N grid, flat index (i N + j) N + k) diagonalizes: S = Q diag(lambda) Q',
// Q's columns cos(pi a (i + 1/2)/N) cos(pi b (j + 1/2)/N) cos(pi c (k + 1/2)/N) normalized.
// A solve is a forward transform, a division by the eigenvalues and the inverse transform:
// O(n log n) with no factor, by FFTW's real-to-real transforms (REDFT10 and its inverse REDFT01),
// planned the same way in every process and split over threads by whole slabs and lines, so a
// solve gives the same bits every run and on any number of threads.
// The graph Laplacian of a path of N points (free ends) has this basis, with the eigenvalues
// 2 - 2 cos(pi a/N); solvers/system/lattice_spectral.h builds the lattice's operators on it.
#pragma once

#include <memory>
#include <vector>

#include "solvers/step_result.h"

namespace jello {

class CosineSolver {
 public:
  // For grids of n x n x n values (n >= 2).
  explicit CosineSolver(int n);
  ~CosineSolver();
  CosineSolver(const CosineSolver&) = delete;
  CosineSolver& operator=(const CosineSolver&) = delete;

  int size() const { return n_; }
  // The eigenvalues, n^3 in the grid's flat order of the frequencies (a, b, c); each > 0.
  // Fails (and keeps the last ones) when one is not positive and finite.
  StepResult setEigenvalues(const std::vector<double>& lambda);
  // x = S^-1 x for `columns` (1 to 3) grids stored one after the other (n^3 values each),
  // split over the threads of src/base/parallel.h.
  void solve(double* x, int columns);

 private:
  int n_;
  std::vector<double> inverse_;  // 1 / (lambda (2n)^3): FFTW's transforms are unnormalized
  struct Plans;
  std::unique_ptr<Plans> plans_;
};

}  // namespace jello
