// projective: backward Euler by the prefactored local/global iterations of projective dynamics
// (Liu et al. 2013, "Fast Simulation of Mass-Spring Systems"; Bouaziz et al. 2014). The step is
// the minimizer of the same incremental potential as `implicit`,
//   E(x) = 1/(2h^2) |x - y|_M^2 + U(x),   y = x0 + h v0,
// with each spring's energy k/2 |(x_b - x_a) - d|^2 minimized over directions d of length L0
// and each violated contact's kc/2 |x - p|^2 over points p of the free side. One iteration:
//   local   every spring projects to its rest length, d = L0 u; every point on a solid side
//           projects onto the surface, p (both happen inside the model's force evaluation:
//           f_spring = -L x + sum k (e_b - e_a) d and f_contact = -W (x - p), exactly);
//   global  (M/h^2 + L + W) x_next = M y/h^2 + sum k (e_b - e_a) d + W p + f_other,
// which is one solve per coordinate with a matrix that depends only on the springs, h and the
// contact set:
//   x_next = x - A^-1 r(x),   r(x) = M (x - y)/h^2 - f(x, (x - x0)/h)   (backward Euler's
//   residual), A_c = M/h^2 + L (+ L_c/h) + W_c,  L = sum_s k_s (e_a - e_b)(e_a - e_b)^T (the
//   spring Laplacian), L_c the same with the springs' damping c_s,
// W_c diagonal: kc (+ dc/h) for each wall a point violates along coordinate c (its exact Hessian
// and its damping's over h), and the same for each plane or sphere contact on all three
// coordinates (kc I >= kc n n^T, so every iteration still lowers the projective energy); L_c/h
// and dc/h only under heavy damping (below). The residual r is exact whatever W is, so W
// only has to cover the contacts (ProjectiveOptions::coverContacts, off by default) (W_c >= each
// contact's Hessian: a contact W misses can make the iteration diverge, a weight on a free point
// only slows it): W is planned at the step's start to cover the contacts at x0, at y and a step
// beyond (a point about to touch is covered before it does), grows when an iterate touches a point
// it misses, and keeps the weights of points that left until they outnumber the wanted ones. A is
// factored with CHOLMOD once per scene and step size, and again only for a coordinate whose weights
// changed (a change of a few points by CHOLMOD's rank-one updates and downdates of the factor,
// cholmod_updown); the factor is shared between coordinates whose matrices are equal. On a
// lattice (ProjectiveOptions::coarseNodes), a light contact, whose weight is under half its
// point's diagonal of M/h^2 + L (jello.w's kc 400 against 2,000 N/m and more), leaves the factor
// alone: each global solve is corrected on 4^3 coarse nodes for the weights the factor lacks or
// holds stale (solvers/system/lattice_coarse_space.h), which is where a missed contact is stiff
// (a face pressed against the whole cube's inertia); heavy ones go into the factor as above, and
// contact_set_changes counts only those. On jello.w at 8^3 one factorization serves the run
// (from 16^3 up, none: below).
// A coarse factor serves while its weights stay close (LatticeCoarseSpace::correct).
// From 16^3 up (ProjectiveOptions::spectralFrom), a coordinate with no contact weight in its
// matrix has no factor at all: its global step solves with the cosine transform's bound
// P' >= M/h^2 + L (+ L_c/h) of solvers/system/lattice_spectral.h, plus one Neumann correction
// through the boundary's difference P' - P (ProjectiveOptions::spectralCorrections): O(n log n)
// a solve and no factorization, and ten iterations as close to backward Euler's step as ten
// with the factor (tests/projective_spectral_test.cpp). A heavy contact's weight puts its
// coordinate back on a CHOLMOD factor; light ones stay with the coarse correction.
// Spring and
// contact damping, the force field and the user force are evaluated at the iterate (lagged one
// iteration): at the fixed point they are exactly where backward Euler evaluates them, so the
// iterations converge to the `implicit` step, damping included. The lag converges while the
// damping's share of A's diagonal is small (h c/(m + k h^2): 0.12 on jello.w); past 0.25, A
// carries the damping's velocity Jacobian too (L_c/h >= each spring's (c/h) u u', dc/h in W),
// refactored only when h changes: without it the iteration diverged (kE 25, dE 0.25, dt 1e-3,
// share 2.9: at its second step). With barrier contact the barrier's force is evaluated at the
// iterate like the others (no contact weights: no point is ever inside), and each update is cut to
// 0.9 of the largest that keeps every point outside every solid (Model::contactStepBound), counted
// in barrier_cuts. Options: iterations per step (10) and a tolerance (m): the iterations stop early
// when an update moves no coordinate more than it (0: always all iterations); Chebyshev
// acceleration (ProjectiveOptions::chebyshevRho).
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <utility>
#include <vector>

#include "solvers/integrator.h"
#include "solvers/linalg/chebyshev_weights.h"
#include "solvers/system/jacobian.h"
#include "solvers/system/lattice_coarse_space.h"

namespace jello {

class LatticeSpectral;
class SpringLaplacian;

class ProjectiveIntegrator final : public Integrator {
 public:
  explicit ProjectiveIntegrator(const ProjectiveOptions& options = {});
  ~ProjectiveIntegrator() override;
  explicit ProjectiveIntegrator(const SolverOptions& options)
      : ProjectiveIntegrator(options.projective) {}

  IntegratorKind kind() const override { return IntegratorKind::Projective; }
  StepResult step(const Model& model, State& state, double h) override;
  std::vector<Statistic> statistics() const override;

  // The last step's iterations and its last update's largest coordinate (m).
  int lastIterations() const { return lastIterations_; }
  double lastUpdate() const { return lastUpdate_; }
  long refactorizations() const { return factorizations_; }

 private:
  void bind(const Model& model);
  // Each obstacle's contact weights at positions x (3n) of the points [lo, hi), into w:
  // kc + dc dampingRate_ (the contact spring, and its damping where A carries it).
  void weightsAt(const Model& model, const double* x, std::ptrdiff_t lo, std::ptrdiff_t hi,
                 const std::array<double*, 3>& w) const;
  // For a step of h: whether A carries the damping's Jacobian (dampingRate_ 1/h) or the lag
  // alone converges (0), from the damping's share of A's diagonal.
  void chooseDamping(const Model& model, double h);
  // The contact weights at x into wanted_ for the points [lo, hi); the number above the weights
  // of the factor their coordinate uses (ProjectiveOptions::coverContacts; off: different; with
  // the coarse correction, only by more than it takes: heavy). *light counts the others.
  long contactWeights(const Model& model, const double* x, std::ptrdiff_t lo, std::ptrdiff_t hi,
                      long* light);
  // The coarse correction of each coordinate's update (delta_) for the weights it wants but
  // its factor lacks (ProjectiveOptions::coarseNodes).
  StepResult correctOnCoarseNodes();
  // The weights for a step from x0 at velocity v0 into weights_; true when they differ from
  // the factored ones (a point about to touch is not covered, or stale weights are dropped).
  bool planWeights(const Model& model, const double* x0, const double* v0, double h);
  // For a new step size: the coarse space's base and the cosine transform's bound, the matrices
  // without contact weights (inertia m/h^2).
  StepResult formUnweighted(double inertia);
  StepResult factorChanged(double h);

  ProjectiveOptions options_;
  ChebyshevWeights chebyshev_;
  long modelId_ = -1;
  int n_ = 0;
  double mass_ = 0.0;
  double h_ = 0.0;            // the step size the factors are for
  double dampingRate_ = 0.0;  // 1/h when A carries the damping, else 0 (chooseDamping)
  std::unique_ptr<SpringLaplacian> laplacian_;
  std::array<SparseMatrix, 3> A_;  // per coordinate: M/h^2 + L + W_c
  // W_c: to factor, wanted at the iterate, factored
  std::array<Eigen::VectorXd, 3> weights_, wanted_, factoredWeights_;
  std::array<int, 3> factorOf_{{0, 1, 2}};  // which coordinate's factor each one uses
  struct Factors;                           // CHOLMOD's, one per distinct matrix
  std::unique_ptr<Factors> factors_;
  // The cosine transform's bound of the matrix without contact weights
  // (ProjectiveOptions::spectralFrom), and which factors it is (by factorOf_'s index).
  std::unique_ptr<LatticeSpectral> spectral_;
  std::array<bool, 3> spectralOf_{};
  long spectralForms_ = 0;
  bool factored_ = false;
  Eigen::VectorXd y_, x_, v_, f_, previous_;  // previous_: the iterate before x_; v_: (x_ - x0)/h
  Eigen::VectorXd ahead_;                     // planWeights' positions
  Eigen::MatrixXd delta_;                     // n x 3, the update of each coordinate
  int lastIterations_ = 0;
  double lastUpdate_ = 0.0;
  std::vector<std::pair<int, double>> changes_;  // a coordinate's changed contact weights
  // The coarse correction (coarseNodes): its space, and one coordinate's weight differences.
  std::unique_ptr<LatticeCoarseSpace> coarse_;
  SparseMatrix free_;  // M/h^2 + L (+ L_c/h), the coarse space's base
  Eigen::VectorXd difference_;
  long coarseCorrections_ = 0;
  long steps_ = 0, iterations_ = 0, factorizations_ = 0, contactChanges_ = 0, updates_ = 0;
  long barrierCuts_ = 0;  // updates cut short by the barrier
  double factorSeconds_ = 0.0, solveSeconds_ = 0.0;
};

}  // namespace jello
