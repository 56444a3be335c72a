#include <cmath>
#include <csignal>
#include <cstdio>
#include <mutex>
#include <optional>
#include <span>
#include <string>

#include "experiments/python/module/bindings.h"
#include "src/base/closed_set.h"
#include "src/base/interrupt.h"
#include "src/world/world_reader.h"

namespace jello::python {

using namespace py::literals;

// ---- conversions -------------------------------------------------------------------------

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
double inRangeReal(double v, double lo, double hi, const char* what) {
  if (!(finite(v, what) >= lo && v <= hi)) {
    char text[96];
    std::snprintf(text, sizeof text, " must be between %g and %g, not %g", lo, hi, v);
    valueError(what + std::string(text));
  }
  return v;
}

namespace {

std::mutex bridgeMutex;
int bridgeUsers = 0;
bool bridgeInstalled = false;
struct sigaction pythonSigint;  // Python's handler, restored when the last bridge ends

void bridgeHandler(int signo, siginfo_t* info, void* context) {
  jello::requestInterrupt(signo);
  if ((pythonSigint.sa_flags & SA_SIGINFO) != 0) {
    pythonSigint.sa_sigaction(signo, info, context);
  } else if (pythonSigint.sa_handler != SIG_DFL && pythonSigint.sa_handler != SIG_IGN) {
    pythonSigint.sa_handler(signo);
  }
}

}  // namespace

SignalBridge::SignalBridge() {
  const std::lock_guard lock(bridgeMutex);
  if (bridgeUsers++ > 0) return;
  jello::clearInterrupt();  // a request left from before is not this call's
  struct sigaction current {};
  if (sigaction(SIGINT, nullptr, &current) != 0) return;
  const bool handled = (current.sa_flags & SA_SIGINFO) != 0 ||
                       (current.sa_handler != SIG_DFL && current.sa_handler != SIG_IGN);
  if (!handled) return;
  pythonSigint = current;
  struct sigaction bridge {};
  bridge.sa_sigaction = bridgeHandler;
  bridge.sa_flags = SA_SIGINFO | (current.sa_flags & SA_RESTART);
  sigemptyset(&bridge.sa_mask);
  bridgeInstalled = sigaction(SIGINT, &bridge, nullptr) == 0;
}

SignalBridge::~SignalBridge() {
  const std::lock_guard lock(bridgeMutex);
  if (--bridgeUsers > 0 || !bridgeInstalled) return;
  sigaction(SIGINT, &pythonSigint, nullptr);
  bridgeInstalled = false;
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

// The keywords mirror jello-sim's flags with '_' for '-' (experiments/python/README.md).
constexpr const char* kSolverOptionNames =
    "linear_solver, preconditioner, matrix_free, clamp, cg_tol, newton_iters, newton_halvings, "
    "newton_tol, newton_xtol, factor_reuse, newton_seed, newton_seed_tol, newton_seed_chebyshev, "
    "refactor_ratio, projective_iters, projective_tol, projective_chebyshev, rtol, cvode_method, "
    "cvode_krylov, atol, "
    "atol_x, atol_v, contact_roots, max_order, stab_lim_det, max_step";

// A Chebyshev contraction rho: in [0, 1).
double chebyshevRho(double rho, const char* name) {
  if (!(rho >= 0.0 && rho < 1.0)) valueError(std::string(name) + " must be at least 0 and below 1");
  return rho;
}

// "'a', 'b' or 'c'" from a table's names.
template <class Kind, class Name>
std::string quotedNames(std::span<const Kind> kinds, Name name) {
  return jello::closed_set::sentence(kinds, [&](Kind kind) {
    // Appended, not concatenated: GCC 12 warns falsely (-Wrestrict) on "'" + string.
    std::string quoted(1, '\'');
    quoted.append(name(kind)).push_back('\'');
    return quoted;
  });
}

bool boolOption(const py::handle& v, const std::string& name) {
  if (!py::isinstance<py::bool_>(v)) valueError(name + " must be True or False");
  return v.cast<bool>();
}

// Long: one branch per keyword option: the Python options' table, read in one place.
jello::SolverOptions solverOptionsFrom(const py::kwargs& kwargs, jello::SolverOptions o) {
  std::optional<double> atol;
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::cast<std::string>(key);
    const char* n = name.c_str();
    const auto real = [&] { return as<double>(value, name); };
    if (name == "linear_solver") {
      const auto kind = jello::parseLinearSolver(as<std::string>(value, name));
      if (!kind)
        valueError("linear_solver must be one of " +
                   quotedNames(jello::allLinearSolvers(), jello::linearSolverName));
      o.implicit.linearSolver = o.cvode.linearSolver = *kind;
    } else if (name == "preconditioner") {
      const auto kind = jello::parsePreconditioner(as<std::string>(value, name));
      if (!kind) {
        valueError("preconditioner must be one of " +
                   quotedNames(jello::allPreconditioners(), jello::preconditionerName));
      }
      o.implicit.preconditioner = o.cvode.preconditioner = *kind;
    } else if (name == "matrix_free") {
      o.implicit.matrixFree = o.cvode.matrixFree = boolOption(value, name);
    } else if (name == "clamp") {
      o.implicit.clampCompression = o.cvode.clampCompression = boolOption(value, name);
    } else if (name == "cg_tol") {
      o.implicit.cgTolerance = o.cvode.cgTolerance = positive(real(), n);
    } else if (name == "newton_iters") {
      o.implicit.newtonMaxIterations = int(inRange(as<long>(value, name), 1, 1000, n));
    } else if (name == "newton_halvings") {
      o.implicit.newtonHalvings = int(inRange(as<long>(value, name), 0, 20, n));
    } else if (name == "newton_tol") {
      o.implicit.newtonTolerance = positive(real(), n);
    } else if (name == "newton_xtol") {
      o.implicit.newtonPositionTolerance = positive(real(), n);
    } else if (name == "factor_reuse") {
      o.implicit.reuseFactor = boolOption(value, name);
    } else if (name == "newton_seed") {
      o.implicit.seedIterations = int(inRange(as<long>(value, name), 0, 1000, n));
    } else if (name == "newton_seed_tol") {
      o.implicit.seedTolerance = positive(real(), n);
    } else if (name == "newton_seed_chebyshev") {
      o.implicit.seedChebyshevRho = chebyshevRho(real(), n);
    } else if (name == "refactor_ratio") {
      const double r = positive(real(), n);
      if (r < 1e-6 || r > 1.0) valueError("refactor_ratio must be between 1e-6 and 1");
      o.implicit.refactorRatio = r;
    } else if (name == "projective_iters") {
      o.projective.iterations = int(inRange(as<long>(value, name), 1, 100000, n));
    } else if (name == "projective_tol") {
      o.projective.tolerance = nonNegative(real(), n);
    } else if (name == "projective_chebyshev") {
      o.projective.chebyshevRho = chebyshevRho(real(), n);
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
      o.cvode.maxStep =
          inRangeReal(real(), CvodeOptions::kMinMaxStep, CvodeOptions::kMaxMaxStep, n);
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

}  // namespace jello::python
