// The atlas's references kept on disk (reference_file.h, jello-scaling --atlas-references): a
// file reads back to the bit, a file made for another point or damaged is refused with its
// line and token, and a reference stored, resumed from a saved state or computed at once is the
// same to the bit (RK4 keeps no history), so that hours of N = 32 may span several runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "experiments/studies/atlas.h"
#include "experiments/studies/reference_file.h"
#include "solvers/simulation.h"
#include "src/base/parallel.h"
#include "tests/experiments_support.h"
#include "tests/test_support.h"

namespace jello::experiments {
namespace {

TrajectoryKey smallKey() {
  return {"falling", 1e3, 2, 3.0517578125e-4, 0.02, 0.1};
}

std::vector<AffineFit> randomFits(int count) {
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  std::vector<AffineFit> fits(std::size_t(count), AffineFit::Zero());
  for (AffineFit& f : fits) {
    for (int i = 0; i < 12; ++i) f(i % 3, i / 3) = normal(random) * std::pow(10.0, i - 6);
  }
  return fits;
}

std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The message of readTrajectory's refusal of `text` (empty: none).
std::string refusal(const std::filesystem::path& file, const std::string& text,
                    const TrajectoryKey& key) {
  std::ofstream(file) << text;
  try {
    readTrajectory(file, key);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return {};
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(ReferenceFile, ReadsBackToTheBitAndRefusesAnythingElse) {
  test::TempDir dir;
  const TrajectoryKey key = smallKey();
  const std::filesystem::path file = dir.path() / key.fileName();
  EXPECT_FALSE(readTrajectory(file, key).has_value());  // none yet

  // Unfinished: three fits and the state at the third (t = 0.04 s), 8 points.
  const std::vector<AffineFit> fits = randomFits(3);
  State s;
  s.t = 2 * 0.02;
  s.x = Eigen::VectorXd::Random(24) * 1e3;
  s.v = Eigen::VectorXd::Random(24) * 1e-9;
  writeTrajectory(file, key, fits, &s);
  std::optional<StoredTrajectory> back = readTrajectory(file, key);
  ASSERT_TRUE(back && back->resume);
  ASSERT_EQ(back->fits.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(back->fits[i], fits[i]);
  EXPECT_EQ(back->resume->t, s.t);
  EXPECT_EQ(back->resume->x, s.x);
  EXPECT_EQ(back->resume->v, s.v);

  // Finished: all six fits, no state.
  const std::vector<AffineFit> all = randomFits(6);
  writeTrajectory(file, key, all, nullptr);
  back = readTrajectory(file, key);
  ASSERT_TRUE(back);
  EXPECT_FALSE(back->resume);
  ASSERT_EQ(back->fits.size(), 6u);
  EXPECT_EQ(back->fits[5], all[5]);
  const std::string good = slurp(file);

  // Made for another point: the field that differs, with the file and its line.
  TrajectoryKey other = key;
  other.k = 1e4;
  std::string why = refusal(file, good, other);
  EXPECT_NE(why.find(file.string() + ":3: made for k_N_per_m = 1000, not 10000"), std::string::npos)
      << why;
  other = key;
  other.scene = "free";
  EXPECT_NE(refusal(file, good, other).find(":2: made for the scene 'falling', not 'free'"),
            std::string::npos);
  other = key;
  other.dt *= 2;
  EXPECT_NE(refusal(file, good, other).find(":5: made for dt_s"), std::string::npos);

  // Damaged: the token and its line.
  const auto damaged = [&](const std::string& from, const std::string& to) {
    return refusal(file, replaced(good, from, to), key);
  };
  why = damaged("fits 6\n", "fits 6\n1 2 3 4 5 6 7 8 9 10 11 1.5x\n");
  EXPECT_NE(why.find(":9: '1.5x' is not a finite number"), std::string::npos) << why;
  why = damaged("fits 6\n", "fits 6\n1 2 3 4 5 6 7 8 9 10 11 nan\n");
  EXPECT_NE(why.find(":9: 'nan' is not a finite number"), std::string::npos) << why;
  why = damaged("fits 6\n", "fits 7\n");
  EXPECT_NE(why.find(":8: '7' is not a count from 0 to 6"), std::string::npos) << why;
  why = damaged("fits 6\n", "fits 5\n");
  EXPECT_NE(why.find(":14: unfinished (5 of 6 fits) and without the state"), std::string::npos)
      << why;
  why = damaged("end\n", "");
  EXPECT_NE(why.find("the file ends early, before 'end'"), std::string::npos) << why;
  why = damaged("end\n", "end\nmore\n");
  EXPECT_NE(why.find("'more' after 'end'"), std::string::npos) << why;
  why = refusal(file, good.substr(0, good.find("fits")), key);
  EXPECT_NE(why.find("the file ends early, before 'fits'"), std::string::npos) << why;

  // Unfinished without its state, or with a state that is not the last fit's.
  writeTrajectory(file, key, fits, nullptr);
  why = refusal(file, slurp(file), key);
  EXPECT_NE(why.find("unfinished (3 of 6 fits) and without the state"), std::string::npos) << why;
  s.t = 0.06;
  writeTrajectory(file, key, fits, &s);
  why = refusal(file, slurp(file), key);
  EXPECT_NE(why.find("is not that of the last fit"), std::string::npos) << why;
  s.t = 0.04;
  writeTrajectory(file, key, fits, &s);
  why = refusal(file, replaced(slurp(file), "state 0.040000000000000001 8", "state 0.04 9"), key);
  EXPECT_NE(why.find("a state of 9 points, not 8"), std::string::npos) << why;

  // A token carrying terminal escapes (a title, a screen clear) is quoted escaped: no control
  // byte reaches the terminal.
  why = refusal(file, replaced(good, "scene falling", "scene \x1b]0;owned\x07\x1b[2J"), key);
  EXPECT_NE(why.find("made for the scene '\\x1b]0;owned\\x07\\x1b[2J', not 'falling'"),
            std::string::npos)
      << why;
  EXPECT_EQ(why.find('\x1b'), std::string::npos) << why;
  EXPECT_EQ(why.find('\x07'), std::string::npos) << why;
}

// A reference computed at once, computed into a directory, read back from it, and resumed from
// a saved state are the same to the bit; the model's threads come back after it.
TEST(AtlasReference, StoredAndResumedReferencesEqualTheOneComputedAtOnce) {
  const World w = atlasScene(1e3, 8, AtlasScene::Falling);
  AtlasSetup setup;
  setup.time = 0.1;
  const AtlasReference once = atlasReference(w, 1e3, AtlasScene::Falling, setup);
  ASSERT_EQ(once.samples.size(), 6u);
  EXPECT_GT(once.check, 0.0);
  EXPECT_LT(once.check, 1e-4);

  test::TempDir dir;
  setup.referenceDir = dir.path();
  setup.checkpoint = 0.0;  // a state after every fit
  // The marked fit below would fail the check: no refinement, the stored files alone.
  setup.referenceRefinements = 0;
  const int threads = parallelThreads();
  setup.referenceThreads = threads + 1;
  const AtlasReference stored = atlasReference(w, 1e3, AtlasScene::Falling, setup);
  EXPECT_EQ(parallelThreads(), threads);
  const TrajectoryKey key{"falling", 1e3, 8, once.dt, setup.interval, setup.time};
  const std::filesystem::path file = dir.path() / key.fileName();
  ASSERT_TRUE(std::filesystem::exists(file));
  TrajectoryKey checkKey = key;
  checkKey.dt *= 2;
  ASSERT_TRUE(std::filesystem::exists(dir.path() / checkKey.fileName()));
  EXPECT_FALSE(readTrajectory(file, key)->resume);  // finished: the state is gone
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(stored.samples[i], once.samples[i]) << i;
  EXPECT_EQ(stored.check, once.check);

  // Read back, not computed: a finished check equal to the reference checks to exactly 0.
  writeTrajectory(dir.path() / checkKey.fileName(), checkKey, once.samples, nullptr);
  EXPECT_EQ(atlasReference(w, 1e3, AtlasScene::Falling, setup).check, 0.0);

  // Resumed: the state at t = 0.04 s (two samples of RK4 steps) with the fits before it, the
  // fit at 0.02 s marked so that a recomputation would show.
  Simulation sim(w, IntegratorKind::RK4, once.dt);
  for (long i = 0; i < 2 * std::lround(setup.interval / once.dt); ++i) ASSERT_TRUE(sim.step().ok);
  std::vector<AffineFit> partial(once.samples.begin(), once.samples.begin() + 3);
  partial[1](0, 3) += 1.0;
  writeTrajectory(file, key, partial, &sim.state());
  std::filesystem::remove(dir.path() / checkKey.fileName());
  const AtlasReference resumed = atlasReference(w, 1e3, AtlasScene::Falling, setup);
  EXPECT_EQ(resumed.samples[1](0, 3), once.samples[1](0, 3) + 1.0);  // kept from the file
  for (std::size_t i : {0u, 2u, 3u, 4u, 5u}) EXPECT_EQ(resumed.samples[i], once.samples[i]) << i;
}

TEST(ScalingCli, ReferenceThreadsNeedOneJob) {
  test::TempDir dir;
  EXPECT_EQ(run(std::string(JELLO_SCALING) + " --quick --no-grid --jobs 2 " +
                "--atlas-reference-threads 2 --out-dir " + dir.path().string()),
            2);
  // A reference directory that cannot be made fails before the run.
  std::ofstream(dir.path() / "file") << "x";
  EXPECT_EQ(run(std::string(JELLO_SCALING) + " --quick --no-grid --atlas-references " +
                (dir.path() / "file" / "refs").string() + " --out-dir " + dir.path().string()),
            1);
}

// --atlas-references-only keeps each point's reference and its check and times nothing; a
// run after it reads them (its rows name their step) instead of computing them again.
TEST(ScalingCli, ReferencesOnlyKeepsThemForTheTimedRun) {
  test::TempDir dir;
  const std::string withGrid = std::string(JELLO_SCALING) +
                               " --quick --atlas-n 4 --atlas-k 1e2 --jobs 1 --out-dir " +
                               dir.path().string();
  const std::string base = withGrid + " --no-grid";
  EXPECT_EQ(run(base + " --atlas-references-only"), 2);  // where would they go?
  const std::filesystem::path refs = dir.path() / "refs";
  EXPECT_EQ(
      run(base + " --atlas-references-only --atlas-trace --atlas-references " + refs.string()), 2);
  ASSERT_EQ(run(base + " --atlas-references-only --atlas-references " + refs.string()), 0);
  std::vector<std::string> kept;
  for (const auto& entry : std::filesystem::directory_iterator(refs)) {
    kept.push_back(entry.path().filename().string());
  }
  // The reference, RK4 at twice its step, and any larger step the check halved.
  ASSERT_GE(kept.size(), 2u);
  for (const std::string& name : kept) {
    EXPECT_EQ(name.rfind("reference_falling_n4_k100_dt", 0), 0u) << name;
    EXPECT_EQ(slurp(refs / name).find("unfinished"), std::string::npos) << name;
  }
  const std::filesystem::path csv = dir.path() / "scaling_atlas.csv";
  EXPECT_TRUE(readCsv(csv).empty()) << "a references-only run times nothing";
  // Nor the resolution grid's runs, asked for or not.
  ASSERT_EQ(run(withGrid + " --atlas-references-only --atlas-references " + refs.string()), 0);
  EXPECT_TRUE(readCsv(dir.path() / "scaling.csv").empty());
  EXPECT_TRUE(readCsv(csv).empty());

  // The timed run finds them: the files do not change, and its rows name the reference's step
  // (the smaller of the two files').
  double referenceDt = 1.0;
  for (const std::string& name : kept) {
    std::istringstream text(slurp(refs / name));
    std::string word;
    while (text >> word && word != "dt_s") continue;
    double dt = 0.0;
    ASSERT_TRUE(text >> dt) << name;
    referenceDt = std::min(referenceDt, dt);
  }
  const std::string before = slurp(refs / kept[0]);
  ASSERT_EQ(run(base + " --atlas-references " + refs.string()), 0);
  EXPECT_EQ(slurp(refs / kept[0]), before);
  const Table rows = readCsv(csv);
  for (const auto& row : rows) EXPECT_EQ(number(row, "reference_dt_s"), referenceDt);
  EXPECT_FALSE(rows.empty());
  // And every run its searches made, one row each (NAME_tries.csv).
  double tried = 0.0;
  for (const auto& row : rows) tried += number(row, "tried");
  EXPECT_EQ(double(readCsv(dir.path() / "scaling_tries.csv").size()), tried);
}

// A stored reference's tokens, its comment lines left out.
std::vector<std::string> tokens(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind('#', 0) == 0) continue;
    std::istringstream words(line);
    for (std::string w; words >> w;) out.push_back(w);
  }
  return out;
}

// The quick atlas's tests read their references from tests/data/atlas-quick-references/
// (quickReferences). Those are today's scenes: recomputed at k = 1e3 (the cheap point; a
// changed scene changes every k), the falling and the free one, they agree with the kept files
// to round-off (other machines' vector paths round differently).
TEST(ScalingCli, TheKeptQuickReferencesAreTodaysScenes) {
  test::TempDir dir;
  const std::filesystem::path kept = JELLO_TEST_DATA_DIR "/atlas-quick-references";
  for (const char* scene : {"falling", "free"}) {
    SCOPED_TRACE(scene);
    const std::filesystem::path refs = dir.path() / scene;
    ASSERT_EQ(run(std::string(JELLO_SCALING) + " --quick --no-grid --atlas-k 1000 --atlas-scene " +
                  scene + " --atlas-references-only --atlas-references " + refs.string() +
                  " --out-dir " + dir.path().string()),
              0);
    int compared = 0;
    for (const auto& entry : std::filesystem::directory_iterator(refs)) {
      const std::filesystem::path stored = kept / entry.path().filename();
      ASSERT_TRUE(std::filesystem::exists(stored)) << stored;
      const std::vector<std::string> fresh = tokens(entry.path()), old = tokens(stored);
      ASSERT_EQ(fresh.size(), old.size()) << stored;
      for (std::size_t i = 0; i < fresh.size(); ++i) {
        char* end = nullptr;
        const double a = std::strtod(fresh[i].c_str(), &end);
        if (*end != '\0' || fresh[i].empty()) {
          EXPECT_EQ(fresh[i], old[i]) << stored << " token " << i;  // a name
          continue;
        }
        const double b = std::strtod(old[i].c_str(), nullptr);
        EXPECT_NEAR(a, b, 1e-9 * std::max(1.0, std::abs(b))) << stored << " token " << i;
      }
      ++compared;
    }
    EXPECT_EQ(compared, 2);  // the reference and its check at twice its step
  }
}

}  // namespace
}  // namespace jello::experiments
