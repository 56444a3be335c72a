#include "experiments/studies/run_context.h"

#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <fstream>
#include <thread>

#include "experiments/common/json_finite.h"
#include "solvers/linalg/solver_threads.h"
#include "src/base/atomic_file.h"
#include "src/model.h"
#include "src/state.h"
#include "src/world/scene_builder.h"

namespace jello::experiments {

namespace {

std::string command(const std::string& cmd) {
  std::string out;
  if (FILE* pipe = ::popen(cmd.c_str(), "r")) {
    char buf[256];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
    if (::pclose(pipe) != 0) return {};
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  }
  return "unknown";
}

// The highest x86-64 level the CPU supports: the clones a portable build runs
// (src/base/vector_clones.h). x86-64-v4 has AVX-512, v3 AVX2: loops that vectorize only with
// AVX-512's masks ran scalar on v3 machines, which a run's timings would otherwise hide.
std::string vectorLevel() {
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
  __builtin_cpu_init();  // the builtin takes literals only
  if (__builtin_cpu_supports("x86-64-v4")) return "x86-64-v4";
  if (__builtin_cpu_supports("x86-64-v3")) return "x86-64-v3";
  if (__builtin_cpu_supports("x86-64-v2")) return "x86-64-v2";
  return "x86-64";
#else
  return "unknown";
#endif
}

// The machine's speed as the run starts: the median over 9 batches of the time of one force
// evaluation (springs, walls, plane, field) of the default scene's 8^3 cube. These are shared
// VMs: the same machine type measured the spring forces 4x apart on one day, so timings are
// comparable within a run, and across runs only through this figure.
double forceEvaluationSeconds() {
  SceneSpec spec;
  const World w = buildWorld(spec);
  const Model model(w);
  const State s = initialState(w);
  Eigen::VectorXd f(s.x.size());
  std::vector<double> batches;
  for (int b = 0; b < 9; ++b) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < 50; ++i) model.forces(s.x.data(), s.v.data(), f.data());
    batches.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
                      50);
  }
  std::nth_element(batches.begin(), batches.begin() + 4, batches.end());
  return batches[4];
}

}  // namespace

bool treeModified(const std::filesystem::path& sourceDir) {
  return !command("git -C '" + sourceDir.string() +
                  "' status --porcelain --untracked-files=no -- . ':(exclude)experiments/results' "
                  "2>/dev/null")
              .empty();
}

nlohmann::json runContext(int argc, char** argv) {
  std::vector<std::string> args(argv, argv + argc);
  const std::string git = std::string("git -C '") + JELLO_SOURCE_DIR + "' ";
  const std::string commit = command(git + "rev-parse HEAD 2>/dev/null");
  const bool dirty = treeModified(JELLO_SOURCE_DIR);
  utsname u{};
  const bool named = ::uname(&u) == 0;
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return {
      {"command_line", args},
      {"commit", commit.empty() ? "unknown" : commit},
      {"tree_modified", dirty},
      {"compiler", std::string(__VERSION__)},
      {"build_type", JELLO_BUILD_TYPE},
      {"blas", jello::loadedBlas()},
      {"solver_threads", jello::solverThreadSettings()},
      {"OPENBLAS_NUM_THREADS",
       std::getenv("OPENBLAS_NUM_THREADS") ? std::getenv("OPENBLAS_NUM_THREADS") : ""},
      {"OMP_THREAD_LIMIT", std::getenv("OMP_THREAD_LIMIT") ? std::getenv("OMP_THREAD_LIMIT") : ""},
      {"machine",
       {{"cpu", cpuModel()},
        {"vector_level", vectorLevel()},
        {"cores", std::thread::hardware_concurrency()},
        {"kernel", named ? std::string(u.sysname) + " " + u.release : "unknown"},
        {"arch", named ? u.machine : "unknown"},
        {"force_evaluation_8_s", forceEvaluationSeconds()}}},
      {"date_utc", date}};
}

void writeSidecar(const std::filesystem::path& path, const nlohmann::json& sidecar) {
  nlohmann::json explained = sidecar;
  explainNonFinite(explained);
  writeFileAtomically(path, explained.dump(2) + "\n");
}

bool prepareOutputDirectory(const std::string& program, const std::filesystem::path& dir,
                            const std::string& name) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "%s: error: cannot create the output directory %s: %s\n", program.c_str(),
                 dir.c_str(), ec.message().c_str());
    return false;
  }
  const std::filesystem::path probe = dir / (name + ".csv");
  if (const std::string why = outputProblem(probe); !why.empty()) {
    std::fprintf(stderr, "%s: error: cannot write %s: %s\n", program.c_str(), probe.c_str(),
                 why.c_str());
    return false;
  }
  return true;
}

bool writeResults(const std::string& program, const std::filesystem::path& dir,
                  const std::string& name, const CsvTable& table, const nlohmann::json& sidecar,
                  const std::vector<std::pair<std::string, const CsvTable*>>& extra) {
  // Every file that can be written is; each failure is reported.
  bool ok = true;
  const auto attempt = [&](auto&& write) {
    try {
      write();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: error: %s\n", program.c_str(), e.what());
      ok = false;
    }
  };
  attempt([&] { std::filesystem::create_directories(dir); });
  attempt([&] { table.write(dir / (name + ".csv")); });
  for (const auto& [suffix, other] : extra) {
    attempt([&] { other->write(dir / (name + "_" + suffix + ".csv")); });
  }
  attempt([&] { writeSidecar(dir / (name + ".json"), sidecar); });
  return ok;
}

}  // namespace jello::experiments
