"""Property tests of the Python layer (Debian's python3-hypothesis; issue 41, item 10): worlds
built from random valid values save and load back equal; random invalid values, given to the
setters or as a world file's text, raise the documented exception (ValueError, its subclass
jello.WorldError, or TypeError for a wrong type) and never crash the interpreter, and a world
that refused a value keeps its previous one."""
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import jello

SETTINGS = settings(max_examples=60, deadline=None, database=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])

positive = st.floats(min_value=1e-6, max_value=1e6, allow_nan=False, allow_infinity=False)
non_negative = st.floats(min_value=0.0, max_value=1e6, allow_nan=False, allow_infinity=False)
coordinate = st.floats(min_value=-3.0, max_value=3.0, allow_nan=False, allow_infinity=False)
# Anything a float can be: NaN, infinities, subnormals, huge and negative values.
any_float = st.floats(allow_nan=True, allow_infinity=True)


@st.composite
def valid_worlds(draw):
    w = jello.World()
    w.integrator = draw(st.sampled_from(["euler", "rk4", "implicit", "midpoint", "projective"]))
    w.dt = draw(st.floats(min_value=1e-6, max_value=0.05))
    w.k = draw(non_negative)
    w.damping = draw(non_negative)
    w.k_collision = draw(non_negative)
    w.d_collision = draw(non_negative)
    w.mass = draw(st.floats(min_value=1e-6, max_value=10.0))
    if draw(st.booleans()):
        normal = draw(st.tuples(coordinate, coordinate, coordinate).filter(
            lambda n: max(abs(c) for c in n) > 1e-3))
        w.plane = (*normal, draw(st.floats(min_value=1.0, max_value=50.0)) *
                   math.sqrt(sum(c * c for c in normal)))
    if draw(st.booleans()):
        w.sphere = (draw(coordinate), draw(coordinate), draw(st.floats(-60.0, -10.0)),
                    draw(st.floats(min_value=0.1, max_value=5.0)))
    velocities = draw(st.lists(st.floats(-10.0, 10.0), min_size=3, max_size=3))
    w.velocities = np.tile(velocities, (w.num_points, 1))
    offset = draw(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3))
    w.positions = w.positions + np.array(offset)
    return w


@SETTINGS
@given(w=valid_worlds())
def test_valid_worlds_save_and_load_back_equal(tmp_path, w):
    path = tmp_path / "w.w"
    w.save(str(path))
    back = jello.load_world(str(path))
    assert back == w
    assert np.array_equal(back.positions, w.positions)
    assert np.array_equal(back.velocities, w.velocities)


SCALARS = ["dt", "k", "damping", "k_collision", "d_collision", "mass", "friction", "slip_speed"]


@SETTINGS
@given(name=st.sampled_from(SCALARS), value=any_float)
def test_a_scalar_setter_accepts_a_valid_value_or_raises_and_keeps_the_old(name, value):
    w = jello.World()
    before = getattr(w, name)
    try:
        setattr(w, name, value)
    except ValueError:
        assert getattr(w, name) == before
        return
    assert math.isfinite(value) and getattr(w, name) == value
    assert value > 0 or (value == 0 and name not in ("dt", "mass", "slip_speed"))


# A few entries of the default cube's positions or velocities replaced by anything (a copy of
# another point's included: two points at one place).
edits = st.lists(st.tuples(st.integers(0, 511), st.integers(0, 2),
                           any_float | st.sampled_from([0.0, 1e6, -1e200, 1e-320])),
                 min_size=1, max_size=4)


@SETTINGS
@given(changes=edits, velocities=st.booleans(), twin=st.integers(0, 511) | st.none())
def test_random_points_are_refused_as_the_reader_refuses_them(tmp_path, changes, velocities,
                                                              twin):
    w = jello.World()
    name = "velocities" if velocities else "positions"
    before = getattr(w, name).copy()
    points = before.copy()
    for point, axis, value in changes:
        points[point, axis] = value
    if twin is not None:
        points[twin] = points[(twin + 1) % 512]
    try:
        setattr(w, name, points)
    except ValueError:
        assert np.array_equal(getattr(w, name), before)
        return
    # Accepted: then the file it saves loads back (the setters check what the reader checks).
    path = tmp_path / "p.w"
    w.save(str(path))
    assert jello.load_world(str(path)) == w


@SETTINGS
@given(text=st.text(max_size=300) | st.builds(
    lambda head, tail: head + tail,
    st.sampled_from(["RK4\n0.001 1\n", "implicit\n0.01 1\n1 2 3 4\n0.002\n0\n0\n"]),
    st.text(alphabet="0123456789.-+eEnaif \n", max_size=200)))
def test_random_world_text_is_refused_as_a_world_error(tmp_path, text):
    path = tmp_path / "r.w"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    with pytest.raises(jello.WorldError) as info:
        jello.load_world(str(path))
    assert info.value.file == str(path)
    assert info.value.line >= 0


@SETTINGS
@given(value=st.one_of(st.text(max_size=20), st.lists(any_float, max_size=6), st.none(),
                       st.integers(), any_float))
def test_a_plane_or_sphere_of_any_value_is_set_or_refused(value):
    w = jello.World()
    for name in ("plane", "sphere"):
        try:
            setattr(w, name, value)
        except (ValueError, TypeError):
            continue
        got = getattr(w, name)
        assert got is None or all(math.isfinite(c) for c in got)
