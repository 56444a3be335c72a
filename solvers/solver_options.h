// Settings of the implicit integrators, as plain structs (solvers/README.md).
#pragma once

#include "solvers/linalg/linear_solver.h"

namespace jello {

struct ImplicitOptions {
  // An indefinite system (the clamp off) falls back to LDLT as CHOLMOD's does.
  LinearSolverKind linearSolver = kDefaultLinearSolver;
  PreconditionerKind preconditioner = kDefaultPreconditioner;  // cg's
  bool matrixFree = true;  // cg: products through the spring kernels, not the sparse matrix
  // The converged integrators (implicit, midpoint, newmark, bdf2;
  // solvers/methods/newton_integrators.h).
  int newtonMaxIterations = 30;  // then the step is retried as two half steps
  // A solve whose residual still falls (halving over ten iterations) may go on to this many
  // times newtonMaxIterations (solvers/methods/newton_cap.h); 1: the cap is the cap.
  int newtonCapFactor = 4;
  // A step Newton leaves unconverged is retried as two half steps, each of them so again, down
  // to h / 2^newtonHalvings; a sub-step still unconverged there is accepted, counted, reported.
  int newtonHalvings = 4;
  double newtonTolerance = 1e-8;          // relative residual that ends the iterations
  double newtonPositionTolerance = 1e-8;  // m: a full Newton update this small ends them too
  int lineSearchMaxCuts = 12;  // halvings of the Newton update; none descends: the whole step
  // Modified Newton: keep the factorization across iterations and steps, and factor afresh only
  // when an iteration shrank the residual by less than refactorRatio (or h, the method's
  // coefficients or the model changed). The converged step is the same; only the cost changes.
  bool reuseFactor = true;
  double refactorRatio = 0.5;
  // Seed iterations: before Newton, up to this many iterations d <- d - P^-1 (h^2/gamma) r(d)
  // with the projective matrix P = M + L(a c + b k) (solvers/system/spring_laplacian.h), factored
  // once per step size; each costs a force evaluation and a back-substitution, no assembly.
  // Light contacts are corrected on a coarse lattice; at a heavy one, the barrier or friction
  // they stop (solvers/system/implicit_system.h, lightContactsAt). 0: none.
  int seedIterations = 0;
  // The seeds stop at this relative residual, from where Newton converges in one or two
  // iterations; at or below newtonTolerance they may converge the step themselves (with
  // Chebyshev acceleration, cheaper than Newton's iterations: solvers/README.md).
  double seedTolerance = 1e-4;
  // Chebyshev acceleration of the seeds (Wang 2015; ProjectiveOptions::chebyshevRho): 0 off.
  double seedChebyshevRho = 0.0;
  // implicit-linear (one solve per step): a step during which a contact begins is not near its
  // linearization (the penalty spring was not in the matrix), so it gets up to this many
  // Newton iterations, to this relative residual: the penalty must act, that's all.
  int contactNewtonIterations = 4;
  double contactNewtonTolerance = 1e-4;
  bool clampCompression = true;  // project each spring's Hessian onto semidefinite matrices
  // The converged integrators: the exact Jacobian first, the clamp only where it fails (the
  // solve meets negative curvature or a non-positive pivot, or its update does not descend),
  // and then for the rest of the step. Newton on the clamped Jacobian converges only linearly
  // where springs are compressed. Overrides clampCompression for them.
  bool clampOnDemand = false;
  double cgTolerance = 1e-6;  // relative residual of the CG solves

  LinearSolverOptions linearSolverOptions() const {
    return {linearSolver, cgTolerance, preconditioner, matrixFree};
  }

  // The converged Newton methods' fastest configuration measured (solvers/README.md, "The fast
  // configuration"): up to 10 Chebyshev-accelerated projective seeds, then plain Newton on the
  // exact Jacobian (clamped on demand), each update solved inexactly by CG to 1e-2 of its
  // right-hand side, preconditioned by the projective matrix. Newton still stops at
  // newtonTolerance on the residual: the converged step is the same.
  static ImplicitOptions fast() {
    ImplicitOptions o;
    o.linearSolver = LinearSolverKind::Cg;
    o.preconditioner = PreconditionerKind::Projective;
    o.cgTolerance = 1e-2;
    o.seedIterations = 10;
    o.seedTolerance = o.newtonTolerance;
    o.seedChebyshevRho = 0.9;
    o.clampOnDemand = true;
    o.reuseFactor = false;
    return o;
  }
};

enum class CvodeMethod {
  Bdf,    // stiff: BDF with Newton iterations over the implicit system
  Adams,  // non-stiff: Adams-Moulton with fixed-point iterations, no linear algebra
};

struct CvodeOptions {
  CvodeMethod method = CvodeMethod::Bdf;
  double rtol = 1e-6;
  // Absolute tolerances, positions (m) and velocities (m/s); 0: 1e-3 * rtol. The positions are
  // those relative to the cube's centre of mass at the start, so translating a scene does not
  // change the answer.
  double atolPosition = 0.0;
  double atolVelocity = 0.0;
  int maxOrder = 5;  // order limit, 1..5 (BDF 3..5 are not A-stable)
  // Contact onset and release located as roots of the penetration depths (walls, plane,
  // sphere, cone, spiral): CVODE stops there and restarts, instead of stepping over the
  // penalty's kink (smooth and barrier contact have none to step over).
  bool contactRoots = false;
  bool stabilityLimitDetection = true;
  double maxStep = 0.0;  // s, 0: no limit; else within kMinMaxStep..kMaxMaxStep
  // CVODE keeps 1/hmax: a subnormal hmax made it infinite and the limit silently vanished.
  static constexpr double kMinMaxStep = 1e-12, kMaxMaxStep = 1e6;
  long maxStepsPerCall = 1000000;  // internal steps CVODE may take to reach one output time
  LinearSolverKind linearSolver = kDefaultLinearSolver;
  PreconditionerKind preconditioner = kDefaultPreconditioner;
  bool matrixFree = true;
  // bdf: Newton's systems by SUNDIALS' SPGMR (matrix-free: CVODE's difference-quotient J v,
  // its tolerance set by CVODE), preconditioned by the reduced system solved with linearSolver,
  // whose factor is kept between CVODE's preconditioner setups (Jacobian reuse). Off: the
  // reduced system solved exactly as a custom DIRECT solver.
  bool krylov = false;
  bool clampCompression = true;
  double cgTolerance = 1e-6;
  // The serial vectors' hot operations by our own vectorized loops (solvers/cvode/fast_nvector.h);
  // off: SUNDIALS' own, for the benchmark that measures the difference.
  bool fastVectors = true;

  LinearSolverOptions linearSolverOptions() const {
    return {linearSolver, cgTolerance, preconditioner, matrixFree};
  }
};

struct ProjectiveOptions {
  int iterations = 10;     // local/global iterations per step
  double tolerance = 0.0;  // m: stop when an update moves no coordinate more (0: never early)
  // A contact change of a few points updates the factor (cholmod_updown); off: it always
  // refactors (the tests compare the two).
  bool updateFactors = true;
  // The contact weights cover the contacts (planned a step ahead, kept after a point leaves: far
  // fewer factorizations) instead of following each iterate's contacts exactly. Off by default:
  // on two hard cases (ThrownIntoAWallWithKCollision1e5, CrushedAgainstThePlane) it does not yet
  // stay stable (tests/hard_cases_test.cpp).
  bool coverContacts = false;
  // Chebyshev semi-iterative acceleration (Wang 2015), on when chebyshevRho > 0: after
  // `chebyshevDelay` plain iterations, x_{k+1} = w_{k+1} (x^_{k+1} - x_{k-1}) + x_{k-1}, x^ the
  // plain iteration's result, w from w = 4 / (4 - rho^2 w) started at 2 / (2 - rho^2), rho the
  // plain iterations' assumed contraction (a scene's constant, as in the paper: 0.85 measured
  // best on the spinning stiff cube, README). An update larger than the run's first, or a change
  // of the contact set, restarts it.
  double chebyshevRho = 0.0;
  int chebyshevDelay = 2;
  // Coarse correction of contacts the factor misses (solvers/system/lattice_coarse_space.h):
  // on a lattice's points, g^3 coarse nodes (g = coarseNodes; 0: off, the factor then follows
  // every contact). A contact whose weight is under kLightContactRatio of its point's diagonal
  // leaves the factor as it is, and each global solve is corrected on the coarse nodes.
  int coarseNodes = 4;
  // On a lattice of at least this many points per edge whose springs are the whole lattice
  // (solvers/system/lattice_spectral.h), a coordinate with no contact weight in its matrix solves
  // the global step with the cosine transform's bound P' of M/h^2 + L instead of a CHOLMOD
  // factor: no factorization, O(n log n) a solve (0: never). 8^3 keeps its factor (a solve of
  // microseconds); from 16^3 the bound, corrected, converges as fast (README, "Projective at
  // 32^3").
  int spectralFrom = 16;
  // Neumann corrections of the bound's solve toward P^-1 (each one more solve and a product with
  // P' - P, near the faces only): one measured best (at 32^3, ten iterations within 0.0012 of
  // backward Euler's step against the factor's 0.00127; none 0.00206; two 0.00125).
  int spectralCorrections = 1;
};

struct SolverOptions {
  ImplicitOptions implicit;
  CvodeOptions cvode;
  ProjectiveOptions projective;
};

}  // namespace jello
