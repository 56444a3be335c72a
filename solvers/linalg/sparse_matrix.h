// The sparse matrix type of the linear algebra: column-major (CHOLMOD's layout), int indices.
// The implicit systems are 3n x 3n, component-major like the state (x of every point, then y,
// then z).
#pragma once

#include <Eigen/SparseCore>

namespace jello {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

}  // namespace jello
