// The simulation behind the viewer, free of GL: the loaded scene and what is drawn of it, the
// step-by-step advance, the user's push or pull, edits of the world's constants, and reloading
// the world file, where a file that has become invalid keeps the running scene. A SimRunner
// steps it on the simulation thread; tests drive it directly.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solvers/simulation.h"
#include "src/world/world_reader.h"
#include "viewer/box_geometry.h"
#include "viewer/interaction.h"
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

// What the renderer needs of a scene; replaced as a whole on reload and on edits of the world,
// so the render thread may keep drawing an old one.
struct SceneGeometry {
  World world;  // constants, plane and sphere (the field's grid is left out: arrows hold it)
  Lattice lattice;
  SurfaceMesh mesh;
  std::vector<Spring> springs;  // surface springs
  std::vector<Arrow> arrows;    // field arrows
  double frameTime = 0.0;       // the world's n*dt
};

class ViewerSession {
 public:
  ViewerSession(SceneSource source, World world);

  const Simulation& simulation() const { return *sim_; }
  Simulation& simulation() { return *sim_; }
  const std::shared_ptr<const SceneGeometry>& geometry() const { return geometry_; }
  const Lattice& lattice() const { return geometry_->lattice; }
  const SurfaceMesh& mesh() const { return geometry_->mesh; }
  const std::vector<Spring>& surfaceSprings() const { return geometry_->springs; }
  const std::vector<Arrow>& arrows() const { return geometry_->arrows; }
  // Simulated seconds per frame in course time: the world's n*dt.
  double frameTime() const { return geometry_->frameTime; }
  const SceneSource& source() const { return source_; }

  // One step of dt with the user's force applied. On failure the state stays the last sane one
  // (an interruption is not a failure: see StepResult).
  StepResult step();
  // Steps through `frameTime` simulated seconds (whole steps of dt). Returns the divergence
  // message when a step fails.
  std::optional<std::string> advance(double frameTime);

  // Reads the world file again and starts over. On failure the running scene is kept and the
  // error (file, line, token) is returned.
  std::optional<std::string> reload();
  // Changes the world's constants (k, damping, mass, obstacles, ...) keeping the current state,
  // time, integrator and time step. The edit gets the world with the current state in it.
  void editWorld(const std::function<void(World&)>& edit);

  // Saves the current state as a world file (atomically) that reloads to the same state.
  void save(const std::filesystem::path& path) const;

  // The time step is the starting one times `scale`.
  void scaleTimeStep(double scale) { sim_->setTimeStep(dt0_ * scale); }
  void setTimeStep(double dt) { sim_->setTimeStep(dt); }

  // Mouse: push the cube with acceleration `accel` (m/s^2), or pull point `picked` towards
  // `target` over `radius` (see interaction.h), until release().
  void push(const Vec3& accel);
  void pull(int picked, const Vec3& target, double radius);
  void release();
  // Picked point and target while pulling.
  std::optional<std::pair<int, Vec3>> pulling() const;
  // k_pull as a multiple of the world's k (interaction.h's pullSpring).
  void setPullStiffnessScale(double scale) { pullScale_ = scale; }
  double pullStiffnessScale() const { return pullScale_; }

 private:
  void build(World world);
  void applyUserForce();

  SceneSource source_;
  std::unique_ptr<Simulation> sim_;
  std::shared_ptr<const SceneGeometry> geometry_;
  double dt0_ = 0.0;
  enum class Drag { None, Push, Pull } drag_ = Drag::None;
  Vec3 accel_, target_;
  int picked_ = -1;
  double radius_ = 0.0;
  double pullScale_ = 1.0;
};

}  // namespace jello::viewer
