// The weights of Chebyshev semi-iterative acceleration (Wang 2015, "A Chebyshev Semi-Iterative
// Approach for Accelerating Projective and Position-based Dynamics") of a fixed-point iteration
// x <- x + delta: after `delay` plain iterations, x_next = w (x + delta - x_previous) +
// x_previous, w = 2 / (2 - rho^2) first and then w = 4 / (4 - rho^2 w), rho the iteration's
// assumed contraction. The run starts again, plain, when an iteration's measure (an update's
// norm, a residual) exceeds the run's first, or when the caller says the iteration itself
// changed. Used by projective's iterations and Newton's seed iterations.
#pragma once

#include <algorithm>

namespace jello {

class ChebyshevWeights {
 public:
  ChebyshevWeights(double rho, int delay) : rho_(rho), delay_(std::max(1, delay)) {}

  // Before a step's iterations: a new plain run (the restarts counted so far are kept).
  void start() {
    omega_ = 1.0;
    plain_ = 0;
  }
  // The weight of this iteration (1: take it plain), given its measure and whether the
  // iteration changed (a new iteration matrix) since the last one.
  double next(double measure, bool changed = false) {
    const int plain = plain_++;  // iterations since the run began
    if (plain == 0) first_ = measure;
    if ((changed && plain > 0) || (omega_ != 1.0 && measure > first_)) {
      // A new iteration, or a measure grown beyond the run's first (the nonlinearity moved the
      // spectrum past rho): this one is taken plain and the count starts again.
      omega_ = 1.0;
      plain_ = 1;
      first_ = measure;
      ++restarts_;
    } else if (plain == delay_) {
      omega_ = 2.0 / (2.0 - rho_ * rho_);
    } else if (plain > delay_) {
      omega_ = 4.0 / (4.0 - rho_ * rho_ * omega_);
    }
    return omega_;
  }
  long restarts() const { return restarts_; }

 private:
  double rho_;
  int delay_;
  double omega_ = 1.0, first_ = 0.0;
  int plain_ = 0;
  long restarts_ = 0;
};

}  // namespace jello
