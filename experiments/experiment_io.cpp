#include "experiment_io.h"

#include <sys/utsname.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <exception>
#include <fstream>
#include <sstream>
#include <thread>

#include "atomic_file.h"
#include "progress.h"

namespace jello::experiments {

CsvTable::CsvTable(std::vector<std::string> columns) : columns_(std::move(columns)) {}

void CsvTable::add(std::vector<Cell> row) {
  std::lock_guard lock(mutex_);
  rows_.push_back(std::move(row));
}

std::string CsvTable::text() const {
  std::lock_guard lock(mutex_);
  std::ostringstream os;
  for (std::size_t i = 0; i < columns_.size(); ++i) os << (i ? "," : "") << columns_[i];
  os << '\n';
  for (const auto& row : rows_) {
    for (std::size_t i = 0; i < row.size(); ++i) {
      if (i) os << ',';
      if (const double* d = std::get_if<double>(&row[i])) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.17g", *d);
        os << buf;
      } else if (const long* l = std::get_if<long>(&row[i])) {
        os << *l;
      } else {
        os << std::get<std::string>(row[i]);
      }
    }
    os << '\n';
  }
  return os.str();
}

void CsvTable::write(const std::filesystem::path& path) const {
  writeFileAtomically(path, text());
}

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

std::string loadedBlas() {
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    for (const char* name : {"libopenblas", "libblis", "libmkl", "libblas.so"}) {
      if (line.find(name) != std::string::npos) return line.substr(line.find('/'));
    }
  }
  return "none loaded";
}

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
      {"blas", loadedBlas()},
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

void parallelFor(int count, int jobs, const std::string& label, bool progress,
                 const std::function<void(int)>& task) {
  std::atomic<int> next{0}, done{0};
  std::exception_ptr failure;
  std::mutex failureMutex;
  const auto worker = [&] {
    for (int i; (i = next.fetch_add(1)) < count;) {
      {
        std::lock_guard lock(failureMutex);
        if (failure) return;
      }
      try {
        task(i);
      } catch (...) {
        std::lock_guard lock(failureMutex);
        if (!failure) failure = std::current_exception();
      }
      ++done;
    }
  };
  std::vector<std::thread> threads;
  for (int t = 1; t < std::max(1, jobs); ++t) threads.emplace_back(worker);
  // The calling thread works too, and draws the progress line between its tasks.
  Progress bar(progress, label);
  std::thread reporter;
  std::atomic<bool> finished{false};
  if (progress) {
    reporter = std::thread([&] {
      while (!finished) {
        bar.report(done, count);
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
      }
    });
  }
  worker();
  for (std::thread& t : threads) t.join();
  finished = true;
  if (reporter.joinable()) reporter.join();
  bar.finish();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace jello::experiments
