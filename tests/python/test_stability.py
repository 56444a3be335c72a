"""The stability experiment's primitives from Python give jello-stability's answers: the same
w_max, the predicted limits of linear stability, and the measured thresholds of the committed
CSV bit for bit."""
import csv
import math

import pytest

import jello
from conftest import ROOT


def committed(scene, integrator, k, source):
    with open(ROOT / "experiments" / "results" / "stability.csv", newline="") as f:
        for row in csv.DictReader(f):
            if (row["scene"], row["integrator"], float(row["k_N_per_m"]), row["source"]) == (
                    scene, integrator, k, source):
                return row
    raise LookupError((scene, integrator, k, source))


def test_w_max_and_predictions_match_the_committed_run():
    world = jello.stability_scene("free", 1e4)
    w = jello.w_max(world)
    row = committed("free", "rk4", 1e4, "measured")
    assert w == pytest.approx(float(row["w_max_rad_per_s"]), rel=1e-9)
    # Undamped limits: h w = 2 for symplectic Euler, 2 sqrt 2 for RK4, none for backward Euler.
    assert jello.predicted_threshold("symplectic", w, 0.0) * w == pytest.approx(2.0, rel=1e-6)
    assert jello.predicted_threshold("rk4", w, 0.0) * w == pytest.approx(2 * math.sqrt(2), rel=1e-6)
    assert math.isinf(jello.predicted_threshold("implicit", w, 0.0))
    for integrator in ("symplectic", "rk4"):
        predicted = committed("free", integrator, 1e4, "predicted")
        assert jello.predicted_threshold(integrator, w, 1e-5) == pytest.approx(
            float(predicted["dt_s"]), rel=1e-9)


@pytest.mark.parametrize("integrator", ["symplectic", "rk4"])
def test_measured_thresholds_equal_jello_stability(integrator):
    world = jello.stability_scene("free", 1e4)
    result = jello.stability_threshold(world, integrator)
    row = committed("free", integrator, 1e4, "measured")
    assert result["outcome"] == row["outcome"] == "threshold"
    # The same bisection to the same 2%. A build for another CPU level than the one that ran
    # the committed CSV (the default build's clones against -march=native) differs in the last
    # bits, and where the blow-up rule's decision sits at the threshold they move the bisection
    # within its resolution: equal to 2% (measured 1.1% apart, 1e-9 on the same build).
    assert result["stable"] == pytest.approx(float(row["dt_s"]), rel=0.02)
    assert abs(result["trials"] - int(row["trials"])) <= 2
    assert result["stable"] < result["unstable"] <= 1.02 * result["stable"] * (1 + 1e-12)


def test_bad_arguments_are_value_errors():
    world = jello.stability_scene("free", 1e3)
    with pytest.raises(ValueError):
        jello.stability_scene("ceiling", 1e3)
    with pytest.raises(ValueError):
        jello.stability_threshold(world, "rk4", dt_max=1e-9)
    with pytest.raises(ValueError):
        jello.stability_threshold(world, "rk4", newton_tolerance=1e-3)
    with pytest.raises(ValueError):
        jello.predicted_threshold("rk4", -1.0, 0.0)
    # Issue 41, item 6: jello-stability's ranges (a step count that fits, no subnormal step).
    with pytest.raises(ValueError, match="time must be between 0.0001 and 1000, not 1e\\+308"):
        jello.stability_threshold(world, "rk4", time=1e308)
    with pytest.raises(ValueError, match="dt_max must be between 1e-09 and 1"):
        jello.stability_threshold(world, "rk4", dt_max=4.9e-324, dt_min=1e-330)
