#include "viewer/panel.h"

#include <GL/freeglut.h>
#include <imgui.h>
#include <imgui_impl_glut.h>
#include <imgui_impl_opengl2.h>
#include <imgui_internal.h>  // the window's content extent: are labels cut

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>
#include <string>

#include "viewer/interaction.h"

namespace jello::viewer {

namespace {

// The counter whose per-step growth is the solver's effort, by preference.
constexpr std::array<const char*, 4> kEffortCounters{"newton_iterations", "projective_iterations",
                                                     "rhs_evaluations", "cg_iterations"};

std::optional<double> statistic(const Frame& frame, const char* name) {
  return findStatistic(frame.solver, name);
}

// A combo box over one closed set's table; true when another row was chosen.
template <class Kind, class Name>
bool tableCombo(const char* label, Kind& value, std::span<const Kind> kinds, Name name) {
  bool changed = false;
  if (ImGui::BeginCombo(label, std::string(name(value)).c_str())) {
    for (Kind kind : kinds) {
      const bool selected = kind == value;
      if (ImGui::Selectable(std::string(name(kind)).c_str(), selected) && !selected) {
        value = kind;
        changed = true;
      }
    }
    ImGui::EndCombo();
  }
  return changed;
}

// A slider for a positive constant on a logarithmic scale; true when an edit was finished.
bool logSlider(const char* label, float* value, float lo, float hi, const char* format) {
  ImGui::SliderFloat(label, value, lo, hi, format, ImGuiSliderFlags_Logarithmic);
  return ImGui::IsItemDeactivatedAfterEdit();
}

}  // namespace

void PlotHistory::add(double wallTime, const Frame& frame) {
  if (frame.steps < lastSteps_) clear();  // a reload: time starts over
  const EnergyReport& e = frame.energy;
  double effort = 0.0, effortStep = std::nan("");
  effortName.clear();
  for (const char* name : kEffortCounters) {
    if (std::optional<double> v = statistic(frame, name)) {
      effortName = name;
      effort = *v;
      break;
    }
  }
  const long steps = frame.steps - std::max(lastSteps_, 0L);
  const double perStep = lastSteps_ >= 0 && steps > 0 && effort >= lastEffort_
                             ? (effort - lastEffort_) / static_cast<double>(steps)
                             : 0.0;
  lastSteps_ = frame.steps;
  lastEffort_ = effort;
  if (std::optional<double> h = statistic(frame, "last_step_s")) effortStep = *h;
  const std::array<double, kCount> sample{e.kinetic,
                                          e.spring,
                                          e.contact,
                                          e.field,
                                          e.total(),
                                          norm(frame.angularMomentum),
                                          effortName.empty() ? 0.0 : perStep,
                                          std::isnan(effortStep) ? 0.0 : effortStep};
  wall.push_back(wallTime);
  for (int i = 0; i < kCount; ++i) values[i].push_back(static_cast<float>(sample[i]));
  while (!wall.empty() && wall.front() < wallTime - kWindow) {
    wall.pop_front();
    for (auto& v : values) v.pop_front();
  }
}

void PlotHistory::clear() {
  wall.clear();
  for (auto& v : values) v.clear();
  lastSteps_ = -1;
  lastEffort_ = 0.0;
}

bool ClickLatch::event(int button, bool down, int x, int y) {
  if (button < 0 || button >= 3) return true;
  const auto b = static_cast<std::size_t>(button);
  if (down) {
    pressUnseen_[b] = true;
    return true;
  }
  if (!pressUnseen_[b]) return true;
  held_[b] = true;  // released before a frame saw the press: after the next one
  releases_[b] = {button, x, y};
  return false;
}

std::vector<ClickLatch::Release> ClickLatch::frameSeen() {
  std::vector<Release> out;
  for (std::size_t b = 0; b < 3; ++b) {
    pressUnseen_[b] = false;
    if (held_[b]) out.push_back(releases_[b]);
    held_[b] = false;
  }
  return out;
}

float panelFontPixels(int height, double uiScale) {
  constexpr double kImGuiFont = 13.0, kCourseHeight = 480.0;
  const double grow = std::clamp(double(height) / kCourseHeight, 1.0, 3.0);
  return static_cast<float>(std::max(6.0, std::round(kImGuiFont * grow * uiScale)));
}

Panel::Panel(double uiScale) : uiScale_(uiScale) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left in the user's directory
  ImGui_ImplGLUT_Init();
  ImGui_ImplOpenGL2_Init();
}

// The font at the window's size, its atlas uploaded again, and the spacing scaled alike; the
// style opaque (a translucent combo popup showed the text under it).
void Panel::scaleTo(int height) {
  const float pixels = panelFontPixels(height, uiScale_);
  if (pixels == fontPixels_) return;
  ImGuiIO& io = ImGui::GetIO();
  io.Fonts->Clear();
  ImFontConfig font;
  font.SizePixels = pixels;
  io.Fonts->AddFontDefault(&font);
  ImGui_ImplOpenGL2_DestroyFontsTexture();
  ImGui_ImplOpenGL2_CreateFontsTexture();
  ImGuiStyle& style = ImGui::GetStyle();
  style = ImGuiStyle();
  ImGui::StyleColorsDark(&style);
  style.ScaleAllSizes(pixels / 13.0f);
  style.Colors[ImGuiCol_PopupBg].w = 1.0f;
  style.Colors[ImGuiCol_WindowBg].w = 1.0f;
  fontPixels_ = pixels;
}

Panel::~Panel() {
  ImGui_ImplOpenGL2_Shutdown();
  ImGui_ImplGLUT_Shutdown();
  ImGui::DestroyContext();
}

bool Panel::mouse(int button, int state, int x, int y) {
  if (button == 3 || button == 4) {
    if (state == GLUT_DOWN) ImGui_ImplGLUT_MouseWheelFunc(0, button == 3 ? 1 : -1, x, y);
  } else if (clicks_.event(button, state == GLUT_DOWN, x, y)) {
    ImGui_ImplGLUT_MouseFunc(button, state, x, y);
  }
  // A release always reaches the viewer too, so that its drags end.
  return state == GLUT_DOWN && ImGui::GetIO().WantCaptureMouse;
}

bool Panel::motion(int x, int y) {
  ImGui_ImplGLUT_MotionFunc(x, y);
  return ImGui::GetIO().WantCaptureMouse && ImGui::IsAnyItemActive();
}

void Panel::passiveMotion(int x, int y) {
  ImGui_ImplGLUT_MotionFunc(x, y);
}

bool Panel::key(unsigned char c, int x, int y) {
  ImGui_ImplGLUT_KeyboardFunc(c, x, y);
  return ImGui::GetIO().WantTextInput;
}

void Panel::keyUp(unsigned char c, int x, int y) {
  ImGui_ImplGLUT_KeyboardUpFunc(c, x, y);
}

void Panel::special(int key, int x, int y, bool down) {
  if (down) {
    ImGui_ImplGLUT_SpecialFunc(key, x, y);
  } else {
    ImGui_ImplGLUT_SpecialUpFunc(key, x, y);
  }
}

void Panel::reshape(int w, int h) {
  ImGui_ImplGLUT_ReshapeFunc(w, h);
}

void Panel::syncFromWorld(const Frame& frame) {
  const World& w = frame.geometry->world;
  k_ = static_cast<float>(w.kElastic);
  d_ = static_cast<float>(w.dElastic);
  kCollision_ = static_cast<float>(w.kCollision);
  dCollision_ = static_cast<float>(w.dCollision);
  contact_ = w.contact;
  if (w.contact.layer > 0.0) contactLayer_ = static_cast<float>(w.contact.layer);
  if (w.contact.dhat > 0.0) dhat_ = static_cast<float>(w.contact.dhat);
  kappa_ = static_cast<float>(w.contact.kappa > 0.0 ? w.contact.kappa : w.kCollision);
  mu_ = static_cast<float>(w.contact.mu);
  mass_ = static_cast<float>(w.mass);
  dt_ = static_cast<float>(frame.dt);
  if (w.plane) savedPlane_ = w.plane;
  if (w.sphere) savedSphere_ = w.sphere;
  plane_ = w.plane.has_value();
  sphere_ = w.sphere.has_value();
  generation_ = frame.generation;
}

void Panel::constants(const Frame& frame, SimRunner& runner) {
  const auto edit = [&runner](std::function<void(World&)> change) {
    runner.post([change = std::move(change)](ViewerSession& s) { s.editWorld(change); }, true);
  };
  if (logSlider("k (N/m)", &k_, 1.0f, 1e6f, "%.4g")) {
    edit([k = double(k_)](World& w) { w.kElastic = k; });
  }
  if (logSlider("damping", &d_, 1e-4f, 100.0f, "%.3g")) {
    edit([d = double(d_)](World& w) { w.dElastic = d; });
  }
  if (logSlider("k contact", &kCollision_, 1.0f, 1e6f, "%.4g")) {
    edit([k = double(kCollision_)](World& w) { w.kCollision = k; });
  }
  if (logSlider("d contact", &dCollision_, 1e-4f, 100.0f, "%.3g")) {
    edit([d = double(dCollision_)](World& w) { w.dCollision = d; });
  }
  bool contactChanged = tableCombo("contact", contact_.model, allContactModels(), contactModelName);
  if (contact_.model == ContactModel::Smooth) {
    contactChanged |= logSlider("layer (m)", &contactLayer_, 1e-4f, 0.1f, "%.3g");
  }
  if (contact_.model == ContactModel::Barrier) {
    contactChanged |= logSlider("dhat (m)", &dhat_, 1e-4f, 0.1f, "%.3g");
    contactChanged |= logSlider("kappa (N/m)", &kappa_, 1.0f, 1e6f, "%.4g");
  }
  // Coulomb friction on every solid (0: none, the course's).
  contactChanged |= ImGui::SliderFloat("friction mu", &mu_, 0.0f, 2.0f, "%.2f");
  if (contactChanged) {
    // A barrier asked for with points inside a solid stops the simulation with the reason.
    const bool barrier = contact_.model == ContactModel::Barrier;
    contact_.layer = contact_.model == ContactModel::Smooth ? double(contactLayer_) : 0.0;
    contact_.dhat = barrier ? double(dhat_) : 0.0;
    contact_.kappa = barrier ? double(kappa_) : 0.0;
    contact_.mu = std::max(0.0, double(mu_));  // ctrl-click can type any number
    edit([law = contact_](World& w) { w.contact = law; });
  }
  if (logSlider("mass (kg)", &mass_, 1e-5f, 1.0f, "%.3g")) {
    edit([m = double(mass_)](World& w) { w.mass = m; });
  }
  if (!frame.geometry->arrows.empty() || fieldScale_ != 1.0f) {
    const float before = fieldScale_;
    ImGui::SliderFloat("field x", &fieldScale_, 0.0f, 4.0f, "%.2f");
    if (ImGui::IsItemDeactivatedAfterEdit() && before > 0.0f) {
      edit([ratio = double(fieldScale_) / before](World& w) {
        for (Vec3& f : w.field.forces) f = f * ratio;
      });
    } else if (before == 0.0f) {
      fieldScale_ = 0.0f;  // a field scaled to nothing cannot be scaled back
    }
  }
  if (savedPlane_ && ImGui::Checkbox("inclined plane", &plane_)) {
    edit([p = plane_ ? savedPlane_ : std::nullopt](World& w) { w.plane = p; });
  }
  if (savedSphere_ && ImGui::Checkbox("sphere", &sphere_)) {
    edit([p = sphere_ ? savedSphere_ : std::nullopt](World& w) { w.sphere = p; });
  }
}

// The settings of the running integrator (jello-sim's solver flags), applied by starting it
// afresh with them on the same state: combos and check boxes at once, sliders when released.
// While nothing is being edited, the panel's copy follows the simulation's.
void Panel::solverOptions(const Frame& frame, SimRunner& runner) {
  if (!ImGui::IsAnyItemActive()) {
    options_ = frame.solverOptions;
    newtonTolerance_ = static_cast<float>(options_.implicit.newtonTolerance);
    rtol_ = static_cast<float>(options_.cvode.rtol);
    chebyshevRho_ = static_cast<float>(options_.projective.chebyshevRho);
    seedTolerance_ = static_cast<float>(options_.implicit.seedTolerance);
    seedChebyshevRho_ = static_cast<float>(options_.implicit.seedChebyshevRho);
  }
  SolverOptions& o = options_;
  bool changed = false;
  const auto released = [] { return ImGui::IsItemDeactivatedAfterEdit(); };
  const auto linearSolver = [&](LinearSolverKind& solver, PreconditionerKind& preconditioner) {
    changed |= tableCombo("linear solver", solver, allLinearSolvers(), linearSolverName);
    if (solver == LinearSolverKind::Cg) {
      changed |=
          tableCombo("preconditioner", preconditioner, allPreconditioners(), preconditionerName);
    }
  };
  // The settings of the integrator's family (src/world/integrator_table.h).
  switch (integratorFamily(frame.integrator)) {
    case IntegratorFamily::Newton:
    case IntegratorFamily::Linearized:
      linearSolver(o.implicit.linearSolver, o.implicit.preconditioner);
      if (logSlider("newton tol", &newtonTolerance_, 1e-12f, 1e-2f, "%.1e")) {
        o.implicit.newtonTolerance = newtonTolerance_;
        changed = true;
      }
      ImGui::SliderInt("newton iters", &o.implicit.newtonMaxIterations, 1, 100);
      changed |= released();
      ImGui::SliderInt("newton halvings", &o.implicit.newtonHalvings, 0, 8);
      changed |= released();
      changed |= ImGui::Checkbox("keep factor", &o.implicit.reuseFactor);
      ImGui::SliderInt("seed iterations", &o.implicit.seedIterations, 0, 100);
      changed |= released();
      if (logSlider("seed tol", &seedTolerance_, 1e-12f, 1e-2f, "%.1e")) {
        o.implicit.seedTolerance = seedTolerance_;
        changed = true;
      }
      ImGui::SliderFloat("seed Chebyshev rho", &seedChebyshevRho_, 0.0f, 0.99f, "%.2f");
      o.implicit.seedChebyshevRho = seedChebyshevRho_;
      changed |= released();
      break;
    case IntegratorFamily::Cvode: {
      int method = static_cast<int>(o.cvode.method);
      changed |= ImGui::Combo("method", &method, "bdf\0adams\0");
      o.cvode.method = static_cast<CvodeMethod>(method);
      if (logSlider("rtol", &rtol_, 1e-10f, 1e-1f, "%.1e")) {
        o.cvode.rtol = rtol_;
        changed = true;
      }
      ImGui::SliderInt("max order", &o.cvode.maxOrder, 1, 5);
      changed |= released();
      if (o.cvode.method == CvodeMethod::Bdf) {
        changed |= ImGui::Checkbox("krylov (SPGMR)", &o.cvode.krylov);
        linearSolver(o.cvode.linearSolver, o.cvode.preconditioner);
      }
      changed |= ImGui::Checkbox("contact roots", &o.cvode.contactRoots);
      break;
    }
    case IntegratorFamily::Projective:
      ImGui::SliderInt("iterations", &o.projective.iterations, 1, 200);
      changed |= released();
      ImGui::SliderFloat("Chebyshev rho", &chebyshevRho_, 0.0f, 0.99f, "%.2f");
      o.projective.chebyshevRho = chebyshevRho_;
      changed |= released();
      break;
    case IntegratorFamily::Explicit:
      ImGui::TextUnformatted("(explicit: no solver settings)");
      return;
  }
  if (changed && !frame.divergence) {
    runner.post([kind = frame.integrator,
                 o](ViewerSession& session) { session.simulation().setIntegrator(kind, o); },
                true);
  }
}

std::pair<float, float> plotRange(const std::vector<float>& data, double relativeFloor) {
  if (data.empty()) return {0.0f, 1.0f};
  const auto [lo, hi] = std::minmax_element(data.begin(), data.end());
  const double scale = std::max(std::abs(double(*lo)), std::abs(double(*hi)));
  const double least = std::max(relativeFloor * scale, 1e-12);
  const double mid = 0.5 * (double(*lo) + double(*hi));
  const double half = 0.5 * std::max(double(*hi) - double(*lo), least);
  return {float(mid - half), float(mid + half)};
}

void Panel::plots(const Frame& frame) {
  const auto plot = [&](int series, const char* overlay) {
    const auto& v = history_.values[series];
    if (v.empty()) return;
    std::vector<float> data(v.begin(), v.end());
    char label[96];
    std::snprintf(label, sizeof label, "%s %.4g", overlay, double(data.back()));
    // |L| as its relative change over the window: its round-off (1e-15) is no trend.
    // Relative to the largest |L| in the window, not to the first: a cube thrown without spin
    // starts at |L| ~ 1e-15, and its change over that read 5e14.
    const double largest = *std::max_element(data.begin(), data.end());
    if (series == PlotHistory::AngularMomentum && largest > 0.0) {
      const double first = data.front();
      for (float& x : data) x = float((double(x) - first) / largest);
      std::snprintf(label, sizeof label, "change %.2g", double(data.back()));
    }
    // A span below 1e-6 of the values (1e-6 absolute for a relative change) is drawn flat.
    const bool relative = series == PlotHistory::AngularMomentum;
    const auto [lo, hi] = relative ? plotRange(data, 0.0) : plotRange(data, 1e-6);
    const auto [rlo, rhi] =
        relative && hi - lo < 2e-6f ? std::pair(lo - 1e-6f, hi + 1e-6f) : std::pair(lo, hi);
    const float em = ImGui::GetFontSize();
    ImGui::PlotLines(PlotHistory::kNames[series], data.data(), int(data.size()), 0, label, rlo, rhi,
                     ImVec2(10.0f * em, 2.5f * em));
  };
  for (int s : {PlotHistory::Total, PlotHistory::Kinetic, PlotHistory::Spring, PlotHistory::Contact,
                PlotHistory::Field, PlotHistory::AngularMomentum}) {
    plot(s, "");
  }
  if (!history_.effortName.empty()) plot(PlotHistory::Effort, history_.effortName.c_str());
  if (statistic(frame, "last_step_s")) plot(PlotHistory::StepSize, "");
}

void Panel::prepare(const Frame& frame, ViewerState& view, SimRunner& runner) {
  if (frame.generation != generation_) syncFromWorld(frame);
  scaleTo(int(ImGui::GetIO().DisplaySize.y));
  if (!warmedUp_) {
    // ImGui sizes an auto-fitting window in its first frame and draws it from the second: a
    // pass that is not rendered, so that the first drawn (or recorded) frame has the panel.
    ImGui_ImplOpenGL2_NewFrame();
    ImGui_ImplGLUT_NewFrame();
    build(frame, view, runner);
    ImGui::EndFrame();
    warmedUp_ = true;
  }
  ImGui_ImplOpenGL2_NewFrame();
  ImGui_ImplGLUT_NewFrame();
  build(frame, view, runner);
  ImGui::Render();
}

void Panel::render() {
  ImGui_ImplOpenGL2_RenderDrawData(ImGui::GetDrawData());
  for (const ClickLatch::Release& r : clicks_.frameSeen()) {
    ImGui_ImplGLUT_MouseFunc(r.button, GLUT_UP, r.x, r.y);
    glutPostRedisplay();  // the next frame sees the release: the click
  }
}

void Panel::build(const Frame& frame, ViewerState& view, SimRunner& runner) {
  width_ = 0;
  if (view.showPanel) {
    // A column at the right edge, the window's height (scrolling when taller), as wide as its
    // widest line (a width of 0 asks ImGui to fit it every frame): no label is cut, and the
    // viewer draws the scene beside it.
    const ImVec2 display = ImGui::GetIO().DisplaySize;
    ImGui::SetNextWindowPos(ImVec2(display.x, 0.0f), ImGuiCond_Always, ImVec2(1.0f, 0.0f));
    ImGui::SetNextWindowSize(ImVec2(0.0f, display.y), ImGuiCond_Always);
    ImGui::Begin("panel (m hides)", &view.showPanel,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    const float em = ImGui::GetFontSize();
    ImGui::PushItemWidth(10.0f * em);
    // Integrator and time step.
    IntegratorKind kind = frame.integrator;
    if (tableCombo("integrator", kind, allIntegrators(), integratorName) && !frame.divergence) {
      runner.post([kind](ViewerSession& s) { s.simulation().setIntegrator(kind); }, true);
    }
    if (std::abs(dt_ - float(frame.dt)) > 1e-9f * float(frame.dt) && !ImGui::IsAnyItemActive())
      dt_ = static_cast<float>(frame.dt);
    if (logSlider("dt (s)", &dt_, 1e-6f, 0.1f, "%.3g")) {
      runner.post([dt = double(dt_)](ViewerSession& s) { s.setTimeStep(dt); }, true);
    }
    float speed = static_cast<float>(view.speed);
    if (ImGui::SliderFloat("speed", &speed, float(kMinSpeed), float(kMaxSpeed), "%.4gx",
                           ImGuiSliderFlags_Logarithmic)) {
      view.speed = speed;
      runner.setSpeed(view.speed);
    }
    ImGui::Text("t %.3f s  %ld steps", frame.state.t, frame.steps);
    if (frame.divergence) {
      ImGui::TextColored(ImVec4(1.0f, 0.35f, 0.3f, 1.0f), "diverged (r reloads)");
    } else if (frame.paused) {
      ImGui::Text("paused");
    } else {
      ImGui::Text("%.3g simulated s per wall s%s", frame.simRate, frame.lagging ? " (behind)" : "");
    }
    if (ImGui::CollapsingHeader("solver")) solverOptions(frame, runner);
    if (ImGui::CollapsingHeader("world")) constants(frame, runner);
    if (ImGui::CollapsingHeader("pull")) {
      ImGui::Checkbox("pull mode (g)", &view.pullMode);
      ImGui::SliderInt("radius ([ ])", &view.pullRadius, 0, int(pullRadii().size()) - 1,
                       pullRadii()[std::size_t(view.pullRadius)] == 0.0        ? "one point"
                       : std::isinf(pullRadii()[std::size_t(view.pullRadius)]) ? "whole cube"
                                                                               : "%d");
      if (logSlider("stiffness x k", &pullScale_, 0.01f, 100.0f, "%.3g")) {
        runner.post(
            [s = double(pullScale_)](ViewerSession& session) { session.setPullStiffnessScale(s); });
      }
    }
    if (ImGui::CollapsingHeader("plots", ImGuiTreeNodeFlags_DefaultOpen)) plots(frame);
    if (ImGui::CollapsingHeader("solver statistics")) {
      for (const Statistic& s : frame.solver) ImGui::Text("%-28s %.6g", s.name.c_str(), s.value);
      if (frame.solver.empty()) ImGui::TextUnformatted("(none: an explicit integrator)");
    }
    ImGui::PopItemWidth();
    const ImGuiWindow* window = ImGui::GetCurrentWindow();
    labelsCut_ = window->DC.CursorMaxPos.x > window->WorkRect.Max.x + 0.5f;
    width_ = view.showPanel ? int(std::ceil(ImGui::GetWindowWidth())) : 0;
    ImGui::End();
  }
}

}  // namespace jello::viewer
