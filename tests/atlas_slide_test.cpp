// The atlas's friction scene (issue 39, item 2; jello-scaling --atlas-scene slide): the cube
// dropped onto a 20 degree incline and thrown down it with Coulomb friction mu = 0.6 > tan 20
// degrees lands, slides and comes to rest within the 2 s window; frictionless, it would still
// be sliding. Its reference resolves static friction's damper.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "experiments/studies/atlas.h"
#include "experiments/studies/stability_analysis.h"
#include "solvers/simulation.h"
#include "src/model.h"
#include "tests/test_support.h"

namespace jello::experiments {
namespace {

using test::meanVelocity;

// The least signed distance of any point to the incline, m.
double clearance(const World& w, const State& s) {
  double least = INFINITY;
  for (int p = 0; p < s.numPoints(); ++p) {
    least = std::min(least, dot(slideNormal(), s.position(p)) + w.plane->d);
  }
  return least;
}

// Implicit at 5 ms on a 6^3 cube (k = 1e3): it lands without sinking 1 cm into the incline,
// slides at least 0.2 m, and from t = 1 s rests: its centre's speed below 5 mm/s, at the end
// creeping at the smoothed law's speed eps (1 - sqrt(1 - tan(theta) / mu)) within a factor 1.5
// (src/PHYSICS.md, "Friction"), its visible motion over the last 0.5 s under 1 mm at the
// corners. Frictionless, it is still sliding faster than 1 m/s at t = 1 s.
TEST(SlideScene, TheCubeLandsSlidesAndComesToRest) {
  const World w = atlasScene(1e3, 6, AtlasScene::Slide);
  const VisibleMotion visible(6);
  Simulation sim(w, IntegratorKind::Implicit, 0.005);
  const Vec3 start = test::centre(sim.state());
  double least = INFINITY, fastestAtRest = 0.0;
  Eigen::Matrix<double, 3, 4> settled;
  while (sim.state().t < kSlideTime - 1e-9) {
    const StepResult r = sim.step();
    ASSERT_TRUE(r.ok) << r.message;
    ASSERT_FALSE(r.unconverged) << "t = " << sim.state().t;
    least = std::min(least, clearance(w, sim.state()));
    if (sim.state().t > 1.0 - 1e-9) {
      fastestAtRest = std::max(fastestAtRest, norm(meanVelocity(sim.state())));
    }
    if (std::abs(sim.state().t - 1.5) < 1e-9) settled = visible.fit(sim.state());
  }
  EXPECT_GT(least, -0.01);
  EXPECT_GT(dot(test::centre(sim.state()) - start, slideDownhill()), 0.2);
  EXPECT_LT(fastestAtRest, 0.005);
  const double tanTheta = -slideDownhill().z / slideDownhill().x;
  const double creep = w.contact.slipSpeed * (1.0 - std::sqrt(1.0 - tanTheta / w.contact.mu));
  const double along = dot(meanVelocity(sim.state()), slideDownhill());
  EXPECT_GT(along, creep / 1.5);
  EXPECT_LT(along, creep * 1.5);
  EXPECT_LT(visible.cornerDistance(settled, visible.fit(sim.state())), 0.001);

  World frictionless = w;
  frictionless.contact.mu = 0.0;
  Simulation slide(frictionless, IntegratorKind::Implicit, 0.005);
  while (slide.state().t < 1.0 - 1e-9) ASSERT_TRUE(slide.step().ok);
  EXPECT_GT(norm(meanVelocity(slide.state())), 1.0);
}

// The reference's step resolves static friction's damper: the scene's w_max is at least its
// rate 2 mu lambda / (m eps) with lambda the weight of two columns of N points, far above the
// lattice's and the contact's at k = 1e3; the scene parses by name and runs 2 s.
TEST(SlideScene, ItsFastestRateIsStaticFrictions) {
  EXPECT_EQ(parseAtlasScene("slide"), AtlasScene::Slide);
  EXPECT_EQ(sceneName(AtlasScene::Slide), "slide");
  const double k = 1e3;
  const int n = 8;
  const World w = atlasScene(k, n, AtlasScene::Slide);
  ASSERT_TRUE(w.plane.has_value());
  const double g = 9.81;
  const double friction =
      2.0 * w.contact.mu * (2.0 * n * w.mass * g) / (w.mass * w.contact.slipSpeed);
  const double wMax = atlasMaxFrequency(w, AtlasScene::Slide);
  EXPECT_GE(wMax, friction * (1.0 - 1e-12));
  const World falling = atlasScene(k, n, AtlasScene::Falling);
  EXPECT_GT(wMax, 10.0 * atlasMaxFrequency(falling, AtlasScene::Falling));
  // The cube starts clear of the incline, aligned with it, and thrown down it.
  const State s = initialState(w);
  EXPECT_NEAR(clearance(w, s), 0.02, 1e-9);
  EXPECT_GT(dot(meanVelocity(s), slideDownhill()), 0.99);
}

}  // namespace
}  // namespace jello::experiments
