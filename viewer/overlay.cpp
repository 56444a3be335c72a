#include "viewer/overlay.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

// glWindowPos (GL 1.4) is declared only with the extension prototypes.
#define GL_GLEXT_PROTOTYPES
#include <GL/freeglut.h>
#include <GL/gl.h>

#include "viewer/box_geometry.h"

namespace jello::viewer {
namespace {

// The drawn pane's lower-left corner in the window (glWindowPos is in window coordinates).
int paneX = 0, paneY = 0;  // set by setOverlayOrigin

void drawText(int x, int y, const std::string& text) {
  glWindowPos2i(paneX + x, paneY + y);
  glutBitmapString(GLUT_BITMAP_8_BY_13, reinterpret_cast<const unsigned char*>(text.c_str()));
}

constexpr int kLineHeight = 16, kCharWidth = 8;

// Draw in the pane's pixels (origin at its lower left) until endPixels().
void beginPixels(const Viewport& viewport) {
  glMatrixMode(GL_PROJECTION);
  glPushMatrix();
  glLoadIdentity();
  glOrtho(0.0, viewport.width, 0.0, viewport.height, -1.0, 1.0);
  glMatrixMode(GL_MODELVIEW);
  glPushMatrix();
  glLoadIdentity();
}

void endPixels() {
  glPopMatrix();
  glMatrixMode(GL_PROJECTION);
  glPopMatrix();
  glMatrixMode(GL_MODELVIEW);
}

// Lines of text on a translucent dark backing; `top` is the first line's baseline, from the
// window's bottom (GL's window coordinates).
void drawTextBlock(const Viewport& viewport, const std::vector<std::string>& lines, int x, int top,
                   const float colour[3], float alpha) {
  if (lines.empty()) return;
  std::size_t longest = 0;
  for (const std::string& line : lines) longest = std::max(longest, line.size());
  const int w = static_cast<int>(longest) * kCharWidth + 8;
  const int h = static_cast<int>(lines.size()) * kLineHeight + 4;
  beginPixels(viewport);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glColor4f(0.0f, 0.0f, 0.0f, 0.6f * alpha);
  glRectd(x - 4, top + kLineHeight - 3, x - 4 + w, top + kLineHeight - 3 - h);
  glColor4f(colour[0], colour[1], colour[2], alpha);
  int y = top;
  for (const std::string& line : lines) {
    drawText(x, y, line);
    y -= kLineHeight;
  }
  glDisable(GL_BLEND);
  endPixels();
}

}  // namespace

void setOverlayOrigin(int x0, int y0) {
  paneX = x0;
  paneY = y0;
}

// The field's colour scale at the bottom right: 0 N ... the strongest drawn force.
void drawLegend(const Viewport& viewport, double strongest) {
  const int w = 120, h = 10, x = viewport.width - w - 16, y = 30;
  beginPixels(viewport);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glColor4f(0.0f, 0.0f, 0.0f, 0.6f);
  glRecti(x - 8, y - 22, x + w + 8, y + h + 20);
  glDisable(GL_BLEND);
  glBegin(GL_QUAD_STRIP);
  for (int i = 0; i <= 16; ++i) {
    const std::array<float, 3> c = strengthColour(i / 16.0);
    glColor3f(c[0], c[1], c[2]);
    glVertex2i(x + w * i / 16, y);
    glVertex2i(x + w * i / 16, y + h);
  }
  glEnd();
  endPixels();
  char label[48];
  std::snprintf(label, sizeof label, "%.3g N", strongest);
  glColor3f(0.92f, 0.92f, 0.92f);
  drawText(x, y - 16, "0");
  drawText(x + w - kCharWidth * static_cast<int>(std::strlen(label)), y - 16, label);
  drawText(x, y + h + 5, "field force");
}

void drawOverlay(const Viewport& viewport, const ViewerState& view, const Overlay& overlay) {
  glDisable(GL_DEPTH_TEST);
  const std::size_t width = static_cast<std::size_t>(std::max(8, viewport.width / kCharWidth - 2));
  if (view.showHud && !overlay.hud.empty()) {
    static constexpr float white[3] = {0.92f, 0.92f, 0.92f};
    drawTextBlock(viewport, wrapText(overlay.hud, width), 8, viewport.height - 18, white, 1.0f);
  }
  if (!overlay.help.empty()) {
    static constexpr float pale[3] = {0.85f, 0.9f, 1.0f};
    const std::vector<std::string> lines = wrapText(overlay.help, width, 20);
    const int top = std::min(viewport.height - 60, 30 + kLineHeight * int(lines.size()));
    drawTextBlock(viewport, lines, 16, top, pale, 1.0f);
  }
  if (!overlay.message.empty() && overlay.messageAlpha > 0.0f) {
    static constexpr float red[3] = {1.0f, 0.4f, 0.35f}, green[3] = {0.6f, 1.0f, 0.6f};
    const std::vector<std::string> lines = wrapText(overlay.message, width);
    drawTextBlock(viewport, lines, 8, 10 + kLineHeight * static_cast<int>(lines.size() - 1),
                  overlay.alarm ? red : green, overlay.messageAlpha);
  }
  glEnable(GL_DEPTH_TEST);
}

}  // namespace jello::viewer
