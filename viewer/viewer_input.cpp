#include <GL/freeglut.h>

#include <iostream>

#include "viewer/interaction.h"
#include "viewer/viewer_window.h"

namespace jello::viewer::window {

// Long: a switch with one case per command.
void Viewer::key(unsigned char key) {
  if (panel_.key(key, lastX_, lastY_)) return glutPostRedisplay();  // typing into the panel
  const KeyResult result = handleKey(view_, key);
  if (key == 'f' && view_.showField && primary().geometry->arrows.empty()) {
    notify(primary().geometry->world.contact.mu > 0.0
               ? "this world has no force field: only friction's arrows (orange) are drawn"
               : "this world has no force field (or it is zero everywhere): no arrows to draw",
           false);
  }
  switch (result.command) {
    case Command::Quit:
      return leave(0);
    case Command::Screenshot:
      screenshotPending_ = true;
      break;
    case Command::Reload: {
      const std::string file = options_.source.world.string();
      forEachRunner([&](SimRunner& r) {
        r.post(
            [&r, file](ViewerSession& s) {
              if (std::optional<std::string> error = s.reload()) {
                r.notify({"reload failed, scene kept: " + *error, true});
              } else {
                r.notify({"reloaded " + file, false});
              }
            },
            true);
      });
      view_.dtScale = 1.0;
      view_.paused = false;
      forEachRunner([](SimRunner& r) { r.setPaused(false); });
      if (group_) {  // a reload is quick: wait for it, and start the shared clock over
        forEachRunner([](SimRunner& r) { r.sync(); });
        group_->setTarget(runner().frame().state.t);
        group_->setPaused(false);
      }
      drag_ = Drag::None;
      break;
    }
    case Command::SwitchIntegrator:
    case Command::NextIntegrator: {
      if (group_) {
        notify("compare mode: the integrators are the --compare list", true);
        break;
      }
      if (primary().divergence) {
        notify("the simulation diverged" + restartHint(), true);
        break;
      }
      const IntegratorKind kind =
          result.integrator ? *result.integrator : nextIntegrator(primary().integrator);
      runner().post([kind](ViewerSession& s) { s.simulation().setIntegrator(kind); }, true);
      notify("integrator " + std::string(integratorName(kind)), false);
      break;
    }
    case Command::TimeStep:
      postAll([scale = view_.dtScale](ViewerSession& s) { s.scaleTimeStep(scale); }, true);
      notify("time step x" + format("%.4g", view_.dtScale) + " of the world's", false);
      break;
    case Command::PullRadius:
      notify("pull radius " + pullRadiusText(pullRadius()), false);
      break;
    case Command::StepOnce:
      if (view_.paused && group_) group_->advanceBy(primary().geometry->frameTime);
      if (view_.paused && !group_) runner().stepFrame();
      break;
    case Command::Pause:
      if (group_) {
        group_->setPaused(view_.paused);
      } else {
        runner().setPaused(view_.paused);
      }
      break;
    case Command::Speed:
      if (group_) {
        group_->setSpeed(view_.speed);
      } else {
        runner().setSpeed(view_.speed);
      }
      notify("playback speed " + format("%.4g", view_.speed) + "x" +
                 (options_.courseTime ? " (ignored in course time)" : ""),
             false);
      break;
    case Command::SaveWorld:
      runner().post([&r = runner(), pane = group_ ? " (the first pane's)" : ""](ViewerSession& s) {
        const std::optional<std::string> name = freeName("jello-%03d.w");
        if (!name) throw std::runtime_error("jello-000.w ... jello-999.w all exist: not saved");
        s.save(*name);
        r.notify({std::string("saved the current state") + pane + " as " + *name, false});
      });
      break;
    case Command::None:
      break;
  }
  glutPostRedisplay();
}

void Viewer::mouse(int button, int state, int x, int y) {
  if (view_.showPanel && panel_.mouse(button, state, x, y)) return glutPostRedisplay();
  lastX_ = pressX_ = x;
  lastY_ = pressY_ = y;
  if (button == 3 || button == 4) {  // freeglut reports the wheel as buttons 3 and 4
    if (state == GLUT_DOWN) view_.camera.zoomBy(button == 3 ? 0.9 : 1.0 / 0.9, view_.focus);
    return glutPostRedisplay();
  }
  if (state == GLUT_UP) {
    if (drag_ == Drag::Push || drag_ == Drag::Pull) {
      postAll([](ViewerSession& s) { s.release(); });
    }
    drag_ = Drag::None;
    return;
  }
  if (button == GLUT_RIGHT_BUTTON) {
    drag_ = Drag::Rotate;
  } else if (button == GLUT_MIDDLE_BUTTON) {
    drag_ = Drag::Pan;
  } else if (button == GLUT_LEFT_BUTTON) {
    const bool pull = view_.pullMode || (glutGetModifiers() & GLUT_ACTIVE_SHIFT);
    if (!pull) {
      drag_ = Drag::Push;
      pushAccel_ = {};
    } else {
      // The pane under the cursor picks; every pane's cube is pulled at the same point.
      const std::vector<Pane> panes = paneLayout(int(runnerCount()), viewport_);
      const std::optional<PanePixel> at =
          group_ ? paneAt(panes, viewport_, x, y) : PanePixel{0, double(x), double(y)};
      if (!at) return;
      dragPane_ = group_ ? panes[std::size_t(at->pane)].size : sceneViewport();
      dragOffsetX_ = x - at->x;
      dragOffsetY_ = y - at->y;
      const Frame& f = frames_[std::size_t(at->pane)];
      if (auto p = pickPoint(view_.camera, dragPane_, f.geometry->mesh, f.state, at->x, at->y)) {
        drag_ = Drag::Pull;
        anchor_ = f.state.position(*p);
        postAll([p = *p, anchor = anchor_, r = pullRadius()](ViewerSession& s) {
          s.pull(p, anchor, r);
        });
      }
    }
  }
}

void Viewer::motion(int x, int y) {
  if (view_.showPanel && drag_ == Drag::None && panel_.motion(x, y)) return glutPostRedisplay();
  if (drag_ == Drag::Rotate) view_.camera.rotate(x - lastX_, y - lastY_);
  if (drag_ == Drag::Pan) view_.camera.pan(x - lastX_, y - lastY_, viewport_.height);
  lastX_ = x;
  lastY_ = y;
  if (drag_ == Drag::Push) {
    Vec3 a = screenDragToWorld(view_.camera, x - pressX_, y - pressY_) * kPushPerPixel;
    if (norm(a) > kMaxPullAcceleration) a = a * (kMaxPullAcceleration / norm(a));
    pushAccel_ = a;
    postAll([a](ViewerSession& s) { s.push(a); });
  } else if (drag_ == Drag::Pull) {
    const Vec3 target =
        dragTarget(view_.camera, dragPane_, x - dragOffsetX_, y - dragOffsetY_, anchor_);
    postAll([target, r = pullRadius()](ViewerSession& s) {
      if (auto pulled = s.pulling()) s.pull(pulled->first, target, r);
    });
  }
  glutPostRedisplay();
}

}  // namespace jello::viewer::window
