#include <Eigen/SparseCore>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <optional>
#include <utility>

#include "experiments/python/module/bindings.h"
#include "solvers/system/jacobian.h"
#include "src/base/interrupt.h"

namespace jello::python {

using namespace py::literals;

namespace {

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
    if (const std::optional<jello::StartProblem> why = sim_.model().startProblem(sim_.state())) {
      valueError(jello::startError(*why, sim_.world(), "the world").what());
    }
    sim_.trackObstacleDistance();
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
      const SignalBridge bridge;
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
      // Python's handler saw the signal too: it raises (KeyboardInterrupt, or what a handler of
      // the caller's raises); if it does not, the stop still is one.
      jello::clearInterrupt();
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
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
    const double friction = 0.0 - sim_.frictionWork();
    return py::dict("kinetic"_a = e.kinetic, "spring"_a = e.spring, "contact"_a = e.contact,
                    "field"_a = field, "user"_a = user, "friction"_a = friction,
                    "total"_a = e.total() + field + user + friction);
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
    const std::optional<double> least = sim_.minObstacleDistance();
    d["min_obstacle_distance_m"] = least ? py::cast(*least) : py::none();
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

// Long: the class's table of methods and properties, one def each.
void bindSimulation(py::module_& m) {
  py::class_<ViewGuard>(m, "_StateView");

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
}

}  // namespace jello::python
