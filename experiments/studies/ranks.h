// The processes of an experiment run. Started by an MPI launcher (`mpirun -np K`, Slurm's
// `srun`), an experiment program is one of K ranks: its grid points are dealt out over the
// ranks (each runs its share on its own thread pool) and rank 0 gathers every row and writes the
// one CSV, identical, timing columns aside, to a single-process run. Started any other way it
// is the only rank and never touches MPI.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "experiments/studies/csv_table.h"
#include "experiments/studies/run_context.h"

namespace jello::experiments {

class Ranks {
 public:
  // Initializes MPI only when an MPI launcher started the process (it sets OMPI_COMM_WORLD_SIZE,
  // PMIX_RANK or PMI_RANK); when that fails, error() says why.
  Ranks(int& argc, char**& argv);
  ~Ranks();  // MPI_Finalize, when initialized
  Ranks(const Ranks&) = delete;
  Ranks& operator=(const Ranks&) = delete;

  const std::string& error() const { return error_; }  // empty when MPI is usable (or unused)
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  bool distributed() const { return size_ > 1; }
  // Threads per rank by default: this machine's cores shared by the ranks running on it.
  int defaultJobs() const;
  // The tasks of [0, count) this rank runs: every size()-th from rank(), in order.
  std::vector<int> share(int count) const;
  // True on every rank when `ok` is true on every rank (a collective call: all ranks must make
  // it, so that one rank's failure cannot leave the others waiting).
  bool all(bool ok) const;
  // The lowest rank whose `text` differs from rank 0's, or -1 when all agree (a collective
  // call). The studies compare their command lines before parsing them: every rank then parses
  // the same line and refuses it, or not, alike, and no rank waits for one that left.
  int firstDiffering(const std::string& text) const;
  // Moves every rank's rows of `table` into rank 0's (a collective call); the rows keep their
  // task order (csv_table.h), so rank 0 writes what a single process would.
  void gather(CsvTable& table) const;
  // prepareOutputDirectory (run_context.h) on rank 0; true on every rank when it succeeded.
  bool prepareOutput(const std::string& program, const std::filesystem::path& dir,
                     const std::string& name) const;
  // writeResults (run_context.h) on rank 0, the sidecar saying how many ranks ran; true on
  // every other rank.
  bool writeOutput(const std::string& program, const std::filesystem::path& dir,
                   const std::string& name, const CsvTable& table, nlohmann::json sidecar,
                   const std::vector<std::pair<std::string, const CsvTable*>>& extra = {}) const;

  // "rank R of K: " when distributed, else "".
  std::string prefix() const;

  // An experiment's grid: runs task(i) for this rank's share of [0, count) on `jobs` threads
  // (progress shown by rank 0 only), then gathers `tables` to rank 0. Returns true on every rank
  // when every rank succeeded; a rank whose task threw prints "<program>: error: ..." itself.
  bool run(const std::string& program, int count, int jobs, const std::string& label, bool progress,
           const std::function<void(int)>& task, const std::vector<CsvTable*>& tables) const;

 private:
  void setUp();  // rank, size and ranks per node, after MPI_Init

  std::string error_;
  bool initialized_ = false;
  int rank_ = 0, size_ = 1, localSize_ = 1;
};

}  // namespace jello::experiments
