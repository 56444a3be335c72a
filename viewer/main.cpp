// jello: the interactive viewer.
//   jello [WORLD] [--integrator NAME | --compare A,B,...] [--dt S] [--speed X | --course-time]
//         [--record DIR --frames N] [--size WxH]
// Exit codes: 0 done, 1 runtime failure (no display, a frame not written), 2 bad arguments or
// world file, 3 the simulation diverged while recording or benchmarking.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <regex>
#include <sstream>

#include "solvers/linalg/solver_threads.h"
#include "src/base/finite_options.h"
#include "src/base/out_of_memory.h"
#include "src/base/parallel.h"
#include "src/model.h"
#include "src/world/world_reader.h"
#include "viewer/texture.h"
#include "viewer/video_writer.h"
#include "viewer/viewer_app.h"
#include "viewer/viewer_state.h"

namespace {

constexpr int kExitUsage = 2;

// worlds/jello.w from the current directory, else from the source tree this was built from.
std::filesystem::path defaultWorld() {
  const std::filesystem::path local = "worlds/jello.w";
  if (std::filesystem::exists(local)) return local;
  return std::filesystem::path(JELLO_WORLDS_DIR) / "jello.w";
}

// The options that are not a ViewerOptions field as they stand.
struct Args {
  std::string world = defaultWorld().string(), integrator, size, compare, compareDt = "auto";
  bool panel = false, noPanel = false;
};

void addOptions(CLI::App& app, jello::viewer::ViewerOptions& opt, Args& args) {
  app.add_option("world", args.world, "World file")->capture_default_str();
  app.add_option("--integrator", args.integrator,
                 "Integrator, overriding the file's: " + jello::integratorNameList());
  app.add_option("--dt", opt.source.dt, "Time step (s), overriding the file's")
      ->check(jello::cli::positive());
  auto* record = app.add_option("--record", opt.recordDir,
                                "Write frames 000.jpg, 001.jpg, ... into this directory and exit")
                     ->check(CLI::Validator(
                         [](const std::string& dir) {
                           return dir.empty() ? std::string("the recording directory is empty")
                                              : std::string();
                         },
                         "DIR", "non-empty"));
  auto* video =
      app.add_option("--record-video", opt.recordVideo,
                     "Encode the recorded frames into this video with ffmpeg (.mp4: H.264, .webm: "
                     "VP8; 15 frames/s) and exit; with --record, the JPEGs too")
          ->check(CLI::Validator(
              [](const std::string& file) { return jello::viewer::VideoWriter::problem(file); },
              "FILE"));
  app.add_option("--frames", opt.frames,
                 "Number of frames to record (1-300: 15 per second; needs --record or "
                 "--record-video)")
      ->check(jello::cli::range(1, jello::viewer::kMaxRecordedFrames));
  record->needs("--frames");
  video->needs("--frames");
  app.add_option("--compare", args.compare,
                 "Run these integrators (2-6, comma-separated, e.g. rk4,implicit) side by side in "
                 "split panes, at one shared simulated time")
      ->excludes("--integrator");
  app.add_option("--compare-dt", args.compareDt,
                 "Each pane's time step: auto (explicit methods at 0.9 of their predicted "
                 "stability limit, the others at 1/60 s, said in each pane) or same (the world's, "
                 "or --dt's)")
      ->check(CLI::IsMember({"auto", "same"}))
      ->needs("--compare")
      ->capture_default_str();
  app.add_option("--size", args.size,
                 "Window size WxH in pixels (default 640x480; interactively with the panel, "
                 "wider by the panel's column, so the scene keeps 640x480 beside it)");
  app.add_option("--ui-scale", opt.uiScale,
                 "The panel's text and spacing, times the scale it takes from the window's "
                 "height (13 px text up to 480 px high, growing with it)")
      ->check(jello::cli::range(0.5, 4.0))
      ->capture_default_str();
  app.add_option("--speed", opt.speed,
                 "Playback speed: simulated seconds per wall second (also of a recording: "
                 "15 frames per speed simulated seconds)")
      ->check(jello::cli::range(jello::viewer::kMinSpeed, jello::viewer::kMaxSpeed))
      ->capture_default_str();
  app.add_flag("--course-time", opt.courseTime,
               "The original pacing: each displayed (or recorded) frame advances the world's n*dt");
  app.add_flag("--panel", args.panel,
               "Show the panel in recordings too (it is shown interactively)");
  app.add_flag("--no-panel", args.noPanel, "Start with the panel hidden (key m shows it)")
      ->excludes("--panel");
  app.add_flag("--wireframe", opt.wireframe, "Start in wireframe mode");
  app.add_flag("--field", opt.field, "Start with the force-field arrows shown (key f)");
  app.add_flag("--follow", opt.follow,
               "Start with the camera following the cube, closer in (key c toggles)");
  app.add_option("--texture", opt.texture,
                 "Texture the shaded cube from the start with this image (JPEG or PNG), or with "
                 "'builtin' (key t toggles; without it, t shows the built-in texture)");
  app.add_flag("!--no-hud", opt.hud, "Hide the heads-up line");
  app.add_option("--benchmark", opt.benchmarkFrames,
                 "Draw this many frames as fast as possible, print frames/s and exit")
      ->check(jello::cli::positive())
      ->excludes(record)
      ->excludes(video);
  app.add_option("--max-field-resolution", opt.source.limits.maxFieldResolution,
                 "Largest force-field resolution a world may ask for")
      ->check(jello::cli::range(2, 1024))
      ->capture_default_str();
  app.add_option("--max-cube-resolution", opt.source.limits.maxCubeResolution,
                 "Largest cube resolution a world may ask for")
      ->check(jello::cli::range(2, 256))
      ->capture_default_str();
}

// The --compare list into opt; a usage error's text, or empty.
std::string applyCompare(const std::string& compare, jello::viewer::ViewerOptions& opt) {
  std::stringstream list(compare);
  for (std::string name; std::getline(list, name, ',');) {
    const std::optional<jello::IntegratorKind> kind = jello::parseIntegratorName(name);
    if (!kind) {
      return "--compare: unknown integrator '" + name + "' (known: " + jello::integratorNameList() +
             ")";
    }
    opt.compare.push_back(*kind);
  }
  if (opt.compare.size() < 2 || opt.compare.size() > 6) {
    return "--compare wants 2 to 6 integrators, e.g. rk4,implicit, not '" + compare + "'";
  }
  return "";
}

// The options that need more than a check of their own into opt; a usage error's text, or empty.
std::string apply(const Args& args, jello::viewer::ViewerOptions& opt) {
  std::smatch m;
  static const std::regex sizePattern(R"((\d{2,5})x(\d{2,5}))");
  opt.sizeGiven = !args.size.empty();
  const std::string size = opt.sizeGiven ? args.size : "640x480";
  if (!std::regex_match(size, m, sizePattern)) {
    return "--size wants WxH in pixels, e.g. 640x480, not '" + args.size + "'";
  }
  opt.size = {std::stoi(m[1]), std::stoi(m[2])};
  if (opt.size.width < 16 || opt.size.height < 16 || opt.size.width > 8192 ||
      opt.size.height > 8192) {
    return "--size must be between 16x16 and 8192x8192";
  }
  if (!args.integrator.empty()) {
    opt.source.integrator = jello::parseIntegratorName(args.integrator);
    if (!opt.source.integrator) {
      return "unknown integrator '" + args.integrator + "' (known: " + jello::integratorNameList() +
             ")";
    }
  }
  if (args.panel || args.noPanel) opt.panel = args.panel;
  if (opt.frames > 0 && opt.recordDir.empty() && opt.recordVideo.empty()) {
    return "--frames needs --record DIR or --record-video FILE";
  }
  if (!opt.texture.empty() && opt.texture != "builtin") {
    try {
      (void)jello::viewer::loadTexture(opt.texture);
    } catch (const std::exception& e) {
      return std::string("--texture: ") + e.what();
    }
  }
  opt.compareSameStep = args.compareDt == "same";
  if (!args.compare.empty()) return applyCompare(args.compare, opt);
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  jello::exitCleanlyWhenOutOfMemory("jello");
  jello::applySolverThreadSettings();
  jello::leaveOneCpuFree();  // the drawing thread's (src/base/parallel.h)
  jello::viewer::ViewerOptions opt;
  Args args;
  CLI::App app{"jello: the interactive jello cube (OpenGL/GLUT viewer)"};
  app.footer("\nKeys and mouse:\n" + jello::viewer::keyTable() +
             "\nExit codes: 0 done, 1 no display or a frame not written, 2 bad arguments or world, "
             "3 diverged while recording.");
  addOptions(app, opt, args);
  try {
    app.parse(argc, argv);
    jello::refuseNonFiniteNumbers(app);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : kExitUsage;
  }
  const auto usageError = [&](const std::string& message) {
    std::cerr << "jello: error: " << message << "\n\n" << app.help();
    return kExitUsage;
  };
  if (const std::string why = apply(args, opt); !why.empty()) return usageError(why);
  opt.source.world = args.world;
  // With --integrator, a file naming an integrator we do not have still loads (with a warning).
  opt.source.limits.acceptUnknownIntegrator = opt.source.integrator.has_value();
  jello::World loaded;
  try {
    loaded = jello::readWorld(opt.source.world, opt.source.limits);
    jello::checkStart(loaded, opt.source.world.string());
  } catch (const std::exception& e) {
    return usageError(e.what());
  }
  if (!loaded.unknownIntegrator.empty()) {
    std::fprintf(stderr,
                 "jello: warning: %s names the integrator '%s', unknown here; stepping "
                 "with --integrator %s\n",
                 args.world.c_str(), loaded.unknownIntegrator.c_str(), args.integrator.c_str());
  }
  return jello::viewer::runViewer(opt, std::move(loaded));
}
