#include "experiments/tools/solver_flags.h"

#include "solvers/linalg/linear_solver.h"
#include "src/base/finite_options.h"

namespace jello {

void addSolverFlags(CLI::App& app, SolverFlags& f) {
  auto& implicit = f.solver.implicit;
  auto& cvode = f.solver.cvode;
  const char* implicitGroup =
      "Implicit solvers (implicit, midpoint, newmark, bdf2, implicit-linear, cvode)";
  // Every flag here is in the group; `option` also shows its default in --help, `bare` does
  // not (a 0 there means "derived" or "none", said in the text).
  const auto bare = [&](const char* name, auto& value, const std::string& help) {
    return app.add_option(name, value, help)->group(implicitGroup);
  };
  const auto option = [&](const char* name, auto& value, const std::string& help) {
    return bare(name, value, help)->capture_default_str();
  };
  const auto flag = [&](const char* name, bool& value, const std::string& help) {
    return app.add_flag(name, value, help)->group(implicitGroup);
  };
  bare("--linear-solver", f.linearSolver,
       "cg (preconditioned, warm-started, matrix-free; the default), cholmod "
       "(supernodal LLT) or ldlt")
      ->check(CLI::IsMember({"cholmod", "ldlt", "cg"}));
  option("--preconditioner", f.preconditioner,
         "cg: jacobi, block-jacobi (each point's 3x3 block), ichol (incomplete "
         "Cholesky), factor (a CHOLMOD factor of an earlier matrix, refreshed when CG "
         "needs more than 10 iterations) or projective (the springs' Laplacian "
         "M + L(a c + b k) with the contacts on its diagonal, factored once per step "
         "size and contact set)")
      ->check(CLI::IsMember({"jacobi", "block-jacobi", "ichol", "factor", "projective"}));
  flag("--csr-product", f.csrProduct,
       "cg: multiply by the sparse matrix instead of through the spring kernels");
  flag("--no-clamp", f.noClamp,
       "Do not clamp compressed springs' Jacobians (the system may be indefinite)");
  option("--cg-tol", implicit.cgTolerance, "Relative residual of CG solves")
      ->check(cli::positive());
  option("--newton-iters", implicit.newtonMaxIterations,
         "implicit, midpoint, newmark, bdf2: most Newton iterations per step (a step "
         "still unconverged is counted and reported)")
      ->check(cli::range(1, 1000));
  option("--newton-tol", implicit.newtonTolerance,
         "implicit, midpoint, newmark, bdf2: relative residual that ends the iterations")
      ->check(cli::positive());
  option("--newton-xtol", implicit.newtonPositionTolerance,
         "implicit, midpoint, newmark, bdf2: a Newton update moving no coordinate more "
         "than this (m) also ends them")
      ->check(cli::positive());
  flag("--no-factor-reuse", f.noFactorReuse,
       "implicit, midpoint, newmark, bdf2: factor the Newton matrix at every iteration "
       "(plain Newton) instead of keeping it while it converges fast enough");
  option("--refactor-ratio", implicit.refactorRatio,
         "implicit, midpoint, newmark, bdf2: factor afresh when an iteration shrinks "
         "the residual by less than this")
      ->check(cli::range(1e-6, 1.0));
  option("--newton-seed", implicit.seedIterations,
         "implicit, midpoint, newmark, bdf2: iterations with the constant projective "
         "matrix before Newton (stopped at the first iterate in contact; 0: none)")
      ->check(cli::range(0, 1000));
  option("--newton-seed-tol", implicit.seedTolerance,
         "implicit, midpoint, newmark, bdf2: relative residual that ends the seed "
         "iterations (at or below --newton-tol they may converge the step themselves)")
      ->check(cli::positive());
  option("--newton-seed-chebyshev", implicit.seedChebyshevRho,
         "implicit, midpoint, newmark, bdf2: Chebyshev acceleration of the seed "
         "iterations with this rho, as --projective-chebyshev (0: off; 0.9 measured "
         "best with --newton-seed-tol 1e-8)")
      ->check(cli::range(0.0, 0.999));
  auto& projective = f.solver.projective;
  option("--projective-iters", projective.iterations,
         "projective: local/global iterations per step")
      ->check(cli::range(1, 100000));
  option("--projective-tol", projective.tolerance,
         "projective: stop a step's iterations early once an update moves no coordinate "
         "more than this (m; 0: never early)")
      ->check(cli::nonNegative());
  option("--projective-chebyshev", projective.chebyshevRho,
         "projective: Chebyshev acceleration of the iterations (Wang 2015) with this "
         "assumed contraction rho, after 2 plain iterations (0: off; 0.85 measured best "
         "on the spinning stiff cube)")
      ->check(cli::range(0.0, 0.999));
  option("--rtol", cvode.rtol, "cvode: relative tolerance")->check(cli::positive());
  option("--cvode-method", f.cvodeMethod,
         "cvode: bdf (stiff: Newton over the implicit system) or adams (non-stiff: "
         "fixed-point iterations, no linear algebra)")
      ->check(CLI::IsMember({"bdf", "adams"}));
  bare("--atol", f.atol,
       "cvode: absolute tolerance of positions (m) and velocities (m/s) (default "
       "1e-3 * rtol)")
      ->check(cli::positive());
  bare("--atol-x", cvode.atolPosition, "cvode: absolute tolerance of positions (m)")
      ->check(cli::positive());
  bare("--atol-v", cvode.atolVelocity, "cvode: absolute tolerance of velocities (m/s)")
      ->check(cli::positive());
  flag("--cvode-krylov", cvode.krylov,
       "cvode (bdf): solve Newton's systems by SPGMR, matrix-free, preconditioned by "
       "the reduced system (--linear-solver), its factor kept between setups");
  flag("--contact-roots", cvode.contactRoots,
       "cvode: locate contact onset and release as roots and restart there");
  option("--max-order", cvode.maxOrder, "cvode: largest BDF order")->check(cli::range(1, 5));
  flag("--no-stab-lim-det", f.noStabLimDet, "cvode: switch off BDF stability-limit detection");
  bare("--max-step", cvode.maxStep, "cvode: largest internal step, s (default none)")
      ->check(cli::positive());
}

SolverOptions solverOptions(const SolverFlags& f) {
  SolverOptions o = f.solver;
  if (!f.linearSolver.empty()) {
    const auto linear = *parseLinearSolver(f.linearSolver);
    o.implicit.linearSolver = o.cvode.linearSolver = linear;
  }
  o.implicit.preconditioner = o.cvode.preconditioner = *parsePreconditioner(f.preconditioner);
  o.implicit.matrixFree = o.cvode.matrixFree = !f.csrProduct;
  o.implicit.clampCompression = o.cvode.clampCompression = !f.noClamp;
  o.cvode.cgTolerance = o.implicit.cgTolerance;
  o.cvode.stabilityLimitDetection = !f.noStabLimDet;
  o.implicit.reuseFactor = !f.noFactorReuse;
  o.cvode.method = f.cvodeMethod == "adams" ? CvodeMethod::Adams : CvodeMethod::Bdf;
  // --atol sets both; --atol-x and --atol-v win over it.
  if (f.atol > 0.0) {
    if (o.cvode.atolPosition == 0.0) o.cvode.atolPosition = f.atol;
    if (o.cvode.atolVelocity == 0.0) o.cvode.atolVelocity = f.atol;
  }
  return o;
}

}  // namespace jello
