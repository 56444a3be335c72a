#include "src/effects/obstacles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace jello {

namespace {

// Any unit vector perpendicular to unit d.
Vec3 perpendicular(const Vec3& d) {
  const Vec3 a = std::abs(d.x) < 0.9 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  return unitVector(cross(d, a));
}

void setOuter(double* m, const Vec3& a, const Vec3& b, double s) {
  const double u[3] = {a.x, a.y, a.z}, w[3] = {b.x, b.y, b.z};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[3 * i + j] += s * u[i] * w[j];
}

}  // namespace

std::optional<Penetration> conePenetration(const Cone& cone, const Vec3& x) {
  const Vec3 d = unitVector(cone.axis);
  const Vec3 rel = x - cone.apex;
  const double h = dot(d, rel);
  if (!(h > 0.0 && h < cone.height)) return std::nullopt;
  const Vec3 radial = rel - d * h;
  const double r = norm(radial);
  const double H = cone.height, R = cone.radius;
  // Outside the lateral surface: most points, told before the slant length's hypot.
  if (!(h * R - r * H > 0.0)) return std::nullopt;
  const double L = std::hypot(H, R);
  const double lateral = (h * R - r * H) / L;  // distance to the lateral surface, > 0 inside
  if (!(lateral > 0.0)) return std::nullopt;
  const double base = H - h;
  Penetration p;
  if (lateral <= base) {
    const Vec3 er = r > 0.0 ? radial * (1.0 / r) : perpendicular(d);
    p.depth = lateral;
    p.gradient = (d * R - er * H) * (1.0 / L);
    if (r > 0.0) {
      // d(er)/dx = (I - d d^T - er er^T) / r.
      const double s = -H / (L * r);
      for (int e = 0; e < 3; ++e) p.hessian[4 * e] += s;
      setOuter(p.hessian, d, d, -s);
      setOuter(p.hessian, er, er, -s);
    }
  } else {
    p.depth = base;
    p.gradient = d * -1.0;
  }
  return p;
}

Penetration coneExterior(const Cone& cone, const Vec3& x) {
  const Vec3 d = unitVector(cone.axis);
  const Vec3 rel = x - cone.apex;
  const double h = dot(d, rel);
  const Vec3 radial = rel - d * h;
  const double r = norm(radial);
  const Vec3 er = r > 0.0 ? radial * (1.0 / r) : perpendicular(d);
  const double H = cone.height, R = cone.radius;
  // The nearest point of each edge, (h, r) coordinates; an interior one leaves D linear there.
  const double t = std::clamp((h * H + r * R) / (H * H + R * R), 0.0, 1.0);
  const double lateral[2] = {t * H, t * R};
  const double base[2] = {H, std::clamp(r, 0.0, R)};
  const double dl = std::hypot(h - lateral[0], r - lateral[1]);
  const double db = std::hypot(h - base[0], r - base[1]);
  const bool onLateral = dl <= db;
  const double* q = onLateral ? lateral : base;
  const bool atVertex = onLateral ? (t == 0.0 || t == 1.0) : (r >= R);
  const double D = onLateral ? dl : db;
  Penetration p;
  p.depth = -D;
  if (!(D > 0.0)) return p;
  const double uh = (h - q[0]) / D, ur = (r - q[1]) / D;  // grad D in (h, r)
  p.gradient = (d * uh + er * ur) * -1.0;
  // Hess D = sum of its (h, r) Hessian on (d, er), + ur Hess(r); at a vertex the (h, r)
  // Hessian is (I - u u^T) / D, along an edge's interior 0.
  if (atVertex) {
    const double a = (1.0 - uh * uh) / D, b = -uh * ur / D, c = (1.0 - ur * ur) / D;
    setOuter(p.hessian, d, d, -a);
    setOuter(p.hessian, d, er, -b);
    setOuter(p.hessian, er, d, -b);
    setOuter(p.hessian, er, er, -c);
  }
  if (r > 0.0) {
    // Hess(r) = (I - d d^T - er er^T) / r.
    const double k = -ur / r;
    for (int e = 0; e < 3; ++e) p.hessian[4 * e] += k;
    setOuter(p.hessian, d, d, -k);
    setOuter(p.hessian, er, er, -k);
  }
  return p;
}

// Long: the six faces' depths and the nearest one's gradient and Hessian.
std::optional<Penetration> spiralPenetration(const Spiral& s, const Vec3& x) {
  const double px = x.x - s.cx, py = x.y - s.cy;
  // Far inside the hole or beyond the rim (by 1% of the radius, past any rounding), or above
  // the top or below the bottom: out, told before hypot and atan2.
  const double squared = px * px + py * py;
  if (squared < 0.98 * s.rInner * s.rInner || squared > 1.02 * s.rOuter * s.rOuter) {
    return std::nullopt;
  }
  const double reachDown = s.pitch * s.turns + s.thickness;
  if (x.z > s.zTop + 1e-9 * (1.0 + std::abs(s.zTop)) ||
      x.z < s.zTop - reachDown - 1e-9 * (1.0 + std::abs(s.zTop) + reachDown)) {
    return std::nullopt;
  }
  const double r = std::hypot(px, py);
  if (!(r > s.rInner && r < s.rOuter) || r == 0.0) return std::nullopt;
  const double c = s.pitch / (2.0 * std::numbers::pi);
  double theta = std::atan2(py, px);
  if (theta < 0.0) theta += 2.0 * std::numbers::pi;
  const double span = 2.0 * std::numbers::pi * s.turns;
  // The turn whose slab holds x: top = zTop - c Theta above x by less than the thickness.
  double top = std::numeric_limits<double>::quiet_NaN(), big = theta;
  for (; big <= span; big += 2.0 * std::numbers::pi) {
    const double depth = s.zTop - c * big - x.z;
    if (depth > 0.0 && depth < s.thickness) {
      top = depth;
      break;
    }
  }
  if (std::isnan(top)) return std::nullopt;
  const double r2 = r * r, r4 = r2 * r2;
  // grad(theta) and its Hessian (in x and y).
  const Vec3 gt{-py / r2, px / r2, 0.0};
  const double txx = 2.0 * px * py / r4, tyy = -txx, txy = (py * py - px * px) / r4;
  const Vec3 er{px / r, py / r, 0.0};
  const double bottom = s.thickness - top, outer = s.rOuter - r;
  const double inner = s.rInner > 0.0 ? r - s.rInner : std::numeric_limits<double>::infinity();
  Penetration p;
  const auto vertical = [&](double depth, double sign) {
    // top: depth = zTop - c theta - z (+ const); bottom: the same with the opposite sign.
    p.depth = depth;
    p.gradient = (gt * -c + Vec3{0.0, 0.0, -1.0}) * sign;
    const double h[9] = {-c * txx, -c * txy, 0, -c * txy, -c * tyy, 0, 0, 0, 0};
    for (int i = 0; i < 9; ++i) p.hessian[i] = sign * h[i];
  };
  const auto radial = [&](double depth, double sign) {
    // outer: depth = rOuter - r (sign -1); inner: depth = r - rInner (sign +1).
    p.depth = depth;
    p.gradient = er * sign;
    const double k = sign / r;  // Hess(r) = (I2 - er er^T) / r in x, y
    const double h[9] = {k * (1 - er.x * er.x),
                         -k * er.x * er.y,
                         0,
                         -k * er.x * er.y,
                         k * (1 - er.y * er.y),
                         0,
                         0,
                         0,
                         0};
    for (int i = 0; i < 9; ++i) p.hessian[i] = h[i];
  };
  // The two ends of the ramp: the arc length r Theta from the start, r (span - Theta) to the
  // end, so that the depth falls to 0 on every face (no energy jumps at the ends).
  const double start = r * big, end = r * (span - big);
  const auto cap = [&](double depth, double sign, double angle) {
    // depth = r * angle with angle = Theta (start, sign +1) or span - Theta (end, sign -1).
    p.depth = depth;
    p.gradient = er * angle + gt * (r * sign);
    const double hr[4] = {(1 - er.x * er.x) / r, -er.x * er.y / r, -er.x * er.y / r,
                          (1 - er.y * er.y) / r};
    const double ht[4] = {txx, txy, txy, tyy};
    const double e[2] = {er.x, er.y}, g[2] = {gt.x, gt.y};
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        p.hessian[3 * i + j] =
            angle * hr[2 * i + j] + sign * (e[i] * g[j] + g[i] * e[j]) + sign * r * ht[2 * i + j];
      }
    }
  };
  const double least = std::min({top, bottom, outer, inner, start, end});
  if (least == top) {
    vertical(top, 1.0);
  } else if (least == bottom) {
    vertical(bottom, -1.0);
  } else if (least == outer) {
    radial(outer, -1.0);
  } else if (least == inner) {
    radial(inner, 1.0);
  } else if (least == start) {
    cap(start, 1.0, big);
  } else {
    cap(end, -1.0, span - big);
  }
  return p;
}

namespace {

// One face of the spiral seen from outside: e > 0 past it (a lower bound on the distance to
// it), its gradient and Hessian (row-major).
struct FaceDistance {
  double e = -std::numeric_limits<double>::infinity();
  Vec3 gradient;
  double hessian[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
};

// r - r0 (sign +1) or r0 - r (sign -1): the distance to the cylinder of radius r0, its gradient
// sign e_r, its Hessian sign (I - e_r e_r^T - e_z e_z^T) / r.
FaceDistance cylinderFace(double r, double r0, const Vec3& er, double sign) {
  FaceDistance f;
  f.e = sign * (r - r0);
  f.gradient = er * sign;
  if (r > 0.0) {
    const double k = sign / r;
    f.hessian[0] = f.hessian[4] = k;
    setOuter(f.hessian, er, er, -k);
  }
  return f;
}

}  // namespace

// Long: the faces of every turn, each a lower bound on its distance, the farthest face of a
// turn, the nearest turn.
Penetration spiralExterior(const Spiral& s, const Vec3& x) {
  const double px = x.x - s.cx, py = x.y - s.cy;
  const double r = std::hypot(px, py);
  const double c = s.pitch / (2.0 * std::numbers::pi);
  const double span = 2.0 * std::numbers::pi * s.turns;
  // The top and bottom: between two points of a turn at radii >= rm the helicoid's height
  // changes by c dTheta over a chord of at least (2/pi) rm dTheta (dTheta <= pi), so by at most
  // G = (pi/2) c / rm times their distance; the vertical gap over sqrt(1 + G^2) is then at most
  // the distance to the slab. rm = rInner / 2, and nearer the axis than that only the inner
  // cylinder bounds the distance (it is at least rInner / 2 there).
  const double rm = 0.5 * s.rInner;
  const bool slabFaces = rm > 0.0 ? r >= rm : true;
  const double steepest = rm > 0.0 ? 0.5 * std::numbers::pi * c / rm : 0.0;
  const double scale = 1.0 / std::sqrt(1.0 + steepest * steepest);
  double theta = r > 0.0 ? std::atan2(py, px) : 0.0;
  if (theta < 0.0) theta += 2.0 * std::numbers::pi;
  const Vec3 er = r > 0.0 ? Vec3{px / r, py / r, 0.0} : Vec3{1.0, 0.0, 0.0};
  const double r2 = std::max(r * r, 1e-300), r4 = r2 * r2;
  const Vec3 gt{-py / r2, px / r2, 0.0};  // grad(theta)
  const double txx = 2.0 * px * py / r4, txy = (py * py - px * px) / r4;
  const double hTheta[9] = {txx, txy, 0, txy, -txx, 0, 0, 0, 0};
  FaceDistance nearest;
  nearest.e = std::numeric_limits<double>::infinity();
  for (double big = theta - 2.0 * std::numbers::pi; big <= span + 2.0 * std::numbers::pi;
       big += 2.0 * std::numbers::pi) {
    FaceDistance farthest;
    const auto consider = [&](const FaceDistance& f) {
      if (f.e > farthest.e) farthest = f;
    };
    // > 0 above this turn's top; past an end, above the end's (the helicoid continued past
    // it would sink below the solid's last top and overstate the gap).
    const double above = x.z - (s.zTop - c * std::clamp(big, 0.0, span));
    FaceDistance top;
    top.e = above * scale;
    const bool along = big > 0.0 && big < span;  // the top's height varies with theta here
    top.gradient = (gt * (along ? c : 0.0) + Vec3{0.0, 0.0, 1.0}) * scale;
    for (int i = 0; i < 9; ++i) top.hessian[i] = along ? c * scale * hTheta[i] : 0.0;
    FaceDistance bottom;
    bottom.e = (-above - s.thickness) * scale;
    bottom.gradient = top.gradient * -1.0;
    for (int i = 0; i < 9; ++i) bottom.hessian[i] = -top.hessian[i];
    if (slabFaces) {
      consider(top);
      consider(bottom);
    }
    consider(cylinderFace(r, s.rOuter, er, 1.0));
    if (s.rInner > 0.0) consider(cylinderFace(r, s.rInner, er, -1.0));
    // The ends: the half-planes through the axis at Theta = 0 and span. Within a quarter turn
    // of one, the distance to its plane (linear in x); farther, the distance to the axis.
    struct End {
      double past, angle, sign;  // how far past it, the plane's angle, its outward side
    };
    for (const End& end : {End{-big, 0.0, -1.0}, End{big - span, span, 1.0}}) {
      if (!(end.past > 0.0)) continue;
      if (end.past < 0.5 * std::numbers::pi) {
        FaceDistance f;  // sign r sin(theta - angle): the signed distance to that plane
        const double ca = std::cos(end.angle), sa = std::sin(end.angle);
        f.e = end.sign * (py * ca - px * sa);
        f.gradient = Vec3{-sa, ca, 0.0} * end.sign;
        consider(f);
      } else {
        consider(cylinderFace(r, 0.0, er, 1.0));
      }
    }
    if (farthest.e < nearest.e) nearest = farthest;
  }
  Penetration p;
  p.depth = -std::max(nearest.e, 0.0);
  p.gradient = nearest.gradient * -1.0;
  for (int i = 0; i < 9; ++i) p.hessian[i] = -nearest.hessian[i];
  return p;
}

namespace {

// CVODE's root function for the spiral: minus the largest, over the turns Theta = theta + 2 pi k,
// of the smallest of the six face depths of spiralPenetration (each negative past its face), so
// > 0 outside, < 0 inside, 0 on the surface, and continuous but on the ray theta = 0 outside
// the slab (where it does not change sign).
double spiralRoot(const Spiral& s, const Vec3& x) {
  const double px = x.x - s.cx, py = x.y - s.cy;
  const double r = std::hypot(px, py);
  const double c = s.pitch / (2.0 * std::numbers::pi);
  double theta = std::atan2(py, px);
  if (theta < 0.0) theta += 2.0 * std::numbers::pi;
  const double span = 2.0 * std::numbers::pi * s.turns;
  const double outer = s.rOuter - r;
  const double inner = s.rInner > 0.0 ? r - s.rInner : std::numeric_limits<double>::infinity();
  double best = -std::numeric_limits<double>::infinity();
  for (double big = theta; big <= span + 2.0 * std::numbers::pi; big += 2.0 * std::numbers::pi) {
    const double top = s.zTop - c * big - x.z;
    best =
        std::max(best, std::min({top, s.thickness - top, outer, inner, r * big, r * (span - big)}));
  }
  return -best;
}

}  // namespace

ObstacleContact::ObstacleContact(const Cone& cone, ContactConstants k) : Obstacle(k), cone_(cone) {}
ObstacleContact::ObstacleContact(const Spiral& spiral, ContactConstants k)
    : Obstacle(k), spiral_(spiral) {}

std::optional<Penetration> ObstacleContact::penetration(const Vec3& x) const {
  return cone_ ? conePenetration(*cone_, x) : spiralPenetration(*spiral_, x);
}

bool ObstacleContact::addPenaltyForces(const double* x, const double* v, double* f, int n, int lo,
                                       int hi) const {
  const ContactConstants& k = constants();
  for (int p = lo; p < hi; ++p) {
    const std::optional<Penetration> q = penetration(pointAt(x, n, p));
    if (!q) continue;
    const Vec3 nrm = unitVector(q->gradient * -1.0);
    const double vn = dot(nrm, pointAt(v, n, p));
    const Vec3 force = q->gradient * (-k.stiffness * q->depth) - nrm * (k.damping * vn);
    f[p] += force.x;
    f[n + p] += force.y;
    f[2 * n + p] += force.z;
  }
  return true;
}

double ObstacleContact::penaltyEnergy(const double* x, int n) const {
  double e = 0.0;
  for (int p = 0; p < n; ++p) {
    if (const std::optional<Penetration> q = penetration(pointAt(x, n, p)))
      e += q->depth * q->depth;
  }
  return 0.5 * constants().stiffness * e;
}

void ObstacleContact::addPenaltyJacobian(const double* x, int n, JacobianBlocks& out) const {
  const ContactConstants& k = constants();
  for (int p = 0; p < n; ++p) {
    const std::optional<Penetration> q = penetration(pointAt(x, n, p));
    if (!q) continue;
    double* K = out.diagK + 9 * p;
    setOuter(K, q->gradient, q->gradient, -k.stiffness);
    if (!out.clampCompression) {
      for (int i = 0; i < 9; ++i) K[i] -= k.stiffness * q->depth * q->hessian[i];
    }
    const Vec3 nrm = unitVector(q->gradient * -1.0);
    setOuter(out.diagD + 9 * p, nrm, nrm, -k.damping);
  }
}

int ObstacleContact::penetrations(const Vec3& x, double reach, Penetration* out) const {
  if (const std::optional<Penetration> q = penetration(x)) {
    out[0] = *q;
    return 1;
  }
  if (!(reach > 0.0)) return 0;
  out[0] = cone_ ? coneExterior(*cone_, x) : spiralExterior(*spiral_, x);
  return out[0].depth > -reach ? 1 : 0;
}

double ObstacleContact::signedDistance(const Vec3& x) const {
  if (const std::optional<Penetration> q = penetration(x)) return -q->depth;
  return -(cone_ ? coneExterior(*cone_, x) : spiralExterior(*spiral_, x)).depth;
}

double ObstacleContact::depth(const Vec3& x) const {
  const std::optional<Penetration> q = penetration(x);
  return q ? q->depth : 0.0;
}

bool ObstacleContact::contactBegins(const double* x0, const double* x1, int n) const {
  for (int p = 0; p < n; ++p) {
    if (inside(pointAt(x1, n, p)) && !inside(pointAt(x0, n, p))) return true;
  }
  return false;
}

int ObstacleContact::contactSprings(const Vec3& x) const {
  return inside(x) ? 1 : 0;
}

void ObstacleContact::addContactWeights(const double* x, int n, std::ptrdiff_t lo,
                                        std::ptrdiff_t hi, double weight,
                                        const std::array<double*, 3>& w) const {
  addToAllCoordinates(lo, hi, weight, w,
                      [&](std::ptrdiff_t p) { return inside(pointAt(x, n, int(p))); });
}

void ObstacleContact::roots(const double* x, int n, double* g) const {
  for (int p = 0; p < n; ++p) {
    const Vec3 xp = pointAt(x, n, p);
    g[p] = cone_ ? signedDistance(xp) : spiralRoot(*spiral_, xp);
  }
}

}  // namespace jello
