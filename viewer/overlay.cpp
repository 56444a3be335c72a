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

// The fixed 8x13 font, or the small proportional one of the compare panes' heads-up.
struct Font {
  void* glut;
  int lineHeight;
  int charWidth;  // for wrapping: the widest a character usually is
};
const Font kFixed{GLUT_BITMAP_8_BY_13, 16, 8};
const Font kSmall{GLUT_BITMAP_HELVETICA_10, 12, 6};

void drawText(int x, int y, const std::string& text, const Font& font = kFixed) {
  glWindowPos2i(paneX + x, paneY + y);
  glutBitmapString(font.glut, reinterpret_cast<const unsigned char*>(text.c_str()));
}

int textWidth(const std::string& text, const Font& font) {
  return glutBitmapLength(font.glut, reinterpret_cast<const unsigned char*>(text.c_str()));
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
                   const float colour[3], float alpha, const Font& font = kFixed) {
  if (lines.empty()) return;
  int longest = 0;
  for (const std::string& line : lines) longest = std::max(longest, textWidth(line, font));
  const int w = longest + 8;
  const int h = static_cast<int>(lines.size()) * font.lineHeight + 4;
  beginPixels(viewport);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glColor4f(0.0f, 0.0f, 0.0f, 0.6f * alpha);
  glRectd(x - 4, top + font.lineHeight - 3, x - 4 + w, top + font.lineHeight - 3 - h);
  glColor4f(colour[0], colour[1], colour[2], alpha);
  int y = top;
  for (const std::string& line : lines) {
    drawText(x, y, line, font);
    y -= font.lineHeight;
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
    const Font& font = overlay.compactHud ? kSmall : kFixed;
    std::size_t chars = static_cast<std::size_t>(std::max(8, viewport.width / font.charWidth - 2));
    if (overlay.compactHud) {
      // A proportional font: as many characters as this text's own average width lets fit (all
      // of it when its widest line fits).
      const int measured = textWidth(overlay.hud, font);
      if (measured <= viewport.width - 8) {
        chars = overlay.hud.size();
      } else if (measured > 0) {
        chars = std::max<std::size_t>(
            8, static_cast<std::size_t>(double(viewport.width - 12) * double(overlay.hud.size()) /
                                        double(measured)));
      }
    }
    const int left = overlay.compactHud ? 4 : 8;
    drawTextBlock(viewport, wrapText(overlay.hud, chars), left,
                  viewport.height - 6 - font.lineHeight, white, 1.0f, font);
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
