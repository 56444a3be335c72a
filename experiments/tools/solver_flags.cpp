#include "experiments/tools/solver_flags.h"

#include <span>
#include <vector>

#include "solvers/linalg/linear_solver.h"
#include "src/base/closed_set.h"
#include "src/base/finite_options.h"
#include "src/world/integrator_table.h"

namespace jello {

namespace {

// "cg (what it is; the default), cholmod (...) or ldlt (...)" from a table, and its names.
template <class Kind, class Name, class Summary>
std::string describeAll(std::span<const Kind> kinds, Kind byDefault, Name name, Summary summary) {
  return closed_set::sentence(kinds, [&](Kind kind) {
    return std::string(name(kind)) + " (" + std::string(summary(kind)) +
           (kind == byDefault ? "; the default)" : ")");
  });
}
template <class Kind, class Name>
std::vector<std::string> namesOf(std::span<const Kind> kinds, Name name) {
  std::vector<std::string> names;
  for (Kind kind : kinds) names.emplace_back(name(kind));
  return names;
}

}  // namespace

// Long: the table of jello-sim's solver flags, one option each.
void addSolverFlags(CLI::App& app, SolverFlags& f) {
  auto& implicit = f.solver.implicit;
  auto& cvode = f.solver.cvode;
  using F = IntegratorFamily;
  const std::string implicitGroup =
      "Implicit solvers (" + integratorNames({F::Newton, F::Linearized, F::Cvode}) + ")";
  // The integrators a flag applies to, as its help's prefix: "implicit, midpoint, ...: ".
  const std::string newton = integratorNames({F::Newton}) + ": ";
  const std::string projectiveOnly = integratorNames({F::Projective}) + ": ";
  const std::string cvodeOnly = integratorNames({F::Cvode}) + ": ";
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
       describeAll(allLinearSolvers(), kDefaultLinearSolver, linearSolverName, linearSolverSummary))
      ->check(CLI::IsMember(namesOf(allLinearSolvers(), linearSolverName)));
  option("--preconditioner", f.preconditioner,
         "cg: " + describeAll(allPreconditioners(), kDefaultPreconditioner, preconditionerName,
                              preconditionerSummary))
      ->check(CLI::IsMember(namesOf(allPreconditioners(), preconditionerName)));
  flag("--csr-product", f.csrProduct,
       "cg: multiply by the sparse matrix instead of through the spring kernels");
  flag("--no-clamp", f.noClamp,
       "Do not clamp compressed springs' Jacobians (the system may be indefinite)");
  flag("--clamp-on-demand", implicit.clampOnDemand,
       "implicit, midpoint, newmark, bdf2: Newton on the exact Jacobian, clamped only where "
       "its solve fails or its update does not descend (then for the rest of the step)");
  option("--cg-tol", implicit.cgTolerance, "Relative residual of CG solves")
      ->check(cli::positive());
  option("--newton-iters", implicit.newtonMaxIterations,
         newton +
             "most Newton iterations per step (a step "
             "still unconverged is retried as two half steps)")
      ->check(cli::range(1, 1000));
  option("--newton-halvings", implicit.newtonHalvings,
         newton +
             "an unconverged step is retried as two half steps, down to h / 2^N; a sub-step "
             "still unconverged there is accepted, counted and reported (0: no retries)")
      ->check(cli::range(0, 20));
  option("--newton-tol", implicit.newtonTolerance,
         newton + "relative residual that ends the iterations")
      ->check(cli::positive());
  option("--newton-xtol", implicit.newtonPositionTolerance,
         newton +
             "a Newton update moving no coordinate more "
             "than this (m) also ends them")
      ->check(cli::positive());
  flag("--no-factor-reuse", f.noFactorReuse,
       newton +
           "factor the Newton matrix at every iteration "
           "(plain Newton) instead of keeping it while it converges fast enough");
  option("--refactor-ratio", implicit.refactorRatio,
         newton +
             "factor afresh when an iteration shrinks "
             "the residual by less than this")
      ->check(cli::range(1e-6, 1.0));
  option(
      "--newton-seed", implicit.seedIterations,
      newton +
          "iterations with the constant projective "
          "matrix before Newton (through light contacts, corrected on a coarse lattice; stopped at "
          "a heavy one, the barrier or friction; 0: none)")
      ->check(cli::range(0, 1000));
  option("--newton-seed-tol", implicit.seedTolerance,
         newton +
             "relative residual that ends the seed "
             "iterations (at or below --newton-tol they may converge the step themselves)")
      ->check(cli::positive());
  option("--newton-seed-chebyshev", implicit.seedChebyshevRho,
         newton +
             "Chebyshev acceleration of the seed "
             "iterations with this rho, as --projective-chebyshev (0: off; 0.9 measured "
             "best with --newton-seed-tol 1e-8)")
      ->check(cli::range(0.0, 0.999));
  auto& projective = f.solver.projective;
  option("--projective-iters", projective.iterations,
         projectiveOnly + "local/global iterations per step")
      ->check(cli::range(1, 100000));
  option("--projective-tol", projective.tolerance,
         projectiveOnly +
             "stop a step's iterations early once an update moves no coordinate "
             "more than this (m; 0: never early)")
      ->check(cli::nonNegative());
  option("--projective-chebyshev", projective.chebyshevRho,
         projectiveOnly +
             "Chebyshev acceleration of the iterations (Wang 2015) with this "
             "assumed contraction rho, after 2 plain iterations (0: off; 0.85 measured best "
             "on the spinning stiff cube)")
      ->check(cli::range(0.0, 0.999));
  option("--rtol", cvode.rtol, cvodeOnly + "relative tolerance")->check(cli::positive());
  option("--cvode-method", f.cvodeMethod,
         cvodeOnly +
             "bdf (stiff: Newton over the implicit system) or adams (non-stiff: "
             "fixed-point iterations, no linear algebra)")
      ->check(CLI::IsMember({"bdf", "adams"}));
  bare("--atol", f.atol,
       cvodeOnly +
           "absolute tolerance of positions (m) and velocities (m/s) (default "
           "1e-3 * rtol)")
      ->check(cli::positive());
  bare("--atol-x", cvode.atolPosition, cvodeOnly + "absolute tolerance of positions (m)")
      ->check(cli::positive());
  bare("--atol-v", cvode.atolVelocity, cvodeOnly + "absolute tolerance of velocities (m/s)")
      ->check(cli::positive());
  flag("--cvode-krylov", cvode.krylov,
       "cvode (bdf): solve Newton's systems by SPGMR, matrix-free, preconditioned by "
       "the reduced system (--linear-solver), its factor kept between setups");
  flag("--contact-roots", cvode.contactRoots,
       cvodeOnly + "locate contact onset and release as roots and restart there");
  option("--max-order", cvode.maxOrder, cvodeOnly + "largest BDF order")->check(cli::range(1, 5));
  flag("--no-stab-lim-det", f.noStabLimDet, cvodeOnly + "switch off BDF stability-limit detection");
  bare("--max-step", cvode.maxStep, cvodeOnly + "largest internal step, s (default none)")
      ->check(cli::range(CvodeOptions::kMinMaxStep, CvodeOptions::kMaxMaxStep));
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
