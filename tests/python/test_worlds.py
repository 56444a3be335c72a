"""Worlds from Python: every committed world loads and round-trips exactly; attributes read and
write the world's fields with their checks; create_world mirrors jello-create-world."""
import subprocess

import numpy as np
import pytest

import jello
from conftest import program


def world_files(worlds_dir):
    files = sorted(worlds_dir.glob("*.w"))
    assert len(files) >= 10
    return files


def test_every_world_loads_and_round_trips(worlds_dir, tmp_path):
    for path in world_files(worlds_dir):
        w = jello.load_world(str(path))
        n = w.cube_resolution
        assert w.num_points == n ** 3
        assert w.positions.shape == (n ** 3, 3) and w.velocities.shape == (n ** 3, 3)
        out = tmp_path / path.name
        w.save(str(out))
        again = jello.load_world(str(out))
        assert again == w, path.name
        assert np.array_equal(again.positions, w.positions)
        if w.field is not None:
            assert np.array_equal(again.field, w.field)
        # A simulation of it takes a step.
        sim = jello.Simulation(w)
        sim.step()
        assert sim.steps == 1


def test_attributes_read_the_file(jello_w):
    w = jello_w
    assert w.integrator == "rk4"
    assert w.dt == 0.0005 and w.steps_per_frame == 1
    assert w.k == 200.0 and w.damping == 0.25
    assert w.k_collision == 400.0 and w.d_collision == 0.25
    assert w.mass == 0.001953  # six decimals, as the course's creator printed it
    assert w.plane == (-1.0, 1.0, 1.0, 2.0)
    assert w.sphere is None
    assert w.field.shape == (30, 30, 30, 3)
    assert w.cube_resolution == 8
    # Point (i, j, k) is row i*64 + j*8 + k, at (i, j, k)/7 in the rest lattice.
    assert np.allclose(w.positions[1 * 64 + 2 * 8 + 3], np.array([1, 2, 3]) / 7.0)


def test_attributes_write_and_check(jello_w, tmp_path):
    w = jello_w.copy()
    w.k = 1e4
    w.damping = 0.5
    w.integrator = "implicit"
    w.plane = None
    w.sphere = (0.5, 0.5, -1.0, 0.75)
    field = np.zeros((4, 4, 4, 3))
    field[..., 2] = -9.81 / 512
    w.field = field
    w.velocities = np.zeros((512, 3))
    w.save(str(tmp_path / "edited.w"))
    back = jello.load_world(str(tmp_path / "edited.w"))
    assert back == w and back != jello_w
    assert back.k == 1e4 and back.integrator == "implicit" and back.plane is None
    assert back.sphere == (0.5, 0.5, -1.0, 0.75)
    assert np.array_equal(back.field, field)
    # The original is untouched: attributes are copies.
    assert jello_w.k == 200.0

    bad = [("k", -1.0), ("mass", 0.0), ("dt", float("nan")), ("damping", float("inf")),
           ("integrator", "leapfrog"), ("plane", (0, 0, 0, 1)), ("sphere", (0, 0, 0, -1)),
           ("steps_per_frame", 0), ("cube_resolution", 1), ("field", np.zeros((3, 3, 2, 3))),
           ("positions", np.zeros((511, 3))), ("velocities", np.full((512, 3), np.nan))]
    for name, value in bad:
        with pytest.raises(ValueError):
            setattr(w, name, value)
    with pytest.raises(TypeError):
        w.k = "stiff"


def test_setters_check_as_the_reader_does_and_save_writes_only_what_loads(jello_w, worlds_dir,
                                                                        tmp_path):
    """Issue 41, items 5 and 7: the setters share the reader's checks of the cube's start, and
    save() refuses a world load_world would refuse, so nothing written fails to load."""
    w = jello_w.copy()
    twins = w.positions
    twins[7] = twins[3]
    far = w.positions
    far[5] = (1e6, 0.0, 0.0)
    with pytest.raises(ValueError, match="points 3 and 7 start at the same position"):
        w.positions = twins
    with pytest.raises(ValueError, match="starts 1e\\+06 m from the origin"):
        w.positions = far
    with pytest.raises(ValueError, match="infinite kinetic energy"):
        w.velocities = np.full((512, 3), 1e200)
    fast = np.zeros((512, 3))
    fast[0] = (1e150, 0.0, 0.0)  # 1/2 m v^2 = 2e297 J: finite, accepted
    w.velocities = fast
    with pytest.raises(ValueError, match="infinite kinetic energy"):
        w.mass = 1e20  # the same velocities, now too much energy
    assert w.mass == jello_w.mass and np.array_equal(w.positions, jello_w.positions)
    w.save(str(tmp_path / "fast.w"))
    assert jello.load_world(str(tmp_path / "fast.w")) == w

    deep = jello_w.copy()
    deep.sphere = (0.0, 0.0, -1.0, 1e308)  # the cube deep inside: infinite contact energy
    with pytest.raises(jello.WorldError, match="sphere's contact energy at the start is inf"):
        deep.save(str(tmp_path / "deep.w"))
    assert not (tmp_path / "deep.w").exists()
    with pytest.raises(ValueError, match="every term of the energy must be finite"):
        jello.Simulation(deep, integrator="implicit")
    text = (worlds_dir / "jello.w").read_text() + "sphere 0 0 -1 1e308\n"
    (tmp_path / "deep.w").write_text(text)
    with pytest.raises(jello.WorldError) as info:
        jello.load_world(str(tmp_path / "deep.w"))
    assert (info.value.line, info.value.token) == (text.count("\n"), "sphere")
    # The system reads a path up to its first NUL: such a path is refused, not truncated.
    with pytest.raises(ValueError, match="NUL"):
        jello.load_world(str(worlds_dir / "jello.w") + "\0.bak")


def test_contact_model_is_an_attribute_and_a_create_world_keyword(jello_w, tmp_path):
    assert jello_w.contact == "penalty" and jello_w.contact_layer == 0.0
    w = jello_w.copy()
    w.contact = "smooth"
    assert w.contact_layer == 0.005  # kDefaultContactLayer
    w.contact_layer = 0.002
    w.save(str(tmp_path / "smooth.w"))
    back = jello.load_world(str(tmp_path / "smooth.w"))
    assert back == w and back != jello_w
    assert (back.contact, back.contact_layer) == ("smooth", 0.002)
    with pytest.raises(ValueError):
        w.contact = "sticky"
    with pytest.raises(ValueError):
        w.contact_layer = -1.0
    with pytest.raises(ValueError):
        jello_w.copy().contact_layer = 0.01  # penalty has no layer
    made = jello.create_world(contact="smooth", contact_layer=0.003)
    assert (made.contact, made.contact_layer) == ("smooth", 0.003)
    with pytest.raises(ValueError):
        jello.create_world(contact_layer=0.003)


def test_friction_is_an_attribute_and_its_work_is_in_the_energy(jello_w, tmp_path):
    assert (jello_w.friction, jello_w.slip_speed) == (0.0, 0.001)
    w = jello_w.copy()
    w.friction = 0.5
    w.contact = "smooth"  # friction survives a change of model
    assert w.friction == 0.5
    with pytest.raises(ValueError):
        w.friction = -1.0
    with pytest.raises(ValueError):
        w.slip_speed = 0.0
    w.save(str(tmp_path / "friction.w"))
    assert jello.load_world(str(tmp_path / "friction.w")) == w
    made = jello.create_world(friction=0.3, slip_speed=0.002)
    assert (made.friction, made.slip_speed) == (0.3, 0.002)
    with pytest.raises(ValueError):
        jello.create_world(slip_speed=0.002)
    sim = jello.Simulation(w, integrator="implicit", dt=0.01)
    sim.run(steps=60)  # into the walls
    e = sim.energy()
    assert e["friction"] > 0.0  # dissipated
    assert e["total"] == pytest.approx(
        e["kinetic"] + e["spring"] + e["contact"] + e["field"] + e["user"] + e["friction"])


def test_the_barrier_has_dhat_and_kappa_and_a_simulation_reports_the_least_distance(jello_w):
    w = jello_w.copy()
    w.contact = "barrier"
    assert (w.dhat, w.kappa) == (0.005, w.k_collision)  # the defaults
    w.kappa = 600.0
    assert w.contact_layer == 0.0
    with pytest.raises(ValueError):
        jello_w.copy().dhat = 0.01  # penalty has no dhat
    with pytest.raises(ValueError):
        w.kappa = 0.0
    made = jello.create_world(contact="barrier", dhat=0.002, k_collision=900.0)
    assert (made.contact, made.dhat, made.kappa) == ("barrier", 0.002, 900.0)
    sim = jello.Simulation(w, integrator="implicit", dt=0.01)
    sim.run(steps=40)
    least = sim.stats["min_obstacle_distance_m"]
    assert 0.0 < least < 0.005
    # A point inside a solid: the barrier cannot start.
    inside = w.copy()
    inside.sphere = (0.5, 0.5, 0.5, 0.3)
    with pytest.raises(ValueError, match="inside the sphere"):
        jello.Simulation(inside)


def test_cube_resolution_resamples(jello_w):
    w = jello_w.copy()
    w.cube_resolution = 4
    assert w.num_points == 64 and w.positions.shape == (64, 3)
    # Corners keep their places (trilinear resampling in lattice coordinates).
    assert np.array_equal(w.positions[0], jello_w.positions[0])
    assert np.array_equal(w.positions[-1], jello_w.positions[-1])


def test_create_world_mirrors_the_program(tmp_path):
    assert jello.create_world() == jello.World()
    cases = [
        ({}, []),
        ({"integrator": "implicit", "dt": 0.01, "k_elastic": 1e4, "plane": None, "field": "vortex",
          "field_resolution": 8, "pose": "rotated", "rotate": 45.0, "axis": (0, 0, 1),
          "velocity": (0, 0, 0), "spin": 2.0, "sphere": (0.5, 0.5, -1, 0.5), "cube": 6},
         ["--integrator", "implicit", "--dt", "0.01", "--k-elastic", "1e4", "--no-plane",
          "--field", "vortex", "--field-resolution", "8", "--pose", "rotated", "--rotate", "45",
          "--axis", "0", "0", "1", "--velocity", "0", "0", "0", "--spin", "2",
          "--sphere", "0.5", "0.5", "-1", "0.5", "--cube", "6"]),
    ]
    creator = program("JELLO_CREATE_WORLD")
    for i, (kwargs, flags) in enumerate(cases):
        out = tmp_path / f"case{i}.w"
        subprocess.run([creator, "-o", str(out), *flags], check=True, capture_output=True)
        assert jello.create_world(**kwargs) == jello.load_world(str(out)), kwargs


def test_create_world_refuses_bad_options():
    for kwargs in [{"k_elastic": -1}, {"pose": "upside-down"}, {"cube": 100},
                   {"plane": (0, 0, 0, 1)}, {"sphere": (0, 0, 0)}, {"colour": "green"},
                   {"axis": (0, 0, 0), "pose": "rotated"}]:
        with pytest.raises(ValueError):
            jello.create_world(**kwargs)
    with pytest.raises(TypeError):
        jello.create_world(dt="fast")


def test_world_errors_name_file_line_and_token(tmp_path):
    path = tmp_path / "bad.w"
    path.write_text("RK4\n0.0005 1\n200 0.25 400 0.25\n0.001953\n1\n-1 1 1 two\n")
    with pytest.raises(jello.WorldError) as info:
        jello.load_world(str(path))
    e = info.value
    assert e.file == str(path) and e.line == 6 and e.token == "two"
    assert "bad.w:6" in str(e)
    assert isinstance(e, ValueError)
    with pytest.raises(jello.WorldError) as info:
        jello.load_world(str(tmp_path / "missing.w"))
    assert info.value.line == 0
    with pytest.raises(jello.WorldError) as info:
        jello.parse_world("Euler\n", name="inline")
    assert info.value.file == "inline"
