// jello-sim's solver flags, the "Implicit solvers" group of its --help (README, jello-sim):
// registered on the command line into SolverFlags, then turned into the solvers' options.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "solvers/solver_options.h"

namespace jello {

struct SolverFlags {
  SolverOptions solver;      // the options the flags set directly
  std::string linearSolver;  // empty: SolverOptions' defaults
  std::string preconditioner{preconditionerName(kDefaultPreconditioner)};
  bool csrProduct = false;
  bool noClamp = false, noStabLimDet = false, noFactorReuse = false;
  std::string cvodeMethod = "bdf";
  double atol = 0.0;
};

void addSolverFlags(CLI::App& app, SolverFlags& flags);
// After parsing: the options the flags say, shared settings given to both the Newton methods and
// CVODE.
SolverOptions solverOptions(const SolverFlags& flags);

}  // namespace jello
