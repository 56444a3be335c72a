// A coarse space for the points of a lattice (src/world/lattice.h): trilinear hat functions of
// the points' lattice indices on g^3 coarse nodes, P (n x g^3, eight entries a row), and the
// Galerkin correction through it of a solve with a matrix that differs from the wanted one on
// the diagonal. Projective dynamics keeps one factor of A_f = M/h^2 + L (+ the contact weights
// it has factored) while the contacts want A = A_f + D, D diagonal (solvers/methods/
// projective_integrator.h); after delta = -A_f^-1 r, the residual of A delta = -r is D delta,
// and the best correction in the span of P (the energy's minimizer there) is
//   delta += P c,   (P' A P) c = -P' D delta.
// A contact D misses is stiff only against the modes that move many points together (a face
// pressed into the floor against the whole cube's inertia m/h^2): those are smooth across the
// lattice, which P spans, while each point's own motion is held by its springs. So the factor
// need not change when a few points touch or leave.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <vector>

#include "solvers/linalg/sparse_matrix.h"
#include "solvers/step_result.h"

namespace jello {

// The coarse nodes per edge projective and Newton's seeds use (4^3 = 64), and the contacts they
// leave to the correction: a weight, or its change, under this fraction of its point's diagonal
// (a heavier one is stiff against the point's own springs, which the coarse space cannot see).
constexpr int kDefaultCoarseNodes = 4;
constexpr double kLightContactRatio = 0.5;

class LatticeCoarseSpace {
 public:
  // The points of a lattice of `resolution` points per edge, in Lattice::index order, on
  // `nodes` coarse nodes per edge (2 <= nodes <= resolution).
  LatticeCoarseSpace(int resolution, int nodes);

  int size() const { return static_cast<int>(base_.rows()); }  // g^3

  // B = P' S P for a symmetric S (n x n, both triangles): the part of P' A P that does not
  // change with the contacts. Keeps S's diagonal (what a contact's weight is weighed against)
  // and forgets the factors of the last S.
  void setBase(const SparseMatrix& S);
  const Eigen::VectorXd& baseDiagonal() const { return diagonal_; }
  // Whether a weight change d (n values) is light at every point: under kLightContactRatio of
  // the base's diagonal there.
  bool light(const Eigen::VectorXd& d) const;
  // delta += P c with (P' (S + diag(w)) P) c = -P' (d o delta): w, n weights (the wanted
  // contact weights of one coordinate); d, n differences (wanted minus factored weights); delta,
  // n values. The coarse factors of the last few w are kept and serve while the same points
  // are in contact and each weight is within a quarter of the one factored: the correction's
  // quality depends on it, not the fixed point (smooth contact's weights change a little at each
  // iteration, and a new 64 x 64 factor for each coordinate at each iteration cost a sixth of
  // projective's step). Fails when the coarse matrix is not positive definite.
  StepResult correct(const Eigen::VectorXd& w, const double* d, double* delta);
  // x += P c: c, g^3 coarse values; x, n values.
  void prolong(const double* c, double* x) const;

 private:
  // The factored P' (S + diag(w)) P of one set of weights w.
  struct Factor {
    Eigen::VectorXd w;
    Eigen::LLT<Eigen::MatrixXd> llt;
  };
  // A kept factor that serves w, or a new one in the oldest slot.
  StepResult factorFor(const Eigen::VectorXd& w, const Factor** out);

  int n_, resolution_, nodes_;
  std::vector<int> cell_;      // per lattice index along an axis: its coarse cell
  std::vector<double> place_;  // and its place in it, 0 to 1
  mutable std::vector<double> along_k_, along_j_;  // prolong's passes
  std::vector<int> node_;                          // n x 8: each point's coarse nodes
  std::vector<double> weight_;     // n x 8: their hat functions' values at the point
  Eigen::MatrixXd base_, work_;    // B, and B + P' diag(w) P
  Eigen::VectorXd diagonal_;       // S's
  std::array<Factor, 3> factors_;  // one per coordinate at most
  int kept_ = 0, next_ = 0;        // factors_ in use; the slot the next new one takes
  Eigen::VectorXd g_;
};

}  // namespace jello
