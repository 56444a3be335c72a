// The atlas's contact axis (issue 39, item 1; jello-scaling --atlas-contact): the falling scene's
// floor at the course's 400 N/m, as stiff as the springs, or 20 times stiffer. The stiffer floor
// raises the scene's fastest mode within Weyl's bound, the reference's step follows it, and the
// cube visibly sinks less into the floor.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "experiments/studies/atlas.h"
#include "experiments/studies/stability_analysis.h"
#include "src/model.h"
#include "src/world/contact_law.h"
#include "tests/test_support.h"

namespace jello::experiments {
namespace {

// The lowest of the visible cube's eight corners over a reference, m.
double lowestCorner(const AtlasReference& ref) {
  double lowest = 1e300;
  for (const auto& fit : ref.samples) {
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner(c & 1 ? 0.5 : -0.5, c & 2 ? 0.5 : -0.5, c & 4 ? 0.5 : -0.5);
      lowest = std::min(lowest, (fit.leftCols<3>() * corner + fit.col(3)).z());
    }
  }
  return lowest;
}

TEST(AtlasContact, NamesAndStiffnesses) {
  for (AtlasContact c : {AtlasContact::Soft, AtlasContact::AsStiff, AtlasContact::Stiffer}) {
    EXPECT_EQ(parseAtlasContact(contactName(c)), c);
  }
  EXPECT_FALSE(parseAtlasContact("hard"));
  const double k = 1e3;
  EXPECT_EQ(atlasScene(k, 4, AtlasScene::Falling).kCollision, 400.0);
  EXPECT_EQ(atlasScene(k, 4, AtlasScene::Falling, AtlasContact::AsStiff).kCollision, k);
  EXPECT_EQ(atlasScene(k, 4, AtlasScene::Falling, AtlasContact::Stiffer).kCollision, 20.0 * k);
  // The soft atlas's stored references keep their names.
  EXPECT_EQ(referenceSceneName(AtlasScene::Falling, AtlasContact::Soft), "falling");
  EXPECT_EQ(referenceSceneName(AtlasScene::Falling, AtlasContact::Stiffer), "falling-contact-20k");
}

TEST(AtlasContact, TheFloorsStiffnessSetsTheFastestModeAndTheReferenceStep) {
  const double k = 1e3;
  const int n = 8;
  const World soft = atlasScene(k, n, AtlasScene::Falling);
  const double lattice = maxAngularFrequency(Model(soft), initialState(soft));
  const double m = soft.mass;
  double previous = 0.0;
  for (AtlasContact c : {AtlasContact::Soft, AtlasContact::AsStiff, AtlasContact::Stiffer}) {
    SCOPED_TRACE(contactName(c));
    const World w = atlasScene(k, n, AtlasScene::Falling, c);
    const double wMax = atlasMaxFrequency(w, AtlasScene::Falling);
    // A point's contact spring adds at most kc/m to the squared frequencies (Weyl).
    EXPECT_GE(wMax, lattice);
    EXPECT_LE(wMax, std::sqrt(lattice * lattice + w.kCollision / m) * (1.0 + 1e-9));
    EXPECT_GT(wMax, previous);
    previous = wMax;
  }
  // 400 N/m next to the springs' 1e3 barely moves it; 20 k does.
  EXPECT_LT(atlasMaxFrequency(soft, AtlasScene::Falling), 1.05 * lattice);
  EXPECT_GT(previous, 1.2 * lattice);
  // The free scene touches nothing: the start's alone.
  const World free = atlasScene(k, n, AtlasScene::Free);
  EXPECT_EQ(atlasMaxFrequency(free, AtlasScene::Free),
            maxAngularFrequency(Model(free), initialState(free)));

  // The references: RK4 within h w_max <= 1 of the contact-inclusive w_max, converged (within
  // 1 mm of RK4 at twice its step), and the stiffer floor holds the cube higher.
  AtlasSetup setup;
  const AtlasReference softRef = atlasReference(soft, k, AtlasScene::Falling, setup);
  const World hard = atlasScene(k, n, AtlasScene::Falling, AtlasContact::Stiffer);
  const AtlasReference hardRef =
      atlasReference(hard, k, AtlasScene::Falling, setup, AtlasContact::Stiffer);
  for (const AtlasReference* ref : {&softRef, &hardRef}) {
    EXPECT_LE(ref->dt * ref->wMax, 1.0 + 1e-12);
  }
  // The impact on the stiff floor is where RK4 at twice the step differs most (measured 1.9 mm
  // against the soft floor's under 1 mm): still within a fifth of the atlas's 1 cm.
  EXPECT_LT(softRef.check, 1e-3);
  EXPECT_LT(hardRef.check, 2e-3);
  std::printf("reference checks: soft %.3g m, 20k %.3g m; lowest corners %.4f, %.4f m\n",
              softRef.check, hardRef.check, lowestCorner(softRef), lowestCorner(hardRef));
  EXPECT_LE(hardRef.dt, softRef.dt);
  EXPECT_LT(lowestCorner(softRef), -2.0);  // the soft floor lets the cube sink in
  EXPECT_GT(lowestCorner(hardRef), lowestCorner(softRef) + 1e-3);
}

// Against the stiff floor at k = 1e4, RK4 at h w_max = 1 is 3.9 mm from RK4 at twice its step,
// over a fifth of the 1 cm tolerance: the reference halves its step (the run at the first step
// its check) until it is within that fifth.
TEST(AtlasContact, AReferenceNotConvergedHalvesItsStep) {
  const double k = 1e4;
  const World hard = atlasScene(k, 8, AtlasScene::Falling, AtlasContact::Stiffer);
  AtlasSetup setup;
  const AtlasReference ref =
      atlasReference(hard, k, AtlasScene::Falling, setup, AtlasContact::Stiffer);
  EXPECT_LE(ref.check, setup.referenceCheck * setup.tolerance);
  EXPECT_LE(ref.dt * ref.wMax, 0.5 * setup.referenceHw);  // halved at least once
  setup.referenceRefinements = 0;                         // as before: h w_max <= 1 alone
  const AtlasReference once =
      atlasReference(hard, k, AtlasScene::Falling, setup, AtlasContact::Stiffer);
  EXPECT_GT(once.check, setup.referenceCheck * setup.tolerance);
  EXPECT_GT(once.dt, ref.dt);
}

// The log barrier's force -b'(d) and stiffness b''(d), b(d) = -kappa (d - dhat)^2 ln(d / dhat)
// (Li et al. 2020), written out here apart from the model's.
double barrierForce(double d, double kappa, double dhat) {
  return kappa * (2.0 * (d - dhat) * std::log(d / dhat) + (d - dhat) * (d - dhat) / d);
}
double barrierStiffness(double d, double kappa, double dhat) {
  const double r = (d - dhat) / d;
  return -kappa * (2.0 * std::log(d / dhat) + 4.0 * r - r * r);
}

// With the barrier (kappa = k, dhat 5 mm) the scene's w_max is the cube's resting where the
// barrier carries twice the weight of a column of points: within Weyl's bound of the lattice's
// and that distance's barrier stiffness (found here by a log-spaced scan). Its reference is
// converged like the others' and holds every corner outside the floor, which the soft floor's
// lets sink in.
TEST(AtlasContact, TheBarrierKeepsTheCubeOutAndItsRestingStiffnessSetsTheStep) {
  EXPECT_EQ(parseAtlasContact("barrier"), AtlasContact::Barrier);
  const double k = 1e3;
  const int n = 8;
  const World w = atlasScene(k, n, AtlasScene::Falling, AtlasContact::Barrier);
  EXPECT_EQ(w.contact.model, ContactModel::Barrier);
  EXPECT_EQ(w.contact.kappa, k);
  EXPECT_EQ(w.contact.dhat, kDefaultBarrierDistance);
  const double load = 2.0 * n * w.mass * 9.81;
  double d = w.contact.dhat;
  while (barrierForce(d, k, w.contact.dhat) < load) d *= 1.0 - 1e-6;
  const double lattice = maxAngularFrequency(Model(w), initialState(w));
  const double wMax = atlasMaxFrequency(w, AtlasScene::Falling);
  EXPECT_GT(wMax, lattice);
  EXPECT_LE(wMax, std::sqrt(lattice * lattice + barrierStiffness(d, k, w.contact.dhat) / w.mass) *
                      (1.0 + 1e-6));

  AtlasSetup setup;
  const AtlasReference ref =
      atlasReference(w, k, AtlasScene::Falling, setup, AtlasContact::Barrier);
  EXPECT_LE(ref.check, setup.referenceCheck * setup.tolerance);
  const World soft = atlasScene(k, n, AtlasScene::Falling);
  const AtlasReference softRef = atlasReference(soft, k, AtlasScene::Falling, setup);
  EXPECT_LE(ref.dt * ref.wMax, setup.referenceHw);
  EXPECT_GT(lowestCorner(ref), -2.0);
  EXPECT_LT(lowestCorner(softRef), -2.0);
}

// A barrier as soft as k = 1e2 cannot stop the falling column in floating point: RK4 crosses it
// at the impact at its step and at every halving, the reference fails (AtlasReferenceFailed),
// and jello-scaling reports that point's integrators as no_reference and finishes the run.
TEST(AtlasContact, AReferenceThatFailsIsReportedAndTheRunGoesOn) {
  const double k = 1e2;
  const World w = atlasScene(k, 8, AtlasScene::Falling, AtlasContact::Barrier);
  EXPECT_THROW(atlasReference(w, k, AtlasScene::Falling, AtlasSetup{}, AtlasContact::Barrier),
               AtlasReferenceFailed);
  const test::TempDir dir;
  const test::Outcome o = test::run(std::string(JELLO_SCALING) +
                                    " --quick --no-grid --atlas-contact barrier --atlas-k 1e2 "
                                    "--out-dir " +
                                    dir.path().string());
  ASSERT_EQ(o.code, 0) << o.output;
  EXPECT_NE(o.output.find("RK4 failed"), std::string::npos) << o.output;
  const std::string csv = test::readFile(dir.path() / "scaling_atlas.csv");
  std::size_t rows = 0;
  for (std::size_t at = csv.find("no_reference"); at != std::string::npos;
       at = csv.find("no_reference", at + 1)) {
    ++rows;
  }
  EXPECT_EQ(rows, atlasIntegrators(true).size()) << csv;
}

// The free scene touches nothing: a floor's stiffness for it is a mistake, said before any run.
TEST(AtlasContact, TheFreeSceneRefusesAFloor) {
  const test::Outcome o = test::run(std::string(JELLO_SCALING) +
                                    " --quick --no-grid --atlas-scene free --atlas-contact 20k "
                                    "--out-dir /nonexistent-jello-dir");
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.output.find("the free scene touches nothing"), std::string::npos) << o.output;
}

}  // namespace
}  // namespace jello::experiments
