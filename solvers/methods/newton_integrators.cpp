#include "solvers/methods/newton_integrators.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "solvers/methods/newton_cap.h"
#include "src/base/interrupt.h"

namespace jello {
namespace {

// Plain seed iterations before Chebyshev's start (ProjectiveOptions::chebyshevDelay's default).
constexpr int kSeedChebyshevDelay = 2;
// The barrier's line search starts at this fraction of the largest step that keeps every point
// out of every solid, so a step ends at a positive distance however the energy decides.
constexpr double kBarrierStepFraction = 0.9;

// Unknown: the displacement d = y - x0 (small, so no digits are lost to the positions' size).
// Forms are filled into the integrator's own, so their vectors are allocated once.
void backwardEulerForm(const State& s, double h, ImplicitStepForm& f) {
  f.gamma = 1.0;
  f.theta = 1.0;
  f.sigma = f.sigmaNew = 1.0 / h;
  f.x0 = s.x;
  f.dPred = h * s.v;
  f.vConst.setZero(s.v.size());
  f.vNewConst.setZero(s.v.size());
}

void midpointForm(const State& s, double h, ImplicitStepForm& f) {
  f.gamma = 2.0;
  f.theta = 0.5;
  f.sigma = 1.0 / h;
  f.sigmaNew = 2.0 / h;
  f.x0 = s.x;
  f.dPred = h * s.v;
  f.vConst.setZero(s.v.size());
  f.vNewConst = -s.v;
}

}  // namespace

NewtonIntegrator::NewtonIntegrator(const ImplicitOptions& options)
    : options_(options),
      system_(options.linearSolverOptions(), options.clampCompression && !options.clampOnDemand,
              true),
      seedWeights_(options.seedChebyshevRho, kSeedChebyshevDelay) {}

void NewtonIntegrator::bind(const Model& model) {
  const bool rebinding = system_.bound();
  if (!system_.bind(model)) return;
  factorValid_ = false;
  if (rebinding) restart();  // another model's history means nothing
}

// x_e, v_e, f and the residual r at displacement d; inertia = gamma/h^2.
void NewtonIntegrator::evaluate(const Model& model, double inertia, const Eigen::VectorXd& d) {
  const ImplicitStepForm& form = form_;
  xe_ = form.x0 + form.theta * d;
  ve_ = form.sigma * d + form.vConst;
  model.forces(xe_, ve_, f_);
  r_ = (inertia * model.mass()) * (d - form.dPred);
  const double inertiaNorm = r_.norm();
  r_ -= f_;
  const double scale = inertiaNorm + f_.norm();
  lastResidual_ = scale > 0.0 ? r_.norm() / scale : 0.0;
}

double NewtonIntegrator::merit(const Model& model, double inertia, const Eigen::VectorXd& d) {
  const ImplicitStepForm& form = form_;
  trial_ = d - form.dPred;
  double e = 0.5 * inertia * model.mass() * trial_.squaredNorm();  // J: r is in newtons
  xe_ = form.x0 + form.theta * d;
  ve_ = form.sigma * d + form.vConst;
  e += (model.potentialEnergy(xe_.data()) - external_.dot(xe_)) / form.theta;
  // Friction by its dissipation potential (convex in v; lambda and n lagged at the step's
  // start), not by the quadratic of its D at the iterate, which is flat along a slip above
  // eps_v: there the line search could not see friction at all.
  e += (-0.5 * (system_.dampingQuadratic(ve_) - system_.frictionQuadratic(ve_.data())) +
        model.frictionPotential(xe_.data(), ve_.data())) /
       form.sigma;
  return e;
}

// The a and b of A = M - a D - b K for the current form: (sigma, theta) h^2/gamma.
std::pair<double, double> NewtonIntegrator::matrixCoefficients(double h) const {
  const double scale = h * h / form_.gamma;
  return {form_.sigma * scale, form_.theta * scale};
}

StepResult NewtonIntegrator::prepareNewtonMatrix(double h, bool refactor) {
  system_.assemble(xe_.data(), ve_.data());
  const auto [a, b] = matrixCoefficients(h);
  if (!refactor && factorValid_ && a == factorA_ && b == factorB_) {
    ++reuses_;
    return StepResult::success();
  }
  factorValid_ = false;
  if (StepResult res = system_.factorize(a, b); !res.ok) return res;
  factorValid_ = true;
  factorA_ = a;
  factorB_ = b;
  return StepResult::success();
}

// Newton's update into delta_ for the right-hand side in rhs_ (the matrix assembled at the
// iterate, factored when `refactor`). Under ImplicitOptions::clampOnDemand an unclamped system
// that fails (a non-positive pivot or curvature, an LDLT fallback) or gives an update that does
// not descend (r.delta >= 0) is clamped, for the rest of the solve, and solved again.
StepResult NewtonIntegrator::solveNewton(double h, bool refactor) {
  const auto attempt = [&](bool fresh) {
    StepResult res = prepareNewtonMatrix(h, fresh);
    // Unclamped on demand, CG's negative curvature goes straight to the clamp below, without
    // an LDLT of the indefinite matrix first (seconds at 16^3, and thrown away).
    const bool unclamped = options_.clampOnDemand && !system_.clampsCompression();
    if (res.ok) res = system_.solve(rhs_, delta_, !unclamped);
    if (res.ok && !delta_.allFinite())
      res = StepResult::failure("Newton produced a non-finite update");
    return res;
  };
  const bool exact = options_.clampOnDemand && !system_.clampsCompression();
  const long fallbacks = system_.solver().stats().fallbacks;
  StepResult res = attempt(refactor);
  const bool failed = !res.ok || system_.solver().stats().fallbacks != fallbacks;
  if (exact && (failed || !(r_.dot(delta_) < 0.0))) {
    ++clampFallbacks_;
    system_.setClampCompression(true);
    delta_.setZero(rhs_.size());
    res = attempt(true);
  }
  return res;
}

std::pair<double, double> NewtonIntegrator::barrierStepBounds(const Model& model,
                                                              const Eigen::VectorXd& d,
                                                              const Eigen::VectorXd& delta) {
  const ImplicitStepForm& form = form_;
  trial_ = form.x0 + d;  // y
  const double y = model.contactStepBound(trial_.data(), delta.data());
  if (form.theta == 1.0) return {y, y};
  trial_ = form.x0 + form.theta * d;  // x_e, moving by theta delta
  dTrial_ = form.theta * delta;
  return {y, model.contactStepBound(trial_.data(), dTrial_.data())};
}

StepResult NewtonIntegrator::seed(const Model& model, double inertia, double h) {
  const auto [a, b] = matrixCoefficients(h);
  if (StepResult res = system_.factorProjectiveForSeeds(a, b); !res.ok) return res;
  const double scale = -h * h / form_.gamma;
  seedWeights_.start();  // ImplicitOptions::seedChebyshevRho
  for (int k = 0; k < options_.seedIterations; ++k) {
    if (interruptRequested()) return StepResult::interruption();
    evaluate(model, inertia, d_);  // x_e of d_ into xe_
    // Light contacts are corrected on a coarse lattice; at a heavy one Newton takes over.
    if (!system_.lightContactsAt(xe_.data())) break;
    if (lastResidual_ <= options_.seedTolerance) break;
    delta_ = scale * r_;
    if (StepResult res = system_.solveProjective(delta_); !res.ok) return res;
    if (StepResult res = system_.correctProjective(delta_); !res.ok) return res;
    ++seeds_;
    if (options_.seedChebyshevRho <= 0.0) {
      d_ += delta_;
      continue;
    }
    const double omega = seedWeights_.next(lastResidual_);
    if (omega == 1.0) {
      previousSeed_ = d_;
      d_ += delta_;
    } else {
      // d_next = omega (d + delta - previous) + previous.
      dTrial_ = omega * (d_ + delta_ - previousSeed_) + previousSeed_;
      previousSeed_ = d_;
      d_ = dTrial_;
    }
  }
  return StepResult::success();
}

StepResult NewtonIntegrator::step(const Model& model, State& s, double h) {
  bind(model);
  stepUnconverged_ = false;
  int iterations = 0;
  StepResult res = StepResult::success();
  if (wantsPilot(s, h)) {
    State pilot = s;
    res = advance(model, pilot, h, 0, iterations);
    if (res.ok) piloted(s, pilot, h);
  }
  if (res.ok) res = advance(model, s, h, 0, iterations);
  lastIterations_ = iterations;
  lastConverged_ = !stepUnconverged_;
  iterations_ += iterations;
  maxIterations_ = std::max<long>(maxIterations_, iterations);
  ++steps_;
  return StepResult::counted(res, stepUnconverged_, unconverged_);
}

// One step of h from s by Newton; unconverged, two half steps instead, down to the floor of
// options_.newtonHalvings halvings, where an unconverged sub-step is accepted and flagged.
StepResult NewtonIntegrator::advance(const Model& model, State& s, double h, int depth,
                                     int& iterations) {
  bool converged = false;
  if (StepResult res = solve(model, s, h, converged, iterations); !res.ok) return res;
  if (converged || depth >= options_.newtonHalvings) {
    if (!converged) stepUnconverged_ = true;
    s.v = form_.sigmaNew * d_ + form_.vNewConst;
    s.x += d_;
    s.t += h;
    accepted(s, h);
    return StepResult::success();
  }
  ++retries_;
  // A failure or a stop inside the halves leaves s where this step started (Integrator::step).
  State start = s;
  for (int half = 0; half < 2; ++half) {
    if (StepResult res = advance(model, s, 0.5 * h, depth + 1, iterations); !res.ok) {
      s = std::move(start);
      return res;
    }
  }
  return StepResult::success();
}

// Long: one Newton solve (seeds, factor reuse, line search, stopping tests) read top to bottom.
// Leaves the displacement in d_ and the form in form_; s is not changed.
StepResult NewtonIntegrator::solve(const Model& model, const State& s, double h, bool& converged,
                                   int& iterations) {
  const Model::FrictionLag lag(model, s.x.data());  // friction's normal forces at the start
  this->form(model, s, h, form_);
  const ImplicitStepForm& form = form_;
  const double inertia = form.gamma / (h * h);  // r = gamma m/h^2 (d - d_pred) - f
  // Newton starts from the inertial guess h v0: d_pred itself holds h^2 a0 terms (newmark,
  // bdf2), metres away from the answer when a stiff spring is stretched.
  d_ = h * s.v;
  if (options_.seedIterations > 0) {
    if (StepResult res = seed(model, inertia, h); !res.ok) return res;
  }
  const bool barrier = model.barrierContact();
  if (barrier) {
    // The start must be outside every solid, as x0 is: the guess pulled back along d from x0
    // (the path of x_e = x0 + theta d is part of y's).
    const double bound = model.contactStepBound(form.x0.data(), d_.data());
    if (bound < 1.0) d_ *= kBarrierStepFraction * bound;
  }
  if (options_.clampOnDemand && system_.clampsCompression()) {
    system_.setClampCompression(false);  // the exact Jacobian again, for this solve
    factorValid_ = false;
  }
  converged = false;
  int k = 0;  // this solve's iterations; `iterations` sums the step's, retries included
  double previousNorm = std::numeric_limits<double>::infinity();
  NewtonCap cap(options_.newtonMaxIterations, options_.newtonCapFactor);
  for (;;) {
    evaluate(model, inertia, d_);
    if (lastResidual_ <= options_.newtonTolerance) {
      converged = true;
      break;
    }
    if (cap.reached(k, lastResidual_)) break;
    if (interruptRequested()) return StepResult::interruption();  // s is still the start
    ++k;
    ++iterations;
    // Newton: (h^2/gamma) J delta = -(h^2/gamma) r. x_e, v_e are those of d_ (evaluate).
    rhs_ = (-h * h / form.gamma) * r_;
    delta_.setZero(rhs_.size());
    // A stale factor that shrank the residual too little last time is renewed here.
    const double norm = r_.norm();
    const bool refactor = !options_.reuseFactor || norm > options_.refactorRatio * previousNorm;
    previousNorm = norm;
    // CG solves to its own tolerance every time. An inexact-Newton forcing term (sqrt of the
    // relative residual) was tried: twice as fast on the spinning cube, but Newton then lands
    // just under its tolerance instead of far below it, which broke a uniform push's F/m
    // acceleration of the centre (2e-6 off) and left midpoint steps unconverged at a 1e-13
    // tolerance; not kept.
    if (StepResult res = solveNewton(h, refactor); !res.ok) return res;
    // The barrier: no step may carry y, or x_e, into a solid; the line search starts at a
    // fraction of the largest step that keeps them out (Li et al. 2020's filtered line search).
    double alphaMax = 1.0;
    if (barrier) {
      const auto [yBound, xeBound] = barrierStepBounds(model, d_, delta_);
      // Where y would enter a solid before x_e comes near it (midpoint: x_e halfway), the
      // barrier, felt at x_e only, cannot stop y: this h has no step outside, and taking 0.9 of
      // the way each iteration would bring y to the surface in round-off. Unconverged: the
      // step is retried in halves, where x_e and y are closer.
      if (yBound < 1.0 && yBound < xeBound) break;
      alphaMax = std::min(yBound, xeBound);
    }
    // An update this small is the answer to within it: the floor that ends the iterations at
    // rest, where round-off keeps the relative residual from falling.
    if (alphaMax >= 1.0 && delta_.cwiseAbs().maxCoeff() <= options_.newtonPositionTolerance) {
      d_ += delta_;
      converged = true;
      break;
    }

    // Backtracking line search on E_k (frozen damping directions, field and user force).
    model.externalForces(xe_.data(), external_);  // field and user force at the iterate
    const double slope = r_.dot(delta_);
    const double alphaStart = alphaMax >= 1.0 ? 1.0 : kBarrierStepFraction * alphaMax;
    double alpha = alphaStart;
    if (slope < 0.0) {
      const double e0 = merit(model, inertia, d_);
      // Near the answer the decrease is below E's round-off (E sums the energy of every
      // spring): there the merit cannot judge, and the full Newton step is taken.
      const double noise = 1e-12 * std::abs(e0);
      bool descended = false;
      for (int cut = 0; cut <= options_.lineSearchMaxCuts; ++cut) {
        dTrial_ = d_ + alpha * delta_;
        const double e = merit(model, inertia, dTrial_);
        if (e <= e0 + 1e-4 * alpha * slope + noise) {
          descended = true;
          break;
        }
        if (cut < options_.lineSearchMaxCuts) {
          alpha *= 0.5;
          ++cuts_;
        }
      }
      // No step along delta descends (the unclamped Hessian can be indefinite, and the merit
      // freezes damping and field): creeping along it would stall Newton, so take the whole
      // Newton step, as plain Newton does, and count it.
      if (!descended) {
        alpha = alphaStart;
        ++searchFailures_;
      }
    }
    d_ += alpha * delta_;
  }
  if (cap.extended()) ++extended_;
  return StepResult::success();
}

Eigen::VectorXd NewtonIntegrator::residual(const Model& model, const State& start, double h,
                                           const Eigen::VectorXd& y) {
  bind(model);
  const Model::FrictionLag lag(model, start.x.data());
  form(model, start, h, form_);
  evaluate(model, form_.gamma / (h * h), y - start.x);
  return r_;
}

SparseMatrix NewtonIntegrator::newtonMatrix(const Model& model, const State& start, double h,
                                            const Eigen::VectorXd& y) {
  bind(model);
  const Model::FrictionLag lag(model, start.x.data());
  form(model, start, h, form_);
  evaluate(model, form_.gamma / (h * h), y - start.x);
  system_.assemble(xe_.data(), ve_.data());
  const auto [a, b] = matrixCoefficients(h);
  system_.formMatrix(a, b);
  factorValid_ = false;  // A now differs from what was factored
  return system_.A() * (form_.gamma / (h * h));
}

std::vector<Statistic> NewtonIntegrator::statistics() const {
  std::vector<Statistic> stats{
      {"newton_iterations", static_cast<double>(iterations_)},
      {"newton_iterations_per_step", steps_ ? double(iterations_) / double(steps_) : 0.0},
      {"newton_iterations_max", static_cast<double>(maxIterations_)},
      {"newton_unconverged_steps", static_cast<double>(unconverged_)},
      {"newton_retried_steps", static_cast<double>(retries_)},
      {"line_search_cuts", static_cast<double>(cuts_)},
      {"line_search_failures", static_cast<double>(searchFailures_)},
      {"newton_extended_solves", static_cast<double>(extended_)},
      {"factor_reuses", static_cast<double>(reuses_)},
      {"seed_iterations", static_cast<double>(seeds_)},
      {"seed_chebyshev_restarts", static_cast<double>(seedWeights_.restarts())},
  };
  if (options_.clampOnDemand) stats.emplace_back("clamp_fallbacks", double(clampFallbacks_));
  system_.appendStatistics(stats);
  return stats;
}

void BackwardEuler::form(const Model&, const State& s, double h, ImplicitStepForm& f) {
  backwardEulerForm(s, h, f);
}

void ImplicitMidpoint::form(const Model&, const State& s, double h, ImplicitStepForm& f) {
  midpointForm(s, h, f);
}

void Newmark::form(const Model& model, const State& s, double h, ImplicitStepForm& f) {
  model.acceleration(s.x, s.v, a0_);
  f.gamma = 4.0;
  f.theta = 1.0;
  f.sigma = f.sigmaNew = 2.0 / h;
  f.x0 = s.x;
  f.dPred = h * s.v + (0.25 * h * h) * a0_;
  f.vConst = -s.v;
  f.vNewConst = -s.v;
}

bool Bdf2::continues(const State& s, double h) const {
  return history_ && h == h_ && s.t == last_.t && s.x == last_.x && s.v == last_.v;
}

bool Bdf2::wantsPilot(const State& s, double h) const {
  return !continues(s, h);
}

// The history behind `start` (newton_integrators.h): x_-1 = x0 - h v0, v_-1 = v0 - h a with
// the pilot's acceleration a = (v_BE - v0)/h.
void Bdf2::piloted(const State& start, const State& pilot, double h) {
  previous_ = start;
  previous_.t = start.t - h;
  previous_.x -= h * start.v;
  previous_.v -= pilot.v - start.v;
  last_ = start;
  h_ = h;
  history_ = true;
}

void Bdf2::form(const Model&, const State& s, double h, ImplicitStepForm& f) {
  current_ = s;  // the step's start: the history after it is accepted
  if (!continues(s, h)) {
    backwardEulerForm(s, h, f);
    return;
  }
  const State& p = previous_;  // (x0, v0); s is (x1, v1)
  f.gamma = 9.0 / 4.0;
  f.theta = 1.0;
  f.sigma = f.sigmaNew = 3.0 / (2.0 * h);
  f.x0 = s.x;
  f.dPred = (s.x - p.x) / 3.0 + (2.0 * h / 9.0) * (4.0 * s.v - p.v);
  f.vConst = (p.x - s.x) / (2.0 * h);
  f.vNewConst = f.vConst;
}

void Bdf2::accepted(const State& after, double h) {
  std::swap(previous_, current_);
  last_ = after;
  h_ = h;
  history_ = true;
}

}  // namespace jello
