#include "solvers/methods/projective_integrator.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include "solvers/linalg/prefactored_cholesky.h"
#include "solvers/system/lattice_spectral.h"
#include "solvers/system/spring_laplacian.h"
#include "src/base/assertions.h"
#include "src/base/interrupt.h"

namespace jello {
namespace {

// The barrier's updates go this fraction of the largest step that keeps every point outside
// (as the Newton integrators' line search starts).
constexpr double kBarrierStepFraction = 0.9;

using Clock = std::chrono::steady_clock;

// A contact change of at most this many points updates the factor (cholmod_updown) instead of
// factoring afresh. Measured on 1 s of jello.w at 8^3: of 96 contact changes 82 became updates,
// and the time spent on factors fell from 80 to 46 ms (limits 8, 64 and 128 within noise).
constexpr int kUpdateLimit = 64;
// Large factors take such changes as a low-rank correction (PrefactoredCholesky::addToDiagonal),
// which every solve then pays for: at most this many points in it, then a new factorization.
// Measured on 1 s of jello.w at 16^3: 2.45 s with 128 (41 factorizations), 2.65 s with 256 (39),
// 2.75 s without a limit; 4.6 s when updates made CHOLMOD solve a double simplicial factor.
constexpr int kCorrectionLimit = 128;
// Stale contact weights (factored, no longer wanted: the point left) stay in the factors until
// they outnumber the wanted ones and this many.
constexpr long kStaleFloor = 16;

// The damping's lag alone converges while the damping's share of the matrix's diagonal is
// small: h c/(m + k h^2) at most this (SpringLaplacian::dampingRatio, per point, and per contact
// with kc and dc) keeps A = M/h^2 + L + W and the steps measured before the damping could enter
// it (jello.w at dt 0.01: 0.12; at its own 5e-4: 1.13, c h/m growing as h falls); above it A
// carries the damping's Jacobian too (a spectral ratio can be twice the diagonal's). Measured over
// the grid of projective_test (RunsCleanWhereverBackwardEulerDoesUnderHeavyDamping): kE 25, dE
// 0.25, dt 1e-3 has 2.9 and diverged at its second step without it.
constexpr double kDampingInMatrixRatio = 0.25;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

// The factors of A_0, A_1, A_2: all three coordinates share the first while no contact tells
// them apart, and are then solved together (one pass over the factor for three columns).
struct ProjectiveIntegrator::Factors {
  std::array<PrefactoredCholesky, 3> llt;
};

ProjectiveIntegrator::ProjectiveIntegrator(const ProjectiveOptions& options)
    : options_(options),
      chebyshev_(options.chebyshevRho, options.chebyshevDelay),
      factors_(std::make_unique<Factors>()) {}

ProjectiveIntegrator::~ProjectiveIntegrator() = default;

void ProjectiveIntegrator::bind(const Model& model) {
  if (model.id() == modelId_) return;
  modelId_ = model.id();
  n_ = model.numPoints();
  mass_ = model.mass();
  laplacian_ = std::make_unique<SpringLaplacian>(model);
  factors_ = std::make_unique<Factors>();  // a new pattern: analyzed afresh
  for (int c = 0; c < 3; ++c) {
    weights_[c].setZero(n_);
    wanted_[c].setZero(n_);
    factoredWeights_[c].setZero(n_);
  }
  coarse_.reset();
  const int resolution = model.latticeResolution();
  spectral_.reset();
  spectralOf_ = {};
  if (options_.spectralFrom >= 2 && resolution >= options_.spectralFrom &&
      LatticeSpectral::fits(model)) {
    spectral_ = std::make_unique<LatticeSpectral>(model);
  }
  if (options_.coarseNodes >= 2 && resolution >= options_.coarseNodes) {
    coarse_ = std::make_unique<LatticeCoarseSpace>(resolution, options_.coarseNodes);
  }
  factored_ = false;
}

void ProjectiveIntegrator::weightsAt(const Model& model, const double* x, std::ptrdiff_t lo,
                                     std::ptrdiff_t hi, const std::array<double*, 3>& w) const {
  for (int c = 0; c < 3; ++c) std::fill(w[c] + lo, w[c] + hi, 0.0);
  for (const auto& obstacle : model.obstacles()) {
    // The contact spring's stiffness, and its damping's velocity Jacobian over h (v = (x - x0)/h)
    // where the damping is heavy enough to need it (chooseDamping).
    const ContactConstants& k = obstacle->constants();
    obstacle->addContactWeights(x, n_, lo, hi, k.stiffness + k.damping * dampingRate_, w);
  }
}

void ProjectiveIntegrator::chooseDamping(const Model& model, double h) {
  const double inertia = mass_ / (h * h);
  double ratio = laplacian_->dampingRatio(inertia, 1.0 / h, 1.0);
  for (const auto& obstacle : model.obstacles()) {
    const ContactConstants& k = obstacle->constants();
    ratio = std::max(ratio, k.damping / h / (inertia + k.stiffness));
  }
  dampingRate_ = ratio > kDampingInMatrixRatio ? 1.0 / h : 0.0;
}

long ProjectiveIntegrator::contactWeights(const Model& model, const double* x, std::ptrdiff_t lo,
                                          std::ptrdiff_t hi, long* light) {
  // Each obstacle's stiffness per contact spring, on the coordinates it reaches.
  const std::array<double*, 3> w{wanted_[0].data(), wanted_[1].data(), wanted_[2].data()};
  weightsAt(model, x, lo, hi, w);
  // The weights above the factor's (covering) or different from them (exact); with the coarse
  // correction, different by more than it takes.
  long count = 0, others = 0;
  const bool exact = !options_.coverContacts;
  for (int c = 0; c < 3; ++c) {
    const double* wc = w[c];
    const double* factored = factoredWeights_[factorOf_[c]].data();
    if (coarse_) {
      const double* diagonal = coarse_->baseDiagonal().data();
#pragma omp simd reduction(+ : count, others)
      for (std::ptrdiff_t p = lo; p < hi; ++p) {
        const double change = std::abs(wc[p] - factored[p]);
        const long heavy = long(change > kLightContactRatio * diagonal[p]);
        count += heavy;
        others += long(change != 0.0) - heavy;
      }
    } else {
#pragma omp simd reduction(+ : count)
      for (std::ptrdiff_t p = lo; p < hi; ++p) {
        count += long(wc[p] > factored[p]) + long(exact && wc[p] < factored[p]);
      }
    }
  }
  *light += others;
  return count;
}

StepResult ProjectiveIntegrator::correctOnCoarseNodes() {
  for (int c = 0; c < 3; ++c) {
    difference_ = wanted_[c] - factoredWeights_[factorOf_[c]];
    if (difference_.isZero(0.0)) continue;
    StepResult res = coarse_->correct(wanted_[c], difference_.data(), delta_.col(c).data());
    if (!res.ok) return res.within("projective coarse correction");
  }
  ++coarseCorrections_;
  return StepResult::success();
}

bool ProjectiveIntegrator::planWeights(const Model& model, const double* x0, const double* v0,
                                       double h) {
  // The weights wanted at x0, at the inertial prediction y = x0 + h v0 and a step beyond it: a
  // point about to touch is covered before it does.
  const std::ptrdiff_t size = 3 * std::ptrdiff_t(n_);
  ahead_.resize(size);
  const std::array<double*, 3> w{wanted_[0].data(), wanted_[1].data(), wanted_[2].data()};
  for (int c = 0; c < 3; ++c) weights_[c].setZero(n_);
  for (double steps : {0.0, 1.0, 2.0}) {
    for (std::ptrdiff_t i = 0; i < size; ++i) ahead_[i] = x0[i] + steps * h * v0[i];
    weightsAt(model, ahead_.data(), 0, n_, w);
    for (int c = 0; c < 3; ++c) weights_[c] = weights_[c].cwiseMax(wanted_[c]);
  }
  // One set of weights for the three coordinates (their largest): one factor, the three
  // solved together, and a point that touched one wall covered for the others.
  weights_[0] = weights_[0].cwiseMax(weights_[1]).cwiseMax(weights_[2]);
  // Covered (every wanted weight factored) and few stale weights (factored, no longer wanted:
  // the point left): the factors stay. Stale weights cost convergence, not correctness (the
  // residual is exact), so they go only when they outnumber the wanted ones.
  const Eigen::VectorXd& factored = factoredWeights_[factorOf_[0]];
  const bool grows = (weights_[0].array() > factored.array()).any();
  const long stale = (factored.array() > weights_[0].array()).count();
  const long wanted = (weights_[0].array() > 0.0).count();
  const bool drop = stale > std::max(kStaleFloor, wanted);
  if (!grows && !drop) {
    for (int c = 0; c < 3; ++c) weights_[c] = factoredWeights_[factorOf_[c]];
    return false;
  }
  if (!drop) weights_[0] = weights_[0].cwiseMax(factored);
  weights_[1] = weights_[0];
  weights_[2] = weights_[0];
  return true;
}

StepResult ProjectiveIntegrator::formUnweighted(double inertia) {
  if (coarse_) {
    // The coarse space's base, whose diagonal a contact's weight is weighed against.
    laplacian_->form(inertia, dampingRate_, 1.0, nullptr, free_);
    coarse_->setBase(free_);
  }
  if (spectral_) {
    // The cosine transform's bound of M/h^2 + L (+ L_c/h): the coordinates without contact
    // weights in the factor solve with it (ProjectiveOptions::spectralFrom).
    const auto start = Clock::now();
    const StepResult formed = spectral_->form(inertia, dampingRate_, 1.0, laplacian_.get());
    factorSeconds_ += secondsSince(start);
    ++spectralForms_;
    if (!formed.ok) return formed.within("projective spectral matrix");
  }
  return StepResult::success();
}

StepResult ProjectiveIntegrator::factorChanged(double h) {
  const bool all = !factored_ || h != h_;
  const double inertia = mass_ / (h * h);
  if (all) {
    if (StepResult res = formUnweighted(inertia); !res.ok) return res;
  }
  for (int c = 0; c < 3; ++c) {
    // A coordinate whose matrix equals an earlier one's shares its factor.
    int same = c;
    for (int e = 0; e < c; ++e) {
      if (factorOf_[e] == e && weights_[c] == weights_[e]) {
        same = e;
        break;
      }
    }
    if (same != c) {
      factorOf_[c] = same;
      continue;
    }
    if (spectral_ && weights_[c].isZero(0.0)) {  // no weight: the cosine transform's bound
      factoredWeights_[c].setZero();
      factorOf_[c] = c;
      spectralOf_[c] = true;
      continue;
    }
    // Its own factor (kept while it shared another's) still holds or nearly holds its matrix;
    // not after the cosine transform served it (its weights are then the transform's: none).
    const bool own = !all && factors_->llt[c].factored() && !spectralOf_[c];
    spectralOf_[c] = false;
    if (own && weights_[c] == factoredWeights_[c]) {
      factorOf_[c] = c;
      continue;
    }
    const auto start = Clock::now();
    if (options_.updateFactors && own) {
      // Its own factor, for this h: a few points entered or left contact. Rank-one updates
      // and downdates of the diagonal, or for large factors a low-rank correction, when few
      // enough to beat a new factorization.
      changes_.clear();
      for (int p = 0; p < n_; ++p) {
        const double delta = weights_[c][p] - factoredWeights_[c][p];
        if (delta != 0.0) changes_.emplace_back(p, delta);
      }
      const int changed = static_cast<int>(changes_.size());
      if (changed <= kUpdateLimit &&
          factors_->llt[c].correctedPoints() + changed <= kCorrectionLimit) {
        const StepResult updated = factors_->llt[c].addToDiagonal(changes_);
        factorSeconds_ += secondsSince(start);
        ++updates_;
        if (!updated.ok) return updated.within("projective matrix");
        factoredWeights_[c] = weights_[c];
        factorOf_[c] = c;
        continue;
      }
    }
    // Heavy damping (chooseDamping): the springs' damping Laplacian over h beside their
    // stiffness Laplacian, covering its velocity Jacobian ((c/h) u u' per spring, at most
    // (c/h) I); the damping is evaluated at the iterate, and its lag alone diverged.
    laplacian_->form(inertia, dampingRate_, 1.0, weights_[c].data(), A_[c]);
    // SPD by construction: M/h^2 > 0, L, L_c and W semidefinite. The three coordinates' matrices
    // share one pattern: a coordinate factored for the first time borrows another's analysis.
    const PrefactoredCholesky* analyzed = nullptr;
    for (int e = 0; e < 3 && !analyzed; ++e) {
      if (e != c && factors_->llt[e].factored()) analyzed = &factors_->llt[e];
    }
    const StepResult factored = factors_->llt[c].factorize(A_[c], analyzed);
    factorSeconds_ += secondsSince(start);
    ++factorizations_;
    if (!factored.ok) return factored.within("projective matrix");
    factoredWeights_[c] = weights_[c];
    factorOf_[c] = c;
  }
  factored_ = true;
  h_ = h;
  return StepResult::success();
}

// Long: one step's local/global loop, fused with the force evaluation for speed.
StepResult ProjectiveIntegrator::step(const Model& model, State& s, double h) {
  bind(model);
  // Friction's normal forces at the step's start, as the Newton methods take them (s.x is
  // written only at the end, after the last evaluation).
  const Model::FrictionLag lag(model, s.x.data());
  const std::ptrdiff_t n = n_, size = 3 * n;
  const double inertia = mass_ / (h * h), inverseH = 1.0 / h;
  y_.resize(size);
  x_.resize(size);
  v_.resize(size);
  f_.resize(size);
  delta_.resize(n, 3);
  double *x = x_.data(), *v = v_.data(), *d = delta_.data();
  const double *x0 = s.x.data(), *y = y_.data(), *f = f_.data();
  const double* v0 = s.v.data();
  for (std::ptrdiff_t i = 0; i < size; ++i) {  // the inertial prediction y = x0 + h v0 first
    x[i] = y_[i] = x0[i] + h * v0[i];
    v[i] = (x[i] - x0[i]) * inverseH;
  }
  if (!factored_ || h != h_) chooseDamping(model, h);  // before any contact weight
  const bool barrier = model.barrierContact();
  if (barrier) {
    // The inertial prediction may lie inside a solid: the iterations start from it pulled back
    // along h v0 from x0, outside.
    for (std::ptrdiff_t i = 0; i < size; ++i) v[i] = h * v0[i];  // scratch: the move
    const double bound = model.contactStepBound(x0, v);
    const double scale = bound < 1.0 ? kBarrierStepFraction * bound : 1.0;
    for (std::ptrdiff_t i = 0; i < size; ++i) {
      x[i] = x0[i] + scale * h * v0[i];
      v[i] = (x[i] - x0[i]) * inverseH;
    }
  }
  // The contact weights for this step: factored afresh only when a point about to touch is not
  // covered, or stale weights have piled up (planWeights).
  const bool plan = !barrier && options_.coverContacts;
  if (plan && planWeights(model, x0, v0, h)) {
    if (StepResult res = factorChanged(h); !res.ok) return res;
  }
  if (coarse_ && (!factored_ || h != h_)) {
    // The factor for h before the first weights: they are weighed against its diagonal.
    if (StepResult res = factorChanged(h); !res.ok) return res;
  }
  int iterations = 0;
  chebyshev_.start();  // ProjectiveOptions::chebyshevRho
  for (; iterations < options_.iterations; ++iterations) {
    if (interruptRequested()) return StepResult::interruption();  // s is still the start
    // Local step inside the force evaluation (damping, field and user force at the iterate,
    // v = (x - x0)/h); on each block of points once its forces are final, the global step's
    // right-hand side -r = f - M (x - y)/h^2 and the contact weights at x, in the same pass.
    std::atomic<long> uncovered{0};  // weights above those of the factor its coordinate uses
    std::atomic<long> light{0};      // the coarse correction's
    model.forces(x, v, f_.data(), [&](std::ptrdiff_t lo, std::ptrdiff_t hi) {
      for (std::ptrdiff_t c = 0; c < 3; ++c) {
        for (std::ptrdiff_t i = c * n + lo; i < c * n + hi; ++i) {
          d[i] = f[i] - inertia * (x[i] - y[i]);
        }
      }
      long others = 0;
      if (const long count = contactWeights(model, x, lo, hi, &others)) {
        uncovered.fetch_add(count, std::memory_order_relaxed);
      }
      if (others) light.fetch_add(others, std::memory_order_relaxed);
    });
    // A point touched that the factor does not cover: its weight joins (the others stay).
    const long missed = uncovered.load(std::memory_order_relaxed);
    const bool changed = missed > 0;
    if (changed && factored_ && h == h_) ++contactChanges_;
    if (changed) {
      if (options_.coverContacts) {
        // Every coordinate's factor takes the largest weight any coordinate misses.
        Eigen::VectorXd& all = weights_[0];
        all = factoredWeights_[factorOf_[0]];
        for (int c = 0; c < 3; ++c) all = all.cwiseMax(wanted_[c]);
        weights_[1] = all;
        weights_[2] = all;
      } else {
        for (int c = 0; c < 3; ++c) weights_[c] = wanted_[c];
      }
    }
    if (changed || !factored_ || h != h_) {  // the first factor, a new h, or new weights
      if (StepResult res = factorChanged(h); !res.ok) return res;
    }
    // Global step: A_c delta_c = -r_c, the coordinates that share a factor solved together.
    const auto start = Clock::now();
    StepResult solved = StepResult::success();
    for (int c = 0; c < 3 && solved.ok;) {  // neighbouring columns with one factor: one solve
      int columns = 1;
      while (c + columns < 3 && factorOf_[c + columns] == factorOf_[c]) ++columns;
      if (spectralOf_[factorOf_[c]]) {
        spectral_->solve(delta_.col(c).data(), columns, options_.spectralCorrections);
      } else {
        solved = factors_->llt[factorOf_[c]].solve(delta_.col(c).data(), columns);
      }
      c += columns;
    }
    if (!solved.ok) return solved;
    if (coarse_ && light.load(std::memory_order_relaxed) > 0 && !changed) {
      if (StepResult res = correctOnCoarseNodes(); !res.ok) return res;
    }

    solveSeconds_ += secondsSince(start);
    if (options_.chebyshevRho > 0.0) {
      // A new contact set is a new iteration matrix: the Chebyshev run starts again.
      const double omega = chebyshev_.next(delta_.norm(), changed);
      if (omega != 1.0) {
        // x_next = omega (x + delta - previous) + previous; delta becomes x_next - x.
        const auto xs = Eigen::Map<const Eigen::MatrixXd>(x, n, 3);
        const auto prev = Eigen::Map<const Eigen::MatrixXd>(previous_.data(), n, 3);
        delta_ = omega * (xs + delta_ - prev) + prev - xs;
      }
      previous_ = x_;
    }
    // The barrier (src/world/contact_law.h): its force is in f, not in A, so an update may aim
    // into a solid; it is cut to 0.9 of the largest that keeps every point outside.
    if (barrier) {
      const double bound = model.contactStepBound(x, d);
      if (bound < 1.0) {
        delta_ *= kBarrierStepFraction * bound;
        ++barrierCuts_;
      }
    }
    // x += delta, the next iterate's velocity and the largest move, in one pass.
    double update = 0.0;
    int finite = 1;
#pragma omp simd reduction(max : update) reduction(& : finite)
    for (std::ptrdiff_t i = 0; i < size; ++i) {
      const double xi = x[i] + d[i], move = std::abs(d[i]);
      x[i] = xi;
      v[i] = (xi - x0[i]) * inverseH;
      update = std::max(update, move);
      finite &= int(move <= std::numeric_limits<double>::max());  // false for NaN too
    }
    lastUpdate_ = finite ? update : std::numeric_limits<double>::quiet_NaN();
    if (!finite) return StepResult::failure("projective update is not finite");
    if (update <= options_.tolerance) {
      ++iterations;
      break;
    }
  }
  lastIterations_ = iterations;
  iterations_ += iterations;
  ++steps_;
  s.v = v_;  // (x - x0)/h of the final iterate
  s.x = x_;  // copied, not swapped: the state's storage stays put (Integrator::step)
  s.t += h;
  return StepResult::success();
}

std::vector<Statistic> ProjectiveIntegrator::statistics() const {
  return {
      {"projective_iterations", static_cast<double>(iterations_)},
      {"projective_iterations_per_step", steps_ ? double(iterations_) / double(steps_) : 0.0},
      {"projective_last_update_m", lastUpdate_},
      {"factorizations", static_cast<double>(factorizations_)},
      {"contact_set_changes", static_cast<double>(contactChanges_)},
      {"barrier_cuts", static_cast<double>(barrierCuts_)},
      {"coarse_corrections", static_cast<double>(coarseCorrections_)},
      {"factor_updates", static_cast<double>(updates_)},
      {"spectral_forms", static_cast<double>(spectralForms_)},
      {"factor_time_s", factorSeconds_},
      {"chebyshev_restarts", static_cast<double>(chebyshev_.restarts())},
      {"solve_time_s", solveSeconds_},
  };
}

}  // namespace jello
