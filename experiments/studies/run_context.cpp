#include "experiments/studies/run_context.h"

#include <sys/utsname.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <fstream>
#include <thread>

#include "solvers/solver_threads.h"
#include "src/atomic_file.h"

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

}  // namespace

nlohmann::json runContext(int argc, char** argv) {
  std::vector<std::string> args(argv, argv + argc);
  const std::string git = std::string("git -C '") + JELLO_SOURCE_DIR + "' ";
  const std::string commit = command(git + "rev-parse HEAD 2>/dev/null");
  const bool dirty = !command(git + "status --porcelain --untracked-files=no 2>/dev/null").empty();
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
      {"OPENBLAS_NUM_THREADS",
       std::getenv("OPENBLAS_NUM_THREADS") ? std::getenv("OPENBLAS_NUM_THREADS") : ""},
      {"OMP_THREAD_LIMIT", std::getenv("OMP_THREAD_LIMIT") ? std::getenv("OMP_THREAD_LIMIT") : ""},
      {"machine",
       {{"cpu", cpuModel()},
        {"cores", std::thread::hardware_concurrency()},
        {"kernel", named ? std::string(u.sysname) + " " + u.release : "unknown"},
        {"arch", named ? u.machine : "unknown"}}},
      {"date_utc", date}};
}

void writeSidecar(const std::filesystem::path& path, const nlohmann::json& sidecar) {
  writeFileAtomically(path, sidecar.dump(2) + "\n");
}

bool writeResults(const std::string& program, const std::filesystem::path& dir,
                  const std::string& name, const CsvTable& table, const nlohmann::json& sidecar,
                  const std::vector<std::pair<std::string, const CsvTable*>>& extra) {
  try {
    std::filesystem::create_directories(dir);
    table.write(dir / (name + ".csv"));
    for (const auto& [suffix, other] : extra) other->write(dir / (name + "_" + suffix + ".csv"));
    writeSidecar(dir / (name + ".json"), sidecar);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", program.c_str(), e.what());
    return false;
  }
  return true;
}

}  // namespace jello::experiments
