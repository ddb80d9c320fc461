"""Cable3D (chapter Sect. 3.4): Table 2 in the plane, derivatives, invariants, statics, bad input."""
import numpy as np
import pytest

from ancfdae import PointForce, PointMoment, RectangularSection, solve_static
from ancfdae.models import BE2D, Beam, Cable3D
from test_be2d import TABLE2_RTOL
from support.numerics import fd_gradient, rel_err

REF_BE = np.array([-0.50853730436, 1.20723985455, 0.0])   # chapter Eq. 113
TABLE2_BE2D = {2: 3.755e-2, 4: 2.035e-3, 8: 5.060e-5, 16: 1.202e-6, 32: 3.876e-8, 64: 1.820e-9}


def rotation(axis, angle):
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def test_b1_in_plane_reproduces_be2d_and_table2(steel, square):
    F = 3 * steel.E * square.I3 / 4.0
    for n, err_table in TABLE2_BE2D.items():
        cable = Beam(Cable3D(steel, square), n, 2.0, supports={0: "clamp"},
                     loads=[PointForce((0.0, F, 0.0), node=-1)])
        assert cable.q_ref.size == 6 * (n + 1)
        res = solve_static(cable)
        assert res.success, res.message
        u = cable.position(res.q, 2.0) - [2.0, 0.0, 0.0]
        assert np.linalg.norm(u - REF_BE) == pytest.approx(err_table, rel=TABLE2_RTOL[n])
        assert res.iterations == 49
        planar = Beam(BE2D(steel, square), n, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, F), node=-1)])
        res2 = solve_static(planar)
        assert res2.success, res2.message
        assert np.allclose(u[:2], planar.position(res2.q, 2.0) - [2.0, 0.0], rtol=0, atol=1e-11)
        assert abs(u[2]) < 1e-14


def test_forces_tangent_and_moment_match_finite_differences(steel):
    sec = RectangularSection(0.05)
    beam = Beam(Cable3D(steel, sec), 3, 1.0, supports={0: "clamp"},
                loads=[PointMoment((2e3, -1e3, 5e2), s=0.7), PointForce((1e3, 2e3, -3e3), s=0.4)])
    rng = np.random.default_rng(3)
    q = beam.initial_state()[0] + 0.05 * rng.standard_normal(beam.n_dof)
    v, a = rng.standard_normal((2, beam.n_dof))
    f, kdata = beam.internal_forces(q)
    energy = lambda x: beam.energy(0.0, x, 0 * x).strain
    assert rel_err(f, fd_gradient(energy, q)) < 1e-7
    J = beam.jacobian(0.0, q, v, a)
    assert rel_err(J.K.toarray(), fd_gradient(lambda x: beam.residual(0.0, x, v, a), q)) < 1e-7
    assert np.abs(J.D.toarray()).max() == 0.0
    assert rel_err(J.M.toarray(), fd_gradient(lambda x: beam.residual(0.0, q, v, x), a, h=1.0)) < 1e-8
    K = beam._asm.csr(kdata).toarray()
    assert np.allclose(K, K.T, rtol=0, atol=1e-9 * np.abs(K).max())


def slope_operator(beam, s, e):
    """r'(s) = Sx q_e for element e of a Cable3D beam."""
    from ancfdae.models.shapes import hermite
    from ancfdae.models.thin.spatial import hermite_operator
    _, dN, _ = hermite(np.array([s]), beam.lengths[[e]])
    return hermite_operator(dN, np.arange(12).reshape(4, 3), 12)[0, 0]


def test_moment_acts_through_bending_rotation_only(steel, square):
    el = Cable3D(steel, square)
    beam = Beam(el, 2, 1.0)
    rng = np.random.default_rng(4)
    q = beam.expand(beam.initial_state()[0] + 0.05 * rng.standard_normal(beam.n_dof))[beam.edofs]
    s, e = 0.2, 1
    Sx = slope_operator(beam, s, e)
    t = Sx @ q[e]
    e1 = t / np.linalg.norm(t)
    # a moment along the current tangent does no work on a cable (no torsion): dropped
    f, _ = el.moment_load(beam.geom, q[e], s, 7.0 * e1, e)
    assert np.abs(f).max() < 1e-12
    # a transverse moment does the work M . (e1 x delta e1), the turn of the tangent
    M = np.array([1.0, -2.0, 0.5])
    dq = rng.standard_normal(12)
    f, _ = el.moment_load(beam.geom, q[e], s, M, e)
    h = 1e-6
    tp, tm = Sx @ (q[e] + h * dq), Sx @ (q[e] - h * dq)
    de1 = (tp / np.linalg.norm(tp) - tm / np.linalg.norm(tm)) / (2 * h)
    assert f @ dq == pytest.approx(M @ np.cross(e1, de1), rel=1e-7)


@pytest.mark.parametrize("axis, angle", [((0, 0, 1), 2.5), ((1, 2, -1), 1.9), ((0, 1, 0), np.pi / 2)])
def test_rigid_rotation_has_zero_strain(steel, square, axis, angle):
    beam = Beam(Cable3D(steel, square), 4, 2.0)
    R = rotation(axis, angle)
    Q = beam.nodal(beam.initial_state()[0])
    Q[:, :3] = Q[:, :3] @ R.T + [0.3, -2.0, 1.0]
    Q[:, 3:] = Q[:, 3:] @ R.T
    q = Q.reshape(-1)
    assert beam.energy(0.0, q, 0 * q).strain < 1e-20 * steel.E
    f, _ = beam.internal_forces(q, tangent=False)
    assert np.abs(f).max() < 1e-5   # N, round-off of forces of order EA ~ 2e9


def test_small_load_bending_axial_and_total_mass(steel, square):
    L, P = 2.0, 1.0
    EI, EA = steel.E * square.I2, steel.E * square.A
    for force, expect in [((0.0, 0.0, P), P * L**3 / (3 * EI)), ((0.0, P, 0.0), P * L**3 / (3 * EI)),
                          ((1e3 * P, 0.0, 0.0), 1e3 * P * L / EA)]:
        beam = Beam(Cable3D(steel, square), 4, L, supports={0: "clamp"}, loads=[PointForce(force, node=-1)])
        res = solve_static(beam, load_steps=1)
        assert res.success, res.message
        u = beam.position(res.q, L) - [L, 0.0, 0.0]
        k = int(np.argmax(np.abs(force)))
        assert u[k] == pytest.approx(expect, rel=1e-8)
    free = Beam(Cable3D(steel, square), 4, L)
    M = free.mass(None).toarray()
    assert np.allclose(M, M.T) and np.linalg.eigvalsh(M).min() > 0
    vz = np.zeros(free.n_dof)
    vz[2::6] = 1.0     # rigid translation along e_z: z of every node, slopes at rest
    assert vz @ M @ vz == pytest.approx(steel.rho * square.A * L, rel=1e-13)


def test_clamp_fixes_transverse_slopes_only_when_axis_aligned(steel, square):
    beam = Beam(Cable3D(steel, square), 2, 1.0, direction=(0, 0, 1), supports={0: "clamp", -1: "pin"})
    names = [beam.element.node_coordinates[i % 6] for i in np.flatnonzero(beam.fixed)]
    assert names == ["x", "y", "z", "x'", "y'", "x", "y", "z"]
    beam = Beam(Cable3D(steel, square), 2, 1.0, direction=(1, 1, 0), supports={0: "clamp"})
    assert beam.n_dof == 18 - 6


def test_bad_input(steel, square):
    with pytest.raises(ValueError, match=r"I2 == I3"):
        Cable3D(steel, RectangularSection(0.1, 0.05))
    with pytest.raises(TypeError, match="material"):
        Cable3D("steel", square)
    with pytest.raises(TypeError, match="section"):
        Cable3D(steel, object())
    with pytest.raises(ValueError, match="bending_points"):
        Cable3D(steel, square, bending_points=0)
    with pytest.raises(ValueError, match="straight"):
        Beam(Cable3D(steel, square), nodes=[[0, 0, 0], [0.5, 0.2, 0], [1.0, 0, 0]])
    with pytest.raises(ValueError, match="kind"):
        Cable3D(steel, square).support_coordinates("weld", np.eye(3))
    beam = Beam(Cable3D(steel, square), 2, 1.0)
    q = beam.q_ref[beam.edofs]
    with pytest.raises(ValueError, match="moment"):
        beam.element.moment_load(beam.geom, q[0], 0.0, (1.0, 2.0), 0)
