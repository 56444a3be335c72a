// When a Newton solve gives up (ImplicitOptions::newtonMaxIterations). The cap is there to catch a
// solve that stalls: an active set that cycles, a step whose equations have no root (the
// penalty's damping jump), whose residual stops falling. A solve whose residual still falls,
// at least halving over its last ten iterations, converges, if slowly: linearly where the
// compression clamp's matrix is not the Hessian (a cube crushed into a stiff floor compresses
// many springs), or cut by the barrier's step bound near a solid. It may go on, up to four times
// the cap (ImplicitOptions::newtonCapFactor). On the crushed hard case smooth and barrier contact
// then leave no step unconverged (SmoothAndBarrierContact.LeaveNoNewtonStepUnconverged), where the
// cap alone left one each; tenfold over ten iterations was enough for smooth contact, not for the
// barrier.
#pragma once

#include <array>

namespace jello {

class NewtonCap {
 public:
  // cap: newtonMaxIterations; factor: newtonCapFactor (1: none past it).
  NewtonCap(int cap, int factor) : cap_(cap), factor_(factor) {}

  // After iteration k's relative residual (k = 0, 1, ... in turn): true when the solve stops
  // unconverged here.
  bool reached(int k, double residual) {
    const std::size_t slot = static_cast<std::size_t>(k) % kWindow;
    const double before = recent_[slot];  // the residual kWindow iterations ago
    recent_[slot] = residual;
    if (k < cap_) return false;
    if (k >= factor_ * cap_ || k < static_cast<int>(kWindow)) return true;
    if (!(residual <= kFall * before)) return true;  // stalled (or not finite)
    extended_ = true;
    return false;
  }
  // Whether the solve went past the cap.
  bool extended() const { return extended_; }

 private:
  static constexpr std::size_t kWindow = 10;
  static constexpr double kFall = 0.5;
  int cap_, factor_;
  std::array<double, kWindow> recent_{};
  bool extended_ = false;
};

}  // namespace jello
