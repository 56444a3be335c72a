#include "viewer/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <numbers>

// glWindowPos (GL 1.4) is declared only with the extension prototypes.
#define GL_GLEXT_PROTOTYPES
#include <GL/freeglut.h>
#include <GL/gl.h>

#include "src/effects/contact.h"
#include "viewer/overlay.h"

namespace jello::viewer {
namespace {

void vertex(const Vec3& p) {
  glVertex3d(p.x, p.y, p.z);
}

void drawBox() {
  const double h = kBoxHalfSize;
  // A solid floor (the grid was see-through: nothing said where the cube stood), pushed back in
  // depth so that its grid lines and the shadows on it win.
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 1.0f);
  glColor3fv(kFloor);
  glBegin(GL_QUADS);
  for (const Vec3& corner : floorCorners()) vertex(corner);
  glEnd();
  glDisable(GL_POLYGON_OFFSET_FILL);
  glColor3f(0.75f, 0.75f, 0.8f);
  glBegin(GL_LINES);
  for (const auto& [a, b] : boxEdges()) {
    vertex(a);
    vertex(b);
  }
  // A grid on the floor, for depth.
  glColor3f(0.3f, 0.3f, 0.36f);
  for (int i = 1; i < 8; ++i) {
    const double c = -h + i * 0.5;
    glVertex3d(c, -h, -h);
    glVertex3d(c, h, -h);
    glVertex3d(-h, c, -h);
    glVertex3d(h, c, -h);
  }
  glEnd();
}

// The light the shadows fall from: the key light's direction (towards it), as drawFrame sets it.
constexpr double kShadowLight[3] = {0.4, 0.5, 1.0};

// Flattens geometry onto the plane a x + b y + c z + d = 0 along the light's direction: the
// classic planar projection (P . L) I - L P^T, with L = (light, 0) a direction.
Eigen::Matrix4d shadowMatrix(const Eigen::Vector4d& plane) {
  const Eigen::Vector4d light(kShadowLight[0], kShadowLight[1], kShadowLight[2], 0.0);
  return plane.dot(light) * Eigen::Matrix4d::Identity() - light * plane.transpose();
}

// The shadow of `casters` on the receiver plane, inside its `polygon`: the casters flattened onto
// it mark the stencil (no colour, no depth), then the polygon is darkened where marked, once
// however many casters overlap. Drawn with the depth test, so the shadow is hidden where
// something stands in front of the receiver.
void drawShadow(const Eigen::Vector4d& receiver, const std::vector<Vec3>& polygon,
                const std::function<void()>& casters) {
  const Eigen::Vector4d light(kShadowLight[0], kShadowLight[1], kShadowLight[2], 0.0);
  // A receiver facing away from the light, or edge-on, is not lit: no shadow to draw.
  if (polygon.empty() || receiver.dot(light) <= 1e-6 * receiver.head<3>().norm()) return;
  glClear(GL_STENCIL_BUFFER_BIT);
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_ALWAYS, 1, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_FALSE);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(-1.0f, -4.0f);
  glPushMatrix();
  const Eigen::Matrix4d flatten = shadowMatrix(receiver);
  glMultMatrixd(flatten.data());
  casters();
  glPopMatrix();
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glStencilFunc(GL_EQUAL, 1, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_ZERO);  // each pixel darkened once
  glDisable(GL_LIGHTING);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glColor4f(0.0f, 0.0f, 0.0f, 0.45f);
  glBegin(GL_POLYGON);
  for (const Vec3& p : polygon) vertex(p);
  glEnd();
  glDisable(GL_BLEND);
  glDisable(GL_POLYGON_OFFSET_FILL);
  glDepthMask(GL_TRUE);
  glDisable(GL_STENCIL_TEST);
}

// The cube's triangles, positions only: what a shadow is cast by.
void drawCubeSilhouette(const Scene& scene) {
  glBegin(GL_TRIANGLES);
  for (const auto& t : scene.mesh->triangles) {
    for (int c = 0; c < 3; ++c) vertex(scene.state->position(t[c]));
  }
  glEnd();
}

// Uploads `image` as the current 2D texture when it is not the one uploaded last.
void bindTexture(const Image& image) {
  static GLuint name = 0;
  static const std::uint8_t* uploaded = nullptr;
  if (name == 0) glGenTextures(1, &name);
  glBindTexture(GL_TEXTURE_2D, name);
  if (uploaded == image.rgb.data()) return;
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, image.width, image.height, 0, GL_RGB, GL_UNSIGNED_BYTE,
               image.rgb.data());
  uploaded = image.rgb.data();
}

void drawShadedCube(const Scene& scene) {
  const std::vector<Vec3> normals = vertexNormals(*scene.mesh, *scene.state);
  glEnable(GL_LIGHTING);
  const bool textured = scene.texture != nullptr && !scene.texture->rgb.empty();
  // Textured, the material is white and the texture gives the colour (GL_MODULATE).
  const GLfloat red[] = {0.85f, 0.18f, 0.28f, 1.0f}, white[] = {1.0f, 1.0f, 1.0f, 1.0f},
                specular[] = {0.5f, 0.5f, 0.5f, 1.0f};
  glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE, textured ? white : red);
  glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, specular);
  glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, 40.0f);
  if (textured) {
    bindTexture(*scene.texture);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    glEnable(GL_TEXTURE_2D);
  }
  glBegin(GL_TRIANGLES);
  for (std::size_t i = 0; i < scene.mesh->triangles.size(); ++i) {
    const auto& t = scene.mesh->triangles[i];
    for (int c = 0; c < 3; ++c) {
      const Vec3& n = normals[t[c]];
      glNormal3d(n.x, n.y, n.z);
      if (textured) glTexCoord2f(scene.mesh->uv[i][c][0], scene.mesh->uv[i][c][1]);
      vertex(scene.state->position(t[c]));
    }
  }
  glEnd();
  if (textured) glDisable(GL_TEXTURE_2D);
  glDisable(GL_LIGHTING);
}

void drawWireframeCube(const ViewerState& view, const Scene& scene) {
  glPointSize(4.0f);
  glColor3f(0.95f, 0.95f, 0.95f);
  glBegin(GL_POINTS);
  for (int p : scene.mesh->points) vertex(scene.state->position(p));
  glEnd();
  glBegin(GL_LINES);
  for (const Spring& s : *scene.springs) {
    switch (s.kind) {
      case SpringKind::Structural:
        if (!view.structural) continue;
        glColor3f(0.35f, 0.75f, 1.0f);
        break;
      case SpringKind::FaceShear:
      case SpringKind::BodyShear:
        if (!view.shear) continue;
        glColor3f(0.4f, 0.9f, 0.4f);
        break;
      case SpringKind::Bend:
        if (!view.bend) continue;
        glColor3f(1.0f, 0.85f, 0.3f);
        break;
    }
    vertex(scene.state->position(s.a));
    vertex(scene.state->position(s.b));
  }
  glEnd();
}

// The six faces of the box as clip planes: a x + b y + c z + d >= 0 is kept.
void clipToBox(bool on) {
  const double h = kBoxHalfSize;
  const GLdouble planes[6][4] = {{1, 0, 0, h},  {-1, 0, 0, h}, {0, 1, 0, h},
                                 {0, -1, 0, h}, {0, 0, 1, h},  {0, 0, -1, h}};
  for (int i = 0; i < 6; ++i) {
    if (on) {
      glClipPlane(GL_CLIP_PLANE0 + i, planes[i]);
      glEnable(GL_CLIP_PLANE0 + i);
    } else {
      glDisable(GL_CLIP_PLANE0 + i);
    }
  }
}

void drawSphere(const Sphere& sphere) {
  glEnable(GL_LIGHTING);
  const GLfloat diffuse[] = {0.55f, 0.6f, 0.68f, 1.0f};
  glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE, diffuse);
  clipToBox(true);
  glPushMatrix();
  glTranslated(sphere.center.x, sphere.center.y, sphere.center.z);
  glutSolidSphere(sphere.radius, 48, 32);
  glPopMatrix();
  clipToBox(false);
  glDisable(GL_LIGHTING);
}

void normal(const Vec3& n) {
  glNormal3d(n.x, n.y, n.z);
}

// Lit like the sphere, a warmer grey: the cone's lateral surface (per-vertex normals of the
// slope) and its base disk, clipped to the box.
void drawCone(const Cone& cone) {
  const Vec3 d = unitVector(cone.axis);
  const Vec3 e1 = unitVector(cross(d, std::abs(d.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
  const Vec3 e2 = cross(d, e1);
  const double H = cone.height, R = cone.radius, L = std::hypot(H, R);
  const Vec3 base = cone.apex + d * H;
  constexpr int kSlices = 64;
  glEnable(GL_LIGHTING);
  const GLfloat diffuse[] = {0.68f, 0.6f, 0.5f, 1.0f};
  glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE, diffuse);
  clipToBox(true);
  glBegin(GL_TRIANGLES);
  for (int i = 0; i < kSlices; ++i) {
    const double a0 = 2.0 * std::numbers::pi * i / kSlices,
                 a1 = 2.0 * std::numbers::pi * (i + 1) / kSlices;
    const Vec3 r0 = e1 * std::cos(a0) + e2 * std::sin(a0),
               r1 = e1 * std::cos(a1) + e2 * std::sin(a1);
    const Vec3 n0 = (r0 * H - d * R) * (1.0 / L), n1 = (r1 * H - d * R) * (1.0 / L);
    normal((n0 + n1) * 0.5);
    vertex(cone.apex);
    normal(n0);
    vertex(base + r0 * R);
    normal(n1);
    vertex(base + r1 * R);
    normal(d);  // the base disk
    vertex(base);
    vertex(base + r1 * R);
    vertex(base + r0 * R);
  }
  glEnd();
  clipToBox(false);
  glDisable(GL_LIGHTING);
}

// The spiral ramp's slab: its helicoid top and bottom, and its inner and outer walls.
void drawSpiral(const Spiral& s) {
  const double c = s.pitch / (2.0 * std::numbers::pi), span = 2.0 * std::numbers::pi * s.turns;
  const int steps = std::max(16, static_cast<int>(48 * s.turns));
  constexpr int kRadial = 6;
  const auto point = [&](double r, double theta, double dz) {
    return Vec3{s.cx + r * std::cos(theta), s.cy + r * std::sin(theta), s.zTop - c * theta + dz};
  };
  const auto topNormal = [&](double r, double theta) {
    const Vec3 n{c * std::sin(theta), -c * std::cos(theta), r};
    return n * (1.0 / norm(n));
  };
  glEnable(GL_LIGHTING);
  const GLfloat diffuse[] = {0.5f, 0.62f, 0.55f, 1.0f};
  glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE, diffuse);
  clipToBox(true);
  for (int j = 0; j < kRadial; ++j) {
    const double r0 = s.rInner + (s.rOuter - s.rInner) * j / kRadial;
    const double r1 = s.rInner + (s.rOuter - s.rInner) * (j + 1) / kRadial;
    for (double side : {0.0, -s.thickness}) {  // top, then bottom
      glBegin(GL_QUAD_STRIP);
      for (int i = 0; i <= steps; ++i) {
        const double theta = span * i / steps;
        const double flip = side == 0.0 ? 1.0 : -1.0;
        normal(topNormal(r0, theta) * flip);
        vertex(point(r0, theta, side));
        normal(topNormal(r1, theta) * flip);
        vertex(point(r1, theta, side));
      }
      glEnd();
    }
  }
  for (double r : {s.rInner, s.rOuter}) {  // the walls
    if (r <= 0.0) continue;
    glBegin(GL_QUAD_STRIP);
    for (int i = 0; i <= steps; ++i) {
      const double theta = span * i / steps;
      const double out = r == s.rOuter ? 1.0 : -1.0;
      normal(Vec3{std::cos(theta), std::sin(theta), 0.0} * out);
      vertex(point(r, theta, 0.0));
      vertex(point(r, theta, -s.thickness));
    }
    glEnd();
  }
  clipToBox(false);
  glDisable(GL_LIGHTING);
}

void drawPlane(const Plane& plane) {
  const std::vector<Vec3> polygon = planeInBox(plane);
  if (polygon.empty()) return;
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  glColor4f(0.3f, 0.6f, 0.9f, 0.35f);
  glBegin(GL_POLYGON);
  for (const Vec3& p : polygon) vertex(p);
  glEnd();
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glColor3f(0.45f, 0.75f, 1.0f);
  glBegin(GL_LINE_LOOP);
  for (const Vec3& p : polygon) vertex(p);
  glEnd();
}

// Arrows with heads (two barbs in the plane facing the camera), coloured by strength or all in
// `colour` when given.
void drawArrows(const std::vector<Arrow>& arrows, const Camera& camera,
                const std::array<float, 3>* colour = nullptr) {
  const Vec3 toEye = camera.forward() * -1.0;
  glLineWidth(1.5f);
  glBegin(GL_LINES);
  for (const Arrow& a : arrows) {
    const std::array<float, 3> c = colour ? *colour : strengthColour(a.strength);
    glColor3f(c[0], c[1], c[2]);
    const Vec3 d = a.head - a.tail;
    const double length = norm(d);
    if (length <= 0.0) continue;
    const Vec3 u = d * (1.0 / length);
    Vec3 side = cross(u, toEye);
    const double sideLength = norm(side);
    side = sideLength > 1e-9 ? side * (1.0 / sideLength) : Vec3{};
    const double barb = 0.3 * length;
    vertex(a.tail);
    vertex(a.head);
    vertex(a.head);
    vertex(a.head - u * barb + side * (0.5 * barb));
    vertex(a.head);
    vertex(a.head - u * barb - side * (0.5 * barb));
  }
  glEnd();
  glLineWidth(1.0f);
}

// The pull: the picked point, the cursor's target, the line between them, and the fall-off
// radius as a circle around the picked point facing the camera.
void drawPull(const ViewerState& view, const Scene& scene) {
  const auto& [picked, target] = *scene.pull;
  glDisable(GL_DEPTH_TEST);
  glColor3f(1.0f, 0.85f, 0.2f);
  glLineWidth(2.0f);
  glBegin(GL_LINES);
  vertex(picked);
  vertex(target);
  glEnd();
  glPointSize(8.0f);
  glBegin(GL_POINTS);
  vertex(picked);
  glColor3f(1.0f, 1.0f, 1.0f);
  vertex(target);
  glEnd();
  const double r = scene.pullRadius;
  if (r > 0.0 && std::isfinite(r)) {
    const Vec3 a = view.camera.right(), b = view.camera.up();
    glColor3f(1.0f, 0.85f, 0.2f);
    glLineWidth(1.0f);
    glBegin(GL_LINE_LOOP);
    for (int i = 0; i < 48; ++i) {
      const double phi = 2.0 * std::numbers::pi * i / 48;
      vertex(picked + a * (r * std::cos(phi)) + b * (r * std::sin(phi)));
    }
    glEnd();
  }
  glLineWidth(1.0f);
  glEnable(GL_DEPTH_TEST);
}

// The push: an arrow from the cube's centre in the pushed direction.
void drawPush(const ViewerState& view, const Scene& scene) {
  const auto& [from, to] = *scene.push;
  const Vec3 d = to - from;
  const double length = norm(d);
  if (length <= 0.0) return;
  const Vec3 u = d * (1.0 / length), side = cross(u, view.camera.forward());
  const double head = std::min(0.25, 0.4 * length);
  const Vec3 s = norm(side) > 0.0 ? side * (head * 0.5 / norm(side)) : Vec3{};
  glDisable(GL_DEPTH_TEST);
  glColor3f(0.3f, 0.8f, 1.0f);
  glLineWidth(3.0f);
  glBegin(GL_LINES);
  vertex(from);
  vertex(to);
  vertex(to);
  vertex(to - u * head + s);
  vertex(to);
  vertex(to - u * head - s);
  glEnd();
  glLineWidth(1.0f);
  glEnable(GL_DEPTH_TEST);
}

}  // namespace

void initRenderer() {
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_NORMALIZE);
  glShadeModel(GL_SMOOTH);
  glEnable(GL_LINE_SMOOTH);
  glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);
  const GLfloat ambient[] = {0.18f, 0.18f, 0.2f, 1.0f};
  glLightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);
  const GLfloat key[] = {0.85f, 0.85f, 0.82f, 1.0f}, fill[] = {0.35f, 0.35f, 0.42f, 1.0f};
  glLightfv(GL_LIGHT0, GL_DIFFUSE, key);
  glLightfv(GL_LIGHT0, GL_SPECULAR, key);
  glLightfv(GL_LIGHT1, GL_DIFFUSE, fill);
  glEnable(GL_LIGHT0);
  glEnable(GL_LIGHT1);
}

void drawFrame(const ViewerState& view, const Viewport& viewport, const Scene& scene,
               const Overlay& overlay, int x0, int y0) {
  setOverlayOrigin(x0, y0);
  glViewport(x0, y0, viewport.width, viewport.height);
  glScissor(x0, y0, viewport.width, viewport.height);
  glEnable(GL_SCISSOR_TEST);
  glClearColor(kBackground[0], kBackground[1], kBackground[2], 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glMatrixMode(GL_PROJECTION);
  const Eigen::Matrix4d projection = projectionMatrix(view.camera, viewport);
  glLoadMatrixd(projection.data());
  glMatrixMode(GL_MODELVIEW);
  const Eigen::Matrix4d model = viewMatrix(view.camera);
  glLoadMatrixd(model.data());
  // Directional lights fixed in the world: a key light from above the camera's side, a fill.
  const GLfloat keyDirection[] = {0.4f, 0.5f, 1.0f, 0.0f},
                fillDirection[] = {-0.6f, -0.3f, 0.2f, 0.0f};
  glLightfv(GL_LIGHT0, GL_POSITION, keyDirection);
  glLightfv(GL_LIGHT1, GL_POSITION, fillDirection);

  drawBox();
  // Shadows on the floor, of the cube and the solids, so a user sees where the cube is and
  // whether it touches.
  drawShadow({0.0, 0.0, 1.0, kBoxHalfSize}, floorCorners(), [&] {
    drawCubeSilhouette(scene);
    if (scene.world->sphere) drawSphere(*scene.world->sphere);
    if (scene.world->cone) drawCone(*scene.world->cone);
    if (scene.world->spiral) drawSpiral(*scene.world->spiral);
  });
  if (view.mode == DisplayMode::Shaded) {
    drawShadedCube(scene);
  } else {
    drawWireframeCube(view, scene);
  }
  if (scene.world->sphere) drawSphere(*scene.world->sphere);
  if (scene.world->cone) drawCone(*scene.world->cone);
  if (scene.world->spiral) drawSpiral(*scene.world->spiral);
  if (view.showField && scene.arrows) drawArrows(*scene.arrows, view.camera);
  if (view.showField && scene.friction) {
    const std::array<float, 3> frictionColour{1.0f, 0.55f, 0.1f};  // orange, off the legend
    drawArrows(*scene.friction, view.camera, &frictionColour);
  }
  if (scene.pull) drawPull(view, scene);
  if (scene.push) drawPush(view, scene);
  if (scene.world->plane) {
    drawPlane(*scene.world->plane);  // blended: last
    // The cube's shadow on the plane (what lies under the plane is in its solid).
    const Plane& p = *scene.world->plane;
    drawShadow({p.a, p.b, p.c, p.d}, planeInBox(p), [&] { drawCubeSilhouette(scene); });
  }
  drawOverlay(viewport, view, overlay);
  if (view.showField && scene.arrows && !scene.arrows->empty()) {
    double strongest = 0.0;
    for (const Arrow& a : *scene.arrows) strongest = std::max(strongest, a.magnitude);
    glDisable(GL_DEPTH_TEST);
    drawLegend(viewport, strongest);
    glEnable(GL_DEPTH_TEST);
  }
  glDisable(GL_SCISSOR_TEST);
}

std::vector<std::uint8_t> readBackBuffer(const Viewport& viewport) {
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(viewport.width) * viewport.height * 3);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, viewport.width, viewport.height, GL_RGB, GL_UNSIGNED_BYTE, pixels.data());
  return pixels;
}

}  // namespace jello::viewer
