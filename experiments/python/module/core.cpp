// jello._core: the simulator as a Python module (pybind11). jello/__init__.py re-exports it and
// defines the exception classes it raises (WorldError, Diverged). README "From Python".
//
// Conventions: positions, velocities and forces cross as (n, 3) float64 arrays; the state's
// own arrays are *views* (no copy) of the simulation's component-major vectors, so their
// strides are (8, 8n). Stepping releases the GIL and polls for Ctrl-C between steps.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "experiments/studies/stability_analysis.h"
#include "solvers/jacobian.h"
#include "solvers/linear_solver.h"
#include "solvers/simulation.h"
#include "solvers/solver_threads.h"
#include "src/model.h"
#include "src/scene_builder.h"
#include "src/state.h"
#include "src/world.h"
#include "src/world_reader.h"
#include "src/world_writer.h"

namespace py = pybind11;
using namespace py::literals;

namespace {

using jello::IntegratorKind;
using jello::State;
using jello::Vec3;
using jello::World;
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Clock = std::chrono::steady_clock;

// ---- conversions -------------------------------------------------------------------------

[[noreturn]] void valueError(const std::string& message) {
  throw py::value_error(message);
}

double finite(double v, const char* what) {
  if (!std::isfinite(v))
    valueError(std::string(what) + " must be finite, not " + std::to_string(v));
  return v;
}
double positive(double v, const char* what) {
  if (!(finite(v, what) > 0.0)) valueError(std::string(what) + " must be positive");
  return v;
}
double nonNegative(double v, const char* what) {
  if (finite(v, what) < 0.0) valueError(std::string(what) + " must not be negative");
  return v;
}
long inRange(long v, long lo, long hi, const char* what) {
  if (v < lo || v > hi) {
    valueError(std::string(what) + " must be between " + std::to_string(lo) + " and " +
               std::to_string(hi) + ", not " + std::to_string(v));
  }
  return v;
}

// A Python value as T, or TypeError naming what it was for (as a typed setter raises).
template <class T>
T as(const py::handle& v, const std::string& what) {
  try {
    return py::cast<T>(v);
  } catch (const py::cast_error&) {
    const char* kind = std::is_same_v<T, std::string> ? "a string"
                       : std::is_integral_v<T>        ? "an integer"
                       : std::is_floating_point_v<T>  ? "a number"
                                                      : "a sequence of numbers";
    throw py::type_error(what + " must be " + kind + ", not " +
                         std::string(py::str(py::type::of(v).attr("__name__"))));
  }
}

IntegratorKind integratorFrom(const std::string& name) {
  const auto kind = jello::parseIntegratorName(name);
  if (!kind) {
    valueError("unknown integrator '" + name + "' (known: " + jello::integratorNameList() + ")");
  }
  return *kind;
}

Vec3 vec3From(const py::handle& h, const char* what) {
  const auto v = as<std::vector<double>>(h, what);
  if (v.size() != 3) valueError(std::string(what) + " takes 3 numbers");
  return {finite(v[0], what), finite(v[1], what), finite(v[2], what)};
}

// A copy of a component-major 3n vector as an (n, 3) array.
py::array_t<double> pointsArray(const Eigen::VectorXd& a) {
  const py::ssize_t n = a.size() / 3;
  py::array_t<double> out({n, py::ssize_t(3)});
  auto m = out.mutable_unchecked<2>();
  for (py::ssize_t p = 0; p < n; ++p) {
    for (py::ssize_t c = 0; c < 3; ++c) m(p, c) = a[c * n + p];
  }
  return out;
}
py::array_t<double> pointsArray(const std::vector<Vec3>& a) {
  py::array_t<double> out({py::ssize_t(a.size()), py::ssize_t(3)});
  auto m = out.mutable_unchecked<2>();
  for (std::size_t p = 0; p < a.size(); ++p) {
    m(p, 0) = a[p].x;
    m(p, 1) = a[p].y;
    m(p, 2) = a[p].z;
  }
  return out;
}

// An (n, 3) array of finite numbers, checked against the expected n.
Array checkedPoints(const py::handle& h, py::ssize_t n, const char* what) {
  Array a = Array::ensure(h);
  if (!a) valueError(std::string(what) + " must be an array of numbers");
  if (a.ndim() != 2 || a.shape(1) != 3 || a.shape(0) != n) {
    std::ostringstream os;
    os << what << " must have shape (" << n << ", 3)";
    valueError(os.str());
  }
  auto r = a.unchecked<2>();
  for (py::ssize_t p = 0; p < n; ++p) {
    for (py::ssize_t c = 0; c < 3; ++c) {
      if (!std::isfinite(r(p, c))) valueError(std::string(what) + " must be finite");
    }
  }
  return a;
}
Eigen::VectorXd componentMajor(const py::handle& h, py::ssize_t n, const char* what) {
  const Array a = checkedPoints(h, n, what);
  auto r = a.unchecked<2>();
  Eigen::VectorXd out(3 * n);
  for (py::ssize_t p = 0; p < n; ++p) {
    for (py::ssize_t c = 0; c < 3; ++c) out[c * n + p] = r(p, c);
  }
  return out;
}
std::vector<Vec3> vec3List(const py::handle& h, py::ssize_t n, const char* what) {
  const Array a = checkedPoints(h, n, what);
  auto r = a.unchecked<2>();
  std::vector<Vec3> out(static_cast<std::size_t>(n));
  for (py::ssize_t p = 0; p < n; ++p) out[p] = {r(p, 0), r(p, 1), r(p, 2)};
  return out;
}

py::tuple vec3Tuple(const Vec3& v) {
  return py::make_tuple(v.x, v.y, v.z);
}

py::dict energyDict(const jello::Energy& e) {
  return py::dict("kinetic_J"_a = e.kinetic, "spring_J"_a = e.spring, "contact_J"_a = e.contact,
                  "total_J"_a = e.total());
}

// ---- exceptions ----------------------------------------------------------------------------

// Raised as jello.Diverged (jello/__init__.py), with the last sane state.
struct DivergedError {
  jello::Divergence divergence;
  State lastSane;
};

py::object jelloAttr(const char* name) {
  return py::module_::import("jello").attr(name);
}

void translateExceptions(std::exception_ptr p) {
  try {
    if (p) std::rethrow_exception(p);
  } catch (const jello::WorldFileError& e) {
    const py::object type = jelloAttr("WorldError");
    const py::object error = type(e.what(), e.file(), e.line(), e.token());
    PyErr_SetObject(type.ptr(), error.ptr());
  } catch (const DivergedError& e) {
    const jello::Divergence& d = e.divergence;
    const py::object type = jelloAttr("Diverged");
    const py::object error =
        type(d.describe(), d.time, d.step, std::string(jello::integratorName(d.integrator)),
             d.reason, pointsArray(e.lastSane.x), pointsArray(e.lastSane.v));
    PyErr_SetObject(type.ptr(), error.ptr());
  }
}

// ---- solver options from keywords -----------------------------------------------------------

// The keywords mirror jello-sim's flags with '_' for '-' (README "From Python").
constexpr const char* kSolverOptionNames =
    "linear_solver, preconditioner, matrix_free, clamp, cg_tol, newton_iters, newton_tol, "
    "newton_xtol, factor_reuse, "
    "refactor_ratio, projective_iters, projective_tol, rtol, cvode_method, cvode_krylov, atol, "
    "atol_x, atol_v, contact_roots, max_order, stab_lim_det, max_step";

bool boolOption(const py::handle& v, const std::string& name) {
  if (!py::isinstance<py::bool_>(v)) valueError(name + " must be True or False");
  return v.cast<bool>();
}

jello::SolverOptions solverOptionsFrom(const py::kwargs& kwargs, jello::SolverOptions o) {
  std::optional<double> atol;
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::cast<std::string>(key);
    const char* n = name.c_str();
    const auto real = [&] { return as<double>(value, name); };
    if (name == "linear_solver") {
      const auto kind = jello::parseLinearSolver(as<std::string>(value, name));
      if (!kind) valueError("linear_solver must be 'cholmod', 'ldlt' or 'cg'");
      o.implicit.linearSolver = o.cvode.linearSolver = *kind;
    } else if (name == "preconditioner") {
      const auto kind = jello::parsePreconditioner(as<std::string>(value, name));
      if (!kind) valueError("preconditioner must be 'jacobi', 'block-jacobi', 'ichol' or 'factor'");
      o.implicit.preconditioner = o.cvode.preconditioner = *kind;
    } else if (name == "matrix_free") {
      o.implicit.matrixFree = o.cvode.matrixFree = boolOption(value, name);
    } else if (name == "clamp") {
      o.implicit.clampCompression = o.cvode.clampCompression = boolOption(value, name);
    } else if (name == "cg_tol") {
      o.implicit.cgTolerance = o.cvode.cgTolerance = positive(real(), n);
    } else if (name == "newton_iters") {
      o.implicit.newtonMaxIterations = int(inRange(as<long>(value, name), 1, 1000, n));
    } else if (name == "newton_tol") {
      o.implicit.newtonTolerance = positive(real(), n);
    } else if (name == "newton_xtol") {
      o.implicit.newtonPositionTolerance = positive(real(), n);
    } else if (name == "factor_reuse") {
      o.implicit.reuseFactor = boolOption(value, name);
    } else if (name == "refactor_ratio") {
      const double r = positive(real(), n);
      if (r < 1e-6 || r > 1.0) valueError("refactor_ratio must be between 1e-6 and 1");
      o.implicit.refactorRatio = r;
    } else if (name == "projective_iters") {
      o.projective.iterations = int(inRange(as<long>(value, name), 1, 100000, n));
    } else if (name == "projective_tol") {
      o.projective.tolerance = nonNegative(real(), n);
    } else if (name == "rtol") {
      o.cvode.rtol = positive(real(), n);
    } else if (name == "cvode_method") {
      const std::string m = as<std::string>(value, name);
      if (m != "bdf" && m != "adams") valueError("cvode_method must be 'bdf' or 'adams'");
      o.cvode.method = m == "adams" ? jello::CvodeMethod::Adams : jello::CvodeMethod::Bdf;
    } else if (name == "atol") {
      atol = positive(real(), n);
    } else if (name == "atol_x") {
      o.cvode.atolPosition = positive(real(), n);
    } else if (name == "atol_v") {
      o.cvode.atolVelocity = positive(real(), n);
    } else if (name == "cvode_krylov") {
      o.cvode.krylov = boolOption(value, name);
    } else if (name == "contact_roots") {
      o.cvode.contactRoots = boolOption(value, name);
    } else if (name == "max_order") {
      o.cvode.maxOrder = int(inRange(as<long>(value, name), 1, 5, n));
    } else if (name == "stab_lim_det") {
      o.cvode.stabilityLimitDetection = boolOption(value, name);
    } else if (name == "max_step") {
      o.cvode.maxStep = positive(real(), n);
    } else {
      valueError("unknown solver option '" + name + "' (known: " + kSolverOptionNames + ")");
    }
  }
  // atol sets both; atol_x and atol_v win over it (as jello-sim's --atol).
  if (atol) {
    if (!kwargs.contains("atol_x")) o.cvode.atolPosition = *atol;
    if (!kwargs.contains("atol_v")) o.cvode.atolVelocity = *atol;
  }
  return o;
}

// ---- worlds --------------------------------------------------------------------------------

World loadWorld(const std::string& path, int maxFieldResolution, int maxCubeResolution) {
  jello::ReaderLimits limits;
  limits.maxFieldResolution = int(inRange(maxFieldResolution, 2, 1024, "max_field_resolution"));
  limits.maxCubeResolution = int(inRange(maxCubeResolution, 2, 256, "max_cube_resolution"));
  return jello::readWorld(path, limits);
}

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is three packed doubles");

py::object fieldArray(const World& w) {
  if (w.field.empty()) return py::none();
  const py::ssize_t r = w.field.resolution;
  py::array_t<double> out({r, r, r, py::ssize_t(3)});
  std::memcpy(out.mutable_data(), w.field.forces.data(), w.field.forces.size() * sizeof(Vec3));
  return out;
}

void setField(World& w, const py::object& value) {
  if (value.is_none()) {
    w.field = {};
    return;
  }
  const Array a = Array::ensure(value);
  if (!a || a.ndim() != 4 || a.shape(3) != 3 || a.shape(0) != a.shape(1) ||
      a.shape(0) != a.shape(2)) {
    valueError("field must be an (R, R, R, 3) array of forces (N), or None");
  }
  const py::ssize_t r = a.shape(0);
  if (r < 2 || r > 128) valueError("field resolution R must be between 2 and 128");
  jello::ForceField f;
  f.resolution = int(r);
  f.forces.resize(static_cast<std::size_t>(r * r * r));
  const double* d = a.data();
  for (std::size_t i = 0; i < f.forces.size(); ++i) {
    f.forces[i] = {finite(d[3 * i], "field"), finite(d[3 * i + 1], "field"),
                   finite(d[3 * i + 2], "field")};
  }
  w.field = std::move(f);
}

bool sameWorld(const World& a, const World& b) {
  const auto samePoints = [](const std::vector<Vec3>& p, const std::vector<Vec3>& q) {
    return p.size() == q.size() &&
           std::equal(p.begin(), p.end(), q.begin(), [](const Vec3& u, const Vec3& v) {
             return u.x == v.x && u.y == v.y && u.z == v.z;
           });
  };
  const auto samePlane = [](const std::optional<jello::Plane>& p,
                            const std::optional<jello::Plane>& q) {
    return p.has_value() == q.has_value() &&
           (!p || (p->a == q->a && p->b == q->b && p->c == q->c && p->d == q->d));
  };
  const auto sameSphere = [](const std::optional<jello::Sphere>& p,
                             const std::optional<jello::Sphere>& q) {
    return p.has_value() == q.has_value() &&
           (!p || (p->center.x == q->center.x && p->center.y == q->center.y &&
                   p->center.z == q->center.z && p->radius == q->radius));
  };
  return a.integrator == b.integrator && a.dt == b.dt && a.stepsPerFrame == b.stepsPerFrame &&
         a.kElastic == b.kElastic && a.dElastic == b.dElastic && a.kCollision == b.kCollision &&
         a.dCollision == b.dCollision && a.mass == b.mass && samePlane(a.plane, b.plane) &&
         a.field.resolution == b.field.resolution && samePoints(a.field.forces, b.field.forces) &&
         a.cubeResolution == b.cubeResolution && samePoints(a.positions, b.positions) &&
         samePoints(a.velocities, b.velocities) && sameSphere(a.sphere, b.sphere);
}

void saveWorld(const World& w, const std::string& path, bool legacy) {
  try {
    jello::writeWorld(w, path, legacy ? jello::NumberFormat::Legacy : jello::NumberFormat::Exact);
  } catch (const std::runtime_error& e) {
    PyErr_SetString(PyExc_OSError, e.what());
    throw py::error_already_set();
  }
}

// jello-create-world's flags as keywords ('-' -> '_'): the same presets, and the same check
// that the world reads back.
World createWorld(const py::kwargs& kwargs) {
  jello::SceneSpec spec;
  std::optional<double> fieldStrength;
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::cast<std::string>(key);
    const char* n = name.c_str();
    const auto real = [&] { return as<double>(value, name); };
    if (name == "integrator") {
      spec.integrator = integratorFrom(as<std::string>(value, name));
    } else if (name == "dt") {
      spec.dt = positive(real(), n);
    } else if (name == "steps_per_frame") {
      spec.stepsPerFrame = int(inRange(as<long>(value, name), 1, 1000000, n));
    } else if (name == "k_elastic") {
      spec.kElastic = nonNegative(real(), n);
    } else if (name == "d_elastic") {
      spec.dElastic = nonNegative(real(), n);
    } else if (name == "k_collision") {
      spec.kCollision = nonNegative(real(), n);
    } else if (name == "d_collision") {
      spec.dCollision = nonNegative(real(), n);
    } else if (name == "mass") {
      spec.mass = positive(real(), n);
    } else if (name == "plane") {
      if (value.is_none()) {
        spec.plane.reset();
      } else {
        const auto p = as<std::vector<double>>(value, name);
        if (p.size() != 4) valueError("plane takes 4 numbers A B C D, or None");
        spec.plane =
            jello::Plane{finite(p[0], n), finite(p[1], n), finite(p[2], n), finite(p[3], n)};
      }
    } else if (name == "field") {
      const std::string f = as<std::string>(value, name);
      if (f == "none")
        spec.field = jello::FieldPreset::None;
      else if (f == "gravity")
        spec.field = jello::FieldPreset::Gravity;
      else if (f == "vortex")
        spec.field = jello::FieldPreset::Vortex;
      else if (f == "radial")
        spec.field = jello::FieldPreset::Radial;
      else
        valueError("field must be 'none', 'gravity', 'vortex' or 'radial'");
    } else if (name == "field_strength") {
      fieldStrength = finite(real(), n);
    } else if (name == "field_resolution") {
      const long r = inRange(as<long>(value, name), 0, 128, n);
      if (r == 1) valueError("field_resolution must be 0 (no field) or between 2 and 128");
      spec.fieldResolution = int(r);
    } else if (name == "pose") {
      const std::string p = as<std::string>(value, name);
      if (p == "rest")
        spec.pose = jello::PosePreset::Rest;
      else if (p == "skewed")
        spec.pose = jello::PosePreset::SkewedCorner;
      else if (p == "stretched")
        spec.pose = jello::PosePreset::Stretched;
      else if (p == "rotated")
        spec.pose = jello::PosePreset::Rotated;
      else if (p == "translated")
        spec.pose = jello::PosePreset::Translated;
      else
        valueError("pose must be 'rest', 'skewed', 'stretched', 'rotated' or 'translated'");
    } else if (name == "stretch") {
      spec.stretch = positive(real(), n);
    } else if (name == "rotate") {
      spec.rotateDegrees = finite(real(), n);
    } else if (name == "axis") {
      spec.rotateAxis = vec3From(value, n);
      if (jello::maxAbs(spec.rotateAxis) == 0.0) valueError("axis must not be zero");
    } else if (name == "translate") {
      spec.translate = vec3From(value, n);
    } else if (name == "velocity") {
      spec.velocity = vec3From(value, n);
    } else if (name == "spin") {
      spec.spin = finite(real(), n);
    } else if (name == "sphere") {
      if (value.is_none()) {
        spec.sphere.reset();
      } else {
        const auto s = as<std::vector<double>>(value, name);
        if (s.size() != 4) valueError("sphere takes 4 numbers CX CY CZ R, or None");
        spec.sphere = jello::Sphere{{finite(s[0], n), finite(s[1], n), finite(s[2], n)},
                                    positive(s[3], "sphere radius")};
      }
    } else if (name == "cube") {
      spec.cubeResolution = int(inRange(as<long>(value, name), 2, 64, n));
    } else {
      valueError("unknown create_world option '" + name +
                 "' (known: integrator, dt, steps_per_frame, k_elastic, d_elastic, k_collision, "
                 "d_collision, mass, plane, field, field_strength, field_resolution, pose, "
                 "stretch, rotate, axis, translate, velocity, spin, sphere, cube)");
    }
  }
  spec.fieldStrength = fieldStrength.value_or(jello::defaultFieldStrength(spec.field, spec.mass));
  const World world = jello::buildWorld(spec);
  try {
    // As jello-create-world: whatever the options, the world must read back.
    return jello::parseWorld(jello::formatWorld(world), "create_world");
  } catch (const jello::WorldFileError& e) {
    valueError(std::string("these options make no valid world: ") + e.what());
  }
}

// ---- the simulation ------------------------------------------------------------------------

class PySimulation;

// The base object of a state view: keeps the simulation alive and counts the live views, so
// that only while some exist (or after one died) is the state compared with its last copy.
struct ViewGuard {
  PySimulation* owner = nullptr;
  py::object keepAlive;
  ViewGuard(PySimulation* o, py::object k) : owner(o), keepAlive(std::move(k)) {}
  ViewGuard(ViewGuard&& other) noexcept
      : owner(std::exchange(other.owner, nullptr)), keepAlive(std::move(other.keepAlive)) {}
  ViewGuard(const ViewGuard&) = delete;
  ViewGuard& operator=(const ViewGuard&) = delete;
  ViewGuard& operator=(ViewGuard&&) = delete;
  ~ViewGuard();
};

class PySimulation {
 public:
  PySimulation(World world, std::optional<std::string> integrator, std::optional<double> dt,
               const py::kwargs& options)
      : sim_(std::move(world),
             integrator ? std::optional(integratorFrom(*integrator)) : std::nullopt,
             dt ? std::optional(positive(*dt, "dt")) : std::nullopt,
             solverOptionsFrom(options, {})) {
    positive(sim_.dt(), "dt");
    energyStart_ = sim_.model().energy(sim_.state());
    angularStart_ = sim_.model().angularMomentum(sim_.state());
  }

  jello::Simulation& sim() { return sim_; }
  const jello::Simulation& sim() const { return sim_; }

  // Steps `count` times (GIL released), calling callback(self) every `every` steps; polls
  // Ctrl-C between steps. Returns the steps done (fewer when the callback returned False).
  long advance(py::object self, long count, const py::object& callback, long every) {
    Busy busy(*this);
    checkEdits();
    // Stepping time only: the callbacks' time is left out. The snapshot is refreshed however
    // the call ends (a Ctrl-C, a callback's exception, a divergence).
    struct Finish {
      PySimulation& s;
      Clock::time_point t0 = Clock::now();
      double outside = 0.0;
      ~Finish() {
        s.wall_ += std::chrono::duration<double>(Clock::now() - t0).count() - outside;
        s.refreshSnapshot();
      }
    } finish{*this};
    long done = 0;
    bool failed = false, interrupted = false;
    {
      py::gil_scoped_release nogil;
      auto lastPoll = finish.t0;
      while (done < count) {
        const jello::StepResult r = sim_.step();
        if (!r.ok) {
          failed = !r.interrupted;
          interrupted = r.interrupted;
          break;
        }
        ++done;
        const bool callNow = !callback.is_none() && done % every == 0;
        bool poll = callNow;
        if (!poll && count > 1) {
          const auto now = Clock::now();
          if (now - lastPoll > std::chrono::milliseconds(20)) {
            poll = true;
            lastPoll = now;
          }
        }
        if (!poll) continue;
        py::gil_scoped_acquire gil;
        // Ctrl-C (or any signal handler raising) ends the run at this step boundary.
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        if (callNow) {
          const auto c0 = Clock::now();
          refreshSnapshot();
          inCallback_ = true;
          struct Leave {
            bool& flag;
            ~Leave() { flag = false; }
          } leave{inCallback_};
          const py::object go = callback(self);
          checkEdits();  // the callback may have written through a view
          finish.outside += std::chrono::duration<double>(Clock::now() - c0).count();
          if (!go.is_none() && !go.cast<bool>()) break;
        }
      }
    }
    if (interrupted) {
      PyErr_SetNone(PyExc_KeyboardInterrupt);
      throw py::error_already_set();
    }
    if (failed) {
      if (const auto& d = sim_.divergence()) throw DivergedError{*d, sim_.state()};
      throw std::runtime_error("step failed");
    }
    return done;
  }

  // Reading while another thread steps would see a half-written state.
  void requireIdle() const {
    if (busy_ && !inCallback_) {
      throw std::runtime_error("the simulation is stepping in another thread");
    }
  }

  // A view of x or v as (n, 3), writable, aliasing the state.
  py::array view(py::object self, bool velocities) {
    State& s = sim_.editableState();
    Eigen::VectorXd& a = velocities ? s.v : s.x;
    const py::ssize_t n = a.size() / 3;
    if (liveViews_ == 0 && !viewsDied_) refreshSnapshot(/*force=*/true);
    ++liveViews_;
    py::object guard = py::cast(ViewGuard(this, std::move(self)));
    return py::array_t<double>({n, py::ssize_t(3)},
                               {py::ssize_t(sizeof(double)), py::ssize_t(sizeof(double)) * n},
                               a.data(), guard);
  }
  void viewDied() {
    --liveViews_;
    viewsDied_ = true;
  }

  // Compares the state with its copy after the last step: a write through a view is news to
  // the integrator (and to the energy rule).
  void noticeEdits() {
    requireIdle();
    checkEdits();
  }
  void checkEdits() {
    if (liveViews_ == 0 && !viewsDied_) return;
    viewsDied_ = false;
    const State& s = sim_.state();
    if (s.x == snapX_ && s.v == snapV_) return;
    if (!std::isfinite(s.x.sum() + s.v.sum())) {
      sim_.editableState().x = snapX_;
      sim_.editableState().v = snapV_;
      valueError("positions or velocities written through a view are not finite (undone)");
    }
    sim_.stateEdited();
    snapX_ = s.x;
    snapV_ = s.v;
  }

  void setIntegrator(const std::string& name, const py::kwargs& options) {
    Busy busy(*this);
    checkEdits();
    sim_.setIntegrator(integratorFrom(name), solverOptionsFrom(options, sim_.solverOptions()));
    forgiveDivergence();
  }

  // Another integrator or step may well not diverge from the last sane state: it may try.
  void forgiveDivergence() {
    if (sim_.divergence()) sim_.stateEdited();
  }

  void setDt(double dt) {
    Busy busy(*this);
    checkEdits();
    sim_.setTimeStep(positive(dt, "dt"));
    forgiveDivergence();
  }

  void setUserForce(const py::object& f) {
    Busy busy(*this);
    checkEdits();
    if (f.is_none()) {
      sim_.clearUserForce();
    } else {
      sim_.setUserForce(componentMajor(f, sim_.model().numPoints(), "user force"));
    }
  }

  py::dict energy() {
    noticeEdits();
    const jello::Energy e = sim_.model().energy(sim_.state());
    const double field = 0.0 - sim_.fieldWork(), user = 0.0 - sim_.userForceWork();  // +0 J
    return py::dict("kinetic"_a = e.kinetic, "spring"_a = e.spring, "contact"_a = e.contact,
                    "field"_a = field, "user"_a = user, "total"_a = e.total() + field + user);
  }

  py::dict stats() {
    noticeEdits();
    const State& s = sim_.state();
    const jello::Model& model = sim_.model();
    const Vec3 L = model.angularMomentum(s);
    py::dict solver;
    for (const jello::Statistic& st : sim_.integrator().statistics())
      solver[st.name.c_str()] = st.value;
    const long steps = sim_.divergence() ? sim_.steps() - 1 : sim_.steps();
    py::dict d(
        "integrator"_a = std::string(jello::integratorName(sim_.integratorKind())),
        "dt_s"_a = sim_.dt(), "points"_a = s.numPoints(),
        "springs"_a = model.springs().numSprings(), "steps"_a = steps, "simulated_time_s"_a = s.t,
        "wall_time_s"_a = wall_, "steps_per_s"_a = wall_ > 0 ? double(steps) / wall_ : 0.0,
        "real_time_factor"_a = wall_ > 0 ? s.t / wall_ : 0.0,
        "energy_start"_a = energyDict(energyStart_), "energy_end"_a = energyDict(model.energy(s)),
        "angular_momentum_start_kg_m2_per_s"_a = vec3Tuple(angularStart_),
        "angular_momentum_end_kg_m2_per_s"_a = vec3Tuple(L),
        "diverged"_a = sim_.divergence().has_value(), "solver"_a = solver);
    if (const auto& div = sim_.divergence()) {
      d["divergence"] =
          py::dict("time_s"_a = div->time, "step"_a = div->step, "reason"_a = div->reason);
    }
    return d;
  }

 private:
  // One call at a time: stepping releases the GIL, so another Python thread could come in.
  struct Busy {
    PySimulation& s;
    explicit Busy(PySimulation& sim) : s(sim) {
      if (s.busy_.exchange(true)) {
        throw std::runtime_error(
            "the simulation is busy (stepping in another thread, or this is its own callback)");
      }
    }
    ~Busy() { s.busy_ = false; }
  };

  void refreshSnapshot(bool force = false) {
    if (!force && liveViews_ == 0) return;
    snapX_ = sim_.state().x;
    snapV_ = sim_.state().v;
  }

  jello::Simulation sim_;
  std::atomic<bool> busy_{false};
  bool inCallback_ = false;
  int liveViews_ = 0;
  bool viewsDied_ = false;
  Eigen::VectorXd snapX_, snapV_;
  double wall_ = 0.0;
  jello::Energy energyStart_;
  Vec3 angularStart_;
};

ViewGuard::~ViewGuard() {
  if (owner) owner->viewDied();
}

long stepsFor(const PySimulation& s, std::optional<double> time, std::optional<long> steps) {
  if (time.has_value() == steps.has_value()) valueError("give exactly one of time= and steps=");
  if (steps) {
    if (*steps < 0) valueError("steps must not be negative");
    return *steps;
  }
  const double wanted = std::ceil(nonNegative(*time, "time") / s.sim().dt() - 1e-9);
  if (!(wanted <= 1e12)) valueError("more than 1e12 steps asked for");
  return static_cast<long>(std::max(0.0, wanted));
}

// forces(world_or_simulation, positions=None, velocities=None) as (n, 3).
py::array_t<double> forcesOf(const jello::Model& model, const State& at, const py::object& x,
                             const py::object& v) {
  const py::ssize_t n = model.numPoints();
  const Eigen::VectorXd xs = x.is_none() ? at.x : componentMajor(x, n, "positions");
  const Eigen::VectorXd vs = v.is_none() ? at.v : componentMajor(v, n, "velocities");
  Eigen::VectorXd f;
  model.forces(xs, vs, f);
  return pointsArray(f);
}

py::object csr(const jello::SparseMatrix& m) {
  const py::module_ sparse = py::module_::import("scipy.sparse");
  const Eigen::Index nnz = m.nonZeros();
  py::array_t<double> data(nnz);
  py::array_t<int> indices(nnz);
  py::array_t<int> indptr(m.cols() + 1);
  std::memcpy(data.mutable_data(), m.valuePtr(), nnz * sizeof(double));
  std::memcpy(indices.mutable_data(), m.innerIndexPtr(), nnz * sizeof(int));
  std::memcpy(indptr.mutable_data(), m.outerIndexPtr(), (m.cols() + 1) * sizeof(int));
  const py::object csc = sparse.attr("csc_matrix")(py::make_tuple(data, indices, indptr),
                                                   "shape"_a = py::make_tuple(m.rows(), m.cols()));
  return csc.attr("tocsr")();
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "jello's simulator core; use it through the jello package (README \"From Python\")";
  py::register_exception_translator(&translateExceptions);

  py::class_<ViewGuard>(m, "_StateView");

  // ---- World
  py::class_<World>(m, "World",
                    "One jello scene as a world file holds it. Attributes are copies; set them "
                    "to change the world (checked: ValueError on a bad value).")
      .def(py::init([] { return jello::buildWorld(jello::SceneSpec{}); }),
           "The course creator's default world (jello.w's values); see create_world")
      .def_property(
          "integrator",
          [](const World& w) { return std::string(jello::integratorName(w.integrator)); },
          [](World& w, const std::string& name) { w.integrator = integratorFrom(name); })
      .def_property(
          "dt", [](const World& w) { return w.dt; },
          [](World& w, double v) { w.dt = positive(v, "dt"); }, "time step, s")
      .def_property(
          "steps_per_frame", [](const World& w) { return w.stepsPerFrame; },
          [](World& w, long v) {
            w.stepsPerFrame = int(inRange(v, 1, 1000000, "steps_per_frame"));
          })
      .def_property(
          "k", [](const World& w) { return w.kElastic; },
          [](World& w, double v) { w.kElastic = nonNegative(v, "k"); },
          "spring stiffness, N/m (structural, shear and bend)")
      .def_property(
          "damping", [](const World& w) { return w.dElastic; },
          [](World& w, double v) { w.dElastic = nonNegative(v, "damping"); },
          "spring damping, N*s/m")
      .def_property(
          "k_collision", [](const World& w) { return w.kCollision; },
          [](World& w, double v) { w.kCollision = nonNegative(v, "k_collision"); },
          "contact stiffness, N/m")
      .def_property(
          "d_collision", [](const World& w) { return w.dCollision; },
          [](World& w, double v) { w.dCollision = nonNegative(v, "d_collision"); },
          "contact damping, N*s/m")
      .def_property(
          "mass", [](const World& w) { return w.mass; },
          [](World& w, double v) { w.mass = positive(v, "mass"); }, "mass of each point, kg")
      .def_property(
          "plane",
          [](const World& w) -> py::object {
            if (!w.plane) return py::none();
            return py::make_tuple(w.plane->a, w.plane->b, w.plane->c, w.plane->d);
          },
          [](World& w, const py::object& v) {
            if (v.is_none()) {
              w.plane.reset();
              return;
            }
            const auto p = as<std::vector<double>>(v, "value");
            if (p.size() != 4) valueError("plane takes 4 numbers (a, b, c, d), or None");
            const jello::Plane plane{finite(p[0], "plane"), finite(p[1], "plane"),
                                     finite(p[2], "plane"), finite(p[3], "plane")};
            if (plane.a == 0.0 && plane.b == 0.0 && plane.c == 0.0) {
              valueError("the plane normal (a, b, c) is zero");
            }
            w.plane = plane;
          },
          "inclined plane (a, b, c, d): a x + b y + c z + d = 0, free where positive; or None")
      .def_property(
          "sphere",
          [](const World& w) -> py::object {
            if (!w.sphere) return py::none();
            const jello::Sphere& s = *w.sphere;
            return py::make_tuple(s.center.x, s.center.y, s.center.z, s.radius);
          },
          [](World& w, const py::object& v) {
            if (v.is_none()) {
              w.sphere.reset();
              return;
            }
            const auto s = as<std::vector<double>>(v, "value");
            if (s.size() != 4) valueError("sphere takes 4 numbers (cx, cy, cz, r), or None");
            w.sphere = jello::Sphere{
                {finite(s[0], "sphere"), finite(s[1], "sphere"), finite(s[2], "sphere")},
                positive(s[3], "sphere radius")};
          },
          "sphere obstacle (cx, cy, cz, r), m; or None")
      .def_property("field", &fieldArray, &setField,
                    "force field on R^3 nodes over the box [-2, 2]^3, an (R, R, R, 3) array (N), "
                    "node (i, j, k) at x = -2 + 4 i/(R-1), ...; or None")
      .def_property(
          "cube_resolution", [](const World& w) { return w.cubeResolution; },
          [](World& w, long n) {
            w = jello::resampleCube(w, int(inRange(n, 2, 64, "cube_resolution")));
          },
          "N: the cube has N^3 points; setting it resamples the state (as jello-sim --cube)")
      .def_property_readonly("num_points", &World::numPoints)
      .def_property(
          "positions", [](const World& w) { return pointsArray(w.positions); },
          [](World& w, const py::object& v) {
            w.positions = vec3List(v, w.numPoints(), "positions");
          },
          "(n, 3) initial positions, m (a copy)")
      .def_property(
          "velocities", [](const World& w) { return pointsArray(w.velocities); },
          [](World& w, const py::object& v) {
            w.velocities = vec3List(v, w.numPoints(), "velocities");
          },
          "(n, 3) initial velocities, m/s (a copy)")
      .def("save", &saveWorld, "path"_a, "legacy"_a = false,
           "Writes the world file atomically (exact numbers; legacy=True: six decimals)")
      .def("copy", [](const World& w) { return World(w); })
      .def("__copy__", [](const World& w) { return World(w); })
      .def("__deepcopy__", [](const World& w, const py::object&) { return World(w); })
      .def("__eq__", [](const World& a, const World& b) { return sameWorld(a, b); })
      .def("__repr__", [](const World& w) {
        std::ostringstream os;
        os << "<jello.World " << w.cubeResolution << "^3 points, "
           << jello::integratorName(w.integrator) << " dt=" << w.dt << ", k=" << w.kElastic
           << ", damping=" << w.dElastic << (w.plane ? ", plane" : "")
           << (w.sphere ? ", sphere" : "")
           << (w.field.empty() ? "" : ", field " + std::to_string(w.field.resolution) + "^3")
           << ">";
        return os.str();
      });

  m.def("load_world", &loadWorld, "path"_a, "max_field_resolution"_a = 128,
        "max_cube_resolution"_a = 64,
        "Reads a world file; raises jello.WorldError (file, line, token) on a bad one.",
        py::call_guard<py::gil_scoped_release>());
  m.def(
      "parse_world",
      [](const std::string& text, const std::string& name) {
        return jello::parseWorld(text, name);
      },
      "text"_a, "name"_a = "<string>", "Reads a world from text (errors call it `name`).");
  m.def("create_world", &createWorld,
        "A world from jello-create-world's options as keywords ('-' becomes '_'): integrator, "
        "dt, steps_per_frame, k_elastic, d_elastic, k_collision, d_collision, mass, plane "
        "(4 numbers or None), field ('none', 'gravity', 'vortex', 'radial'), field_strength, "
        "field_resolution, pose ('rest', 'skewed', 'stretched', 'rotated', 'translated'), "
        "stretch, rotate, axis, translate, velocity, spin, sphere (4 numbers), cube. With none: "
        "the course's jello.w.");
  m.def(
      "integrators",
      [] {
        py::dict d;
        for (IntegratorKind k : jello::allIntegrators()) {
          d[py::str(std::string(jello::integratorName(k)))] =
              std::string(jello::integratorSummary(k));
        }
        return d;
      },
      "Every integrator's name and a line about it, in the table's order.");
  m.def("loaded_blas", &jello::loadedBlas, "The BLAS library this process loaded.");

  // ---- Simulation
  py::class_<PySimulation>(m, "Simulation",
                           "A world being stepped: Simulation(world, integrator=None, dt=None, "
                           "**solver_options). integrator and dt default to the world's; the "
                           "solver options are jello-sim's flags with '_' (README).")
      .def(py::init([](World world, std::optional<std::string> integrator, std::optional<double> dt,
                       const py::kwargs& options) {
             return std::make_unique<PySimulation>(std::move(world), integrator, dt, options);
           }),
           "world"_a, "integrator"_a = py::none(), "dt"_a = py::none())
      .def(
          "step",
          [](py::object self, long n) {
            PySimulation& s = self.cast<PySimulation&>();
            if (n < 0) valueError("n must not be negative");
            return s.advance(self, n, py::none(), 1);
          },
          "n"_a = 1, "Takes n steps of dt (GIL released); raises jello.Diverged.")
      .def(
          "run",
          [](py::object self, std::optional<double> time, std::optional<long> steps,
             const py::object& callback, long every) {
            PySimulation& s = self.cast<PySimulation&>();
            if (every < 1) valueError("every must be at least 1");
            return s.advance(self, stepsFor(s, time, steps), callback, every);
          },
          "time"_a = py::none(), "steps"_a = py::none(), "callback"_a = py::none(), "every"_a = 1,
          "Runs for `time` seconds (ceil(time/dt) steps) or `steps` steps, calling "
          "callback(sim) every `every` steps (it may return False to stop). Ctrl-C stops it at "
          "a step boundary (KeyboardInterrupt). Returns the steps taken.")
      .def_property_readonly("t", [](const PySimulation& s) { return s.sim().state().t; })
      .def_property_readonly("steps", [](const PySimulation& s) { return s.sim().steps(); })
      .def_property(
          "dt", [](const PySimulation& s) { return s.sim().dt(); }, &PySimulation::setDt)
      .def_property_readonly("integrator",
                             [](const PySimulation& s) {
                               return std::string(jello::integratorName(s.sim().integratorKind()));
                             })
      .def_property_readonly(
          "positions", [](py::object self) { return self.cast<PySimulation&>().view(self, false); },
          "(n, 3) view of the positions (m): no copy, writable; a write is noticed at the next "
          "call (the integrator restarts, as after the viewer's integrator switch)")
      .def_property_readonly(
          "velocities", [](py::object self) { return self.cast<PySimulation&>().view(self, true); },
          "(n, 3) view of the velocities (m/s), like positions")
      .def_property_readonly("num_points",
                             [](const PySimulation& s) { return s.sim().model().numPoints(); })
      .def("energy", &PySimulation::energy,
           "Energy (J): kinetic, spring, contact; field and user: minus the work the force field "
           "and the user force have done since the start; total: their sum (changed only by "
           "damping and by the integrator's error)")
      .def(
          "momentum",
          [](PySimulation& s) {
            s.noticeEdits();
            const State& st = s.sim().state();
            const Eigen::Index n = st.numPoints();
            const double mass = s.sim().model().mass();
            return py::make_tuple(mass * st.v.head(n).sum(), mass * st.v.segment(n, n).sum(),
                                  mass * st.v.tail(n).sum());
          },
          "Linear momentum (kg m/s)")
      .def(
          "angular_momentum",
          [](PySimulation& s) {
            s.noticeEdits();
            return vec3Tuple(s.sim().model().angularMomentum(s.sim().state()));
          },
          "Angular momentum about the centre of mass (kg m^2/s)")
      .def_property_readonly("stats", &PySimulation::stats,
                             "The summary jello-sim --stats writes, as a dict")
      .def_property_readonly(
          "diverged",
          [](PySimulation& s) {
            s.noticeEdits();  // a sane state written through a view clears a divergence
            return s.sim().divergence().has_value();
          },
          "True after a divergence, until the state is edited, the integrator switched or dt "
          "changed")
      .def("set_integrator", &PySimulation::setIntegrator, "name"_a,
           "Switches the integrator, keeping the state; keywords change solver options (the "
           "others stay as they were).")
      .def("set_user_force", &PySimulation::setUserForce, "forces"_a,
           "A constant external force per point, (n, 3) N; None removes it.")
      .def(
          "jacobian",
          [](PySimulation& s, const py::object& positions, bool clamp, bool field) {
            s.noticeEdits();
            const jello::Model& model = s.sim().model();
            const Eigen::VectorXd x =
                positions.is_none() ? s.sim().state().x
                                    : componentMajor(positions, model.numPoints(), "positions");
            jello::JacobianAssembler assembler(model);
            jello::JacobianOptions options;
            options.clampCompression = clamp;
            options.includeField = field;
            assembler.assemble(x.data(), options);
            return py::make_tuple(csr(assembler.K()), csr(assembler.D()));
          },
          "positions"_a = py::none(), "clamp"_a = false, "field"_a = true,
          "(K, D) = (df/dx, df/dv) as 3n x 3n scipy.sparse.csr_matrix, component-major (row "
          "c*n + p: component c of point p). Exact by default but for the damping forces' "
          "dependence on x, which is left out (src/PHYSICS.md; it vanishes at v = 0); "
          "clamp=True gives the implicit solvers' clamped K, field=False leaves out the "
          "field's gradient.")
      .def(
          "world",
          [](PySimulation& s) {
            s.noticeEdits();
            return s.sim().currentWorld();
          },
          "The world with the current state as its initial state (what jello-sim --out saves)")
      .def(
          "save",
          [](PySimulation& s, const std::string& path) {
            s.noticeEdits();
            saveWorld(s.sim().currentWorld(), path, false);
          },
          "path"_a, "Writes the current state as a world file (as jello-sim --out)");

  m.def(
      "forces",
      [](const py::object& of, const py::object& positions, const py::object& velocities) {
        if (py::isinstance<PySimulation>(of)) {
          PySimulation& s = of.cast<PySimulation&>();
          s.noticeEdits();
          return forcesOf(s.sim().model(), s.sim().state(), positions, velocities);
        }
        const World& w = of.cast<const World&>();
        return forcesOf(jello::Model(w), jello::initialState(w), positions, velocities);
      },
      "of"_a, "positions"_a = py::none(), "velocities"_a = py::none(),
      "Total force (N) on each point, (n, 3), of a World (at its initial state) or a Simulation "
      "(at its state, user force included), or at the positions and velocities given.");

  // ---- the stability experiment's primitives (jello-stability)
  m.def(
      "w_max",
      [](const World& w) {
        return jello::experiments::maxAngularFrequency(jello::Model(w), jello::initialState(w));
      },
      "world"_a, "Fastest angular frequency (rad/s) of the world linearized at its initial state.",
      py::call_guard<py::gil_scoped_release>());
  m.def(
      "predicted_threshold",
      [](const std::string& integrator, double wMax, double dampingRatio) {
        return jello::experiments::predictedThreshold(integratorFrom(integrator),
                                                      positive(wMax, "w_max"),
                                                      nonNegative(dampingRatio, "damping_ratio"));
      },
      "integrator"_a, "w_max"_a, "damping_ratio"_a,
      "Largest stable dt (s) predicted from linear stability for modes up to w_max with damping "
      "ratio c/k = damping_ratio (s): inf for unconditionally stable integrators, 0 for never.");
  m.def(
      "stability_threshold",
      [](const World& w, const std::string& integrator, double time, double energyFactor,
         double tolerance, double dtMax, double dtMin, std::optional<double> guess,
         const py::kwargs& options) {
        const IntegratorKind kind = integratorFrom(integrator);
        jello::experiments::BlowUpRule rule;
        rule.time = positive(time, "time");
        rule.energyFactor = positive(energyFactor, "energy_factor");
        positive(tolerance, "tolerance");
        if (!(positive(dtMin, "dt_min") < positive(dtMax, "dt_max"))) {
          valueError("dt_min must be below dt_max");
        }
        jello::SolverOptions solver;
        solver.cvode.rtol = 1e-3;  // jello-stability's default
        solver = solverOptionsFrom(options, solver);
        jello::experiments::Threshold t;
        {
          py::gil_scoped_release nogil;
          // The search starts at Courant number 1, as jello-stability's does.
          const double start = guess ? *guess
                                     : 1.0 / jello::experiments::maxAngularFrequency(
                                                 jello::Model(w), jello::initialState(w));
          t = jello::experiments::findThreshold(w, kind, rule, start, dtMax, tolerance, dtMin,
                                                solver);
        }
        const char* outcome = t.stableToMax()  ? "stable_to_max"
                              : t.stable > 0.0 ? "threshold"
                                               : "unstable_to_min";
        return py::dict("stable"_a = t.stable, "unstable"_a = t.unstable, "trials"_a = t.trials,
                        "outcome"_a = outcome);
      },
      "world"_a, "integrator"_a, "time"_a = 0.2, "energy_factor"_a = 10.0, "tolerance"_a = 0.02,
      "dt_max"_a = 0.05, "dt_min"_a = 1e-8, "guess"_a = py::none(),
      "Measures the largest stable dt by jello-stability's bisection and blow-up rule: dict "
      "with stable, unstable (s), trials and outcome ('threshold', 'stable_to_max', "
      "'unstable_to_min').");
  m.def(
      "stability_scene",
      [](const std::string& scene, double k, double dampingRatio, double contactRatio) {
        if (scene != "free" && scene != "wall") valueError("scene must be 'free' or 'wall'");
        return jello::experiments::stabilityScene(scene, positive(k, "k"),
                                                  nonNegative(dampingRatio, "damping_ratio"),
                                                  positive(contactRatio, "contact_ratio"));
      },
      "scene"_a, "k"_a, "damping_ratio"_a = 1e-5, "contact_ratio"_a = 20.0,
      "jello-stability's scenes: 'free' (the pulled-corner cube touching nothing) or 'wall' "
      "(pressed onto the floor), springs k (N/m), damping c = damping_ratio * k.");
}
