"""Failures from Python: divergence as jello.Diverged with the last sane state, Ctrl-C during a
long run as KeyboardInterrupt at a step boundary, and the GIL released while stepping."""
import os
import signal
import threading
import time

import numpy as np
import pytest

import jello


def test_divergence_raises_diverged_with_the_last_sane_state(worlds_dir):
    world = jello.load_world(str(worlds_dir / "stiff-k1e5.w"))
    sim = jello.Simulation(world, integrator="euler", dt=1e-3)
    with pytest.raises(jello.Diverged) as info:
        sim.run(time=1.0)
    e = info.value
    assert isinstance(e, RuntimeError)
    assert e.integrator == "euler" and e.step >= 1 and e.reason
    assert e.t == pytest.approx((e.step - 1) * 1e-3)
    assert f"step {e.step}" in str(e) and "euler" in str(e)
    assert e.positions.shape == (world.num_points, 3)
    assert np.all(np.isfinite(e.positions)) and np.all(np.isfinite(e.velocities))
    # The simulation holds that state and refuses to go on, saying the same.
    assert sim.diverged and sim.t == e.t
    assert np.array_equal(sim.positions, e.positions)
    with pytest.raises(jello.Diverged):
        sim.step()
    stats = sim.stats
    assert stats["diverged"] and stats["divergence"]["step"] == e.step
    # Another integrator (or dt) may try again from the last sane state.
    sim.set_integrator("implicit")
    assert not sim.diverged
    sim.dt = 0.01
    sim.step(3)
    # So may an edited state: a sane one written through the views clears a divergence.
    sim.set_integrator("euler")
    sim.dt = 1e-3
    with pytest.raises(jello.Diverged):
        sim.run(time=1.0)
    sim.velocities[:] = 0.01
    assert not sim.diverged


def test_ctrl_c_stops_a_long_run_at_a_step_boundary(jello_w):
    sim = jello.Simulation(jello_w, integrator="rk4")
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    started = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        sim.run(time=1e4)  # hours of stepping, but for the interrupt
    elapsed = time.monotonic() - started
    timer.join()
    assert elapsed < 10.0
    assert 0 < sim.steps < 2e7
    assert sim.t == pytest.approx(sim.steps * 0.0005)  # whole steps only
    assert np.all(np.isfinite(sim.positions))
    sim.step()  # and it goes on from there


def test_ctrl_c_stops_inside_one_long_step_and_keeps_its_start(worlds_dir):
    """Issue 41, item 8: one cvode step of 10 s on the stiff cube takes minutes; SIGINT a second
    in gave no KeyboardInterrupt for 169 s. The step polls the interrupt as jello-sim's does and
    its state stays the step's start; Python's own handler is back afterwards."""
    world = jello.load_world(str(worlds_dir / "stiff-k1e5.w"))
    sim = jello.Simulation(world, integrator="cvode", dt=10.0)
    start = sim.positions.copy()
    handler = signal.getsignal(signal.SIGINT)
    timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    started = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        sim.step(1)
    elapsed = time.monotonic() - started
    timer.join()
    assert elapsed < 10.0
    assert sim.t == 0.0 and sim.steps == 0
    assert np.array_equal(sim.positions, start)
    assert signal.getsignal(signal.SIGINT) is handler
    # A later call is not interrupted by the old request.
    sim.dt = 1e-4
    sim.step(2)
    assert sim.steps == 2


def test_the_gil_is_released_while_stepping(jello_w):
    sim = jello.Simulation(jello_w, integrator="rk4")
    counter = [0]
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            counter[0] += 1

    thread = threading.Thread(target=spin)
    thread.start()
    time.sleep(0.05)
    before = counter[0]
    started = time.monotonic()
    sim.run(time=0.5)  # 1,000 steps, a few tenths of a second
    elapsed = time.monotonic() - started
    during = counter[0] - before
    stop.set()
    thread.join()
    # Holding the GIL, the thread would not have counted at all until the run returned.
    assert elapsed > 0.02
    assert during > 1000, f"{during} increments in {elapsed:.3f} s"


def test_a_second_thread_cannot_step_a_busy_simulation(jello_w):
    # No sleeps: the run's first callback lets the other thread go (it then finds the run
    # stepping, its GIL released, whatever the machine's speed), and the run ends at the first
    # callback after the other thread is done.
    sim = jello.Simulation(jello_w, integrator="rk4")
    errors = []
    stepping, finished = threading.Event(), threading.Event()

    def other():
        stepping.wait(timeout=60)
        try:
            sim.step()
        except RuntimeError as e:
            errors.append(str(e))
        try:
            sim.energy()
        except RuntimeError as e:
            errors.append(str(e))
        finished.set()

    def callback(_):
        stepping.set()
        return not finished.is_set()

    thread = threading.Thread(target=other)
    thread.start()
    sim.run(steps=10_000_000, callback=callback, every=100)
    thread.join()
    assert len(errors) == 2 and "busy" in errors[0] and "another thread" in errors[1]
