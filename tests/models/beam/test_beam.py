"""Beam assembly, supports, loads and their input checks."""
import numpy as np
import pytest

from ancfdae import DistributedLoad, Gravity, PointForce, PointMoment, solve_static
from ancfdae.models import BE2D, Beam


def test_dof_count_and_clamp(steel, square):
    beam = Beam(BE2D(steel, square), 8, 2.0, supports={0: "clamp"})
    assert beam.q_ref.size == 4 * 9          # chapter Table 2: 4 (n + 1)
    assert beam.n_dof == 4 * 9 - 3          # clamp fixes x, y, y' (benchmarks.md B1)
    assert [beam.element.node_coordinates[i] for i in np.flatnonzero(beam.fixed)] == ["x", "y", "y'"]


def test_jacobian_pattern_is_banded_and_fixed(steel, square):
    beam = Beam(BE2D(steel, square), 6, 2.0, supports={0: "clamp"}, loads=[PointMoment(1.0, s=0.7)])
    q, v = beam.initial_state()
    J1 = beam.jacobian(0.0, q, v, v)
    J2 = beam.jacobian(0.0, q + 0.01, v, v)
    assert J1.K.indices is J2.K.indices and J1.K.indptr is J2.M.indptr
    rows, cols = J1.K.nonzero()
    assert np.abs(rows - cols).max() <= 7


def test_gravity_and_distributed_load_totals(steel, square):
    g = np.array([0.0, -9.81])
    beam = Beam(BE2D(steel, square), 5, 2.0, loads=[Gravity(g)])
    q, v = beam.initial_state()
    r = beam.residual(0.0, q, v, 0 * v)
    assert -r[1::4].sum() == pytest.approx(steel.rho * square.A * 2.0 * g[1], rel=1e-12)
    # gravity is conservative: its potential is -m g . (displacement)
    dq = np.zeros_like(q)
    dq[1::4] = -0.1
    assert beam.energy(0.0, q + dq, v).potential == pytest.approx(-steel.rho * square.A * 2.0 * 9.81 * 0.1)
    w = np.array([3.0, 0.0])
    beam = Beam(BE2D(steel, square), 5, 2.0, loads=[DistributedLoad(w, time=lambda t: 2.0)])
    r = beam.residual(0.0, q, v, 0 * v)
    assert -r[0::4].sum() == pytest.approx(2 * 3.0 * 2.0, rel=1e-12)


def test_force_between_nodes_equals_statically_equivalent(steel, square):
    beam = Beam(BE2D(steel, square), 4, 2.0, loads=[PointForce((0.0, 10.0), s=0.75)])
    q, v = beam.initial_state()
    r = -beam.residual(0.0, q, v, 0 * v)
    assert r[1::4].sum() == pytest.approx(10.0)
    # moment about the origin of the nodal forces, with the slope "moments"
    mom = (beam.points[:, 0] * r[1::4]).sum() + r[3::4].sum()
    assert mom == pytest.approx(7.5)


def test_time_function_and_load_factor_scale_loads(steel, square):
    beam = Beam(BE2D(steel, square), 2, 2.0, loads=[PointForce((0.0, 1.0), node=-1, time=lambda t: t**2)])
    q, v = beam.initial_state()
    assert -beam.residual(3.0, q, v, v)[-3] == pytest.approx(9.0)
    beam.load_factor = 0.5
    assert -beam.residual(3.0, q, v, v)[-3] == pytest.approx(4.5)
    assert beam.external_power(3.0, q, np.ones_like(q)) == pytest.approx(4.5)


def test_initial_velocity_rigid_rotation(steel, square):
    omega = 2.0
    beam = Beam(BE2D(steel, square), 4, 2.0, initial_velocity=lambda p: omega * np.column_stack([-p[:, 1], p[:, 0]]))
    _, v = beam.initial_state()
    V = v.reshape(-1, 4)
    assert np.allclose(V[:, 1], omega * beam.points[:, 0])
    assert np.allclose(V[:, 3], omega, rtol=1e-8)      # d/dt of the slope (1, 0) rotating at omega


@pytest.mark.parametrize("kwargs, err, match", [
    ({"n_elements": 0}, ValueError, "n_elements"),
    ({"n_elements": 2, "length": -1.0}, ValueError, "length"),
    ({"n_elements": 2, "length": 1.0, "supports": {0: "glue"}}, ValueError, "supports"),
    ({"n_elements": 2, "length": 1.0, "supports": {0: ("z",)}}, ValueError, "supports"),
    ({"n_elements": 2, "length": 1.0, "supports": {7: "clamp"}}, ValueError, "supports"),
    ({"n_elements": 2, "length": 1.0, "loads": [PointForce((0.0, 1.0), node=5)]}, ValueError, "load"),
    ({"n_elements": 2, "length": 1.0, "loads": [PointForce((0.0, 1.0), s=3.0)]}, ValueError, "load s"),
    ({"n_elements": 2, "length": 1.0, "loads": [PointForce((0.0, 1.0, 0.0), node=1)]}, ValueError, "force"),
    ({"n_elements": 2, "length": 1.0, "loads": ["gravity"]}, TypeError, "loads"),
    ({"n_elements": 2, "length": 1.0, "start": (0.0, 0.0, 0.0)}, ValueError, "start"),
    ({"n_elements": 2, "length": 1.0, "initial_velocity": np.zeros((2, 4))}, ValueError, "initial_velocity"),
])
def test_bad_beam_input(steel, square, kwargs, err, match):
    with pytest.raises(err, match=match):
        Beam(BE2D(steel, square), **kwargs)


@pytest.mark.parametrize("make, match", [
    (lambda: PointForce((0.0, np.nan), node=0), "force"),
    (lambda: PointForce((0.0, np.inf), node=0), "force"),
    (lambda: PointForce((0.0, 1.0)), "node"),
    (lambda: PointForce((0.0, 1.0), node=0, s=1.0), "node"),
    (lambda: PointForce((0.0, 1.0), node=0, time=3.0), "time"),
    (lambda: PointMoment((1.0, 2.0), node=0), "moment"),
    (lambda: Gravity((0.0, np.nan)), "g"),
])
def test_bad_loads(make, match):
    with pytest.raises(ValueError, match=match):
        make()
