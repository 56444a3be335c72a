// What the parts of the Python module share (jello._core, experiments/python/README.md): the
// conversions between Python values and the simulator's, the exceptions it raises, the solver
// options as keywords, and the functions that bind each part.
//   convert.cpp     conversions, exceptions, solver options from keywords
//   worlds.cpp      World, load_world, parse_world, create_world
//   simulation.cpp  Simulation (state views, stepping with the GIL released), forces
//   core.cpp        the module: integrators, the stability experiment's primitives
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <exception>
#include <string>
#include <type_traits>
#include <vector>

#include "solvers/simulation.h"
#include "solvers/solver_options.h"
#include "src/model.h"
#include "src/state.h"
#include "src/world/world.h"

namespace py = pybind11;

namespace jello::python {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Clock = std::chrono::steady_clock;

[[noreturn]] inline void valueError(const std::string& message) {
  throw py::value_error(message);
}

// A Python value as T, or TypeError naming what it was for (as a typed setter raises).
template <class T>
T as(const py::handle& v, const std::string& what) {
  try {
    return py::cast<T>(v);
  } catch (const py::cast_error&) {
    // An int too large for C's: a bad value, not a bad type ("must be an integer, not int").
    if constexpr (std::is_integral_v<T>) {
      if (py::isinstance<py::int_>(v) && !py::isinstance<py::bool_>(v)) {
        throw py::value_error(what + " is out of range (too large an integer)");
      }
    }
    const char* kind = std::is_same_v<T, std::string> ? "a string"
                       : std::is_integral_v<T>        ? "an integer"
                       : std::is_floating_point_v<T>  ? "a number"
                                                      : "a sequence of numbers";
    throw py::type_error(what + " must be " + kind + ", not " +
                         std::string(py::str(py::type::of(v).attr("__name__"))));
  }
}

// Checked numbers: ValueError naming `what` otherwise.
double finite(double v, const char* what);
double positive(double v, const char* what);
double nonNegative(double v, const char* what);
long inRange(long v, long lo, long hi, const char* what);
double inRangeReal(double v, double lo, double hi, const char* what);
IntegratorKind integratorFrom(const std::string& name);
Vec3 vec3From(const py::handle& h, const char* what);

// (n, 3) arrays: copies out of component-major vectors or point lists, and checked ones in.
py::array_t<double> pointsArray(const Eigen::VectorXd& a);
py::array_t<double> pointsArray(const std::vector<Vec3>& a);
Array checkedPoints(const py::handle& h, py::ssize_t n, const char* what);
Eigen::VectorXd componentMajor(const py::handle& h, py::ssize_t n, const char* what);
std::vector<Vec3> vec3List(const py::handle& h, py::ssize_t n, const char* what);
py::tuple vec3Tuple(const Vec3& v);
py::dict energyDict(const Energy& e);

// While a step runs without the GIL, Ctrl-C (SIGINT) also asks the step itself to stop
// (src/base/interrupt.h, polled inside CVODE's right-hand side, Newton and projective
// iterations), then reaches Python's own handler, which raises KeyboardInterrupt at the next
// PyErr_CheckSignals: a step of minutes stops within a fraction of a second, as jello-sim's
// does, its state the step's start. Nested and concurrent bridges share one installation; with
// SIGINT ignored or at its default (the process ends anyway), none is installed.
class SignalBridge {
 public:
  SignalBridge();
  ~SignalBridge();
  SignalBridge(const SignalBridge&) = delete;
  SignalBridge& operator=(const SignalBridge&) = delete;
};

// Raised as jello.Diverged (jello/__init__.py), with the last sane state.
struct DivergedError {
  Divergence divergence;
  State lastSane;
};
// WorldFileError -> jello.WorldError, DivergedError -> jello.Diverged.
void translateExceptions(std::exception_ptr p);

// jello-sim's solver flags as keywords ('-' -> '_'), over `o`; True/False flags.
bool boolOption(const py::handle& v, const std::string& name);
SolverOptions solverOptionsFrom(const py::kwargs& kwargs, SolverOptions o);

// Writes a world atomically; OSError naming the path when it cannot.
void saveWorld(const World& w, const std::string& path, bool legacy);

void bindWorlds(py::module_& m);
void bindSimulation(py::module_& m);

}  // namespace jello::python
