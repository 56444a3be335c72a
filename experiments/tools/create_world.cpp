// jello-create-world: writes a world file. With no arguments it writes ./jello.w with the
// original course creator's values (reference-worlds/createWorld-default.w); flags set every
// field. The file is checked by reading it back before it replaces anything on disk.
#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "experiments/common/signal_handler.h"
#include "experiments/tools/contact_flags.h"
#include "src/base/atomic_file.h"
#include "src/base/finite_options.h"
#include "src/base/out_of_memory.h"
#include "src/world/scene_builder.h"
#include "src/world/world_reader.h"
#include "src/world/world_writer.h"

namespace {

using jello::FieldPreset;
using jello::PosePreset;
using jello::Vec3;

Vec3 toVec3(const std::vector<double>& v) {
  return {v[0], v[1], v[2]};
}

const std::map<std::string, FieldPreset> kFields{{"none", FieldPreset::None},
                                                 {"gravity", FieldPreset::Gravity},
                                                 {"vortex", FieldPreset::Vortex},
                                                 {"radial", FieldPreset::Radial}};
const std::map<std::string, PosePreset> kPoses{{"rest", PosePreset::Rest},
                                               {"skewed", PosePreset::SkewedCorner},
                                               {"stretched", PosePreset::Stretched},
                                               {"rotated", PosePreset::Rotated},
                                               {"translated", PosePreset::Translated}};

// The flags that are not a SceneSpec field as they stand: names, lists of numbers, switches.
struct Flags {
  std::string out = "jello.w";
  std::string integrator = "rk4";
  std::vector<double> plane, sphere, cone, spiral, velocity, translate, axis;
  std::optional<double> fieldStrength;
  std::string field = "none", pose = "skewed";
  jello::ContactFlags contact;
  bool noPlane = false, legacy = false;
};

// The integrator, time step and constants.
void addConstants(CLI::App& app, jello::SceneSpec& spec, Flags& f) {
  app.add_option("-o,--output", f.out, "File to write (default jello.w)");
  app.add_option("--integrator", f.integrator, "Integrator: " + jello::integratorNameList())
      ->capture_default_str();
  app.add_option("--dt", spec.dt, "Time step, s")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("-n,--steps-per-frame", spec.stepsPerFrame, "Steps per drawn frame")
      ->check(jello::cli::range(1, 1000000))
      ->capture_default_str();
  app.add_option("--k-elastic", spec.kElastic, "Spring stiffness, N/m")
      ->check(jello::cli::nonNegative())
      ->capture_default_str();
  app.add_option("--d-elastic", spec.dElastic, "Spring damping, N*s/m")
      ->check(jello::cli::nonNegative())
      ->capture_default_str();
  app.add_option("--k-collision", spec.kCollision, "Contact stiffness, N/m")
      ->check(jello::cli::nonNegative())
      ->capture_default_str();
  app.add_option("--d-collision", spec.dCollision, "Contact damping, N*s/m")
      ->check(jello::cli::nonNegative())
      ->capture_default_str();
  jello::addContactFlags(app, f.contact, "default penalty; another is an extension");
  app.add_option("--mass", spec.mass, "Mass of each point, kg (default 1/512)")
      ->check(jello::cli::positive());
}

// The plane, the field and the other obstacles.
void addSurroundings(CLI::App& app, jello::SceneSpec& spec, Flags& f) {
  auto* planeOpt = app.add_option("--plane", f.plane,
                                  "Inclined plane A B C D: Ax+By+Cz+D=0, "
                                  "free where positive (default -1 1 1 2)")
                       ->expected(4);
  app.add_flag("--no-plane", f.noPlane, "No inclined plane")->excludes(planeOpt);
  app.add_option("--field", f.field,
                 "Force field: none (zero), gravity F=(0,0,-s), vortex F=s(-y,x,0), "
                 "radial F=-s(x,y,z)")
      ->check(CLI::IsMember(kFields, CLI::ignore_case))
      ->capture_default_str();
  app.add_option("--field-strength", f.fieldStrength,
                 "s above; default: gravity 9.81*mass N, vortex 5*mass N/m (rotate.w), "
                 "radial 25*mass N/m");
  app.add_option("--field-resolution", spec.fieldResolution,
                 "Field nodes per axis, 2..128, or 0 for no field (default 30)")
      ->check(jello::cli::range(0, 128));
  app.add_option("--sphere", f.sphere, "Sphere obstacle CX CY CZ R (an extension)")->expected(4);
  app.add_option("--cone", f.cone,
                 "Cone obstacle: apex AX AY AZ, axis DX DY DZ (apex to base), height H, base "
                 "radius R (an extension)")
      ->expected(8);
  app.add_option("--spiral", f.spiral,
                 "Spiral ramp obstacle: axis CX CY, top height Z, radii RIN ROUT, pitch P (m per "
                 "turn), turns T, thickness W (an extension)")
      ->expected(8);
}

// The cube: its pose, motion and resolution, and how the file is written.
void addCube(CLI::App& app, jello::SceneSpec& spec, Flags& f) {
  app.add_option("--pose", f.pose,
                 "Initial pose: rest, skewed (far corner out by one spacing), stretched, "
                 "rotated, translated")
      ->check(CLI::IsMember(kPoses, CLI::ignore_case))
      ->capture_default_str();
  app.add_option("--stretch", spec.stretch, "Stretch factor along x for --pose stretched")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--rotate", spec.rotateDegrees, "Angle, degrees, for --pose rotated")
      ->capture_default_str();
  app.add_option("--axis", f.axis, "Rotation axis X Y Z for --pose rotated (default 1 1 1)")
      ->expected(3);
  app.add_option("--translate", f.translate,
                 "Offset X Y Z, m, for --pose translated "
                 "(default 0.5 0.5 0.5)")
      ->expected(3);
  app.add_option("--velocity", f.velocity,
                 "Uniform initial velocity VX VY VZ, m/s "
                 "(default 10 -10 20)")
      ->expected(3);
  app.add_option("--spin", spec.spin,
                 "Initial spin about the vertical axis through the cube's centre, rad/s");
  app.add_option("--cube", spec.cubeResolution,
                 "Cube resolution N: N^3 points (default 8; other values are an extension)")
      ->check(jello::cli::range(2, 64));
  app.add_flag("--legacy", f.legacy,
               "Print six decimals like the original creator (not exact: 1/512 becomes "
               "0.001953)");
}

// The flags into the scene; a usage error's text, or empty.
std::string apply(Flags& f, jello::SceneSpec& spec) {
  const auto kind = jello::parseIntegratorName(f.integrator);
  if (!kind) {
    return "unknown integrator '" + f.integrator + "' (known: " + jello::integratorNameList() + ")";
  }
  spec.integrator = *kind;
  if (std::string error = jello::applyContactFlags(f.contact, spec.contact, spec.kCollision);
      !error.empty()) {
    return error;
  }
  f.field = CLI::detail::to_lower(f.field);
  spec.field = kFields.at(f.field);
  spec.pose = kPoses.at(CLI::detail::to_lower(f.pose));
  if (f.noPlane) spec.plane.reset();
  if (!f.plane.empty()) spec.plane = jello::Plane{f.plane[0], f.plane[1], f.plane[2], f.plane[3]};
  if (!f.sphere.empty()) {
    spec.sphere = jello::Sphere{{f.sphere[0], f.sphere[1], f.sphere[2]}, f.sphere[3]};
  }
  if (!f.cone.empty()) {
    const std::vector<double>& c = f.cone;
    spec.cone = jello::Cone{{c[0], c[1], c[2]}, {c[3], c[4], c[5]}, c[6], c[7]};
  }
  if (!f.spiral.empty()) {
    const std::vector<double>& s = f.spiral;
    spec.spiral = jello::Spiral{s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7]};
  }
  if (!f.velocity.empty()) spec.velocity = toVec3(f.velocity);
  if (!f.translate.empty()) spec.translate = toVec3(f.translate);
  if (!f.axis.empty()) spec.rotateAxis = toVec3(f.axis);
  spec.fieldStrength = f.fieldStrength.value_or(jello::defaultFieldStrength(spec.field, spec.mass));
  if (spec.pose == PosePreset::Rotated && jello::maxAbs(spec.rotateAxis) == 0.0) {
    return "--axis must not be zero";
  }
  return "";
}

// Whatever the flags, the file must load: it is read back before it replaces anything.
int write(const jello::World& world, const Flags& f) {
  const std::string text = jello::formatWorld(
      world, f.legacy ? jello::NumberFormat::Legacy : jello::NumberFormat::Exact);
  try {
    (void)jello::parseWorld(text, f.out);
    jello::writeFileAtomically(f.out, text);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "jello-create-world: error: %s\n", e.what());
    return 1;
  }
  std::printf("wrote %s (%d points%s%s%s%s, field %s)\n", f.out.c_str(), world.numPoints(),
              world.plane ? ", plane" : "", world.sphere ? ", sphere" : "",
              world.cone ? ", cone" : "", world.spiral ? ", spiral" : "",
              world.field.resolution
                  ? (f.field + " at " + std::to_string(world.field.resolution) + "^3 nodes").c_str()
                  : "none");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  jello::exitCleanlyWhenOutOfMemory("jello-create-world");
  jello::ignoreBrokenPipes("jello-create-world");
  // A file-size limit fails the write (reported), not the process.
  jello::setSignalHandler("jello-create-world", SIGXFSZ, SIG_IGN);
  jello::SceneSpec spec;
  Flags flags;
  CLI::App app{
      "Writes a jello world file. With no arguments: ./jello.w with the original course "
      "creator's values (RK4, dt 0.0005, k 200, plane -x+y+z+2=0, zero 30^3 field, "
      "skewed corner, velocity (10,-10,20)).",
      "jello-create-world"};
  addConstants(app, spec, flags);
  addSurroundings(app, spec, flags);
  addCube(app, spec, flags);
  try {
    app.parse(argc, argv);
    jello::refuseNonFiniteNumbers(app);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  if (const std::string why = apply(flags, spec); !why.empty()) {
    std::fprintf(stderr, "jello-create-world: error: %s\n", why.c_str());
    return 2;
  }
  return write(jello::buildWorld(spec), flags);
}
