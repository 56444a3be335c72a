// The experiments: the stability analysis against closed forms, the tested definition of
// "blew up", and --quick runs of each program whose CSV must hold the physics the README
// states (thresholds near their predictions, flat Courant numbers, convergence orders).
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <sstream>
#include <thread>

#include "experiments/common/json_finite.h"
#include "experiments/studies/atlas.h"
#include "experiments/studies/csv_table.h"
#include "experiments/studies/parallel_for.h"
#include "experiments/studies/ranks.h"
#include "experiments/studies/run_context.h"
#include "experiments/studies/stability_analysis.h"
#include "solvers/simulation.h"
#include "solvers/system/modes.h"
#include "src/base/parallel.h"
#include "src/world/scene_builder.h"
#include "tests/experiments_support.h"
#include "tests/test_support.h"

namespace jello::experiments {
namespace {

// Issue 41, item 5: JSON has no infinity, so nlohmann writes null; what the programs write says
// why (the contact energy of an infinite start was a bare null in jello-sim's statistics).
TEST(Outputs, ANullInTheStatisticsSaysWhy) {
  nlohmann::json doc = {
      {"energy_end", {{"contact", std::numeric_limits<double>::infinity()}, {"spring", 1.5}}},
      {"residuals", {0.5, std::nan("")}},
      {"min_obstacle_distance_m", nullptr},
      {"null_because", {{"min_obstacle_distance_m", "the scene has no solid"}}}};
  explainNonFinite(doc);
  EXPECT_TRUE(doc["energy_end"]["contact"].is_null());
  EXPECT_EQ(doc["energy_end"]["spring"], 1.5);
  EXPECT_TRUE(doc["residuals"][1].is_null());
  EXPECT_EQ(doc["null_because"]["energy_end.contact"], "not finite: inf");
  EXPECT_EQ(doc["null_because"]["residuals[1]"], "not finite: nan");
  EXPECT_EQ(doc["null_because"]["min_obstacle_distance_m"], "the scene has no solid");
  // Every null in the document has its reason.
  const auto parsed = nlohmann::json::parse(doc.dump());
  EXPECT_EQ(parsed["null_because"].size(), 3u);
  nlohmann::json finite = {{"a", 1.0}};
  explainNonFinite(finite);
  EXPECT_FALSE(finite.contains("null_because"));
}

TEST(StabilityAnalysis, WMaxOfTheLatticeAtRestIsTheDenseSolvesValue) {
  // src/PHYSICS.md: w_max = 4.0715 sqrt(k/m) for the full 8^3 lattice at rest.
  World w = buildWorld(stiffCube(1e4));
  const Lattice lattice{8};
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      for (int k = 0; k < 8; ++k)
        w.positions[lattice.index(i, j, k)] = lattice.restPosition(i, j, k);
    }
  }
  const double wMax = maxAngularFrequency(Model(w), initialState(w));
  EXPECT_NEAR(wMax / std::sqrt(1e4 / w.mass), 4.0715, 5e-4);
}

TEST(StabilityAnalysis, PredictedThresholdsMatchTheClosedForms) {
  const double w = 1000.0;
  EXPECT_NEAR(predictedThreshold(IntegratorKind::RK4, w, 0.0) * w, 2.0 * std::numbers::sqrt2, 1e-6);
  EXPECT_NEAR(predictedThreshold(IntegratorKind::Symplectic, w, 0.0) * w, 2.0, 1e-6);
  EXPECT_EQ(predictedThreshold(IntegratorKind::Euler, w, 0.0), 0.0);  // never stable undamped
  // Damped (zeta_max = r w / 2 = 0.25 < 1): forward Euler is stable exactly for h <= r = c/k.
  EXPECT_NEAR(predictedThreshold(IntegratorKind::Euler, w, 5e-4), 5e-4, 1e-9);
  // Every implicit method (and cvode) is A-stable on the linear equation, damped or not.
  for (const IntegratorKind kind : allIntegrators()) {
    if (isExplicit(kind)) continue;
    EXPECT_TRUE(std::isinf(predictedThreshold(kind, w, 0.0))) << integratorName(kind);
    EXPECT_TRUE(std::isinf(predictedThreshold(kind, w, 5e-4))) << integratorName(kind);
  }
  // Strongly damped real modes: RK4's limit on the negative real axis is 2.785 / |lambda|.
  const double r = 0.02, zeta = r * w / 2.0, lambda = w * (zeta + std::sqrt(zeta * zeta - 1.0));
  EXPECT_NEAR(predictedThreshold(IntegratorKind::RK4, w, r) * lambda, 2.785, 0.01);
}

TEST(StabilityAnalysis, BlewUpMeansDivergedOrTenfoldEnergyWithinTheRunTime) {
  const World w = stabilityScene("free", 1e4, 1e-5);
  const double wMax = maxAngularFrequency(Model(w), initialState(w));
  const double limit = predictedThreshold(IntegratorKind::RK4, wMax, 1e-5);
  const BlowUpRule rule{0.1, 10.0};
  EXPECT_FALSE(runTrial(w, IntegratorKind::RK4, 0.9 * limit, rule).blewUp);
  const Trial above = runTrial(w, IntegratorKind::RK4, 1.2 * limit, rule);
  EXPECT_TRUE(above.blewUp);
  EXPECT_LT(above.steps, std::lround(0.1 / (1.2 * limit)));
  // A huge factor leaves only the simulation's own divergence check, which applies the same
  // tenfold energy rule (solvers/simulation.h, every 16 steps) besides its bounds: still
  // caught, as a divergence, no earlier.
  const Trial diverged = runTrial(w, IntegratorKind::RK4, 1.2 * limit, {0.1, 1e300});
  EXPECT_TRUE(diverged.blewUp);
  EXPECT_NE(diverged.reason.find("diverged"), std::string::npos) << diverged.reason;
  EXPECT_GE(diverged.steps, above.steps);
}

// The blow-up rule cannot fire on a bounded oscillation: symplectic Euler just below its limit
// (h w_max = 1.9) swings the energy of the fastest mode by up to 1/(1 - h w/2) = 20x its start
// (a start-referenced rule fires there) and stays bounded for 10 s; at h w_max = 2.1 the mode
// grows and the rule fires. The cube at rest at k = 10 (damping ratio 1e-5 s), displaced along
// its fastest mode (Spectra's top eigenvector of -K/m) by 10^-4 m: linear, so w_max at the start
// is w_max all along. (The free scene's corner, pulled a whole spacing, is not: there symplectic
// Euler at h w_max = 1.9 really blows up, a point 122 m out by step 49.)
TEST(StabilityAnalysis, TheBlowUpRuleIgnoresABoundedSwingAndCatchesGrowth) {
  SceneSpec spec = stiffCube(10.0);
  spec.dElastic = 1e-5 * 10.0;
  spec.pose = PosePreset::Rest;
  World w = buildWorld(spec);
  const Model model(w);
  const FastestMode fastest = fastestMode(model, initialState(w));
  const Eigen::VectorXd& mode = fastest.shape;
  const double wMax = fastest.wMax;
  const int n = model.numPoints();
  const double scale = 1e-4 / mode.cwiseAbs().maxCoeff();
  for (int p = 0; p < n; ++p) {
    w.positions[p] += Vec3{scale * mode[p], scale * mode[n + p], scale * mode[2 * n + p]};
  }
  const BlowUpRule rule{10.0, 10.0, 0};
  // The swing: the largest energy over the first steps against the start's.
  Simulation sim(w, IntegratorKind::Symplectic, 1.9 / wMax);
  const double e0 = sim.model().energy(sim.state()).total();
  double largest = e0;
  for (int i = 0; i < 400; ++i) {
    ASSERT_TRUE(sim.step().ok);
    largest = std::max(largest, sim.model().energy(sim.state()).total());
  }
  EXPECT_GT(largest, 10.0 * e0) << "the swing a start-referenced rule fires on";
  EXPECT_TRUE(sim.checkEnergy().ok) << "the simulation's rule (an envelope of 16 steps)";
  const Trial below = runTrial(w, IntegratorKind::Symplectic, 1.9 / wMax, rule);
  EXPECT_FALSE(below.blewUp) << below.reason;
  EXPECT_EQ(below.steps, std::lround(10.0 / (1.9 / wMax)));
  const Trial above = runTrial(w, IntegratorKind::Symplectic, 2.1 / wMax, rule);
  EXPECT_TRUE(above.blewUp);
  EXPECT_LT(above.steps, 1000);
  // The free scene, nonlinear, at the same h w_max: a real blow-up, a point far out or fast
  // (the simulation's bounds: measured 509 m/s against a speed bound of 340 m/s at step 47).
  const World pulled = stabilityScene("free", 10.0, 1e-5);
  const double wPulled = maxAngularFrequency(Model(pulled), initialState(pulled));
  const Trial real = runTrial(pulled, IntegratorKind::Symplectic, 1.9 / wPulled, rule);
  EXPECT_TRUE(real.blewUp);
  EXPECT_TRUE(real.reason.find("position bound") != std::string::npos ||
              real.reason.find("speed bound") != std::string::npos)
      << real.reason;
}

// Explicit methods run at least minSteps steps: RK4 at k = 10 just past its limit (h w_max 1.05
// times 2 sqrt 2) grows too slowly for a 0.2 s window (20 steps) and is caught within 2000.
TEST(StabilityAnalysis, ExplicitTrialsRunLongEnoughToSeeSlowGrowth) {
  const World w = stabilityScene("free", 10.0, 1e-5);
  const double wMax = maxAngularFrequency(Model(w), initialState(w));
  const double dt = 1.05 * predictedThreshold(IntegratorKind::RK4, wMax, 1e-5);
  EXPECT_FALSE(runTrial(w, IntegratorKind::RK4, dt, {0.2, 10.0, 1}).blewUp);
  const Trial trial = runTrial(w, IntegratorKind::RK4, dt, {0.2, 10.0, 2000});
  EXPECT_TRUE(trial.blewUp);
  EXPECT_GT(trial.steps, std::lround(0.2 / dt));
}

// Share of the bottom layer's samples (every step, every bottom point) above the floor.
double offTheFloor(const World& w, IntegratorKind kind, double dt, double time) {
  Simulation sim(w, kind, dt);
  const int n = sim.model().numPoints();
  long off = 0, samples = 0;
  for (long i = 0; i < std::lround(time / dt); ++i) {
    if (!sim.step().ok) return 1.0;
    for (int p = 0; p < n; p += w.cubeResolution) {
      ++samples;
      off += sim.state().x[2 * n + p] > -2.0;
    }
  }
  return double(off) / double(samples);
}

TEST(StabilityAnalysis, TheWallSceneRestsOnTheFloorInContact) {
  const World w = stabilityScene("wall", 1e4, 1e-5);
  double lowest = 1e9;
  for (const Vec3& p : w.positions) lowest = std::min(lowest, p.z);
  const double spacing = 1.0 / 7.0;
  EXPECT_LT(lowest, -2.0 - 0.5e-2 * spacing);  // sunk about 1% of a spacing
  EXPECT_GT(lowest, -2.0 - 2e-2 * spacing);
  EXPECT_EQ(w.kCollision, 20.0 * 1e4);
  // The contact springs raise w_max above the free cube's.
  const World free = stabilityScene("free", 1e4, 1e-5);
  EXPECT_GT(maxAngularFrequency(Model(w), initialState(w)),
            1.1 * maxAngularFrequency(Model(free), initialState(free)));
}

// Above the contact mode's limit but below the lattice's, RK4 does not blow up on the wall:
// the unstable contact oscillation lifts the bottom points off the floor, where the penalty
// spring stops acting, and chatters instead (the README's stability map).
TEST(StabilityAnalysis, AboveItsContactLimitRk4ChattersOnTheFloorInsteadOfBlowingUp) {
  const World w = stabilityScene("wall", 1e4, 1e-5);
  const double wMax = maxAngularFrequency(Model(w), initialState(w));
  const double limit = predictedThreshold(IntegratorKind::RK4, wMax, 1e-5);
  EXPECT_EQ(offTheFloor(w, IntegratorKind::RK4, 0.9 * limit, 0.1), 0.0);
  EXPECT_GT(offTheFloor(w, IntegratorKind::RK4, 1.15 * limit, 0.1), 0.1);
  EXPECT_FALSE(runTrial(w, IntegratorKind::RK4, 1.15 * limit, {0.1, 10.0}).blewUp);
  // Symplectic Euler's contact mode grows without bound past its limit: it does blow up.
  const double symplectic = predictedThreshold(IntegratorKind::Symplectic, wMax, 1e-5);
  EXPECT_TRUE(runTrial(w, IntegratorKind::Symplectic, 1.15 * symplectic, {0.1, 10.0}).blewUp);
}

// --- the programs' --quick runs ---------------------------------------------------------------

TEST(StabilityMapQuick, ThresholdsMeetTheirPredictionsAndImplicitNeverBlowsUp) {
  test::TempDir dir;
  ASSERT_EQ(run(std::string(JELLO_STABILITY) + " --quick --out-dir " + dir.path().string()), 0);
  const Table rows = readCsv(dir.path() / "stability.csv");
  expectSidecar(dir.path() / "stability.json", "jello-stability");
  // 2 k x every integrator x (predicted, measured)
  ASSERT_EQ(rows.size(), 2u * allIntegrators().size() * 2u);
  std::map<std::string, double> predicted;
  std::map<std::string, std::vector<double>> courant;
  for (const auto& r : rows) {
    if (r.at("source") == "predicted")
      predicted[r.at("integrator") + r.at("k_N_per_m")] = number(r, "dt_s");
  }
  for (const auto& r : rows) {
    if (r.at("source") != "measured") continue;
    const std::string integrator = r.at("integrator");
    if (integrator == "rk4" || integrator == "symplectic") {
      const double ratio = number(r, "dt_s") / predicted.at(integrator + r.at("k_N_per_m"));
      EXPECT_NEAR(ratio, 1.0, 0.25) << integrator << " at k = " << r.at("k_N_per_m");
      courant[integrator].push_back(number(r, "courant_number"));
    }
    if (integrator == "implicit" || integrator == "implicit-linear" || integrator == "bdf2") {
      EXPECT_EQ(r.at("outcome"), "stable_to_max") << integrator << " at " << r.at("k_N_per_m");
    }
  }
  const auto& c = courant["rk4"];
  ASSERT_EQ(c.size(), 2u);
  EXPECT_LT(*std::max_element(c.begin(), c.end()) / *std::min_element(c.begin(), c.end()), 1.25);
}

TEST(ScalingQuick, EveryIntegratorAndSizeHasItsCostAndTheImplicitSplit) {
  test::TempDir dir;
  ASSERT_EQ(
      run(std::string(JELLO_SCALING) + " --quick --no-atlas --out-dir " + dir.path().string()), 0);
  expectSidecar(dir.path() / "scaling.json", "jello-scaling");
  const Table rows = readCsv(dir.path() / "scaling.csv");
  EXPECT_EQ(rows.size(), 2u * 7u);  // N = 6, 8 x (3 explicit + implicit and cvode x 2 solvers)
  for (const auto& r : rows) {
    const double n = number(r, "n");
    EXPECT_EQ(number(r, "unknowns"), 3 * n * n * n);
    const double cost = number(r, "wall_per_simulated_s");
    EXPECT_TRUE(std::isfinite(cost) && cost > 0.0);
    if (r.at("integrator") == "implicit") {
      EXPECT_LE(number(r, "factor_per_simulated_s") + number(r, "solve_per_simulated_s"), cost);
    }
  }
}

// The atlas's quick grid (N = 8, k = 1e3 and 1e5, 4 steps tried each): every cost is at a step
// whose visible motion (the affine fit at the corners) is within 1 cm of a reference that is
// itself ten times closer; RK4's cost grows with k (its limit falls as 1/sqrt(k)). Through the
// bounce, backward Euler's artificial damping of the contact (projective's too: it takes the
// same step) lowers the rebound beyond 1 cm at every step tried, while midpoint (second order,
// no damping of its own) keeps the visible motion at steps more than 20 times RK4's at k = 1e5.
TEST(ScalingQuick, TheAtlasKeepsTheVisibleMotionAndBackwardEulerLosesTheBounce) {
  test::TempDir dir;
  ASSERT_EQ(run(std::string(JELLO_SCALING) + " --quick --no-grid --atlas-references " +
                quickReferences(dir.path()).string() + " --out-dir " + dir.path().string()),
            0);
  // --no-grid: the atlas alone, the grid's file only its header.
  ASSERT_TRUE(std::filesystem::exists(dir.path() / "scaling.csv"));
  EXPECT_TRUE(readCsv(dir.path() / "scaling.csv").empty());
  const Table rows = readCsv(dir.path() / "scaling_atlas.csv");
  ASSERT_EQ(rows.size(), 2u * 5u);
  std::map<std::string, std::map<std::string, std::string>> point;
  for (const auto& r : rows) {
    EXPECT_EQ(r.at("n"), "8");
    EXPECT_LT(number(r, "reference_check_m"), 1e-3);
    EXPECT_LE(number(r, "reference_dt_s") * number(r, "w_max_rad_per_s"), 1.0 + 1e-12);
    point[r.at("integrator") + "@" + r.at("k_N_per_m")] = r;
    if (r.at("outcome") != "ok") continue;
    EXPECT_LE(number(r, "visible_error_m"), 0.01) << r.at("integrator");
    EXPECT_GT(number(r, "wall_per_simulated_s"), 0.0);
  }
  for (const char* key : {"rk4@1000", "rk4@100000", "symplectic@100000", "midpoint@100000"}) {
    ASSERT_EQ(point.count(key), 1u) << key;
    EXPECT_EQ(point[key].at("outcome"), "ok") << key;
  }
  EXPECT_GT(number(point["rk4@100000"], "wall_per_simulated_s"),
            3.0 * number(point["rk4@1000"], "wall_per_simulated_s"));
  EXPECT_GT(number(point["midpoint@100000"], "dt_s"), 20.0 * number(point["rk4@100000"], "dt_s"));
  for (const char* key :
       {"implicit@1000", "implicit@100000", "projective@1000", "projective@100000"}) {
    EXPECT_EQ(point[key].at("outcome"), "not_reached") << key;
    EXPECT_GT(number(point[key], "visible_error_m"), 0.01) << key;
    EXPECT_EQ(point[key].at("tried"), "4") << key;
  }
}

// The free scene (--atlas-scene free): the same throw and spin without gravity touches nothing
// in its window (the reference's path, checked point by point), so only rigid motion and what
// the spin stretches are visible. There midpoint keeps the visible motion at the largest step
// tried (0.02 s, more than 20 times RK4's at k = 1e5), while backward Euler's damping of the
// rotation itself (its rigid rotation spirals in by 1/sqrt(1 + (w h)^2) a step) needs a smaller
// step than midpoint's at both k; projective, backward Euler's step at a fraction of its cost,
// keeps the motion at that step and costs less than RK4 at k = 1e5 (measured 0.18 against
// 0.36 s per simulated second in the full run, 28x RK4's step).
TEST(ScalingQuick, TheFreeSceneTouchesNothingAndMidpointKeepsItsMotionAtTheLargestStep) {
  const World w = experiments::atlasScene(1e3, 8, experiments::AtlasScene::Free);
  EXPECT_TRUE(w.field.empty());
  Simulation sim(w, IntegratorKind::RK4, 2e-4);
  for (int i = 0; i < 5000; ++i) {
    ASSERT_TRUE(sim.step().ok);
    ASSERT_FALSE(sim.model().inContact(sim.state().x.data())) << "t = " << sim.state().t;
  }
  test::TempDir dir;
  ASSERT_EQ(run(std::string(JELLO_SCALING) + " --quick --no-grid --atlas-scene free " +
                "--atlas-references " + quickReferences(dir.path()).string() + " --out-dir " +
                dir.path().string()),
            0);
  std::ifstream sidecarFile(dir.path() / "scaling.json");
  const auto sidecar = nlohmann::json::parse(sidecarFile);
  EXPECT_EQ(sidecar["parameters"]["atlas"]["scene_name"], "free");
  std::map<std::string, std::map<std::string, std::string>> point;
  for (const auto& r : readCsv(dir.path() / "scaling_atlas.csv")) {
    point[r.at("integrator") + "@" + r.at("k_N_per_m")] = r;
    if (r.at("outcome") == "ok") {
      EXPECT_LE(number(r, "visible_error_m"), 0.01) << r.at("integrator");
    }
  }
  for (const char* k : {"1000", "100000"}) {
    SCOPED_TRACE(k);
    const std::string at = std::string("@") + k;
    ASSERT_EQ(point["midpoint" + at].at("outcome"), "ok");
    EXPECT_EQ(number(point["midpoint" + at], "dt_s"), 0.02);
    EXPECT_EQ(point["implicit" + at].at("outcome"), "ok");
    EXPECT_LT(number(point["implicit" + at], "dt_s"), number(point["midpoint" + at], "dt_s"));
  }
  EXPECT_GT(number(point["midpoint@100000"], "dt_s"), 20.0 * number(point["rk4@100000"], "dt_s"));
  ASSERT_EQ(point["projective@100000"].at("outcome"), "ok");
  EXPECT_GT(number(point["projective@100000"], "dt_s"), 20.0 * number(point["rk4@100000"], "dt_s"));
  EXPECT_LT(number(point["projective@100000"], "wall_per_simulated_s"),
            number(point["rk4@100000"], "wall_per_simulated_s"));
}

// --- the sidecar's record of the tree ------------------------------------------------------

// A tracked file changed outside experiments/results/ marks the tree modified; the results an
// earlier program of the same run wrote do not (they are not the code that runs).
TEST(RunContext, ResultsWrittenByAnEarlierProgramDoNotMarkTheTreeModified) {
  if (test::run("git --version").code != 0) GTEST_SKIP() << "no git";
  test::TempDir dir;
  const auto& root = dir.path();
  std::filesystem::create_directories(root / "experiments" / "results");
  std::filesystem::create_directories(root / "src");
  const auto write = [](const std::filesystem::path& p, const std::string& text) {
    std::ofstream(p) << text;
  };
  write(root / "src" / "code.cpp", "int x;\n");
  write(root / "experiments" / "results" / "r.csv", "a\n1\n");
  const std::string git = "git -C '" + root.string() + "' ";
  ASSERT_EQ(test::run(git + "init -q && " + git + "add -A && " + git +
                      "-c user.name=t -c user.email=t@t commit -q -m start")
                .code,
            0);
  EXPECT_FALSE(treeModified(root));
  write(root / "experiments" / "results" / "r.csv", "a\n2\n");
  write(root / "experiments" / "results" / "new.csv", "a\n");  // untracked: ignored too
  EXPECT_FALSE(treeModified(root));
  write(root / "src" / "code.cpp", "int y;\n");
  EXPECT_TRUE(treeModified(root));
  EXPECT_FALSE(treeModified(root / "no-such-dir"));
}

// --- row order, threads and MPI ranks --------------------------------------------------------

TEST(CsvTable, RowsAreInTaskOrderWhateverTheThreadsAndSurviveAGather) {
  // Later tasks finish first (shorter sleeps), each adding two rows, on three threads.
  CsvTable table({"task", "row"});
  table.add({std::string("setup"), 0L});
  parallelFor(12, 3, "", false, [&](int i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2 * (12 - i)));
    table.add({long(i), 0L});
    table.add({long(i), 1L});
  });
  std::string expected = "task,row\nsetup,0\n";
  for (int i = 0; i < 12; ++i) expected += std::to_string(i) + ",0\n" + std::to_string(i) + ",1\n";
  EXPECT_EQ(table.text(), expected);
  // Rank 0 ran the even tasks, rank 1 the odd ones: merged, the table is the same.
  CsvTable even({"task", "row"}), odd({"task", "row"});
  even.add({std::string("setup"), 0L});
  parallelFor(std::vector<int>{0, 2, 4, 6, 8, 10}, 2, "", false, [&](int i) {
    even.add({long(i), 0L});
    even.add({long(i), 1L});
  });
  parallelFor(std::vector<int>{1, 3, 5, 7, 9, 11}, 2, "", false, [&](int i) {
    odd.add({long(i), 0L});
    odd.add({long(i), 1L});
  });
  even.merge(odd.serialize());
  EXPECT_EQ(even.text(), expected);
  EXPECT_EQ(even.rows(), 25u);
  EXPECT_THROW(even.merge("3 x 1,2\n"), std::runtime_error);
}

// Several jobs hold the CPUs: their tasks' model loops run on the task's thread, and the setting
// comes back after; one job leaves it alone.
TEST(ParallelFor, JobsKeepTheModelsLoopsOnTheirOwnThread) {
  setParallelThreads(2);
  std::atomic<int> threaded{0};
  parallelFor(4, 2, "", false, [&](int) { threaded += parallelThreads() > 1; });
  EXPECT_EQ(threaded, 0);
  EXPECT_EQ(parallelThreads(), 2);
  parallelFor(2, 1, "", false, [&](int) { threaded += parallelThreads() > 1; });
  EXPECT_EQ(threaded, 2);
  setParallelThreads(1);
}

TEST(Ranks, WithoutAnMpiLauncherTheProcessIsTheOnlyRankAndRunsEveryTask) {
  int argc = 1;
  char name[] = "experiments_test";
  char* args[] = {name, nullptr};
  char** argv = args;
  const Ranks ranks(argc, argv);
  EXPECT_TRUE(ranks.error().empty());
  EXPECT_EQ(ranks.size(), 1);
  EXPECT_TRUE(ranks.root());
  EXPECT_EQ(ranks.share(3), (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(ranks.all(true));
  EXPECT_FALSE(ranks.all(false));
}

#ifdef JELLO_MPIEXEC
// The CSV with the columns a clock decides blanked out.
std::string withoutTiming(const std::filesystem::path& csv, const std::set<std::string>& timing) {
  std::string out;
  const Table rows = readCsv(csv);
  for (const auto& row : rows) {
    for (const auto& [column, value] : row)
      out += column + "=" + (timing.count(column) ? "-" : value) + ";";
    out += "\n";
  }
  return out;
}

struct Distributed {
  const char* program;
  const char* name;
  std::set<std::string> timing;
  std::string options;  // added to both runs
};

class MpiRun : public ::testing::TestWithParam<Distributed> {};

TEST_P(MpiRun, TwoRanksWriteTheSingleProcessCsvTimingAside) {
  const Distributed& d = GetParam();
  test::TempDir dir;
  const std::string serial = (dir.path() / "serial").string(), mpi = (dir.path() / "mpi").string();
  ASSERT_EQ(run(std::string(d.program) + " --quick" + d.options + " --jobs 2 --out-dir " + serial),
            0);
  // Two ranks of one thread each. mpirun refuses root unless told (CI runs as root); PMIx's
  // shared-memory store fails on some VMs and containers ("getting local rank failed"), its
  // hash store works everywhere.
  const test::Outcome o = test::run(
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 PMIX_MCA_gds=hash " JELLO_MPIEXEC
      " -np 2 --oversubscribe " +
      std::string(d.program) + " --quick" + d.options + " --quiet --jobs 1 --out-dir " + mpi);
  ASSERT_EQ(o.code, 0) << o.output;
  const std::string csv = std::string(d.name) + ".csv";
  const std::string expected = withoutTiming(std::filesystem::path(serial) / csv, d.timing);
  EXPECT_GT(expected.size(), 100u);
  EXPECT_EQ(withoutTiming(std::filesystem::path(mpi) / csv, d.timing), expected);
  std::ifstream in(std::filesystem::path(mpi) / (std::string(d.name) + ".json"));
  EXPECT_EQ(nlohmann::json::parse(in).at("mpi_ranks"), 2);  // both ranks ran, one wrote
}

INSTANTIATE_TEST_SUITE_P(
    QuickGrids, MpiRun,
    ::testing::Values(Distributed{JELLO_STABILITY, "stability", {"wall_time_s"}, ""},
                      Distributed{JELLO_WORK_PRECISION,
                                  "work_precision",
                                  {"setup_s", "first_step_s", "wall_time_s", "wall_time_min_s",
                                   "wall_time_max_s"},
                                  ""},
                      // Scaling runs each point for a wall-time budget: how far it got is timing
                      // too. Its atlas (ScalingQuick's) is left out: only scaling.csv is compared,
                      // and the atlas took all but 5 of the test's 50 s.
                      Distributed{JELLO_SCALING,
                                  "scaling",
                                  {"steps", "simulated_s", "wall_s", "wall_per_simulated_s",
                                   "assemble_per_simulated_s", "factor_per_simulated_s",
                                   "solve_per_simulated_s", "factorizations"},
                                  " --no-atlas"}),
    [](const ::testing::TestParamInfo<Distributed>& test) { return std::string(test.param.name); });

// A bad argument under mpirun: one message (rank 0's), and every rank exits with the usage code.
TEST(MpiUsage, ABadArgumentIsReportedOnceAndFailsTheJob) {
  const test::Outcome o = test::run(
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 PMIX_MCA_gds=hash " JELLO_MPIEXEC
      " -np 2 --oversubscribe " +
      std::string(JELLO_SCALING) + " --n 0");
  EXPECT_NE(o.code, 0) << o.output;
  std::size_t count = 0;
  for (std::size_t at = o.output.find("--n"); at != std::string::npos;
       at = o.output.find("--n", at + 1)) {
    ++count;
  }
  EXPECT_EQ(count, 1u) << o.output;
}

// Issue 41, item 3: a bad option on one rank left the good rank at 100% CPU for minutes, its
// partner silent in MPI_Finalize; ranks given different values wrote a CSV whose rows
// alternated between them. Rank 0's command line is the job's: any other fails it at once.
TEST(MpiUsage, RanksGivenDifferentArgumentsFailTheJobAtOnceWithOneMessage) {
  test::TempDir dir;
  const std::string stability =
      std::string(JELLO_STABILITY) + " --quick --quiet --out-dir " + (dir.path() / "o").string();
  for (const char* other : {" --bogus", " --time nan", " --k 100000"}) {
    const auto started = std::chrono::steady_clock::now();
    const test::Outcome o = test::run(
        "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout 100 " JELLO_MPIEXEC
        " --oversubscribe -np 1 " +
        stability + " --k 100 : -np 1 " + stability + other);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    EXPECT_NE(o.code, 0) << other << ": " << o.output;
    EXPECT_NE(o.code, 124) << other << ": the job hung";
    EXPECT_LT(seconds, 30.0) << other;
    const std::string message = "rank 1 was started with other arguments than rank 0";
    const std::size_t at = o.output.find(message);
    EXPECT_NE(at, std::string::npos) << other << ": " << o.output;
    EXPECT_EQ(o.output.find(message, at + 1), std::string::npos) << "said once: " << o.output;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "o" / "stability.csv"));
  }
}

// Issue 41, item 2: the README's mpirun failed in MPI_Init on these machines from a shell with
// nothing exported (the programs started themselves again to set the solver threads' variables).
// Its command as written (four ranks of jello-stability, --quick into a scratch directory;
// as root, --allow-run-as-root), with no thread variable and no PMIx setting in the environment:
// it runs, and the sidecar shows the settings were made by the libraries' calls, not exported.
TEST(MpiUsage, TheReadmesCommandRunsFromAShellWithNothingExported) {
  std::ifstream readme(std::filesystem::path(JELLO_WORLDS_DIR).parent_path() / "experiments" /
                       "README.md");
  std::string command;
  for (std::string line; std::getline(readme, line);) {
    if (line.rfind("mpirun ", 0) == 0) {
      command = line.substr(0, line.find('#'));
      break;
    }
  }
  ASSERT_FALSE(command.empty()) << "experiments/README.md has no mpirun command";
  test::TempDir dir;
  const auto replace = [&](const std::string& what, const std::string& with) {
    const std::size_t at = command.find(what);
    ASSERT_NE(at, std::string::npos) << what << " in " << command;
    command.replace(at, what.size(), with);
  };
  replace("build/release/bin/jello-stability", JELLO_STABILITY);
  replace("experiments/results", dir.path().string() + " --quick --quiet");
  if (::geteuid() == 0) replace("mpirun ", "mpirun --allow-run-as-root ");
  const test::Outcome o = test::run(
      "env -u OMP_THREAD_LIMIT -u OPENBLAS_NUM_THREADS -u OMP_WAIT_POLICY -u OMP_NUM_THREADS "
      "-u PMIX_MCA_gds -u OMPI_ALLOW_RUN_AS_ROOT -u OMPI_ALLOW_RUN_AS_ROOT_CONFIRM timeout 300 " +
      command);
  ASSERT_EQ(o.code, 0) << command << "\n" << o.output;
  std::ifstream in(dir.path() / "stability.json");
  const nlohmann::json sidecar = nlohmann::json::parse(in);
  EXPECT_EQ(sidecar.at("mpi_ranks"), 4);
  EXPECT_EQ(sidecar.at("OPENBLAS_NUM_THREADS"), "");  // not exported, and no restart set it
  EXPECT_EQ(sidecar.at("solver_threads"), "openblas 1 thread; openmp serial");
}
#endif

TEST(ExperimentPrograms, RefuseBadArguments) {
  EXPECT_EQ(run(std::string(JELLO_STABILITY) + " --integrators leapfrog"), 2);
  EXPECT_EQ(run(std::string(JELLO_STABILITY) + " --k -5"), 2);
  EXPECT_EQ(run(std::string(JELLO_WORK_PRECISION) + " --levels 1"), 2);
  EXPECT_EQ(run(std::string(JELLO_SCALING) + " --n 1"), 2);
  EXPECT_EQ(run(std::string(JELLO_SCALING) + " --quick --out-dir /proc/jello"), 1);
}

}  // namespace
}  // namespace jello::experiments
