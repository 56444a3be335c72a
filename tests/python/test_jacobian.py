"""The Jacobians from Python against finite differences of the forces from Python, on a scene
with every effect: springs, floor contact, the plane, the sphere and a force field."""
import numpy as np
import pytest

import jello


@pytest.fixture(scope="module")
def busy_scene():
    world = jello.create_world(pose="translated", translate=(0.23, 0.31, -2.05), plane=(0, 1, 1, 1.2),
                               sphere=(0.8, 0.9, -1.9, 0.45), field="vortex",
                               field_strength=0.5, field_resolution=6, velocity=(0.3, -0.2, 0.1))
    sim = jello.Simulation(world)
    x = sim.positions.copy()
    # The scene touches everything it has, somewhere.
    assert x[:, 2].min() < -2.0                              # below the floor
    assert (x[:, 1] + x[:, 2] + 1.2).min() < 0.0                # behind the plane
    d = np.linalg.norm(x - np.array([0.8, 0.9, -1.9]), axis=1)
    assert d.min() < 0.45                                    # inside the sphere
    return sim


def component_major(a):
    return a.T.ravel()


def test_stiffness_matches_central_differences(busy_scene):
    """K is df/dx of the elastic, contact and field forces; the damping forces' dependence on x
    (through the spring and contact directions) is left out, as src/PHYSICS.md says, so the
    differences are taken at v = 0, where that term vanishes."""
    sim = busy_scene
    K, _ = sim.jacobian()
    assert K.shape == (3 * sim.num_points, 3 * sim.num_points)
    x0 = sim.positions.copy()
    n = sim.num_points
    still = np.zeros_like(x0)
    eps = 1e-6
    dense = K.toarray()
    worst = 0.0
    for c in range(3):
        for p in range(n):
            xp, xm = x0.copy(), x0.copy()
            xp[p, c] += eps
            xm[p, c] -= eps
            column = (component_major(jello.forces(sim, positions=xp, velocities=still)) -
                      component_major(jello.forces(sim, positions=xm, velocities=still))) / (2 * eps)
            worst = max(worst, np.max(np.abs(column - dense[:, c * n + p])))
    assert worst < 1e-7 * np.max(np.abs(dense)), worst  # measured 1.7e-9


def test_damping_matches_differences_and_clamping_is_optional(busy_scene):
    sim = busy_scene
    _, D = sim.jacobian()
    v0 = sim.velocities.copy()
    n = sim.num_points
    rng = np.random.default_rng(1)
    dv = rng.normal(size=v0.shape)
    # The forces are linear in v: one difference checks D exactly on a random direction.
    change = component_major(jello.forces(sim, velocities=v0 + dv) - jello.forces(sim, velocities=v0))
    assert np.allclose(D @ component_major(dv), change, rtol=1e-9, atol=1e-12)
    # D is symmetric and negative semidefinite (damping only removes energy).
    assert abs(D - D.T).max() == 0.0
    assert component_major(dv) @ (D @ component_major(dv)) < 0.0
    # The clamped stiffness is what the implicit solvers factor: symmetric; the exact one with
    # the field's gradient is not, and without it it is.
    K_exact, _ = sim.jacobian()
    K_no_field, _ = sim.jacobian(field=False)
    K_clamped, _ = sim.jacobian(clamp=True, field=False)
    assert abs(K_exact - K_exact.T).max() > 0.0
    assert abs(K_no_field - K_no_field.T).max() < 1e-9 * abs(K_no_field).max()
    assert abs(K_clamped - K_clamped.T).max() < 1e-9 * abs(K_clamped).max()
    assert K_clamped.shape == K_exact.shape == (3 * n, 3 * n)
