"""Simulations from Python: the same bits as jello-sim, state views that alias the state, the
integrator told of edits, energy and momentum as physics says."""
import gc
import subprocess

import numpy as np
import pytest

import jello
from conftest import program


@pytest.mark.parametrize("integrator, dt, steps, options, flags", [
    ("rk4", None, 200, {}, []),
    ("implicit", 0.01, 20, {}, []),
    ("bdf2", 0.005, 20, {"newton_tol": 1e-10}, ["--newton-tol", "1e-10"]),
    ("projective", 0.01, 10, {"projective_iters": 5}, ["--projective-iters", "5"]),
    ("projective", 0.01, 10, {"projective_chebyshev": 0.85}, ["--projective-chebyshev", "0.85"]),
    ("implicit", 0.01, 10,
     {"preconditioner": "projective", "newton_seed": 60, "newton_seed_tol": 1e-8,
      "newton_seed_chebyshev": 0.9},
     ["--preconditioner", "projective", "--newton-seed", "60", "--newton-seed-tol", "1e-8",
      "--newton-seed-chebyshev", "0.9"]),
    ("cvode", 0.01, 5, {"rtol": 1e-4, "cvode_method": "adams"},
     ["--rtol", "1e-4", "--cvode-method", "adams"]),
])
def test_run_equals_jello_sim_bit_for_bit(worlds_dir, tmp_path, integrator, dt, steps, options,
                                          flags):
    world_path = str(worlds_dir / "jello.w")
    out = tmp_path / "out.w"
    command = [program("JELLO_SIM"), world_path, "--integrator", integrator,
               "--steps", str(steps), "--out", str(out), "--quiet", *flags]
    if dt is not None:
        command += ["--dt", str(dt)]
    subprocess.run(command, check=True)
    expected = jello.load_world(str(out))

    sim = jello.Simulation(jello.load_world(world_path), integrator=integrator, dt=dt, **options)
    assert sim.step(steps) == steps
    assert np.array_equal(sim.positions, expected.positions)
    assert np.array_equal(sim.velocities, expected.velocities)
    assert sim.world() == expected


def test_views_alias_the_state_and_keep_it_alive(jello_w):
    sim = jello.Simulation(jello_w)
    x, v = sim.positions, sim.velocities
    assert x.shape == (512, 3) and x.dtype == np.float64 and x.flags.writeable
    assert not x.flags.owndata
    sim.step(10)
    assert np.array_equal(x, sim.positions)  # the same memory, now 10 steps on
    assert sim.t == pytest.approx(10 * 0.0005)
    # Writing through the view changes the state: a fresh simulation from the edited world
    # takes the same next step, bit for bit.
    v[:] = 0.0
    x[:, 2] += 0.25
    edited = sim.world()
    assert np.array_equal(edited.velocities, np.zeros((512, 3)))
    sim.step(5)
    fresh = jello.Simulation(edited)
    fresh.step(5)
    assert np.array_equal(sim.positions, fresh.positions)
    # The views keep the simulation alive after its last name is gone.
    del sim, fresh
    gc.collect()
    before = x.copy()
    x[0, 0] += 1.0  # writes into live memory, not freed memory
    assert x[0, 0] == before[0, 0] + 1.0


def test_an_edit_restarts_a_multistep_integrator(worlds_dir):
    """bdf2 keeps the previous state; an edit through a view must drop it (as the viewer's
    integrator switch does), or the next step would blend the old trajectory into the new."""
    world = jello.load_world(str(worlds_dir / "spinning-k1e4.w"))
    sim = jello.Simulation(world, integrator="bdf2", dt=0.005, newton_tol=1e-12)
    sim.step(4)
    v = sim.velocities
    v *= 0.5
    edited = sim.world()
    sim.step()
    fresh = jello.Simulation(edited, integrator="bdf2", dt=0.005, newton_tol=1e-12)
    fresh.step()
    # Both take a backward-Euler start step from the same state: equal to the solver's
    # tolerance. Without the restart the difference is that of BDF2 from a false history.
    assert np.max(np.abs(sim.positions - fresh.positions)) < 1e-9
    assert sim.stats["steps"] == 5


def test_non_finite_writes_are_refused_and_undone(jello_w):
    sim = jello.Simulation(jello_w)
    x = sim.positions
    good = x.copy()
    x[3, 1] = np.nan
    with pytest.raises(ValueError, match="not finite"):
        sim.step()
    assert np.array_equal(sim.positions, good)
    sim.step()
    assert sim.steps == 1


def test_energy_is_conserved_with_the_field_term():
    """Undamped cube in a radial (conservative) field under RK4: kinetic + spring + contact +
    field (minus the field's work) is conserved up to RK4's error, which falls at least 10x
    per halving of dt (fourth order: 16x); the field term itself is 6% of the total."""
    world = jello.create_world(d_elastic=0.0, d_collision=0.0, plane=None, field="radial",
                               field_resolution=9, pose="stretched", stretch=1.05,
                               velocity=(0.5, 0, 0), cube=4)
    drift = []
    for dt in (1e-4, 5e-5):
        sim = jello.Simulation(world, integrator="rk4", dt=dt)
        e0 = sim.energy()
        sim.run(time=0.5)
        e1 = sim.energy()
        assert e1["total"] == pytest.approx(
            e1["kinetic"] + e1["spring"] + e1["contact"] + e1["field"] + e1["user"])
        assert abs(e1["field"]) > 0.05 * e0["total"]  # the field did work: the term matters
        drift.append(abs(e1["total"] - e0["total"]) / e0["total"])
    assert drift[1] < 1e-6
    assert drift[0] / drift[1] > 10.0


def test_momentum_and_angular_momentum_are_conserved():
    """No walls reached, no plane, no field: springs are internal forces, so linear and angular
    momentum stay as they were: linear to round-off under RK4 and midpoint, angular to round-off
    under midpoint (symplectic) and to RK4's error under RK4."""
    world = jello.create_world(plane=None, pose="stretched", velocity=(0.2, -0.1, 0.05),
                               spin=1.5)
    for integrator, dt in [("rk4", 5e-4), ("midpoint", 0.01)]:
        sim = jello.Simulation(world, integrator=integrator, dt=dt, newton_tol=1e-14,
                               newton_xtol=1e-15, newton_iters=100)
        p0, l0 = np.array(sim.momentum()), np.array(sim.angular_momentum())
        assert np.linalg.norm(l0) > 1e-4
        sim.run(time=0.2)
        assert np.allclose(sim.momentum(), p0, rtol=0, atol=1e-12), integrator
        # Midpoint keeps quadratic invariants exactly; RK4 only to its error.
        tolerance = 1e-6 if integrator == "rk4" else 1e-11  # measured 1.2e-7 and 1.9e-13
        assert sim.stats["solver"].get("newton_unconverged_steps", 0) == 0
        assert np.linalg.norm(np.array(sim.angular_momentum()) - l0) < tolerance * np.linalg.norm(l0)


def test_seeded_newton_takes_the_default_steps():
    """newton_seed and the projective preconditioner change Newton's start and its linear
    solves, not the converged backward-Euler steps (the solver options reach the C++ side)."""
    world = jello.create_world(plane=None, pose="stretched", spin=1.5)
    tight = dict(newton_tol=1e-12, newton_xtol=1e-12, newton_iters=100)
    plain = jello.Simulation(world, integrator="implicit", dt=0.005, **tight)
    seeded = jello.Simulation(world, integrator="implicit", dt=0.005, linear_solver="cg",
                              preconditioner="projective", newton_seed=30, cg_tol=1e-12,
                              **tight)
    plain.run(steps=4)
    seeded.run(steps=4)
    assert np.abs(plain.positions - seeded.positions).max() < 1e-8
    assert seeded.stats["solver"]["seed_iterations"] > 0
    assert seeded.stats["solver"]["newton_iterations"] < plain.stats["solver"]["newton_iterations"]
    with pytest.raises(ValueError, match="projective"):
        jello.Simulation(world, integrator="implicit", preconditioner="nope")
    with pytest.raises(ValueError):
        jello.Simulation(world, integrator="implicit", newton_seed=-1)
    with pytest.raises(ValueError, match="projective_chebyshev"):
        jello.Simulation(world, integrator="projective", projective_chebyshev=1.0)
    with pytest.raises(ValueError, match="newton_seed_chebyshev"):
        jello.Simulation(world, integrator="implicit", newton_seed_chebyshev=float("nan"))
    with pytest.raises(ValueError, match="newton_seed_tol"):
        jello.Simulation(world, integrator="implicit", newton_seed_tol=0.0)


def test_run_callback_every_and_stop(jello_w):
    sim = jello.Simulation(jello_w)
    seen = []

    def record(s):
        seen.append((s.steps, s.energy()["total"]))
        return len(seen) < 3  # stop after the third call

    taken = sim.run(steps=100, callback=record, every=10)
    assert taken == 30 and [s for s, _ in seen] == [10, 20, 30]
    assert sim.run(time=0.01) == 20  # ceil(0.01 / 0.0005)
    with pytest.raises(ValueError):
        sim.run()
    with pytest.raises(ValueError):
        sim.run(time=1.0, steps=3)

    def recurse(s):
        s.step()

    with pytest.raises(RuntimeError, match="busy"):
        sim.run(steps=2, callback=recurse)


def test_set_integrator_user_force_and_stats(jello_w):
    sim = jello.Simulation(jello_w, integrator="implicit", dt=0.01)
    sim.step(3)
    st = sim.stats
    assert st["integrator"] == "implicit" and st["steps"] == 3 and st["points"] == 512
    assert st["solver"]["newton_iterations"] >= 3
    assert set(st["energy_end"]) == {"kinetic_J", "spring_J", "contact_J", "total_J"}
    sim.set_integrator("cvode", rtol=1e-4)
    assert sim.integrator == "cvode"
    sim.step()
    assert sim.stats["solver"]["rhs_evaluations"] > 0
    # A uniform push accelerates the centre of mass by F/m per point.
    sim.set_integrator("rk4")
    sim.dt = 1e-4
    world = jello.create_world(plane=None, velocity=(0, 0, 0), pose="rest")
    free = jello.Simulation(world, integrator="rk4", dt=1e-4)
    push = np.zeros((512, 3))
    push[:, 0] = 0.01
    free.set_user_force(push)
    free.run(steps=100)
    expected = 0.5 * (0.01 / world.mass) * 0.01 ** 2
    moved = free.positions[:, 0].mean() - world.positions[:, 0].mean()
    assert moved == pytest.approx(expected, rel=1e-9)
    assert free.energy()["user"] == pytest.approx(-0.01 * 512 * moved, rel=1e-9)
    free.set_user_force(None)
    with pytest.raises(ValueError):
        free.set_user_force(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="unknown solver option"):
        sim.set_integrator("implicit", newton_iterations=5)
    for bad in [{"rtol": -1.0}, {"max_order": 6}, {"linear_solver": "magic"},
                {"cvode_method": "rk"}, {"clamp": 1}]:
        with pytest.raises(ValueError):
            jello.Simulation(jello_w, integrator="cvode", **bad)
    with pytest.raises(ValueError):
        jello.Simulation(jello_w, integrator="leapfrog")
    # An int too large for C's is a bad value, not a bad type (was "must be an integer, not int").
    with pytest.raises(ValueError, match="newton_iters is out of range"):
        jello.Simulation(jello_w, integrator="implicit", newton_iters=10 ** 30)
    with pytest.raises(ValueError):
        jello.Simulation(jello_w, dt=0.0)
