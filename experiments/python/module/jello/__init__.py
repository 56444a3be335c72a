"""jello: the elastic jello cube simulator, from Python (experiments/python/README.md).

    import jello
    world = jello.load_world("worlds/jello.w")
    sim = jello.Simulation(world, integrator="implicit", dt=0.01)
    sim.run(time=1.0)
    print(sim.energy()["total"], sim.stats["solver"])

Arrays follow numpy's conventions: positions, velocities and forces are (n, 3) arrays of
float64 in SI units; point (i, j, k) of an N^3 cube is row i*N*N + j*N + k. The Jacobians K and
D are 3n x 3n scipy.sparse matrices in the state's component-major ordering: row c*n + p is
component c of point p, so `forces.T.ravel()` lines up with their rows.
"""

# CHOLMOD's and OpenBLAS's thread pools only cost at this problem's sizes: the module sets both
# to one thread as it loads, by the libraries' own calls, unless the user chose otherwise
# (solvers/linalg/solver_threads.h).


class WorldError(ValueError):
    """A world file or text that cannot be read: `file`, `line` (1-based; 0 when the file could
    not be opened) and the offending `token`, as jello-sim reports them."""

    def __init__(self, message, file="", line=0, token=""):
        super().__init__(message)
        self.file = file
        self.line = line
        self.token = token


class Diverged(RuntimeError):
    """The simulation diverged (a non-finite or far state, or its energy grew past the budget).

    `t` is the simulated time of the last sane state, `step` the step that broke it (1-based,
    counted from the simulation's start), `integrator` its name, `reason` the rule that fired,
    and `positions`, `velocities` copies of the last sane state ((n, 3) arrays). The simulation
    keeps that state and refuses further steps until its state is edited or it is reset."""

    def __init__(self, message, t=0.0, step=0, integrator="", reason="", positions=None,
                 velocities=None):
        super().__init__(message)
        self.t = t
        self.step = step
        self.integrator = integrator
        self.reason = reason
        self.positions = positions
        self.velocities = velocities


from ._core import (  # noqa: E402  (the exceptions above must exist when it loads)
    Simulation,
    World,
    create_world,
    forces,
    integrator_table,
    integrators,
    load_world,
    loaded_blas,
    parse_world,
    predicted_threshold,
    stability_scene,
    stability_threshold,
    w_max,
)

__all__ = [
    "Diverged", "Simulation", "World", "WorldError", "create_world", "forces",
    "integrator_table", "integrators", "load_world", "loaded_blas", "parse_world", "predicted_threshold", "stability_scene",
    "stability_threshold", "w_max",
]
