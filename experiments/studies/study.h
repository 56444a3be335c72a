// What the study programs (jello-stability, jello-work-precision, jello-scaling) share, so that
// each main is its options, its grid, its run and its writing: the MPI ranks, the process's
// handlers (out of memory, broken pipes) and single-threaded BLAS and CHOLMOD, the options every
// study has (--jobs, --out-dir, --name, --quick, --quiet), the parsing (under mpirun rank 0
// alone prints), the run's context taken before the run, the output directory checked before
// it, the grid run over the ranks and the results written with their sidecar after it.
#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "experiments/studies/csv_table.h"
#include "experiments/studies/ranks.h"

namespace jello::experiments {

class Study {
 public:
  // `program` names it in messages and the sidecar; `defaultName` is NAME's default.
  Study(std::string program, const std::string& description, std::string defaultName, int& argc,
        char**& argv);

  CLI::App& app() { return app_; }
  const Ranks& ranks() const { return ranks_; }
  const std::string& program() const { return program_; }

  // The common options, registered after the study's own (so --help lists them last).
  int jobs = 1;  // the machine's cores shared by the ranks on it, unless --jobs
  std::string outDir = "experiments/results";
  std::string name;
  bool quick = false, quiet = false;
  void addCommonOptions(const std::string& quickHelp,
                        const std::string& jobsHelp = "Grid points run in parallel (per MPI rank)");

  // Parses the command line, then check() (a usage error's text, or empty), takes the run's
  // context and makes the output directory. An exit code when the program must stop here (0
  // after --help, 2 for a bad option, 1 for MPI or an unwritable directory), else nothing.
  std::optional<int> start(int argc, char** argv,
                           const std::function<std::string()>& check = nullptr);
  // Whether the command line gave `option` (a --quick default yields to it).
  bool given(const char* option) const { return app_.count(option) > 0; }
  // "<program>: error: what" on stderr; returns 1 for main to return.
  int fail(const std::string& what) const;

  // The grid: task(i) for this rank's share of [0, count) on `jobs` threads, then `tables`
  // gathered to rank 0; the wall time of the run starts here. False when a task failed.
  bool run(int count, const std::string& label, const std::function<void(int)>& task,
           const std::vector<CsvTable*>& tables);

  // Writes NAME.csv, NAME_<suffix>.csv of each extra and NAME.json (the context, the program,
  // `parameters` and the run's wall time) on rank 0, then unless --quiet "wrote ... rows to
  // DIR (T s)". The exit code: 0, or 1 when a file could not be written.
  int finish(const CsvTable& table, nlohmann::json parameters,
             const std::vector<std::pair<std::string, const CsvTable*>>& extra = {});

 private:
  std::string program_;
  Ranks ranks_;
  CLI::App app_;
  nlohmann::json context_;
  std::chrono::steady_clock::time_point started_;
};

}  // namespace jello::experiments
