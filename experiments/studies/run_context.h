// The record of an experiment run: a JSON sidecar beside its CSV saying how the numbers were
// made (command line, source commit and whether the tree had changes, compiler, build type,
// the BLAS this process loaded, thread settings, machine, date).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "experiments/studies/csv_table.h"

namespace jello::experiments {

// Command line, commit and whether the tracked tree is modified, compiler, BLAS, machine, date:
// taken as the run starts, so that the outputs the run writes do not mark its own tree modified.
nlohmann::json runContext(int argc, char** argv);
// Whether the git work tree at `sourceDir` has tracked changes outside experiments/results/: the
// results an earlier program of the same run wrote there are not the code that runs (without
// the exclusion, the second program of scripts/run-experiments.sh recorded a modified tree).
// False when `sourceDir` is not a git work tree.
bool treeModified(const std::filesystem::path& sourceDir);
void writeSidecar(const std::filesystem::path& path, const nlohmann::json& sidecar);

// Creates `dir` and checks that NAME.csv can be written there, before a long run: false, with
// the reason on stderr naming `program`, when not.
bool prepareOutputDirectory(const std::string& program, const std::filesystem::path& dir,
                            const std::string& name);

// Writes `table` to DIR/NAME.csv, each of `extra` to DIR/NAME_<suffix>.csv and the sidecar
// to DIR/NAME.json, creating DIR. Every file that can be written is; on any failure prints
// "<program>: error: ..." for each and returns false.
bool writeResults(const std::string& program, const std::filesystem::path& dir,
                  const std::string& name, const CsvTable& table, const nlohmann::json& sidecar,
                  const std::vector<std::pair<std::string, const CsvTable*>>& extra = {});

}  // namespace jello::experiments
