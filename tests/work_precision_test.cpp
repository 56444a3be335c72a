// jello-work-precision's --quick run: errors over the trajectory fall with each method's order,
// the artificial damping of the implicit methods is the linear theory's, and the long-run drift
// of energy and angular momentum is bounded where the methods say so.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "tests/experiments_support.h"
#include "tests/test_support.h"

namespace jello::experiments {
namespace {

// One --quick run of jello-work-precision (about 12 s) read by the tests below, all in one
// process (tests/CMakeLists.txt: ONE_PROCESS).
class WorkPrecisionQuick : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir;
    code_ = run(std::string(JELLO_WORK_PRECISION) + " --quick --repeats 2 --out-dir " +
                dir_->path().string());
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override { ASSERT_EQ(code_, 0); }
  static std::filesystem::path path(const std::string& file) { return dir_->path() / file; }

 private:
  static inline test::TempDir* dir_ = nullptr;
  static inline int code_ = -1;
};

TEST_F(WorkPrecisionQuick, ErrorsOverTheTrajectoryFallWithTheMethodsOrders) {
  expectSidecar(path("work_precision.json"), "jello-work-precision");
  std::map<std::string, std::vector<std::pair<double, double>>> errors;
  std::vector<std::pair<double, double>> bdf;
  for (const auto& r : readCsv(path("work_precision.csv"))) {
    EXPECT_EQ(r.at("outcome"), "ok") << r.at("integrator") << " dt " << r.at("dt_s");
    // Timings: the median of 2 runs lies within their spread; set-up is timed apart.
    EXPECT_EQ(r.at("repeats"), "2");
    EXPECT_GT(number(r, "wall_time_s"), 0.0);
    EXPECT_LE(number(r, "wall_time_min_s"), number(r, "wall_time_s"));
    EXPECT_GE(number(r, "wall_time_max_s"), number(r, "wall_time_s"));
    EXPECT_GT(number(r, "setup_s"), 0.0);
    EXPECT_LE(number(r, "first_step_s"), number(r, "wall_time_max_s"));
    // The RMS over samples of the worst point cannot exceed the maximum over them.
    const double e = number(r, "position_error_max_m");
    EXPECT_LE(number(r, "position_error_rms_m"), e * (1 + 1e-12));
    EXPECT_GE(number(r, "force_evaluations"), number(r, "steps"));
    if (r.at("integrator") == "cvode") {
      EXPECT_EQ(r.at("cvode_method"), "bdf");
      EXPECT_GE(number(r, "cvode_steps"), 1.0);
      bdf.emplace_back(number(r, "rtol"), e);
    } else {
      errors[r.at("integrator")].emplace_back(number(r, "dt_s"), e);
    }
    if (r.at("integrator") == "rk4") {  // one force evaluation per stage
      EXPECT_EQ(number(r, "force_evaluations"), 4 * number(r, "steps"));
    }
    if (r.at("integrator") == "implicit") {
      EXPECT_GE(number(r, "newton_iterations"), 1.0);
    }
  }
  ASSERT_EQ(errors["rk4"].size(), 3u);
  ASSERT_EQ(errors["implicit"].size(), 3u);
  EXPECT_NEAR(slope(errors["euler"]), 1.0, 0.35);
  EXPECT_NEAR(slope(errors["implicit"]), 1.0, 0.35);
  EXPECT_NEAR(slope(errors["symplectic"]), 1.0, 0.35);
  EXPECT_NEAR(slope(errors["rk4"]), 4.0, 0.6);
  std::sort(bdf.begin(), bdf.end());
  ASSERT_EQ(bdf.size(), 3u);
  EXPECT_LT(bdf[0].second, bdf[2].second);  // tighter tolerance, smaller error
}

// The undamped stiff cube loses energy to backward Euler and BDF2 only, as fast as the linear
// theory on its modes predicts (mode_theory.h: within 5%; the springs' nonlinearity at a 5%
// stretch is the difference, 0.1-0.2% here); midpoint keeps it.
TEST_F(WorkPrecisionQuick, ArtificialDampingIsTheLinearTheorysPerMode) {
  const Table damping = readCsv(path("work_precision_damping.csv"));
  std::set<std::string> seen;
  for (const auto& r : damping) {
    const std::string& integrator = r.at("integrator");
    seen.insert(integrator);
    const double measured = number(r, "energy_ratio"),
                 predicted = number(r, "predicted_energy_ratio");
    if (integrator == "midpoint") {  // the springs' nonlinearity costs it about 1% at most
      EXPECT_GT(measured, 0.97) << "dt " << r.at("dt_s");
      EXPECT_NEAR(predicted, 1.0, 1e-12) << "dt " << r.at("dt_s");
      continue;
    }
    EXPECT_GT(number(r, "energy_decay_rate_per_s"), 0.0) << integrator << " dt " << r.at("dt_s");
    EXPECT_NEAR(number(r, "energy_decay_rate_per_s") / number(r, "predicted_decay_rate_per_s"), 1.0,
                0.05)
        << integrator << " dt " << r.at("dt_s");
  }
  EXPECT_EQ(seen, (std::set<std::string>{"implicit", "bdf2", "midpoint"}));
}

// The long run of the undamped spinning cube (3 s in --quick): its equations keep energy and
// angular momentum. Symplectic Euler keeps angular momentum exactly (a quadratic invariant of
// its map, spring forces being central), implicit midpoint to its Newton tolerance (the same
// invariant, solved to 1e-8); both swing the energy without drifting: no larger in the second
// half of the run than in the first. RK4 at half its limit loses energy steadily (more in the
// second half), backward Euler all but the rigid spin's, and angular momentum too.
TEST_F(WorkPrecisionQuick, LongRunDriftIsBoundedForSymplecticAndMidpointAndDampedForImplicit) {
  std::map<std::string, Table::value_type> runs;
  for (const auto& r : readCsv(path("work_precision_drift_summary.csv"))) {
    EXPECT_EQ(r.at("outcome"), "ok") << r.at("integrator");
    runs[r.at("integrator")] = r;
  }
  ASSERT_EQ(runs.size(), 4u);
  const auto value = [&](const char* integrator, const char* column) {
    return number(runs.at(integrator), column);
  };
  for (const char* bounded : {"symplectic", "midpoint"}) {
    EXPECT_LT(value(bounded, "energy_deviation_max_second_half"),
              1.25 * value(bounded, "energy_deviation_max_first_half"))
        << bounded;
  }
  EXPECT_LT(value("symplectic", "angular_momentum_error_max"), 1e-12);
  EXPECT_LT(value("midpoint", "angular_momentum_error_max"), 1e-4);
  EXPECT_LT(value("midpoint", "energy_deviation_max_first_half"), 0.05);
  EXPECT_GT(value("implicit", "angular_momentum_error_max"),
            1e3 * value("midpoint", "angular_momentum_error_max"));
  EXPECT_LT(value("implicit", "energy_ratio_end"), 0.01);
  EXPECT_LT(value("rk4", "energy_ratio_end"), 1.0);
  EXPECT_GT(value("rk4", "energy_ratio_end"), 10 * value("implicit", "energy_ratio_end"));
  EXPECT_GT(value("rk4", "energy_deviation_max_second_half"),
            value("rk4", "energy_deviation_max_first_half"));
  // The series: one row per sample from t = 0 at E/E0 = 1, the summary's end value last.
  std::map<std::string, std::vector<double>> series;
  for (const auto& r : readCsv(path("work_precision_drift.csv"))) {
    series[r.at("integrator")].push_back(number(r, "energy_ratio"));
  }
  // RK4's loss is steady: no sample above the one before (beyond 0.1% swings).
  for (std::size_t i = 1; i < series["rk4"].size(); ++i) {
    EXPECT_LT(series["rk4"][i], series["rk4"][i - 1] + 1e-3) << "sample " << i;
  }
  for (const auto& [name, ratios] : series) {
    ASSERT_EQ(ratios.size(), 31u) << name;  // 3 s every 0.1 s
    EXPECT_EQ(ratios.front(), 1.0) << name;
    EXPECT_DOUBLE_EQ(ratios.back(), number(runs.at(name), "energy_ratio_end")) << name;
  }
}

}  // namespace
}  // namespace jello::experiments
