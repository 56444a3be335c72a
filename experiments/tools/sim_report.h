// jello-sim's run as data and what it reports: the options of the command line, what a run
// came to (Outcome), the trace (CSV), the summary on standard output, the statistics (JSON,
// with the warnings and errors on standard error) and the outputs written (jello_sim.cpp runs).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>

#include "experiments/tools/contact_flags.h"
#include "solvers/simulation.h"
#include "src/world/world_reader.h"

namespace jello::simtool {

struct Options {
  std::string world;
  std::string integrator;
  std::optional<double> dt;
  std::optional<double> time;
  std::optional<long> steps;
  std::optional<int> cube;
  std::string out, trace, stats;
  bool outGiven = false, traceGiven = false, statsGiven = false;  // even as an empty string
  long every = 100;
  bool quiet = false;
  bool strict = false;   // an unconverged step stops the run (exit 4)
  SolverOptions solver;  // from the solver flags (solver_flags.h)
  ContactFlags contact;  // over the file's (contact_flags.h)
  ReaderLimits limits;
};

// What a run came to: the steps done, its wall time, and why it stopped early if it did.
struct Outcome {
  long total = 0;  // steps asked for
  long done = 0;   // steps taken (a diverged step not counted)
  double wall = 0.0;
  bool diverged = false;
  int interrupted = 0;      // the signal that stopped it
  std::string failure;      // a step that could not run (a resource limit), not a divergence
  std::string unconverged;  // --strict: the step accepted unconverged that stopped the run
  Energy start, end;
  Vec3 startL, endL;
};

// The CSV of --trace: one row every K steps (energies and centre of mass).
class Trace {
 public:
  explicit Trace(bool on);
  void row(const Simulation& sim);
  std::string text() const { return csv_.str(); }

 private:
  bool on_;
  std::ostringstream csv_;
};

// The summary as JSON (--stats), and on stderr what went wrong: unconverged steps, a signal, a
// failure, a divergence.
nlohmann::json statistics(const Options& opt, const Simulation& sim, const Outcome& o);
// The summary on standard output.
void printSummary(const Options& opt, const Simulation& sim, const Outcome& o);
// Writes --trace, --stats and --out (see the definition); false when a write failed.
bool writeOutputs(const Options& opt, const Simulation& sim, const Outcome& o, const Trace& trace,
                  const nlohmann::json& stats);

}  // namespace jello::simtool
