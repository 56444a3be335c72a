#include "viewer/viewer_state.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "viewer/interaction.h"

namespace jello::viewer {

// Long: a switch with one case per key.
KeyResult handleKey(ViewerState& s, unsigned char key) {
  const auto integrators = allIntegrators();
  // Keys 1-9, then 0 for the tenth; n steps through all of them (and the panel lists them).
  const std::size_t index = key == '0' ? 9 : static_cast<std::size_t>(key - '1');
  if (key >= '0' && key <= '9' && index < integrators.size()) {
    return {Command::SwitchIntegrator, integrators[index]};
  }
  switch (key) {
    case 27:
      return {Command::Quit, {}};
    case ' ':
      return {Command::Screenshot, {}};
    case 'r':
      return {Command::Reload, {}};
    case 'n':
      return {Command::NextIntegrator, {}};
    case 'e':
      s.camera = Camera{};
      break;
    case 'c':  // following brings the camera in to frame the cube (it stays where it is after)
      s.follow = !s.follow;
      if (s.follow) s.camera.radius = std::min(s.camera.radius, kFollowRadius);
      s.camera.keepAboveFloor();
      break;
    case 'z':
      s.camera.zoomBy(0.9, s.focus);  // 10% per press, as one wheel notch, towards the cube
      break;
    case 'x':
      s.camera.zoomBy(1.0 / 0.9);
      break;
    case 'v':
      s.mode = s.mode == DisplayMode::Shaded ? DisplayMode::Wireframe : DisplayMode::Shaded;
      break;
    case 's':
      s.structural = !s.structural;
      break;
    case 'h':
      s.shear = !s.shear;
      break;
    case 'b':
      s.bend = !s.bend;
      break;
    case 'p':
      s.paused = !s.paused;
      return {Command::Pause, {}};
    case '<':
      s.speed = std::max(kMinSpeed, s.speed * 0.5);
      return {Command::Speed, {}};
    case '>':
      s.speed = std::min(kMaxSpeed, s.speed * 2.0);
      return {Command::Speed, {}};
    case 'w':
      return {Command::SaveWorld, {}};
    case 'm':
      s.showPanel = !s.showPanel;
      break;
    case '?':
      s.showHelp = !s.showHelp;
      break;
    case 't':
      s.texture = !s.texture;
      break;
    case 'f':
      s.showField = !s.showField;
      break;
    case 'i':
      s.showHud = !s.showHud;
      break;
    case 'g':
      s.pullMode = !s.pullMode;
      break;
    case '[':
      s.pullRadius = std::max(0, s.pullRadius - 1);
      return {Command::PullRadius, {}};
    case ']':
      s.pullRadius = std::min(int(pullRadii().size()) - 1, s.pullRadius + 1);
      return {Command::PullRadius, {}};
    case '+':
    case '=':
      s.dtScale *= 2.0;
      return {Command::TimeStep, {}};
    case '-':
      s.dtScale *= 0.5;
      return {Command::TimeStep, {}};
    case '.':
      return {Command::StepOnce, {}};
    default:
      break;
  }
  return {};
}

IntegratorKind nextIntegrator(IntegratorKind kind) {
  const auto all = allIntegrators();
  const auto at = std::find(all.begin(), all.end(), kind);
  return at == all.end() || at + 1 == all.end() ? all.front() : *(at + 1);
}

namespace {

// "1-9, 0", "integrator: 1 euler, 2 symplectic, ... (same state)", from the integrator table:
// the first ten have a number key each, n steps through all.
KeyBinding integratorKeys() {
  const auto integrators = allIntegrators();
  std::string action = "integrator:";
  for (std::size_t i = 0; i < std::min<std::size_t>(integrators.size(), 10); ++i) {
    action += (i ? ", " : " ") + std::to_string((i + 1) % 10) + " " +
              std::string(integratorName(integrators[i]));
  }
  const std::string keys =
      integrators.size() <= 9 ? "1-" + std::to_string(integrators.size()) : std::string("1-9, 0");
  return {keys, action + " (same state)"};
}

}  // namespace

std::span<const KeyBinding> keyBindings() {
  static const std::vector<KeyBinding> table{
      {"right-drag", "rotate the camera"},
      {"left-drag", "push the whole cube in the dragged direction"},
      {"Shift+left-drag", "pull the surface point under the cursor (also left-drag in pull mode)"},
      {"g", "pull mode on/off"},
      {"[ ]", "pull radius smaller/larger: one point ... the whole cube"},
      {"z x, wheel", "zoom in/out"},
      {"middle-drag", "pan the camera"},
      {"e", "reset the camera"},
      {"c", "camera follows the cube on/off (--follow)"},
      {"v", "wireframe/shaded"},
      {"t", "texture on the shaded cube on/off (--texture FILE, else a built-in one)"},
      {"s h b", "wireframe: structural, shear, bend springs on/off"},
      {"p", "pause/resume"},
      {".", "advance one frame (the world's n*dt) while paused"},
      {"< >", "playback speed /2, x2 (simulated seconds per wall second)"},
      integratorKeys(),
      {"n", "next integrator in the table (all of them; the panel lists them too)"},
      {"+ -", "time step x2, /2 (playback speed unchanged)"},
      {"r", "reload the world file (a bad file keeps the running scene)"},
      {"f", "force-field arrows on/off"},
      {"i", "heads-up line on/off"},
      {"m", "panel on/off (constants, integrator, live plots)"},
      {"?", "this key table on screen"},
      {"w", "save the current state as a world file (jello-NNN.w)"},
      {"space", "save a screenshot (jello-NNN.jpg in the current directory)"},
      {"ESC", "quit"},
  };
  return table;
}

std::string keyTable() {
  std::ostringstream os;
  for (const KeyBinding& k : keyBindings()) {
    os << "  " << k.keys << std::string(18 - k.keys.size(), ' ') << k.action << '\n';
  }
  return os.str();
}

std::vector<std::string> wrapText(const std::string& text, std::size_t width, std::size_t hanging) {
  std::vector<std::string> lines;
  hanging = std::min(hanging, width / 2);
  std::size_t start = 0;
  bool continued = false;  // this line goes on from the one before
  while (start < text.size()) {
    const std::size_t room = continued ? width - hanging : width;
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    if (end - start > room) {
      std::size_t space = text.rfind(' ', start + room);
      // Never after a lone number: "7 midpoint" is one entry of the key table.
      while (space != std::string::npos && space > start) {
        const std::size_t word = text.rfind(' ', space - 1);
        const std::size_t from = word == std::string::npos || word < start ? start : word + 1;
        const std::string token = text.substr(from, space - from);
        const bool number =
            !token.empty() && token.size() <= 2 &&
            std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; });
        if (!number || from == start) break;
        space = from - 1;
      }
      end = space != std::string::npos && space > start ? space : start + room;
    }
    lines.push_back((continued ? std::string(hanging, ' ') : std::string()) +
                    text.substr(start, end - start));
    continued = end < text.size() && text[end] != '\n';
    start = end < text.size() && (text[end] == '\n' || text[end] == ' ') ? end + 1 : end;
  }
  return lines;
}

std::string pullRadiusText(double radius) {
  if (radius == 0.0) return "one point";
  if (std::isinf(radius)) return "whole cube";
  char text[32];
  std::snprintf(text, sizeof text, "%.2g m", radius);
  return text;
}

int stepsPerFrame(double frameTime, double dt) {
  const double steps = std::round(frameTime / dt);
  return steps < 1.0 ? 1 : steps > 1e6 ? 1000000 : int(steps);
}

std::vector<Pane> paneLayout(int count, const Viewport& window) {
  count = std::max(count, 1);
  const int rows = count <= 3 ? 1 : 2, columns = (count + rows - 1) / rows;
  const int w = std::max(1, window.width / columns), h = std::max(1, window.height / rows);
  std::vector<Pane> panes;
  for (int i = 0; i < count; ++i) {
    const int row = i / columns, column = i % columns;
    panes.push_back({column * w, window.height - (row + 1) * h, {w, h}});
  }
  return panes;
}

std::optional<PanePixel> paneAt(const std::vector<Pane>& panes, const Viewport& window, double x,
                                double y) {
  for (std::size_t i = 0; i < panes.size(); ++i) {
    const Pane& p = panes[i];
    const double top = window.height - (p.y + p.size.height);  // the pane's top row, y down
    if (x >= p.x && x < p.x + p.size.width && y >= top && y < top + p.size.height) {
      return PanePixel{static_cast<int>(i), x - p.x, y - top};
    }
  }
  return std::nullopt;
}

double recordedFrameSpan(double speed, bool courseTime, double courseFrameTime) {
  return courseTime ? courseFrameTime : speed / kRecordedFramesPerSecond;
}

}  // namespace jello::viewer
