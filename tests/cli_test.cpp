// jello-sim and jello-create-world as a user runs them: exit codes, messages, files.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "src/base/atomic_file.h"
#include "src/world/scene_builder.h"
#include "src/world/world_reader.h"
#include "src/world/world_writer.h"
#include "tests/test_support.h"

namespace jello {
namespace {

using test::Outcome;
using test::run;

std::string sim() {
  return JELLO_SIM;
}
std::string create() {
  return JELLO_CREATE_WORLD;
}
std::string world(const char* name) {
  return (test::worldsDir() / name).string();
}
bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

TEST(JelloSim, RunsAWorldAndPrintsTheSummary) {
  const Outcome r = run(sim() + " " + world("jello.w") + " --steps 200");
  EXPECT_EQ(r.code, 0) << r.output;
  for (const char* part : {"steps        200", "simulated    0.1 s", "steps/s", "real time",
                           "kinetic", "spring", "total"}) {
    EXPECT_TRUE(contains(r.output, part)) << part << "\n" << r.output;
  }
}

TEST(JelloSim, WritesTheFinalStateStatsAndTrace) {
  test::TempDir dir;
  const auto out = dir.path() / "end.w", stats = dir.path() / "s.json",
             trace = dir.path() / "t.csv";
  const Outcome r =
      run(sim() + " " + world("moveLeft.w") + " --time 0.05 --quiet --out " + out.string() +
          " --stats " + stats.string() + " --trace " + trace.string() + " --every 10");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output, "");
  const World end = readWorld(out);
  EXPECT_FALSE(end.usesExtensions());  // the original course code could load it
  EXPECT_EQ(end.integrator, IntegratorKind::RK4);
  EXPECT_LT(end.positions[0].x, 0.0);  // moved left

  const auto json = nlohmann::json::parse(test::readFile(stats));
  EXPECT_EQ(json["steps"], 100);
  EXPECT_EQ(json["integrator"], "rk4");
  EXPECT_EQ(json["diverged"], false);
  EXPECT_GT(json["energy_start"]["total_J"].get<double>(), 0.0);

  const std::string csv = test::readFile(trace);
  EXPECT_EQ(csv.rfind("step,t_s,kinetic_J,spring_J,contact_J,total_J,", 0), 0u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 11);  // header, steps 0..100 by 10
}

// --time that is not a whole number of steps: whole steps, past the time asked, and a note that
// says so (never silently short of it).
TEST(JelloSim, SaysWhenTheTimeIsNotAWholeNumberOfSteps) {
  const Outcome r =
      run(sim() + " " + world("jello.w") + " --integrator projective --dt 0.03 " + "--time 0.1");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(contains(r.output,
                       "not a whole number of steps of 0.03 s: running 4 steps, to "
                       "t = 0.12 s"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "simulated    0.12 s")) << r.output;
  const Outcome exact = run(sim() + " " + world("jello.w") + " --steps 3 --dt 0.03");
  EXPECT_FALSE(contains(exact.output, "whole number")) << exact.output;
  const Outcome quiet = run(sim() + " " + world("jello.w") + " --dt 0.03 --time 0.1 " +
                            "--integrator projective --quiet");
  EXPECT_EQ(quiet.output, "");
}

TEST(JelloSim, ReportsDivergenceWithExitCodeThreeAndWritesNoWorld) {
  test::TempDir dir;
  SceneSpec spec;
  spec.kElastic = 1e4;
  spec.dElastic = 0.0;
  const auto stiff = dir.path() / "stiff.w", out = dir.path() / "out.w";
  writeWorld(buildWorld(spec), stiff);
  const Outcome r =
      run(sim() + " " + stiff.string() + " --integrator rk4 --dt 0.01 --out " + out.string());
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_TRUE(contains(r.output, "diverged at t = ")) << r.output;
  EXPECT_TRUE(contains(r.output, "integrator rk4")) << r.output;
  EXPECT_FALSE(contains(r.output, "nan")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  // A growth that a 50-step run ended inside with exit 0 (RK4 just past its limit, energy up
  // 70x): a divergence now, and nothing is saved.
  const Outcome slow = run(sim() + " " + world("stiff-k1e4.w") +
                           " --integrator rk4 --dt 3.3e-4 --steps 50 -q --out " + out.string());
  EXPECT_EQ(slow.code, 3) << slow.output;
  EXPECT_TRUE(contains(slow.output, "the energy grew")) << slow.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(JelloSim, ImplicitIntegratorsRunTheStiffSceneThatExplicitOnesCannot) {
  test::TempDir dir;
  const auto stiff = dir.path() / "stiff.w", stats = dir.path() / "s.json";
  writeWorld(buildWorld(stiffCube(1e4)), stiff);
  EXPECT_EQ(run(sim() + " " + stiff.string() + " --integrator euler --dt 0.01 -q").code, 3);
  const Outcome r = run(sim() + " " + stiff.string() +
                        " --integrator implicit --dt 0.01 --time 0.1 --stats " + stats.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "factorizations")) << r.output;
  const auto json = nlohmann::json::parse(test::readFile(stats));
  EXPECT_EQ(json["integrator"], "implicit");
  // Converged, none left unconverged: each Newton iteration either factors or reuses the last
  // factor, and reusing saves most of them.
  const double factorizations = json["solver"]["factorizations"].get<double>();
  EXPECT_EQ(factorizations + json["solver"]["factor_reuses"].get<double>(),
            json["solver"]["newton_iterations"].get<double>());
  EXPECT_GT(json["solver"]["factor_reuses"].get<double>(), factorizations);
  EXPECT_EQ(json["solver"]["newton_unconverged_steps"], 0);
  EXPECT_GT(json["solver"]["compression_clamps"].get<double>(), 0.0);
  EXPECT_EQ(json["angular_momentum_end_kg_m2_per_s"].size(), 3u);

  // The linearized step factors once per step.
  ASSERT_EQ(run(sim() + " " + stiff.string() + " --integrator implicit-linear --dt 0.01" +
                " --time 0.1 -q --stats " + stats.string())
                .code,
            0);
  EXPECT_EQ(nlohmann::json::parse(test::readFile(stats))["solver"]["factorizations"], 10);

  // A Newton cap too low to converge, and no retries: the run goes on, counts and says so.
  const Outcome capped = run(sim() + " " + stiff.string() +
                             " --integrator midpoint --dt 0.01 --time 0.05 -q --newton-iters 1 "
                             "--newton-tol 1e-14 --newton-halvings 0 --stats " +
                             stats.string());
  ASSERT_EQ(capped.code, 0) << capped.output;
  EXPECT_TRUE(contains(capped.output,
                       "5 of 5 steps taken were accepted unconverged: Newton did "
                       "not converge within 1 iterations"))
      << capped.output;
  EXPECT_EQ(nlohmann::json::parse(test::readFile(stats))["solver"]["newton_unconverged_steps"], 5);

  const Outcome c = run(sim() + " " + stiff.string() +
                        " --integrator cvode --dt 0.01 --time 0.02 --rtol 1e-3 --max-order 2"
                        " --linear-solver cg --stats " +
                        stats.string());
  ASSERT_EQ(c.code, 0) << c.output;
  const auto cj = nlohmann::json::parse(test::readFile(stats));
  EXPECT_EQ(cj["steps"], 2);  // output intervals
  EXPECT_GT(cj["solver"]["cvode_steps"].get<double>(), 2.0);
  EXPECT_LE(cj["solver"]["last_order"].get<double>(), 2.0);
}

TEST(JelloSim, StopsCleanlyOnSigintAndWritesNoWorld) {
  test::TempDir dir;
  const auto out = dir.path() / "out.w", stats = dir.path() / "s.json",
             trace = dir.path() / "t.csv";
  const Outcome r = run("timeout --preserve-status -s INT 1 " + sim() + " " +
                        world("skewedCorner.w") + " --time 100 --out " + out.string() +
                        " --stats " + stats.string() + " --trace " + trace.string());
  EXPECT_EQ(r.code, 130) << r.output;
  EXPECT_TRUE(contains(r.output, "interrupted (signal 2) at t = ")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  const auto json = nlohmann::json::parse(test::readFile(stats));
  EXPECT_EQ(json["interrupted"], true);
  EXPECT_GT(json["steps"].get<long>(), 0);
  // The trace ends with a complete row at or before the step where it stopped.
  const std::string csv = test::readFile(trace);
  EXPECT_EQ(csv.back(), '\n');
}

TEST(JelloSim, SighupStopsLikeSigtermAndTheProgressLineIsTimeBased) {
  // SIGHUP (the terminal closed) ends the run with its statistics, exit 128 + 1. The steps
  // here take about 0.4 s each: a progress line appears anyway (it used to wait for 256 steps).
  test::TempDir dir;
  const auto stats = dir.path() / "s.json";
  const Outcome r = run("timeout --preserve-status -s HUP 5 " + sim() + " " + world("jello.w") +
                        " --integrator projective --dt 0.01 --time 100 --projective-iters 2000"
                        " --stats " +
                        stats.string());
  EXPECT_EQ(r.code, 129) << r.output;
  EXPECT_TRUE(contains(r.output, "interrupted (signal 1)")) << r.output;
  EXPECT_EQ(nlohmann::json::parse(test::readFile(stats))["interrupted"], true);
  EXPECT_TRUE(contains(r.output, "projective steps")) << r.output;  // the progress line
}

TEST(JelloSim, RunningOutOfMemoryIsAClearErrorNotAnAbort) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves more address space than the limit allows";
#else
  // A 64^3 cube's springs need about 200 MB: under a 130 MB address-space limit an allocation
  // fails, in the model or in Eigen, and the program says so and exits 1 (it used to abort
  // with an uncaught std::bad_alloc, exit 134).
  const Outcome r = run("bash -c 'ulimit -v 130000; " + sim() + " " + world("jello.w") +
                        " --cube 64 --steps 1 --quiet'");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "jello-sim: error: out of memory")) << r.output;
  EXPECT_FALSE(contains(r.output, "terminate called")) << r.output;
#endif
}

// OpenBLAS, under CHOLMOD's supernodal factorizations (the cholmod linear solver, projective),
// retries its 128 MiB buffer forever, deaf to SIGTERM, when an address-space limit leaves no
// room: the factorization refuses first, naming the limit (exit 1, not "diverged", no world).
TEST(JelloSim, AnAddressSpaceLimitTooTightForTheBlasIsReportedNotAHang) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves more address space than the limit allows";
#else
  test::TempDir dir;
  for (const char* how :
       {"--integrator implicit --linear-solver cholmod", "--integrator projective",
        "--integrator cvode --linear-solver cholmod"}) {
    const auto out = dir.path() / "out.w";
    const auto start = std::chrono::steady_clock::now();
    const Outcome r =
        run("bash -c 'ulimit -v 150000; OPENBLAS_NUM_THREADS=1 timeout -s KILL 60 " + sim() + " " +
            world("jello.w") + " " + how + " --steps 3 --out " + out.string() + "'");
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.code, 1) << how << "\n" << r.output;
    EXPECT_LT(seconds, 30.0) << how;
    EXPECT_TRUE(contains(r.output, "the address-space limit (ulimit -v 150000 kB)")) << r.output;
    EXPECT_TRUE(contains(r.output, "--linear-solver cg")) << r.output;
    EXPECT_FALSE(contains(r.output, "diverged")) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << how;
  }
  // The default matrix-free CG needs no BLAS and runs under the same limit.
  const Outcome cg = run("bash -c 'ulimit -v 150000; OPENBLAS_NUM_THREADS=1 timeout -s KILL 60 " +
                         sim() + " " + world("jello.w") + " --integrator implicit --steps 3 -q'");
  EXPECT_EQ(cg.code, 0) << cg.output;
#endif
}

// CVODE follows a lightly damped stiff mode at its tolerance: jello.w at k = 1e7 costs about 35
// minutes a simulated second (scripts/cvode-stiff.py). jello-sim says so before it starts, with
// its estimate; jello.w itself (k = 200) and the same stiff scene damped past critical (zeta > 1,
// which BDF steps over) get no warning.
TEST(JelloSim, WarnsBeforeAnHourOfCvodeOnALightlyDampedStiffScene) {
  test::TempDir dir;
  World w = readWorld(world("jello.w"));
  w.kElastic = 1e7;
  const auto stiff = dir.path() / "k1e7.w", damped = dir.path() / "damped.w";
  writeWorld(w, stiff);
  w.dElastic = 100.0;  // zeta = d w_max / 2k = 1.46
  writeWorld(w, damped);
  const std::string cvode = " --integrator cvode --time 1";
  const Outcome r = run("timeout -s TERM 3 " + sim() + " " + stiff.string() + cvode);
  EXPECT_TRUE(
      contains(r.output, "warning: cvode follows this scene's fastest mode (w_max = 2.91e+05"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "expect about 4.2e+06 internal steps for 1 simulated s"))
      << r.output;
  for (const std::string& quiet : {world("jello.w"), damped.string()}) {
    const Outcome q = run("timeout -s TERM 3 " + sim() + " " + quiet + cvode);
    EXPECT_TRUE(contains(q.output, "integrator   cvode")) << q.output;  // the summary: it ran
    EXPECT_FALSE(contains(q.output, "warning")) << quiet << "\n" << q.output;
  }
}

TEST(JelloSim, SigtermInsideOneLongStepStopsWithinASecond) {
  // One output interval of cvode (--dt 5, rtol 1e-9) on the stiff cube takes minutes, and so
  // does one projective step of 100,000 iterations: SIGTERM after one second must stop either
  // within about a second more, with the statistics written and nothing counted as diverged.
  const std::pair<const char*, const char*> runs[] = {
      {"cvode", " --dt 5 --time 5 --rtol 1e-9"},
      {"projective", " --dt 0.01 --time 100 --projective-iters 100000"}};
  for (const auto& [integrator, options] : runs) {
    test::TempDir dir;
    const auto stats = dir.path() / "s.json";
    const auto start = std::chrono::steady_clock::now();
    const Outcome r =
        run("timeout --preserve-status -s TERM 1 " + sim() + " " + world("stiff-k1e5.w") +
            " --integrator " + integrator + options + " --stats " + stats.string() + " 2>&1");
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.code, 128 + SIGTERM) << integrator << "\n" << r.output;
    EXPECT_LT(seconds, 3.0) << integrator;  // 1 s before the signal, then at most ~2 s
    EXPECT_FALSE(contains(r.output, "diverged")) << r.output;
    const auto json = nlohmann::json::parse(test::readFile(stats));
    EXPECT_EQ(json["interrupted"], true) << integrator;
  }
}

// Two outputs that resolve to one file, however they are spelled, would lose one of them: ./r.x
// against r.x, an absolute path against its relative form, a symlink against its target (even
// dangling, as the write follows it), a hard link against its twin. Each is refused before the
// run with exit 2, naming both flags, and nothing is written.
TEST(JelloSim, RefusesTwoOutputsThatResolveToOneFile) {
  test::TempDir dir;
  const std::string in =
      "cd " + dir.path().string() + " && " + sim() + " " + world("jello.w") + " --steps 10 ";
  std::filesystem::create_symlink("r.json", dir.path() / "link.json");  // dangling: r.json later
  const std::vector<std::string> pairs = {
      "--out r.x --trace ./r.x",
      "--out r.x --trace " + (dir.path() / "r.x").string(),
      "--trace r.json --stats link.json",
      "--out sub/../r.x --stats r.x",
  };
  std::filesystem::create_directory(dir.path() / "sub");
  for (const std::string& pair : pairs) {
    const Outcome r = run(in + pair + " 2>&1");
    EXPECT_EQ(r.code, 2) << pair << ": " << r.output;
    EXPECT_TRUE(contains(r.output, "name the same file")) << pair << ": " << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "r.x")) << pair;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "r.json")) << pair;
  }
  // A hard link to an existing file: the same inode.
  { std::ofstream(dir.path() / "a.json") << "{}"; }
  std::filesystem::create_hard_link(dir.path() / "a.json", dir.path() / "b.json");
  const Outcome hard = run(in + "--stats a.json --trace b.json 2>&1");
  EXPECT_EQ(hard.code, 2) << hard.output;
  EXPECT_TRUE(contains(hard.output, "--stats a.json and --trace b.json name the same file"))
      << hard.output;
  // Two different files are fine.
  const Outcome two = run(in + "--stats s.json --trace t.csv 2>&1");
  EXPECT_EQ(two.code, 0) << two.output;
}

TEST(JelloSim, ChecksEveryOutputBeforeTheRunAndWritesEveryOneItCan) {
  test::TempDir dir;
  const auto stats = dir.path() / "s.json", trace = dir.path() / "t.csv";
  // A missing directory, an empty path, a directory, two outputs to one file: refused before
  // the (long) run, each named.
  const Outcome r = run(sim() + " " + world("jello.w") + " --time 1000 --stats " +
                        (dir.path() / "missing" / "s.json").string() + " --trace '' 2>&1");
  EXPECT_EQ(r.code, 1) << r.output;  // an I/O failure, found before the run
  EXPECT_TRUE(contains(r.output, "(--stats): the directory")) << r.output;
  EXPECT_TRUE(contains(r.output, "does not exist")) << r.output;
  EXPECT_TRUE(contains(r.output, "(--trace): the output path is empty")) << r.output;
  const Outcome same = run(sim() + " " + world("jello.w") + " --steps 5 --out " + stats.string() +
                           " --stats " + stats.string() + " 2>&1");
  EXPECT_EQ(same.code, 2) << same.output;  // a usage error
  EXPECT_TRUE(contains(same.output, "name the same file")) << same.output;
  const Outcome directory =
      run(sim() + " " + world("jello.w") + " --steps 5 --stats " + dir.path().string() + " 2>&1");
  EXPECT_EQ(directory.code, 1) << directory.output;
  EXPECT_TRUE(contains(directory.output, "it is a directory")) << directory.output;
  // At the end, an output that cannot be written (the trace, past a 4 kB file-size limit) is
  // reported, and the others are still written.
  const Outcome limited = run("bash -c 'ulimit -f 4; " + sim() + " " + world("jello.w") +
                              " --steps 400 --every 1 --trace " + trace.string() + " --stats " +
                              stats.string() + "' 2>&1");
  EXPECT_EQ(limited.code, 1) << limited.output;
  EXPECT_TRUE(contains(limited.output, trace.string())) << limited.output;
  EXPECT_TRUE(std::filesystem::exists(stats));
  EXPECT_FALSE(std::filesystem::exists(trace));
}

TEST(JelloSim, AFullDiskLeavesThePreviousFileIntactAndSaysSo) {
  // ulimit -f makes every write past 4 kB fail with EFBIG, as a full disk fails with ENOSPC.
  test::TempDir dir;
  const auto out = dir.path() / "out.w";
  writeFileAtomically(out, "previous contents\n");
  const Outcome r = run("ulimit -f 4; " + sim() + " " + world("jello.w") + " --steps 10 -q --out " +
                        out.string());
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "cannot write " + out.string() + ": write: File too large"))
      << r.output;
  EXPECT_EQ(test::readFile(out), "previous contents\n");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator{}),
            1);  // no temporary file left behind
}

TEST(JelloSim, ReportsADirectoryItCannotWriteInto) {
  const Outcome missing =
      run(sim() + " " + world("jello.w") + " --steps 1 -q --out /no/such/dir/o.w");
  EXPECT_EQ(missing.code, 1);
  EXPECT_TRUE(contains(missing.output, "cannot write /no/such/dir/o.w")) << missing.output;
  const Outcome unwritable =
      run(sim() + " " + world("jello.w") + " --steps 1 -q --stats /proc/s.json");
  EXPECT_EQ(unwritable.code, 1);
  EXPECT_TRUE(contains(unwritable.output, "cannot write /proc/s.json")) << unwritable.output;
}

TEST(JelloSim, RefusesWorldsOverItsLimits) {
  const Outcome r = run(sim() + " " + world("jello.w") + " --max-field-resolution 16");
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(contains(r.output,
                       "jello.w:7: force-field resolution must be 0 (none) or "
                       "between 2 and 16 (at '30')"))
      << r.output;
}

TEST(JelloSim, RefusesABadWorldNamingFileAndLine) {
  test::TempDir dir;
  const auto bad = dir.path() / "bad.w";
  std::ofstream(bad) << "RK4\n0.001 1\n1 2 x 4\n";
  const Outcome r = run(sim() + " " + bad.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(contains(r.output, bad.string() + ":3: ")) << r.output;
  EXPECT_TRUE(contains(r.output, "'x'")) << r.output;
}

// Issue 41, item 5: a cube that starts deep inside a sphere of radius 1e308 ran to exit 0 under
// implicit with an infinite contact energy; it is refused before the run, naming the line.
TEST(JelloSim, RefusesAStartWhoseEnergyIsNotFiniteNamingTheLine) {
  test::TempDir dir;
  const std::string jello = test::readFile(test::worldsDir() / "jello.w");
  const auto deep = dir.path() / "deep.w";
  std::ofstream(deep) << jello << "sphere 0 0 -1 1e308\n";
  const std::string line = std::to_string(std::count(jello.begin(), jello.end(), '\n') + 1);
  for (const char* integrator : {"implicit", "midpoint", "bdf2", "newmark", "rk4"}) {
    std::string command = sim();
    command.append(" ").append(deep.string()).append(" --steps 5 --integrator ");
    command.append(integrator).append(" --out ").append((dir.path() / "out.w").string());
    const Outcome r = run(command);
    EXPECT_EQ(r.code, 1) << integrator << ": " << r.output;
    EXPECT_TRUE(contains(r.output, deep.string() + ":" + line +
                                       ": the sphere's contact energy at the start is inf J"))
        << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "out.w"));
  }
}

// Issue 41 (low): a force field of resolution 1024 read from a pipe (its size unknown) allocated
// about 25 GB before reading a number. Under a 2 GB address-space limit the truncated field is
// now refused naming file and line, not reported as out of memory.
TEST(JelloSim, AHugeFieldFromAPipeIsReadAsItArrives) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves more address space than the limit allows";
#else
  test::TempDir dir;
  const auto head = dir.path() / "head.w";
  std::ofstream(head) << "RK4\n0.001 1\n1 0 1 0\n0.001953125\n0\n1024\n1 2 3\n4 5 6\n";
  std::string command = "bash -c 'ulimit -v 2000000; cat ";
  command.append(head.string()).append(" | ").append(sim());
  command.append(" /dev/stdin --max-field-resolution 1024 --steps 1'");
  const Outcome r = run(command);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "/dev/stdin:")) << r.output;
  EXPECT_TRUE(contains(r.output, "force-field")) << r.output;
  EXPECT_FALSE(contains(r.output, "memory")) << r.output;
#endif
}

TEST(JelloSim, AnswersBadUsageWithExitCodeTwo) {
  EXPECT_EQ(run(sim()).code, 2);
  EXPECT_EQ(run(sim() + " " + world("jello.w") + " --integrator verlet").code, 2);
  EXPECT_EQ(run(sim() + " " + world("jello.w") + " --dt -1").code, 2);
  EXPECT_EQ(run(sim() + " " + world("jello.w") + " --time 1e300 --dt 1e-9").code, 2);
  const Outcome help = run(sim() + " --help");
  EXPECT_EQ(help.code, 0);
  EXPECT_TRUE(contains(help.output, "--integrator")) << help.output;
}

TEST(JelloSim, ResamplesTheCube) {
  const Outcome r = run(sim() + " " + world("jello.w") + " --cube 12 --steps 20");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "1728 points")) << r.output;
}

TEST(JelloCreateWorld, WithNoArgumentsWritesTheOriginalDefaultWorld) {
  test::TempDir dir;
  const Outcome r = run("cd " + dir.path().string() + " && " + create());
  ASSERT_EQ(r.code, 0) << r.output;
  const World made = readWorld(dir.path() / "jello.w");
  const World original = test::loadWorld("createWorld-default.w");
  // Equal to the six decimals the original printed (its mass 0.001953 is our exact 1/512).
  EXPECT_EQ(formatWorld(made, NumberFormat::Legacy), formatWorld(original, NumberFormat::Legacy));
  EXPECT_EQ(made.mass, 1.0 / 512);
}

TEST(JelloCreateWorld, LegacyOutputIsByteIdenticalToTheOriginalCreator) {
  test::TempDir dir;
  const auto out = dir.path() / "legacy.w";
  ASSERT_EQ(run(create() + " --legacy -o " + out.string()).code, 0);
  EXPECT_EQ(test::readFile(out), test::readFile(test::worldsDir() / "createWorld-default.w"));
}

TEST(JelloCreateWorld, FlagsSetEveryField) {
  test::TempDir dir;
  const auto out = dir.path() / "w.w";
  const Outcome r = run(create() + " -o " + out.string() +
                        " --integrator symplectic --dt 0.002 -n 3 --k-elastic 1000"
                        " --d-elastic 0.5 --k-collision 2000 --d-collision 0.7 --mass 0.004"
                        " --plane 0 0 1 1.5 --field vortex --field-strength 0.1"
                        " --field-resolution 5 --pose rotated --rotate 45 --axis 0 0 1"
                        " --velocity 1 2 3 --spin 2 --sphere 0 0 -1 0.5 --cube 6");
  ASSERT_EQ(r.code, 0) << r.output;
  const World w = readWorld(out);
  EXPECT_EQ(w.integrator, IntegratorKind::Symplectic);
  EXPECT_EQ(w.dt, 0.002);
  EXPECT_EQ(w.stepsPerFrame, 3);
  EXPECT_EQ(w.kElastic, 1000);
  EXPECT_EQ(w.dElastic, 0.5);
  EXPECT_EQ(w.kCollision, 2000);
  EXPECT_EQ(w.dCollision, 0.7);
  EXPECT_EQ(w.mass, 0.004);
  ASSERT_TRUE(w.plane.has_value());
  EXPECT_EQ(w.plane->d, 1.5);
  EXPECT_EQ(w.field.resolution, 5);
  EXPECT_NEAR(w.field.forces[0].x, 0.1 * 2.0, 1e-15);  // s * -y at y = -2
  EXPECT_EQ(w.cubeResolution, 6);
  ASSERT_TRUE(w.sphere.has_value());
  EXPECT_EQ(w.sphere->radius, 0.5);
  // Rotated 45 degrees about z through the centre: the cube's centre of mass stays put.
  Vec3 centre;
  for (const Vec3& x : w.positions) centre += x * (1.0 / static_cast<double>(w.positions.size()));
  EXPECT_NEAR(centre.x, 0.5, 1e-12);
  EXPECT_NEAR(centre.z, 0.5, 1e-12);
  EXPECT_NEAR(w.velocities[0].z, 3.0, 1e-12);
}

TEST(JelloCreateWorld, RefusesBadValuesAndWritesNothing) {
  test::TempDir dir;
  const auto out = dir.path() / "w.w";
  EXPECT_EQ(run(create() + " -o " + out.string() + " --dt 0").code, 2);
  EXPECT_EQ(run(create() + " -o " + out.string() + " --integrator leapfrog").code, 2);
  EXPECT_EQ(run(create() + " -o " + out.string() + " --plane 0 0 0 1").code, 1);
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_NE(run(create() + " -o /nonexistent/dir/w.w").code, 0);
}

// --contact and --contact-layer: written into the world by jello-create-world, overriding the
// file's in jello-sim (its stats say which ran), refused with exit 2 when wrong.
TEST(Contact, FlagsChooseTheModelInBothToolsAndBadOnesAreRefused) {
  test::TempDir dir;
  const auto out = dir.path() / "w.w";
  ASSERT_EQ(run(create() + " -o " + out.string() + " --contact smooth").code, 0);
  EXPECT_EQ(readWorld(out).contact, (ContactLaw{ContactModel::Smooth, kDefaultContactLayer}));
  ASSERT_EQ(run(create() + " -o " + out.string() + " --contact SMOOTH --contact-layer 0.002").code,
            0);
  EXPECT_EQ(readWorld(out).contact, (ContactLaw{ContactModel::Smooth, 0.002}));
  const auto bad = dir.path() / "bad.w";
  EXPECT_EQ(run(create() + " -o " + bad.string() + " --contact sticky").code, 2);
  EXPECT_EQ(run(create() + " -o " + bad.string() + " --contact-layer 0.01").code, 2);
  EXPECT_EQ(run(create() + " -o " + bad.string() + " --contact smooth --contact-layer 0").code, 2);
  EXPECT_FALSE(std::filesystem::exists(bad));

  const auto stats = dir.path() / "s.json";
  const auto modelRun = [&](const std::string& file, const std::string& flags) {
    const Outcome r =
        run(sim() + " " + file + " --steps 20 --quiet --stats " + stats.string() + " " + flags);
    EXPECT_EQ(r.code, 0) << r.output;
    std::ifstream in(stats);
    const nlohmann::json j = nlohmann::json::parse(in);
    return std::make_pair(j["contact"]["model"].get<std::string>(),
                          j["contact"]["layer_m"].get<double>());
  };
  EXPECT_EQ(modelRun(out.string(), ""), std::make_pair(std::string("smooth"), 0.002));
  EXPECT_EQ(modelRun(out.string(), "--contact penalty"),
            std::make_pair(std::string("penalty"), 0.0));
  EXPECT_EQ(modelRun(out.string(), "--contact-layer 0.003"),
            std::make_pair(std::string("smooth"), 0.003));
  EXPECT_EQ(modelRun(world("jello.w"), "--contact smooth"),
            std::make_pair(std::string("smooth"), kDefaultContactLayer));
  const Outcome wrong = run(sim() + " " + world("jello.w") + " --steps 1 --contact-layer 0.01");
  EXPECT_EQ(wrong.code, 2);
  EXPECT_TRUE(contains(wrong.output, "applies to the smooth contact model only")) << wrong.output;
  EXPECT_EQ(run(sim() + " " + world("jello.w") + " --steps 1 --contact bogus").code, 2);

  // The barrier: --dhat and --kappa (kappa defaults to the world's kCollision), only with it.
  ASSERT_EQ(run(create() + " -o " + out.string() + " --contact barrier --dhat 0.003").code, 0);
  EXPECT_EQ(readWorld(out).contact, (ContactLaw{ContactModel::Barrier, 0.0, 0.003, 400.0}));
  EXPECT_EQ(run(create() + " -o " + bad.string() + " --kappa 10").code, 2);
  EXPECT_EQ(run(sim() + " " + world("jello.w") + " --steps 1 --contact smooth --dhat 0.01").code,
            2);
  const Outcome barrier = run(sim() + " " + world("jello.w") +
                              " --integrator implicit --dt 0.01 --steps 40 --quiet --contact "
                              "barrier --kappa 500 --stats " +
                              stats.string());
  ASSERT_EQ(barrier.code, 0) << barrier.output;
  const auto readStats = [&] { return nlohmann::json::parse(test::readFile(stats)); };
  {
    const nlohmann::json j = readStats();
    EXPECT_EQ(j["contact"]["model"], "barrier");
    EXPECT_EQ(j["contact"]["dhat_m"].get<double>(), kDefaultBarrierDistance);
    EXPECT_EQ(j["contact"]["kappa_N_per_m"].get<double>(), 500.0);
    const double least = j["min_obstacle_distance_m"].get<double>();
    EXPECT_GT(least, 0.0);                      // never inside
    EXPECT_LT(least, kDefaultBarrierDistance);  // but the barrier was met
  }
  // The penalty lets points in: the least distance is negative, the deepest penetration.
  ASSERT_EQ(run(sim() + " " + world("jello.w") + " --integrator implicit --dt 0.01 --steps 40 " +
                "--quiet --stats " + stats.string())
                .code,
            0);
  EXPECT_LT(readStats()["min_obstacle_distance_m"].get<double>(), 0.0);
  // The showcase's spiral ramp is held too (it was refused while the spiral had no exterior
  // distance): its cube lands on the ramp within 0.6 s and no point reaches a solid.
  const Outcome spiral = run(sim() + " " + world("showcase.w") +
                             " --steps 60 --dt 0.01 --integrator implicit --contact barrier "
                             "--quiet --stats " +
                             stats.string());
  EXPECT_EQ(spiral.code, 0) << spiral.output;
  const double least = readStats()["min_obstacle_distance_m"].get<double>();
  EXPECT_GT(least, 0.0);
  EXPECT_LT(least, 0.01);  // it came within the barrier's reach
}

// Friction: --friction MU and --slip-speed in both tools (jello-sim's over the file's), with any
// contact model; the statistics report mu and the work friction did (negative: dissipated).
TEST(Contact, FrictionFlagsSetMuAndTheSlipSpeedAndTheStatsCountItsWork) {
  test::TempDir dir;
  const auto out = dir.path() / "w.w", bad = dir.path() / "bad.w", stats = dir.path() / "s.json";
  ASSERT_EQ(run(create() + " -o " + out.string() + " --friction 0.4 --slip-speed 0.002").code, 0);
  ContactLaw expected;
  expected.mu = 0.4;
  expected.slipSpeed = 0.002;
  EXPECT_EQ(readWorld(out).contact, expected);
  EXPECT_EQ(run(create() + " -o " + bad.string() + " --slip-speed 0.002").code, 2);
  EXPECT_EQ(run(create() + " -o " + bad.string() + " --friction -1").code, 2);
  EXPECT_FALSE(std::filesystem::exists(bad));
  const auto friction = [&](const std::string& file, const std::string& flags) {
    const Outcome r = run(sim() + " " + file + " --integrator implicit --dt 0.01 --steps 60 " +
                          "--quiet --stats " + stats.string() + " " + flags);
    EXPECT_EQ(r.code, 0) << r.output;
    std::ifstream in(stats);
    const nlohmann::json j = nlohmann::json::parse(in);
    return std::make_pair(j["contact"]["friction_mu"].get<double>(),
                          j["contact"]["friction_work_J"].get<double>());
  };
  const auto [mu, work] = friction(out.string(), "");
  EXPECT_EQ(mu, 0.4);
  EXPECT_LT(work, 0.0);  // jello.w's cube hits the walls within 0.6 s
  EXPECT_EQ(friction(out.string(), "--friction 0"), std::make_pair(0.0, 0.0));
  EXPECT_EQ(friction(world("jello.w"), "--friction 0.7 --contact smooth").first, 0.7);
  const Outcome lone = run(sim() + " " + world("jello.w") + " --steps 1 --slip-speed 0.01");
  EXPECT_EQ(lone.code, 2);
  EXPECT_TRUE(contains(lone.output, "--slip-speed applies with friction only")) << lone.output;
}

// #16: --stats /dev/stdout works (the link is followed to the pipe and written in place), and
// --out to a device leaves the device a device. Private stand-ins, never the machine's own
// /dev/stdout or /dev/null: a writer that regressed would replace them.
// A step Newton cannot converge even in halves is accepted, counted and said; --strict stops
// the run there with exit 4, naming the step, and writes no world.
TEST(JelloSim, UnconvergedStepsAreCountedAndStrictMakesThemAnError) {
  test::TempDir dir;
  const auto out = dir.path() / "out.w", stats = dir.path() / "s.json";
  const std::string starved = sim() + " " + world("jello.w") +
                              " --integrator implicit --steps 3 --newton-iters 1 --newton-tol "
                              "1e-14 --newton-xtol 1e-300 --newton-halvings 1 --stats " +
                              stats.string() + " --out " + out.string();
  const Outcome lenient = run(starved + " --quiet");
  EXPECT_EQ(lenient.code, 0) << lenient.output;
  EXPECT_TRUE(contains(lenient.output, "3 of 3 steps taken were accepted unconverged"))
      << lenient.output;
  EXPECT_TRUE(std::filesystem::exists(out));
  {
    std::ifstream in(stats);
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["solver"]["newton_unconverged_steps"].get<double>(), 3.0);
    EXPECT_EQ(j["solver"]["newton_retried_steps"].get<double>(), 3.0);  // one halving each
    EXPECT_EQ(j["steps"].get<long>(), 3);
  }
  std::filesystem::remove(out);
  const Outcome strict = run(starved + " --quiet --strict");
  EXPECT_EQ(strict.code, 4) << strict.output;
  EXPECT_TRUE(contains(strict.output,
                       "step 1 (to t = 0.0005 s, integrator implicit) did not "
                       "converge within 1 Newton iterations, even as 2 sub-steps"))
      << strict.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  std::ifstream in(stats);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["steps"].get<long>(), 1);
  EXPECT_TRUE(j.contains("unconverged"));
  // Converged runs are not touched by --strict.
  EXPECT_EQ(
      run(sim() + " " + world("jello.w") + " --integrator implicit --steps 3 --quiet --strict")
          .code,
      0);
}

TEST(JelloSim, WritesStatsToDevStdoutAndLeavesADeviceADevice) {
  test::TempDir dir;
  const auto stdoutLink = dir.path() / "stdout";
  std::filesystem::create_symlink("/proc/self/fd/1", stdoutLink);  // as /dev/stdout is
  const Outcome r =
      run(sim() + " " + world("jello.w") + " --steps 5 -q --stats " + stdoutLink.string());
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\"steps\": 5")) << r.output;
  EXPECT_TRUE(std::filesystem::is_symlink(stdoutLink));

  const auto node = dir.path() / "null";
  if (::mknod(node.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0) {
    GTEST_SKIP() << "cannot make a device node here (not root)";
  }
  const Outcome out = run(sim() + " " + world("jello.w") + " --steps 5 -q --out " + node.string());
  EXPECT_EQ(out.code, 0) << out.output;
  EXPECT_TRUE(std::filesystem::is_character_file(node));
}

TEST(JelloSim, IntegratorOnTheCommandLineRescuesAFileNamingAnUnknownOne) {
  // Files by other course authors name integrators they added ("Midpoint", "IPC").
  test::TempDir dir;
  const auto file = dir.path() / "ipc.w";
  std::string text = test::readFile(world("jello.w"));
  text.replace(0, text.find('\n'), "IPC");
  { std::ofstream(file) << text; }
  const Outcome refused = run(sim() + " " + file.string() + " --steps 5 -q 2>&1");
  EXPECT_EQ(refused.code, 1) << refused.output;
  EXPECT_TRUE(contains(refused.output, ":1:")) << refused.output;  // file:line
  EXPECT_TRUE(contains(refused.output, "--integrator")) << refused.output;
  const Outcome rescued = run(sim() + " " + file.string() + " --steps 5 -q --integrator rk4 2>&1");
  EXPECT_EQ(rescued.code, 0) << rescued.output;
  EXPECT_TRUE(contains(rescued.output, "warning")) << rescued.output;
  EXPECT_TRUE(contains(rescued.output, "'IPC'")) << rescued.output;
}

TEST(JelloSim, AClosedOutputPipeDoesNotKillTheRun) {
  // `jello-sim ... | :` : the reader is gone before the summary is printed. SIGPIPE is ignored,
  // the write fails with EPIPE, and the run still writes its statistics and exits 0.
  test::TempDir dir;
  const auto stats = dir.path() / "s.json", rc = dir.path() / "rc";
  const Outcome r = run("bash -c '(" + sim() + " " + world("jello.w") + " --steps 4000 --stats " +
                        stats.string() + " 2>&1; echo $? > " + rc.string() + ") | :'");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(test::readFile(rc), "0\n");
  EXPECT_TRUE(std::filesystem::exists(stats));
}

TEST(Experiments, RefuseAnUnwritableOutputDirectoryBeforeTheRun) {
  // Before the fix, a study ran for its whole length and then failed to write.
  const std::filesystem::path bin = std::filesystem::path(sim()).parent_path();
  for (const char* program : {"jello-stability", "jello-work-precision", "jello-scaling"}) {
    if (!std::filesystem::exists(bin / program)) continue;  // not built here
    const auto start = std::chrono::steady_clock::now();
    const Outcome r = run((bin / program).string() + " --out-dir /proc/jello-results 2>&1");
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.code, 1) << program << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "/proc/jello-results")) << r.output;
    EXPECT_LT(seconds, 2.0) << program;  // refused at once, not after the study
  }
}

// An extreme value that the option's range admits but the study cannot use ends with exit 1 and
// a message naming the option, not a signal: --drift-k 1e308 (and 1e-300) made Spectra's
// eigensolver throw outside any try block, and the program died of SIGABRT printing nothing.
TEST(Experiments, AnOptionTheStudyCannotUseIsNamedNotASignal) {
  const std::filesystem::path bin = std::filesystem::path(sim()).parent_path();
  if (!std::filesystem::exists(bin / "jello-work-precision")) GTEST_SKIP() << "not built here";
  test::TempDir dir;
  for (const char* k : {"1e308", "1e-300"}) {
    const Outcome r = run((bin / "jello-work-precision").string() + " --quick --quiet --drift-k " +
                          k + " --out-dir " + dir.path().string() + " 2>&1");
    EXPECT_EQ(r.code, 1) << k << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "--drift-k")) << k << "\n" << r.output;
  }
}

// Values an option's type admits but its study cannot use are refused with their range (exit 2)
// before the run: jello-stability --time 1e308 overflowed the step count and exited 0 with
// thresholds from --min-steps alone; --dt-max 4.9e-324 (subnormal) reported stability to it.
TEST(Experiments, StabilityRefusesTimesAndStepsItCannotRun) {
  const std::filesystem::path bin = std::filesystem::path(sim()).parent_path();
  if (!std::filesystem::exists(bin / "jello-stability")) GTEST_SKIP() << "not built here";
  test::TempDir dir;
  for (const char* bad : {"--time 1e308", "--time 1e-300", "--dt-max 4.9e-324", "--dt-max 1e300"}) {
    const Outcome r = run((bin / "jello-stability").string() + " --quick --quiet " + bad +
                          " --out-dir " + dir.path().string() + " 2>&1");
    EXPECT_EQ(r.code, 2) << bad << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "must be at")) << bad << "\n" << r.output;
  }
}

// Issue 41, item 6 for jello-scaling: a budget of 1e308 s never ended and a step of 4.9e-324 s
// never moved the clock; each is refused with its range (exit 2).
TEST(Experiments, ScalingRefusesBudgetsAndStepsItCannotRun) {
  const std::filesystem::path bin = std::filesystem::path(sim()).parent_path();
  if (!std::filesystem::exists(bin / "jello-scaling")) GTEST_SKIP() << "not built here";
  test::TempDir dir;
  for (const char* bad :
       {"--budget 1e308", "--budget 4.9e-324", "--implicit-dt 4.9e-324", "--implicit-dt 1e300",
        "--atlas-budget 1e308", "--atlas-checkpoint 1e-300"}) {
    const Outcome r = run((bin / "jello-scaling").string() + " --quick --quiet " + bad +
                          " --out-dir " + dir.path().string() + " 2>&1");
    EXPECT_EQ(r.code, 2) << bad << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "must be at")) << bad << "\n" << r.output;
  }
}

// Issue 41 (low): `--name ../escape` or an absolute --name wrote outside --out-dir, `--name ''`
// wrote hidden files (".csv"); cvode's --max-step 4.9e-324 was silently no limit.
TEST(Experiments, NameIsAStemInTheOutputDirectoryAndMaxStepIsNotSubnormal) {
  const std::filesystem::path bin = std::filesystem::path(sim()).parent_path();
  if (!std::filesystem::exists(bin / "jello-stability")) GTEST_SKIP() << "not built here";
  test::TempDir dir;
  const auto out = dir.path() / "out";
  for (const char* bad :
       {"--name ../escape", "--name /tmp/jello-escape", "--name ''", "--name .hidden"}) {
    const Outcome r = run((bin / "jello-stability").string() + " --quick --quiet " + bad +
                          " --out-dir " + out.string() + " 2>&1");
    EXPECT_EQ(r.code, 2) << bad << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "--name")) << bad << "\n" << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "escape.csv"));
  EXPECT_FALSE(std::filesystem::exists("/tmp/jello-escape.csv"));
  for (const char* bad : {"4.9e-324", "1e-300", "1e300"}) {
    const Outcome r = run(sim() + " " + world("jello.w") +
                          " --integrator cvode --steps 1 --quiet --max-step " + bad);
    EXPECT_EQ(r.code, 2) << bad << "\n" << r.output;
  }
  EXPECT_EQ(run(sim() + " " + world("jello.w") +
                " --integrator cvode --steps 1 --quiet "
                "--max-step 1e-4")
                .code,
            0);
}

// Every numeric option of every program refuses NaN and infinities with exit code 2, found
// from each program's own --help, so a new option is covered without being listed here.
TEST(EveryProgram, RefusesNanAndInfinityInEveryNumericOption) {
  const std::filesystem::path bin = std::filesystem::path(sim()).parent_path();
  const std::string jelloWorld = world("jello.w");
  struct Program {
    std::string name, arguments;  // arguments every run needs (a world file)
  };
  const Program programs[] = {{"jello-sim", jelloWorld}, {"jello-create-world", ""},
                              {"jello-stability", ""},   {"jello-work-precision", ""},
                              {"jello-scaling", ""},     {"jello", jelloWorld}};
  // "  --plane FLOAT x 4 ...", "  -n,--steps-per-frame INT:INT in [1 - 1000000]=1"
  const std::regex numeric(R"(^\s+(?:-\w,)?(--[\w-]+) ((?:FLOAT|INT|UINT)\S*)(?: x (\d+))?)");
  int checked = 0;
  for (const Program& program : programs) {
    const std::filesystem::path path = bin / program.name;
    if (!std::filesystem::exists(path)) {
      std::printf("%s is not built here: not checked\n", program.name.c_str());
      continue;
    }
    const Outcome help = run(path.string() + " --help");
    ASSERT_EQ(help.code, 0) << program.name;
    std::istringstream lines(help.output);
    std::string line;
    while (std::getline(lines, line)) {
      std::smatch m;
      if (!std::regex_search(line, m, numeric)) continue;
      const std::string option = m[1];
      const bool floating = m[2].str().rfind("FLOAT", 0) == 0;
      const int count = m[3].matched ? std::stoi(m[3]) : 1;
      for (const char* bad : {"nan", "inf", "-inf"}) {
        std::string values;
        for (int i = 0; i < count; ++i) values += std::string(" ") + bad;
        const Outcome r =
            run(path.string() + " " + program.arguments + " " + option + values + " 2>&1");
        EXPECT_EQ(r.code, 2) << program.name << " " << option << values << "\n" << r.output;
        // ("-inf" may be taken for an option by CLI11 and refused as such: exit 2 all the same.)
        if (floating && std::string(bad) != "-inf") {
          EXPECT_TRUE(contains(r.output, "finite")) << program.name << " " << option << "\n"
                                                    << r.output;
        }
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 40);  // the programs have at least this many numeric options
}

}  // namespace
}  // namespace jello
