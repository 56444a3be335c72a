// The atlas's references kept on disk (jello-scaling --atlas-references DIR). At N = 32 and
// k = 1e8 a reference is RK4 at 0.6 us for a simulated second, hours of CPU: kept in a file, it
// is computed once and reused by later runs (a cluster's ranks, a rerun of the integrators), and
// while it is computed the file holds the last state reached, so that a run stopped on the way
// (a session's end, a job's time limit) resumes there. RK4 keeps no history between steps, so
// a resumed trajectory equals the uninterrupted one to the last bit.
//
// The file is text: `name value` lines naming what it was computed for (the key), then the
// visible-motion fits at t = 0, interval, 2 interval, ..., twelve numbers a line ([A | t] by
// columns), and, while unfinished, the state at the last fit (t, then each point's position and
// velocity, six numbers a line). Numbers carry 17 significant digits, which read back exactly.
//   # comment lines
//   scene falling
//   k_N_per_m 100000000
//   n 32
//   dt_s 6.103515625e-07
//   interval_s 0.02
//   time_s 1
//   fits 51
//   <12 numbers> x 51
//   state 0.02 32768          (unfinished only: t and the number of points)
//   <6 numbers> x 32768
//   end
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "src/state.h"

namespace jello::experiments {

using AffineFit = Eigen::Matrix<double, 3, 4>;  // [A | t]

// What a stored trajectory was computed for: a file made for anything else is refused.
struct TrajectoryKey {
  std::string scene;  // "falling" or "free"
  double k = 0.0;     // N/m
  int n = 0;
  double dt = 0.0;        // s, RK4's step
  double interval = 0.0;  // s between fits
  double time = 0.0;      // s, the window
  // reference_<scene>_n<n>_k<k>_dt<dt>.txt
  std::string fileName() const;
};

struct StoredTrajectory {
  std::vector<AffineFit> fits;  // at t = 0, interval, 2 interval, ...
  std::optional<State> resume;  // unfinished: the state at the last fit
};

// The trajectory in `file`, or nullopt when there is no such file. Throws std::runtime_error
// naming the file and, for bad content, its line and token, or the key's field that differs.
std::optional<StoredTrajectory> readTrajectory(const std::filesystem::path& file,
                                               const TrajectoryKey& key);

// Replaces `file` atomically (atomic_file.h): a finished trajectory when resume is null.
void writeTrajectory(const std::filesystem::path& file, const TrajectoryKey& key,
                     const std::vector<AffineFit>& fits, const State* resume);

}  // namespace jello::experiments
