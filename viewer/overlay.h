// The 2D layer of a frame, in window pixels over the pane being drawn: the heads-up text, the
// key help, the fading message on its dark backing, and the field's colour legend. Drawn by
// renderer.cpp after the scene.
#pragma once

#include "viewer/camera.h"
#include "viewer/renderer.h"
#include "viewer/viewer_state.h"

namespace jello::viewer {

// The lower-left corner (window pixels, y up) of the pane the text goes into.
void setOverlayOrigin(int x0, int y0);
void drawOverlay(const Viewport& viewport, const ViewerState& view, const Overlay& overlay);
// The field's colour scale at the bottom right: 0 N ... `strongest` N.
void drawLegend(const Viewport& viewport, double strongest);

}  // namespace jello::viewer
