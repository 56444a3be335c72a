// The crossover atlas: for a spring stiffness k and a cube resolution N, each integrator's wall
// time per simulated second at the largest step that keeps the visible motion within a
// tolerance of a converged reference over the whole window, and stays stable. The scene is a
// cube thrown sideways and spinning, falling under gravity onto the floor and bouncing (the
// reference worlds' damping), or the same throw without gravity, touching nothing
// (AtlasScene); its visible motion is what an affine map of the cube at rest
// shows: the centre of mass, the rotation and the homogeneous stretch and shear, measured at
// the cube's eight corners. Part of jello-scaling (its NAME_atlas.csv).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "experiments/studies/atlas_scene.h"
#include "experiments/studies/csv_table.h"
#include "solvers/integrator.h"
#include "src/state.h"
#include "src/world/world.h"

namespace jello::experiments {

struct AtlasSetup {
  double time = 1.0;         // s, the window: the throw, the contact and the rebound
  double interval = 0.02;    // s between samples, and the implicit methods' largest step
  double tolerance = 0.01;   // m, at the corners (1% of the cube's edge)
  double referenceHw = 1.0;  // h w_max of the reference's RK4 steps, at most
  // The reference's step is halved, up to referenceRefinements times, while RK4 at twice it is
  // further than this fraction of the tolerance from it at the corners (a fifth: RK4's own
  // error is then about 1% of the tolerance). Measured on the 20-times-stiffer floor at k = 1e5, N
  // = 8: 40, 3.2, 0.19 and 0.008 mm at h w_max = 1, 1/2, 1/4, 1/8 (fourth order, once the step is
  // small enough).
  double referenceCheck = 0.2;
  int referenceRefinements = 4;
  double runBudget = 20.0;  // wall seconds: a run that would take longer ends the search
  int halvings = 7;         // step sizes tried per integrator (explicit: below its limit)
  // s, the first step of the fixed-step methods that are not explicit (0: the sample interval;
  // else the interval over a whole number), e.g. to trace them at a small step.
  double firstStep = 0.0;
  // Where references are kept (reference_file.h; empty: nowhere): one found there is used, one
  // computed is written there, and while it is computed its last state every `checkpoint` wall
  // seconds, from which a later run resumes.
  std::filesystem::path referenceDir;
  double checkpoint = 60.0;
  int referenceThreads = 0;  // the model's threads for the reference (0: the runs' own)
};

// Visible motion: the least-squares affine map x = A r + t of the rest lattice (r centred) onto
// a state, and the largest distance between two such maps at the cube's corners.
class VisibleMotion {
 public:
  explicit VisibleMotion(int n);
  Eigen::Matrix<double, 3, 4> fit(const State& s) const;  // [A | t]
  double cornerDistance(const Eigen::Matrix<double, 3, 4>& a,
                        const Eigen::Matrix<double, 3, 4>& b) const;

 private:
  std::vector<Eigen::Vector3d> rest_;  // centred
  Eigen::Matrix3d inverseGram_;
};

struct AtlasReference {
  std::vector<Eigen::Matrix<double, 3, 4>> samples;  // the fit at t = k * interval
  double wMax = 0.0;                                 // rad/s, of the scene at the start
  double dt = 0.0;                                   // s
  double check = 0.0;  // m, the largest corner distance from RK4 at twice the reference's step
};
// What atlasReference throws when RK4 fails at its step and at every halving of it (a point
// crossing a barrier too soft for the impact): the point has no reference.
struct AtlasReferenceFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// A point without a reference: a row for `kind` with outcome "no_reference".
void atlasNoReference(double k, int n, double wMax, IntegratorKind kind, CsvTable& table);

// The reference of `scene` at stiffness k (`w`, atlasScene's with `contact`), and its check:
// RK4 at h w_max <= setup.referenceHw (w_max atlasMaxFrequency's), halved while the check is
// above setup.referenceCheck of the tolerance.
AtlasReference atlasReference(const World& w, double k, AtlasScene scene, const AtlasSetup& setup,
                              AtlasContact contact = AtlasContact::Soft);

// The integrators an atlas point compares (quick: symplectic, rk4, implicit, midpoint,
// projective).
std::vector<IntegratorKind> atlasIntegrators(bool quick);

CsvTable atlasTable();
// Searches `kind`'s largest step (cvode: loosest tolerance) within the tolerance on `w` and adds
// the row: k, n, integrator, dt_s, rtol, steps (cvode: output intervals), wall_per_simulated_s,
// visible_error_m (of the run kept, or of the last finished run), tried,
// outcome ("ok", "not_reached": none of the steps tried was within the tolerance, "budget": the
// next smaller step would have taken longer than the run budget).
// `tries`, when given, gets a row for every run of the search (NAME_tries.csv): k, n,
// integrator, dt_s, rtol, steps, wall_per_simulated_s, visible_error_m (the run's, as far as it
// went), finished (1, or 0 and why: "budget", "diverged" or "failed"), so that how
// the error falls with the step (its order, or a floor) is seen, not only the step kept.
void atlasPoint(const World& w, double k, int n, IntegratorKind kind, const AtlasReference& ref,
                const AtlasSetup& setup, CsvTable& table, CsvTable* tries = nullptr);
CsvTable atlasTriesTable();

// The visible motion over time (jello-scaling --atlas-trace, issue 39 item 5): the reference's
// samples (`kind` empty, integrator "reference") or `kind`'s run at its largest candidate step
// (cvode: its loosest tolerance), as far as it goes: k, n, integrator, dt_s, rtol, t_s, the
// fit's centre height centre_z_m, the cube's height height_m (A_zz) and width width_m (A_xx),
// and its corner distance from the reference's fit.
CsvTable atlasTraceTable();
void atlasTrace(const World& w, double k, int n, std::optional<IntegratorKind> kind,
                const AtlasReference& ref, const AtlasSetup& setup, CsvTable& table);

}  // namespace jello::experiments
