// The simulation behind the viewer, free of GL: the loaded scene and what is drawn of it, the
// frame-by-frame advance, the user's push or pull, and reloading the world file, where a file
// that has become invalid keeps the running scene.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solvers/simulation.h"
#include "src/world_reader.h"
#include "viewer/box_geometry.h"
#include "viewer/surface.h"

namespace jello::viewer {

// Where the scene comes from: the file and the command line's overrides, applied again on
// every reload.
struct SceneSource {
  std::filesystem::path world;
  std::optional<IntegratorKind> integrator;
  std::optional<double> dt;  // s
  ReaderLimits limits;
};

class ViewerSession {
 public:
  ViewerSession(SceneSource source, World world);

  const Simulation& simulation() const { return *sim_; }
  Simulation& simulation() { return *sim_; }
  const Lattice& lattice() const { return lattice_; }
  const SurfaceMesh& mesh() const { return mesh_; }
  const std::vector<Spring>& surfaceSprings() const { return springs_; }
  const std::vector<Arrow>& arrows() const { return arrows_; }
  // Simulated seconds per displayed frame: the world's n*dt.
  double frameTime() const { return frameTime_; }

  // Steps the simulation through `frameTime` simulated seconds (stepsPerFrame steps of dt), the
  // user's force applied. Returns the divergence message when a step fails; the state then
  // stays the last sane one.
  std::optional<std::string> advance(double frameTime);

  // Reads the world file again and starts over. On failure the running scene is kept and the
  // error (file, line, token) is returned.
  std::optional<std::string> reload();

  // The time step is the starting one times `scale`.
  void scaleTimeStep(double scale) { sim_->setTimeStep(dt0_ * scale); }

  // Mouse: push the cube with acceleration `accel` (m/s^2), or pull point `picked` towards
  // `target` over `radius` (see interaction.h), until release().
  void push(const Vec3& accel);
  void pull(int picked, const Vec3& target, double radius);
  void release();
  // Picked point and target while pulling.
  std::optional<std::pair<int, Vec3>> pulling() const;

 private:
  void build(World world);
  void applyUserForce();

  SceneSource source_;
  std::unique_ptr<Simulation> sim_;
  Lattice lattice_;
  SurfaceMesh mesh_;
  std::vector<Spring> springs_;
  std::vector<Arrow> arrows_;
  double dt0_ = 0.0;
  double frameTime_ = 0.0;
  enum class Drag { None, Push, Pull } drag_ = Drag::None;
  Vec3 accel_, target_;
  int picked_ = -1;
  double radius_ = 0.0;
};

}  // namespace jello::viewer
