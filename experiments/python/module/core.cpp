// jello._core: the simulator as a Python module (pybind11). jello/__init__.py re-exports it and
// defines the exception classes it raises (WorldError, Diverged). experiments/python/README.md; the
// parts are listed in bindings.h.
//
// Conventions: positions, velocities and forces cross as (n, 3) float64 arrays; the state's
// own arrays are *views* (no copy) of the simulation's component-major vectors, so their
// strides are (8, 8n). Stepping releases the GIL and polls for Ctrl-C between steps.
#include <optional>
#include <string>

#include "experiments/python/module/bindings.h"
#include "experiments/studies/stability_analysis.h"
#include "solvers/linalg/solver_threads.h"

namespace py = pybind11;
using namespace py::literals;
using jello::IntegratorKind;
using jello::World;
using jello::python::inRangeReal;
using jello::python::integratorFrom;
using jello::python::nonNegative;
using jello::python::positive;
using jello::python::solverOptionsFrom;
using jello::python::valueError;

// Long: the module's table of functions, one def each.
PYBIND11_MODULE(_core, m) {
  m.doc() = "jello's simulator core; use it through the jello package (README \"From Python\")";
  py::register_exception_translator(&jello::python::translateExceptions);
  jello::applySolverThreadSettings();  // single-threaded BLAS and CHOLMOD, as the programs
  jello::python::bindWorlds(m);
  jello::python::bindSimulation(m);

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
  m.def(
      "integrator_table",
      [] {
        py::list rows;
        for (IntegratorKind k : jello::allIntegrators()) {
          py::dict row;
          row["name"] = std::string(jello::integratorName(k));
          row["file_name"] = std::string(jello::integratorFileName(k));
          row["family"] = std::string(jello::familyName(jello::integratorFamily(k)));
          row["linear_model"] = std::string(jello::linearModelName(jello::linearModel(k)));
          row["summary"] = std::string(jello::integratorSummary(k));
          row["explicit"] = jello::isExplicit(k);
          row["adaptive"] = jello::linearModel(k) == jello::LinearModel::Adaptive;
          rows.append(row);
        }
        return rows;
      },
      "Every row of the integrator table with its traits (family, linear model, explicit, "
      "adaptive), in the table's order.");
  m.def("loaded_blas", &jello::loadedBlas, "The BLAS library this process loaded.");

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
        using Rule = jello::experiments::BlowUpRule;
        rule.time = inRangeReal(time, Rule::kMinTime, Rule::kMaxTime, "time");
        rule.energyFactor = positive(energyFactor, "energy_factor");
        positive(tolerance, "tolerance");
        inRangeReal(dtMax, Rule::kMinDtMax, Rule::kMaxDtMax, "dt_max");
        if (!(positive(dtMin, "dt_min") < dtMax)) {
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
