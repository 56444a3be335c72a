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

}  // namespace

int main(int argc, char** argv) {
  jello::exitCleanlyWhenOutOfMemory("jello-create-world");
  jello::ignoreBrokenPipes("jello-create-world");
  // A file-size limit fails the write (reported), not the process.
  jello::setSignalHandler("jello-create-world", SIGXFSZ, SIG_IGN);
  jello::SceneSpec spec;
  std::string out = "jello.w";
  std::string integrator = "rk4";
  std::vector<double> plane, sphere, cone, spiral, velocity, translate, axis;
  std::optional<double> fieldStrength;
  bool noPlane = false, legacy = false;

  CLI::App app{
      "Writes a jello world file. With no arguments: ./jello.w with the original course "
      "creator's values (RK4, dt 0.0005, k 200, plane -x+y+z+2=0, zero 30^3 field, "
      "skewed corner, velocity (10,-10,20)).",
      "jello-create-world"};
  app.add_option("-o,--output", out, "File to write (default jello.w)");
  app.add_option("--integrator", integrator, "Integrator: " + jello::integratorNameList())
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
  app.add_option("--mass", spec.mass, "Mass of each point, kg (default 1/512)")
      ->check(jello::cli::positive());
  auto* planeOpt = app.add_option("--plane", plane,
                                  "Inclined plane A B C D: Ax+By+Cz+D=0, "
                                  "free where positive (default -1 1 1 2)")
                       ->expected(4);
  app.add_flag("--no-plane", noPlane, "No inclined plane")->excludes(planeOpt);

  const std::map<std::string, FieldPreset> fields{{"none", FieldPreset::None},
                                                  {"gravity", FieldPreset::Gravity},
                                                  {"vortex", FieldPreset::Vortex},
                                                  {"radial", FieldPreset::Radial}};
  std::string field = "none", pose = "skewed";
  app.add_option("--field", field,
                 "Force field: none (zero), gravity F=(0,0,-s), vortex F=s(-y,x,0), "
                 "radial F=-s(x,y,z)")
      ->check(CLI::IsMember(fields, CLI::ignore_case))
      ->capture_default_str();
  app.add_option("--field-strength", fieldStrength,
                 "s above; default: gravity 9.81*mass N, vortex 5*mass N/m (rotate.w), "
                 "radial 25*mass N/m");
  app.add_option("--field-resolution", spec.fieldResolution,
                 "Field nodes per axis, 2..128, or 0 for no field (default 30)")
      ->check(jello::cli::range(0, 128));

  const std::map<std::string, PosePreset> poses{{"rest", PosePreset::Rest},
                                                {"skewed", PosePreset::SkewedCorner},
                                                {"stretched", PosePreset::Stretched},
                                                {"rotated", PosePreset::Rotated},
                                                {"translated", PosePreset::Translated}};
  app.add_option("--pose", pose,
                 "Initial pose: rest, skewed (far corner out by one spacing), stretched, "
                 "rotated, translated")
      ->check(CLI::IsMember(poses, CLI::ignore_case))
      ->capture_default_str();
  app.add_option("--stretch", spec.stretch, "Stretch factor along x for --pose stretched")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--rotate", spec.rotateDegrees, "Angle, degrees, for --pose rotated")
      ->capture_default_str();
  app.add_option("--axis", axis, "Rotation axis X Y Z for --pose rotated (default 1 1 1)")
      ->expected(3);
  app.add_option("--translate", translate,
                 "Offset X Y Z, m, for --pose translated "
                 "(default 0.5 0.5 0.5)")
      ->expected(3);
  app.add_option("--velocity", velocity,
                 "Uniform initial velocity VX VY VZ, m/s "
                 "(default 10 -10 20)")
      ->expected(3);
  app.add_option("--spin", spec.spin,
                 "Initial spin about the vertical axis through the cube's centre, rad/s");
  app.add_option("--sphere", sphere, "Sphere obstacle CX CY CZ R (an extension)")->expected(4);
  app.add_option("--cone", cone,
                 "Cone obstacle: apex AX AY AZ, axis DX DY DZ (apex to base), height H, base "
                 "radius R (an extension)")
      ->expected(8);
  app.add_option("--spiral", spiral,
                 "Spiral ramp obstacle: axis CX CY, top height Z, radii RIN ROUT, pitch P (m per "
                 "turn), turns T, thickness W (an extension)")
      ->expected(8);
  app.add_option("--cube", spec.cubeResolution,
                 "Cube resolution N: N^3 points (default 8; other values are an extension)")
      ->check(jello::cli::range(2, 64));
  app.add_flag("--legacy", legacy,
               "Print six decimals like the original creator (not exact: 1/512 becomes "
               "0.001953)");
  try {
    app.parse(argc, argv);
    jello::refuseNonFiniteNumbers(app);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  const auto kind = jello::parseIntegratorName(integrator);
  if (!kind) {
    std::fprintf(stderr, "jello-create-world: error: unknown integrator '%s' (known: %s)\n",
                 integrator.c_str(), jello::integratorNameList().c_str());
    return 2;
  }
  spec.integrator = *kind;
  field = CLI::detail::to_lower(field);
  spec.field = fields.at(field);
  spec.pose = poses.at(CLI::detail::to_lower(pose));
  if (noPlane) spec.plane.reset();
  if (!plane.empty()) spec.plane = jello::Plane{plane[0], plane[1], plane[2], plane[3]};
  if (!sphere.empty()) spec.sphere = jello::Sphere{{sphere[0], sphere[1], sphere[2]}, sphere[3]};
  if (!cone.empty()) {
    spec.cone =
        jello::Cone{{cone[0], cone[1], cone[2]}, {cone[3], cone[4], cone[5]}, cone[6], cone[7]};
  }
  if (!spiral.empty()) {
    spec.spiral = jello::Spiral{spiral[0], spiral[1], spiral[2], spiral[3],
                                spiral[4], spiral[5], spiral[6], spiral[7]};
  }
  if (!velocity.empty()) spec.velocity = toVec3(velocity);
  if (!translate.empty()) spec.translate = toVec3(translate);
  if (!axis.empty()) spec.rotateAxis = toVec3(axis);
  spec.fieldStrength = fieldStrength.value_or(jello::defaultFieldStrength(spec.field, spec.mass));
  if (spec.pose == PosePreset::Rotated && jello::maxAbs(spec.rotateAxis) == 0.0) {
    std::fprintf(stderr, "jello-create-world: error: --axis must not be zero\n");
    return 2;
  }

  const jello::World world = jello::buildWorld(spec);
  const std::string text =
      jello::formatWorld(world, legacy ? jello::NumberFormat::Legacy : jello::NumberFormat::Exact);
  try {
    // Whatever the flags, the file must load: check it before it replaces anything.
    (void)jello::parseWorld(text, out);
    jello::writeFileAtomically(out, text);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "jello-create-world: error: %s\n", e.what());
    return 1;
  }
  std::printf("wrote %s (%d points%s%s%s%s, field %s)\n", out.c_str(), world.numPoints(),
              world.plane ? ", plane" : "", world.sphere ? ", sphere" : "",
              world.cone ? ", cone" : "", world.spiral ? ", spiral" : "",
              world.field.resolution
                  ? (field + " at " + std::to_string(world.field.resolution) + "^3 nodes").c_str()
                  : "none");
  return 0;
}
