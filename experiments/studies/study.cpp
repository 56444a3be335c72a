#include "experiments/studies/study.h"

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "experiments/common/signal_handler.h"
#include "experiments/studies/run_context.h"
#include "solvers/linalg/solver_threads.h"
#include "src/base/finite_options.h"
#include "src/base/out_of_memory.h"

namespace jello::experiments {

Study::Study(std::string program, const std::string& description, std::string defaultName,
             int& argc, char**& argv)
    : name(std::move(defaultName)),
      program_(std::move(program)),
      ranks_(argc, argv),
      app_(program_ + ": " + description) {
  exitCleanlyWhenOutOfMemory(program_.c_str());
  ignoreBrokenPipes(program_.c_str());
  applySolverThreadSettings();
  jobs = ranks_.defaultJobs();
}

void Study::addCommonOptions(const std::string& quickHelp, const std::string& jobsHelp) {
  app_.add_option("--jobs", jobs, jobsHelp)->check(cli::range(1, 256))->capture_default_str();
  app_.add_option("--out-dir", outDir, "Directory for NAME.csv and NAME.json")
      ->capture_default_str();
  // A stem, not a path: "../x" or "/tmp/x" wrote outside --out-dir, "" hidden files (".csv").
  app_.add_option("--name", name, "File name stem (in --out-dir: no '/', not starting with '.')")
      ->check(CLI::Validator(
          [](const std::string& stem) -> std::string {
            if (stem.empty()) return "--name must not be empty";
            if (stem.find('/') != std::string::npos || stem.front() == '.') {
              return "--name is a file name stem in --out-dir: no '/', not starting with '.'";
            }
            for (const char c : stem) {
              if (static_cast<unsigned char>(c) < 0x20) return "--name holds a control character";
            }
            return "";
          },
          "STEM"))
      ->capture_default_str();
  app_.add_flag("--quick", quick, quickHelp);
  app_.add_flag("--quiet", quiet, "No progress line");
}

std::optional<int> Study::start(int argc, char** argv, const std::function<std::string()>& check) {
  if (!ranks_.error().empty()) return fail(ranks_.error());
  // Under mpirun every rank parses its own command line: one given another (a bad option, --k
  // 100 against --k 1e5) would refuse alone and leave the others waiting for it, or run a CSV
  // whose rows alternate between the two. Rank 0's line is the job's: any other fails it.
  std::string line;
  for (int i = 1; i < argc; ++i) line.append(argv[i]).push_back('\0');
  if (const int other = ranks_.firstDiffering(line); other >= 0) {
    if (ranks_.root()) {
      std::cerr << program_ << ": error: rank " << other
                << " was started with other arguments than rank 0 (every rank of a job runs "
                   "one study: give them all the same command line)\n";
    }
    return 2;
  }
  try {
    app_.parse(argc, argv);
    refuseNonFiniteNumbers(app_);
  } catch (const CLI::ParseError& e) {
    // Under mpirun every rank parses the same line: rank 0 alone prints, all exit alike.
    return (ranks_.root() ? app_.exit(e) : e.get_exit_code()) == 0 ? 0 : 2;
  }
  if (check) {
    if (const std::string why = check(); !why.empty()) {
      if (ranks_.root()) std::cerr << program_ << ": error: " << why << '\n';
      return 2;
    }
  }
  // The tree as the run starts: the code that ran (outputs written later do not count).
  context_ = runContext(argc, argv);
  // The output directory is made and checked before the (long) run.
  if (!ranks_.prepareOutput(program_, outDir, name)) return 1;
  return std::nullopt;
}

int Study::fail(const std::string& what) const {
  std::cerr << program_ << ": error: " << what << '\n';
  return 1;
}

bool Study::run(int count, const std::string& label, const std::function<void(int)>& task,
                const std::vector<CsvTable*>& tables) {
  started_ = std::chrono::steady_clock::now();
  return ranks_.run(program_, count, jobs, label, !quiet, task, tables);
}

int Study::finish(const CsvTable& table, nlohmann::json parameters,
                  const std::vector<std::pair<std::string, const CsvTable*>>& extra) {
  nlohmann::json sidecar = context_;
  sidecar["program"] = program_;
  sidecar["parameters"] = std::move(parameters);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  sidecar["wall_time_s"] = wall;
  const std::filesystem::path dir = outDir;
  if (!ranks_.writeOutput(program_, dir, name, table, sidecar, extra)) return 1;
  if (!quiet && ranks_.root()) {
    std::string rows = std::to_string(table.rows());
    for (const auto& [suffix, t] : extra) rows += " + " + std::to_string(t->rows());
    std::printf("wrote %s rows to %s (%.1f s)\n", rows.c_str(), dir.c_str(), wall);
  }
  return 0;
}

}  // namespace jello::experiments
