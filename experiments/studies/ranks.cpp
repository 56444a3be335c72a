#include "experiments/studies/ranks.h"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <stdexcept>
#include <thread>

#include "experiments/studies/parallel_for.h"
#include "src/base/parallel.h"

#ifdef JELLO_HAVE_MPI
#include <mpi.h>
#endif

namespace jello::experiments {

namespace {

// Open MPI's mpirun sets OMPI_COMM_WORLD_SIZE; PMIx (Open MPI 4 and Slurm's srun --mpi=pmix)
// PMIX_RANK; PMI-1/2 launchers (srun --mpi=pmi2, MPICH's hydra) PMI_RANK.
bool startedByMpiLauncher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"}) {
    if (std::getenv(name) != nullptr) return true;
  }
  return false;
}

#ifdef JELLO_HAVE_MPI
void check(int code, const char* what) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw std::runtime_error(std::string(what) +
                           " failed: " + std::string(text, std::size_t(length)));
}
#endif

}  // namespace

Ranks::Ranks(int& argc, char**& argv) {
  if (!startedByMpiLauncher()) return;
#ifdef JELLO_HAVE_MPI
  if (const int code = MPI_Init(&argc, &argv); code != MPI_SUCCESS) {
    error_ = "MPI_Init failed with code " + std::to_string(code);
    return;
  }
  initialized_ = true;
  try {
    setUp();
  } catch (const std::exception& e) {
    error_ = e.what();
  }
#else
  (void)argc;
  (void)argv;
  error_ =
      "started by an MPI launcher, but this build has no MPI (configure with -DJELLO_MPI=ON and "
      "libopenmpi-dev installed)";
#endif
}

void Ranks::setUp() {
#ifdef JELLO_HAVE_MPI
  // Errors come back as codes (checked) instead of aborting the job inside MPI.
  check(MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN), "MPI_Comm_set_errhandler");
  check(MPI_Comm_rank(MPI_COMM_WORLD, &rank_), "MPI_Comm_rank");
  check(MPI_Comm_size(MPI_COMM_WORLD, &size_), "MPI_Comm_size");
  MPI_Comm local;
  check(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local),
        "MPI_Comm_split_type");
  check(MPI_Comm_size(local, &localSize_), "MPI_Comm_size");
  check(MPI_Comm_free(&local), "MPI_Comm_free");
  // The node's CPUs are shared by its ranks: the model's loops split over this rank's share.
  if (localSize_ > 1) setParallelThreads(std::max(1, parallelThreads() / localSize_));
#endif
}

Ranks::~Ranks() {
#ifdef JELLO_HAVE_MPI
  if (initialized_) MPI_Finalize();  // nothing to do with a failure while exiting
#endif
}

int Ranks::defaultJobs() const {
  const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, cores / std::max(1, localSize_));
}

std::vector<int> Ranks::share(int count) const {
  std::vector<int> tasks;
  for (int i = rank_; i < count; i += size_) tasks.push_back(i);
  return tasks;
}

bool Ranks::all(bool ok) const {
  if (!distributed()) return ok;
#ifdef JELLO_HAVE_MPI
  int mine = ok ? 1 : 0, every = 0;
  check(MPI_Allreduce(&mine, &every, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD), "MPI_Allreduce");
  return every == 1;
#else
  return ok;
#endif
}

int Ranks::firstDiffering(const std::string& text) const {
  if (!distributed()) return -1;
#ifdef JELLO_HAVE_MPI
  // A command line is far below 2 GB: an int counts its bytes.
  int length = int(text.size());
  check(MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD), "MPI_Bcast");
  std::string rootText = root() ? text : std::string(std::size_t(length), '\0');
  check(MPI_Bcast(rootText.data(), length, MPI_CHAR, 0, MPI_COMM_WORLD), "MPI_Bcast");
  int mine = rootText == text ? size_ : rank_, first = size_;
  check(MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD), "MPI_Allreduce");
  return first == size_ ? -1 : first;
#else
  (void)text;
  return -1;
#endif
}

void Ranks::gather(CsvTable& table) const {
  if (!distributed()) return;
#ifdef JELLO_HAVE_MPI
  const std::string mine = root() ? std::string() : table.serialize();
  const int length = int(mine.size());
  std::vector<int> lengths(root() ? std::size_t(size_) : 0), offsets(lengths.size());
  check(MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD),
        "MPI_Gather");
  std::string all;
  if (root()) {
    int total = 0;
    for (std::size_t r = 0; r < lengths.size(); ++r) {
      offsets[r] = total;
      total += lengths[r];
    }
    all.resize(std::size_t(total));
  }
  check(MPI_Gatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(),
                    MPI_CHAR, 0, MPI_COMM_WORLD),
        "MPI_Gatherv");
  if (root()) {
    table.merge(all);
  } else {
    table.clear();
  }
#else
  (void)table;
#endif
}

bool Ranks::run(const std::string& program, int count, int jobs, const std::string& label,
                bool progress, const std::function<void(int)>& task,
                const std::vector<CsvTable*>& tables) const {
  bool ok = true;
  try {
    parallelFor(share(count), jobs, label, progress && root(), task);
  } catch (const std::exception& e) {
    std::cerr << program << ": error: " << prefix() << e.what() << '\n';
    ok = false;
  }
  if (!all(ok)) return false;
  try {
    for (CsvTable* table : tables) gather(*table);
  } catch (const std::exception& e) {
    std::cerr << program << ": error: " << prefix() << e.what() << '\n';
    ok = false;
  }
  return all(ok);
}

bool Ranks::prepareOutput(const std::string& program, const std::filesystem::path& dir,
                          const std::string& name) const {
  return all(!root() || prepareOutputDirectory(program, dir, name));
}

bool Ranks::writeOutput(const std::string& program, const std::filesystem::path& dir,
                        const std::string& name, const CsvTable& table, nlohmann::json sidecar,
                        const std::vector<std::pair<std::string, const CsvTable*>>& extra) const {
  if (!root()) return true;
  sidecar["mpi_ranks"] = size_;
  return writeResults(program, dir, name, table, sidecar, extra);
}

std::string Ranks::prefix() const {
  if (!distributed()) return {};
  return "rank " + std::to_string(rank_) + " of " + std::to_string(size_) + ": ";
}

}  // namespace jello::experiments
