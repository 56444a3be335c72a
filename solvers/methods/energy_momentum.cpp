#include "solvers/methods/energy_momentum.h"

#include <Eigen/Dense>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "solvers/methods/newton_cap.h"
#include "src/base/interrupt.h"

namespace jello {

// The fallback where BiCGSTAB stalls: a sparse LU of the exact matrix, its pattern analysed once.
struct SparseLuFallback {
  Eigen::SparseLU<SparseMatrix, Eigen::COLAMDOrdering<int>> lu;
};

namespace {

// BiCGSTAB's preconditioner (Eigen's interface): the symmetric midpoint matrix's CHOLMOD factor,
// factored by its owner. A failed solve is remembered and reported after the iteration.
class SpdPreconditioner {
 public:
  using StorageIndex = int;
  void use(SpdSolver* solver) { solver_ = solver; }
  bool failed() const { return failed_; }
  template <typename M>
  SpdPreconditioner& analyzePattern(const M&) {
    return *this;
  }
  template <typename M>
  SpdPreconditioner& factorize(const M&) {
    return *this;
  }
  template <typename M>
  SpdPreconditioner& compute(const M&) {
    failed_ = false;
    return *this;
  }
  Eigen::ComputationInfo info() const { return Eigen::Success; }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    if (!solver_->solve(b, x).ok || !x.allFinite()) {
      failed_ = true;
      x = b;
    }
    return x;
  }

 private:
  SpdSolver* solver_ = nullptr;
  mutable bool failed_ = false;
};

// BiCGSTAB's relative residual: an inexact Newton step whose error is this fraction of the
// update, far below what the line search and the stopping test see.
constexpr double kKrylovTolerance = 1e-8;
// A solve that stops short of it is kept down to this relative residual; past it, the LU.
constexpr double kKrylovAcceptable = 1e-3;
constexpr int kKrylovMaxIterations = 100;

// The midpoint step only starts Newton: solved loosely, without retries.
ImplicitOptions guessOptions(ImplicitOptions o) {
  o.newtonTolerance = std::max(o.newtonTolerance, 1e-6);
  o.newtonPositionTolerance = std::max(o.newtonPositionTolerance, 1e-8);
  o.newtonHalvings = 0;
  return o;
}

}  // namespace

EnergyMomentum::EnergyMomentum(const SolverOptions& options)
    : options_(options.implicit), midpoint_(guessOptions(options.implicit)) {}

EnergyMomentum::~EnergyMomentum() = default;

void EnergyMomentum::bind(const Model& model) {
  if (model.id() == modelId_) return;
  modelId_ = model.id();
  jacobian_ = std::make_unique<JacobianAssembler>(model);
  springDamping_ = false;
  springs_ = model.springs().springs();
  for (const Spring& sp : springs_) springDamping_ |= sp.damping != 0.0;
  A_ = jacobian_->pattern();
  S_ = A_;
  spd_ = std::make_unique<SpdSolver>(LinearSolverKind::Cholmod);  // analyses S_'s pattern once
  lu_.reset();
}

void EnergyMomentum::springForces(const Model& model, const double* x0, const double* x1,
                                  double* f) {
  addDiscreteGradient(model.springs().springs(), model.numPoints(), x0, x1, f);
}

void EnergyMomentum::addDiscreteGradient(const std::vector<Spring>& springs, std::ptrdiff_t n,
                                         const double* x0, const double* x1, double* f) {
  for (const Spring& s : springs) {
    double d0[3], d1[3], q0 = 0.0, q1 = 0.0;
    for (int c = 0; c < 3; ++c) {
      d0[c] = x0[c * n + s.b] - x0[c * n + s.a];
      d1[c] = x1[c * n + s.b] - x1[c * n + s.a];
      q0 += d0[c] * d0[c];
      q1 += d1[c] * d1[c];
    }
    // 2 (U(q1) - U(q0))/(q1 - q0) for U = k/2 (sqrt q - L)^2, in the form without cancellation.
    const double scale = s.stiffness * (1.0 - 2.0 * s.rest / (std::sqrt(q0) + std::sqrt(q1)));
    for (int c = 0; c < 3; ++c) {
      const double dm = 0.5 * (d0[c] + d1[c]);
      f[c * n + s.a] += scale * dm;
      f[c * n + s.b] -= scale * dm;
    }
  }
}

double EnergyMomentum::evaluate(const Model& model, const State& s, double h,
                                const Eigen::VectorXd& x1) {
  const std::ptrdiff_t size = s.x.size();
  xm_ = 0.5 * (s.x + x1);
  vm_ = (x1 - s.x) / h;
  const bool contact =
      model.inContact(s.x.data()) || model.inContact(x1.data()) || model.inContact(xm_.data());
  const double inertia = 2.0 * model.mass() / (h * h);
  isolated_ = !contact && !springDamping_ && !model.hasField() && !model.hasUserForce() &&
              !model.hasFriction();
  if (isolated_) {
    // Springs alone: their discrete gradient is F, computed without the midpoint forces whose
    // difference would add round-off (an undamped free cube keeps its momenta to 1e-13).
    f_.setZero(size);
    addDiscreteGradient(springs_, model.numPoints(), s.x.data(), x1.data(), f_.data());
    work_ = inertia * (x1 - s.x - h * s.v);
    r_ = work_ - f_;
    return work_.norm() + f_.norm();
  }
  // Every force at the midpoint and its velocity, and at rest: their difference is the
  // dissipation (damping, friction), the second the elastic and external forces.
  model.forces(xm_, vm_, f_);
  work_.setZero(size);  // a zero velocity until the external forces below
  model.forces(xm_, work_, fRest_);
  // f = f_m - springs(x_m) + springs' discrete gradient: the dissipation f_m - f_rest and the
  // contact and external forces f_rest - springs(x_m) at the midpoint stay.
  fElastic_.setZero(size);
  model.springs().accumulate(xm_.data(), work_.data(), fElastic_.data());  // at rest: elastic
  f_ -= fElastic_;
  addDiscreteGradient(springs_, model.numPoints(), s.x.data(), x1.data(), f_.data());
  // Contact: Gonzalez's correction along the step dx = h v_m, where any point touches.
  if (contact) {
    // F_c(x_m): the elastic forces at rest less the springs' and the external ones.
    fContact_ = fRest_ - fElastic_;
    model.externalForces(xm_.data(), work_);
    if (work_.size() == size) fContact_ -= work_;
    const double contact0 = model.potentialEnergy(s.x.data()) - model.springs().energy(s.x.data());
    const double contact1 = model.potentialEnergy(x1.data()) - model.springs().energy(x1.data());
    const double dx2 = h * h * vm_.squaredNorm();
    if (dx2 > 0.0) {
      const double alpha = (-(contact1 - contact0) - h * fContact_.dot(vm_)) / dx2;
      f_ += (alpha * h) * vm_;
    }
  }
  work_ = inertia * (x1 - s.x - h * s.v);
  r_ = work_ - f_;
  return work_.norm() + f_.norm();
}

Eigen::VectorXd EnergyMomentum::residual(const Model& model, const State& start, double h,
                                         const Eigen::VectorXd& x1) {
  const Model::FrictionLag lag(model, start.x.data());
  evaluate(model, start, h, x1);
  return r_;
}

void EnergyMomentum::assemble(const Model& model, const State& s, double h) {
  // h^2/2 of the Newton matrix, M - (h^2/2) dF/dx1: the midpoint's M - (h^2/4) K - (h/2) D at
  // x_m for contact and damping, each spring's midpoint block then replaced by the exact
  // derivative of its discrete gradient F_b = -s d_m, s = k (1 - 2L/(l0 + l1)):
  //   dF_b/dx1_b = -(s/2) I - g d_m u1',  g = 2kL/(l0 + l1)^2,  u1 = d1/l1
  // (not symmetric). Exact, Newton converges quadratically near the step. S_ keeps the midpoint's
  // symmetric matrix (springs clamped), the preconditioner.
  jacobian_->assemble(xm_.data(), {.clampCompression = true});
  jacobian_->combine(0.5 * h, 0.25 * h * h, S_);
  A_ = S_;
  const std::ptrdiff_t n = model.numPoints();
  const std::vector<Spring>& springs = springs_;
  const std::vector<int>& slots = jacobian_->springSlots();
  const std::vector<int>& diagonal = jacobian_->diagonalSlots();
  double* a = A_.valuePtr();
  const double* x0 = s.x.data();
  const double* x1 = x1_.data();
  for (std::size_t i = 0; i < springs.size(); ++i) {
    const Spring& sp = springs[i];
    double d0[3], d1[3], dm[3], um[3];
    double l0 = 0.0, l1 = 0.0, lm = 0.0;
    for (int c = 0; c < 3; ++c) {
      d0[c] = x0[c * n + sp.b] - x0[c * n + sp.a];
      d1[c] = x1[c * n + sp.b] - x1[c * n + sp.a];
      dm[c] = 0.5 * (d0[c] + d1[c]);
      l0 += d0[c] * d0[c];
      l1 += d1[c] * d1[c];
      lm += dm[c] * dm[c];
    }
    l0 = std::sqrt(l0);
    l1 = std::sqrt(l1);
    lm = std::sqrt(lm);
    for (int c = 0; c < 3; ++c) um[c] = dm[c] / lm;
    const double k = sp.stiffness, sum = l0 + l1;
    const double scale = k * (1.0 - 2.0 * sp.rest / sum), g = 2.0 * k * sp.rest / (sum * sum);
    const double transverse = k * std::max(0.0, 1.0 - sp.rest / lm);  // S_'s, clamped
    double change[3][3];  // of A's (b,b) block: -(h^2/2) B + (h^2/4) (-H_m)
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        const double identity = r == c ? 1.0 : 0.0;
        const double exact = -0.5 * scale * identity - g * dm[r] * d1[c] / l1;
        const double midpoint = transverse * (identity - um[r] * um[c]) + k * um[r] * um[c];
        change[r][c] = -0.5 * h * h * exact - 0.25 * h * h * midpoint;
      }
    }
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        a[slots[18 * i + 3 * r + c]] -= change[r][c];      // (a,b)
        a[slots[18 * i + 9 + 3 * r + c]] -= change[r][c];  // (b,a)
        a[diagonal[9 * std::size_t(sp.a) + 3 * r + c]] += change[r][c];
        a[diagonal[9 * std::size_t(sp.b) + 3 * r + c]] += change[r][c];
      }
    }
  }
}

const SparseMatrix& EnergyMomentum::newtonMatrix(const Model& model, const State& start, double h,
                                                 const Eigen::VectorXd& x1) {
  bind(model);
  const Model::FrictionLag lag(model, start.x.data());
  evaluate(model, start, h, x1);
  x1_ = x1;
  assemble(model, start, h);
  return A_;
}

StepResult EnergyMomentum::factor() {
  ++factorizations_;
  if (StepResult res = spd_->factorize(S_); !res.ok) {
    return StepResult::failure("energy-momentum: the midpoint matrix could not be factored (" +
                               res.message + ")");
  }
  return StepResult::success();
}

StepResult EnergyMomentum::solveNewton(double h, double tolerance) {
  Eigen::BiCGSTAB<SparseMatrix, SpdPreconditioner> bicg;
  bicg.preconditioner().use(spd_.get());
  bicg.compute(A_);
  bicg.setTolerance(tolerance);
  bicg.setMaxIterations(kKrylovMaxIterations);
  trial_ = (-0.5 * h * h) * r_;
  delta_ = bicg.solve(trial_);
  krylovIterations_ += bicg.iterations();
  if (bicg.preconditioner().failed()) {
    return StepResult::failure("energy-momentum: the preconditioner's solve failed");
  }
  // An inexact solve still gives a Newton step (its error a small fraction of the update);
  // where BiCGSTAB stalls short of that (seen on the spinning cube at k 1e5 where springs
  // buckle and the clamped preconditioner is far from the exact matrix), the sparse LU.
  if (delta_.allFinite() && bicg.error() <= kKrylovAcceptable) return StepResult::success();
  if (!lu_) {  // the first fallback for this model: its pattern analysed once
    lu_ = std::make_unique<SparseLuFallback>();
    lu_->lu.analyzePattern(A_);
  }
  lu_->lu.factorize(A_);
  ++luFallbacks_;
  if (lu_->lu.info() != Eigen::Success) {
    return StepResult::failure("energy-momentum: the Newton matrix could not be factored (" +
                               lu_->lu.lastErrorMessage() + ")");
  }
  delta_ = lu_->lu.solve(trial_);
  if (lu_->lu.info() != Eigen::Success || !delta_.allFinite()) {
    return StepResult::failure("energy-momentum: the Newton system could not be solved");
  }
  return StepResult::success();
}

StepResult EnergyMomentum::solve(const Model& model, const State& s, double h, bool& converged) {
  const Model::FrictionLag lag(model, s.x.data());  // friction's normal forces at the start
  // The guess: the implicit midpoint's step (an unconverged or failed one still a guess).
  guess_ = s;
  const StepResult guessed = midpoint_.step(model, guess_, h);
  if (guessed.interrupted) return guessed;
  x1_ = guessed.ok && guess_.x.allFinite() ? guess_.x : Eigen::VectorXd(s.x + h * s.v);
  converged = false;
  double scale = evaluate(model, s, h, x1_);
  double norm = r_.norm();
  bool factored = false;
  double previous = std::numeric_limits<double>::infinity();
  NewtonCap cap(options_.newtonMaxIterations, options_.newtonCapFactor);
  for (int k = 0;; ++k) {
    if (norm <= options_.newtonTolerance * scale) {
      converged = true;
      break;
    }
    if (cap.reached(k, norm / scale)) break;
    if (interruptRequested()) return StepResult::interruption();
    // The exact matrix at every iterate; its preconditioner kept while the residual falls fast.
    assemble(model, s, h);
    if (!factored || !options_.reuseFactor || norm > options_.refactorRatio * previous) {
      if (StepResult res = factor(); !res.ok) return res;
      factored = true;
    }
    if (StepResult res = solveNewton(h, kKrylovTolerance); !res.ok) return res;
    ++iterations_;
    // Backtracking on |r|: the first of 1, 1/2, ... that lowers it, else the whole update.
    double t = 1.0, trialNorm = 0.0, trialScale = 0.0;
    int cut = 0;
    for (;; ++cut) {
      trial_ = x1_ + t * delta_;
      trialScale = evaluate(model, s, h, trial_);
      trialNorm = r_.norm();
      if (trialNorm < norm || cut >= options_.lineSearchMaxCuts) break;
      t *= 0.5;
    }
    if (!(trialNorm < norm)) {
      // Nothing along the update lowers |r|: at round-off's floor (within 100 times the
      // tolerance) the step has converged as far as it can; elsewhere it has not.
      evaluate(model, s, h, x1_);
      converged = norm <= 100.0 * options_.newtonTolerance * scale;
      break;
    }
    lineSearchCuts_ += cut;
    x1_.swap(trial_);
    previous = norm;
    norm = trialNorm;
    scale = trialScale;
    maxIterations_ = std::max<long>(maxIterations_, k + 1);
    if (t * delta_.cwiseAbs().maxCoeff() <= options_.newtonPositionTolerance) {
      converged = true;  // the absolute floor: round-off keeps the relative test from being met
      break;
    }
  }
  if (cap.extended()) ++extended_;
  if (!x1_.allFinite()) return StepResult::failure("energy-momentum: the step is not finite");
  return StepResult::success();
}

void EnergyMomentum::keepMomenta(const Model& model, const State& s, double h) {
  // With v1 = 2 (x1 - x0)/h - v0 and x_m = (x0 + x1)/2 exactly,
  //   P1 - P0 = m sum (v1 - v0),   L1 - L0 = m sum x_m x (v1 - v0)
  // (x1 x v1 - x0 x v0 = x_m x (v1 - v0) + h v_m x v_m), which the springs' central forces make
  // zero and Newton's residual does not quite. A rigid change of v1 removes both:
  // dv_i = a + w x (x_m,i - c), c the midpoints' centre, I w = -dL + c x dP, a = -dP/(N m);
  // x1 moves by h dv/2, a change of the order of the residual's.
  const std::ptrdiff_t n = model.numPoints();
  const double m = model.mass();
  Eigen::Vector3d dp = Eigen::Vector3d::Zero(), dl = Eigen::Vector3d::Zero();
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (std::ptrdiff_t p = 0; p < n; ++p) {
    Eigen::Vector3d xm, dv;
    for (int k = 0; k < 3; ++k) {
      const double x0 = s.x[k * n + p], x1 = x1_[k * n + p];
      xm[k] = 0.5 * (x0 + x1);
      dv[k] = (2.0 / h) * (x1 - x0) - 2.0 * s.v[k * n + p];
    }
    dp += m * dv;
    dl += m * xm.cross(dv);
    c += xm;
  }
  c /= double(n);
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  for (std::ptrdiff_t p = 0; p < n; ++p) {
    Eigen::Vector3d r;
    for (int k = 0; k < 3; ++k) r[k] = 0.5 * (s.x[k * n + p] + x1_[k * n + p]) - c[k];
    inertia += m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  const Eigen::Vector3d a = -dp / (double(n) * m);
  const Eigen::Vector3d w = inertia.ldlt().solve(-dl + c.cross(dp));
  if (!a.allFinite() || !w.allFinite()) return;  // a degenerate cube: left as solved
  for (std::ptrdiff_t p = 0; p < n; ++p) {
    Eigen::Vector3d r;
    for (int k = 0; k < 3; ++k) r[k] = 0.5 * (s.x[k * n + p] + x1_[k * n + p]) - c[k];
    const Eigen::Vector3d dv = a + w.cross(r);
    for (int k = 0; k < 3; ++k) x1_[k * n + p] += 0.5 * h * dv[k];
  }
}

StepResult EnergyMomentum::advance(const Model& model, State& s, double h, int depth) {
  bool converged = false;
  if (StepResult res = solve(model, s, h, converged); !res.ok) return res;
  if (converged || depth >= options_.newtonHalvings) {
    if (!converged) stepUnconverged_ = true;
    if (isolated_) {
      keepMomenta(model, s, h);
      keepMomenta(model, s, h);  // again: the first's change moved x_m (second order)
    }
    // v1 = 2 (x1 - x0)/h - v0, then x1.
    s.v = (2.0 / h) * (x1_ - s.x) - s.v;
    s.x = x1_;
    s.t += h;
    return StepResult::success();
  }
  ++retries_;
  const State start = s;
  for (int half = 0; half < 2; ++half) {
    if (StepResult res = advance(model, s, 0.5 * h, depth + 1); !res.ok) {
      s = start;
      return res;
    }
  }
  return StepResult::success();
}

StepResult EnergyMomentum::step(const Model& model, State& s, double h) {
  bind(model);
  stepUnconverged_ = false;
  // The state's vectors are written in place (Integrator::step): advance assigns into them.
  const StepResult res = advance(model, s, h, 0);
  ++steps_;
  return StepResult::counted(res, stepUnconverged_, unconverged_);
}

std::vector<Statistic> EnergyMomentum::statistics() const {
  return {
      {"newton_iterations", static_cast<double>(iterations_)},
      {"newton_iterations_per_step", steps_ ? double(iterations_) / double(steps_) : 0.0},
      {"newton_iterations_max", static_cast<double>(maxIterations_)},
      {"newton_unconverged_steps", static_cast<double>(unconverged_)},
      {"newton_retried_steps", static_cast<double>(retries_)},
      {"factorizations", static_cast<double>(factorizations_)},
      {"krylov_iterations", static_cast<double>(krylovIterations_)},
      {"lu_fallbacks", static_cast<double>(luFallbacks_)},
      {"line_search_cuts", static_cast<double>(lineSearchCuts_)},
      {"newton_extended_solves", static_cast<double>(extended_)},
  };
}

}  // namespace jello
