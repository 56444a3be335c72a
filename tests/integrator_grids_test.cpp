// Grids of runs that prove a rule of the integrators over many worlds (label slow: a minute in
// release, several under the sanitizers, which leave them out; the code they reach is tested
// there by the shorter tests of tests/simulation_test.cpp and tests/projective_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "solvers/simulation.h"
#include "src/world/scene_builder.h"
#include "tests/newton_test_support.h"
#include "tests/test_support.h"

namespace jello {
namespace {

// A cube pushed from rest by a force field: the field's work is the trapezoid rule along each
// step, which each integrator's own update matches only to O(h). implicit-linear (the field at
// the step's start plus its Jacobian) gained 1.8 J over it by step 96 of a radial field that did
// 190 J of work, and was flagged as diverged while within 0.005 m of RK4; the budget now allows
// 5% of the work done (kWorkUncertainty). Every integrator runs 0.3 s clean (explicit ones at
// the world's 5e-4 s, within their limits; the others at 1e-3 s) and ends where RK4 does, to
// within 3% of the length of the centre's path (the first-order methods are farthest).
TEST(Simulation, AFieldPushingACubeFromRestIsNoDivergenceUnderAnyIntegrator) {
  SceneSpec spec;
  spec.field = FieldPreset::Radial;
  spec.fieldStrength = 1.0;
  spec.pose = PosePreset::Rest;
  spec.velocity = {0.0, 0.0, 0.0};
  spec.plane.reset();
  const World w = buildWorld(spec);
  Simulation reference(w, IntegratorKind::RK4, 1e-4);
  double travel = 0.0;  // m, the length of the centre's path
  for (int i = 0; i < 3000; ++i) {
    const Vec3 before = test::centre(reference.state());
    ASSERT_TRUE(reference.step().ok) << i;
    travel += norm(test::centre(reference.state()) - before);
  }
  ASSERT_GT(reference.fieldWork(), 40.0);  // J (measured 45): a field that does the driving
  for (IntegratorKind kind : allIntegrators()) {
    const double dt = isExplicit(kind) ? 5e-4 : 1e-3;
    Simulation sim(w, kind, dt);
    const long steps = std::lround(0.3 / dt);
    for (long i = 0; i < steps; ++i) {
      const StepResult r = sim.step();
      ASSERT_TRUE(r.ok) << integratorName(kind) << " step " << i << ": " << r.message;
    }
    EXPECT_TRUE(sim.checkEnergy().ok) << integratorName(kind);
    // The same motion, to first order.
    const double apart = norm(test::centre(sim.state()) - test::centre(reference.state()));
    // Shown per integrator for the record; asserted below.
    std::printf("%-16s centre %.3g m from RK4's at 1e-4 s, of %.3g m travelled\n",
                std::string(integratorName(kind)).c_str(), apart, travel);
    EXPECT_LT(apart, 0.03 * travel) << integratorName(kind);  // measured at most 1.6%
  }
}

// The damping, lagged one iteration, converges because the matrix covers its Jacobian (L_c/h and
// dc/h in the contact weights). Without them a soft, damped cube (kE 25, dE 0.25, dt 0.001) ran
// away at its second step while backward Euler ran it clean. Over a grid of k, c and h spanning
// the course worlds' values (kE 25 to 2e4, damping 0 to 2.5, dt 1e-3 and 1e-2), every cell that
// converged backward Euler runs clean for 0.2 s (every step converged, no divergence flagged)
// projective runs clean too, and ends near it: their centres within 5 cm.
TEST(Projective, RunsCleanWhereverBackwardEulerDoesUnderHeavyDamping) {
  int clean = 0;
  for (double k : {25.0, 400.0, 2e4}) {
    for (double c : {0.0, 0.25, 2.5}) {
      for (double h : {1e-3, 1e-2}) {
        SCOPED_TRACE("k " + std::to_string(k) + ", c " + std::to_string(c) + ", h " +
                     std::to_string(h));
        SceneSpec spec;
        spec.kElastic = k;
        spec.dElastic = spec.dCollision = c;
        spec.plane.reset();
        spec.velocity = {2.0, -2.0, 4.0};  // into the walls within 0.2 s: contact damping too
        spec.dt = h;
        const World w = buildWorld(spec);
        const long steps = std::lround(0.2 / h);
        Simulation be(w, IntegratorKind::Implicit), pd(w, IntegratorKind::Projective);
        bool beClean = true;
        for (long i = 0; i < steps && beClean; ++i) beClean = be.step().ok;
        const auto unconverged =
            findStatistic(be.integrator().statistics(), "newton_unconverged_steps");
        ASSERT_TRUE(unconverged.has_value());
        if (!beClean || *unconverged > 0.0) continue;
        ++clean;
        for (long i = 0; i < steps; ++i) {
          const StepResult r = pd.step();
          ASSERT_TRUE(r.ok) << "step " << i << ": " << r.message;
        }
        const Vec3 gap = test::centre(pd.state()) - test::centre(be.state());
        EXPECT_LT(norm(gap), 0.05);
      }
    }
  }
  std::printf("backward Euler ran %d of 18 cells clean\n", clean);
  EXPECT_EQ(clean, 18);  // measured: the grid is not vacuous
}

}  // namespace
}  // namespace jello
