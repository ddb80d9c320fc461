"""BE3D (chapter Sects. 3.5-3.6): Table 2 in the plane, derivatives, inertia, invariants, directors, bad input."""
import numpy as np
import pytest

from ancfdae import Material, PointForce, PointMoment, RectangularSection, solve_static
from ancfdae.models import BE2D, BE3D, Beam
from ancfdae.models.thin.be3d_kinematics import spin_coefficients
from test_be2d import TABLE2_RTOL
from support.numerics import fd_gradient, rel_err

REF_BE = np.array([-0.50853730436, 1.20723985455, 0.0])   # chapter Eq. 113
TABLE2_BE3D = {2: 3.755e-2, 4: 2.035e-3, 8: 5.060e-5, 16: 1.202e-6, 32: 3.876e-8, 64: 1.820e-9}
FLAT = RectangularSection(0.1, 0.05)    # I3 = 4 I2: unequal bending stiffnesses


def rotation(axis, angle):
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def element_state(beam, q, v=None):
    """Element coordinate (and velocity) arrays of a Beam state."""
    qe = beam.expand(q)[beam.edofs]
    return qe if v is None else (qe, beam._expand_v(v)[beam.edofs])


def deformed_3d(steel, n, update="none"):
    """A cantilever bent about both axes and twisted (solved with fixed directors)."""
    F = 3 * steel.E * FLAT.I2 / 4.0
    beam = Beam(BE3D(steel, FLAT, director_update=update), n, 2.0, supports={0: "clamp"},
                loads=[PointForce((0.0, 0.5 * F, 0.3 * F), node=-1), PointMoment((1e5, 0.0, 0.0), node=-1)])
    res = solve_static(beam)
    assert res.success, res.message
    return beam, res.q


def spin_velocity(beam, q, omega):
    """Velocity of a rigid rotation with angular velocity ``omega`` (nodal spin omega . e1)."""
    Q = beam.nodal(q)
    V = np.zeros_like(Q)
    V[:, :3] = np.cross(omega, Q[:, :3])
    V[:, 3:6] = np.cross(omega, Q[:, 3:6])
    a = Q[:, 3:6]
    g = np.stack([j.v for j in spin_coefficients(a, beam.geom["directors"], 1)], axis=-1)
    V[:, 6] = (a / np.linalg.norm(a, axis=1)[:, None]) @ omega - np.einsum("ni,ni->n", g, V[:, 3:6])
    return V.reshape(-1)[beam.free]


def test_b1_in_plane_reproduces_be2d_and_table2(steel, square):
    F = 3 * steel.E * square.I3 / 4.0
    for n, err_table in TABLE2_BE3D.items():
        beam = Beam(BE3D(steel, square), n, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, F, 0.0), node=-1)])
        assert beam.q_ref.size == 7 * (n + 1)          # chapter Table 2: 14, 21, 35, ...
        res = solve_static(beam)
        assert res.success, res.message
        u = beam.position(res.q, 2.0) - [2.0, 0.0, 0.0]
        assert np.linalg.norm(u - REF_BE) == pytest.approx(err_table, rel=TABLE2_RTOL[n])
        assert res.iterations == 49
        planar = Beam(BE2D(steel, square), n, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, F), node=-1)])
        res2 = solve_static(planar)
        assert res2.success, res2.message
        assert np.allclose(u[:2], planar.position(res2.q, 2.0) - [2.0, 0.0], rtol=0, atol=1e-11)
        Q = beam.nodal(res.q)
        assert np.abs(Q[:, [2, 5, 6]]).max() < 1e-14    # z, z', theta stay zero


def test_residual_jacobian_and_kinetic_energy(steel):
    beam = Beam(BE3D(steel, FLAT, director=(0.2, -0.3, 1.0)), 3, 1.0, supports={0: "clamp"},
                loads=[PointMoment((2e3, -1e3, 5e2), s=0.7), PointForce((1e3, 2e3, -3e3), s=0.4)])
    rng = np.random.default_rng(5)
    q = beam.initial_state()[0] + 0.05 * rng.standard_normal(beam.n_dof)
    v, a = 10 * rng.standard_normal((2, beam.n_dof))
    f, kdata = beam.internal_forces(q)
    assert rel_err(f, fd_gradient(lambda x: beam.energy(0.0, x, 0 * x).strain, q)) < 1e-7
    K = beam._asm.csr(kdata).toarray()
    assert np.allclose(K, K.T, rtol=0, atol=1e-9 * np.abs(K).max())
    J = beam.jacobian(0.0, q, v, a)
    assert J.same_pattern
    assert rel_err(J.K.toarray(), fd_gradient(lambda x: beam.residual(0.0, x, v, a), q)) < 1e-7
    # the residual is quadratic in v and linear in a: central differences with h = 1 are exact
    assert rel_err(J.D.toarray(), fd_gradient(lambda x: beam.residual(0.0, q, x, a), v, h=1.0)) < 1e-8
    assert rel_err(J.M.toarray(), fd_gradient(lambda x: beam.residual(0.0, q, v, x), a, h=1.0)) < 1e-8
    M = beam.mass(q).toarray()
    assert np.allclose(M, J.M.toarray()) and np.allclose(M, M.T) and np.linalg.eigvalsh(M).min() > 0
    assert beam.energy(0.0, q, v).kinetic == pytest.approx(0.5 * v @ M @ v, rel=1e-13)


def test_inertia_force_follows_lagrange_equations(steel):
    """f_rot = d/dt dT/dv - dT/dq with T = kinetic_energy_extra, by finite differences."""
    el = BE3D(steel, FLAT, director=(0.1, 0.4, 1.0))
    beam = Beam(el, 2, 1.0)
    rng = np.random.default_rng(6)
    q = beam.q_ref[beam.edofs] + 0.1 * rng.standard_normal(beam.edofs.shape)
    v, a = rng.standard_normal((2,) + q.shape)
    T = lambda x, y: el.kinetic_energy_extra(beam.geom, x.reshape(q.shape), y.reshape(q.shape)).sum()
    dTdv = lambda x, y: fd_gradient(lambda z: T(x, z), y.ravel(), h=1e-4)
    h = 1e-5
    ddt = (dTdv(q + h * v, v + h * a) - dTdv(q - h * v, v - h * a)) / (2 * h)
    lagrange = ddt - fd_gradient(lambda z: T(z, v), q.ravel())
    f, dq, dv, da = el.inertia(beam.geom, q, v, a)
    assert rel_err(f.ravel(), lagrange) < 1e-6
    assert np.allclose(el.inertia(beam.geom, q, v, a, tangent=False)[0], f)
    assert el.kinetic_energy_extra(beam.geom, q, v).sum() == pytest.approx(0.5 * np.einsum("ei,eij,ej", v, da, v),
                                                                         rel=1e-13)
    # uniform spin of the straight reference beam: T = rho J L omega^2 / 2
    v0 = np.zeros((2, 14))
    v0[:, [6, 13]] = 3.0
    T0 = el.kinetic_energy_extra(beam.geom, beam.q_ref[beam.edofs], v0).sum()
    assert T0 == pytest.approx(0.5 * steel.rho * FLAT.J * 1.0 * 9.0, rel=1e-13)


def test_curvatures_spin_and_moment_match_the_frames(steel):
    el = BE3D(steel, FLAT, director=(0.3, 0.2, 1.0))
    beam = Beam(el, 3, 1.0)
    rng = np.random.default_rng(7)
    q = beam.q_ref[beam.edofs] + 0.15 * rng.standard_normal(beam.edofs.shape)
    s, L, h = np.array([-0.6, 0.1, 0.8]), beam.lengths[:, None, None, None], 1e-6
    F = el.frames(beam.geom, q, s)
    assert np.abs(np.einsum("epij,epik->epjk", F, F) - np.eye(3)).max() < 1e-14
    assert np.allclose(np.linalg.det(F), 1.0)
    # curvature vector components (Eqs. 18-20): k1 = e2'.e3, k2 = e3'.e1, k3 = e1'.e2 (per xi)
    dF = (el.frames(beam.geom, q, s + h) - el.frames(beam.geom, q, s - h)) / (2 * h) * (2 / L)
    k_frames = np.stack([np.einsum("epi,epi->ep", dF[..., i], F[..., j]) for i, j in ((1, 2), (2, 0), (0, 1))], -1)
    assert rel_err(el.curvature(beam.geom, q, s), k_frames) < 1e-7
    # spin about the axis: omega1 = e2_dot . e3
    v = rng.standard_normal(q.shape)
    dFt = (el.frames(beam.geom, q + h * v, s) - el.frames(beam.geom, q - h * v, s)) / (2 * h)
    assert rel_err(el.spin(beam.geom, q, v, s), np.einsum("epi,epi->ep", dFt[..., 1], F[..., 2])) < 1e-7
    # a moment does the virtual work M . delta phi, delta phi = 1/2 sum e_i x delta e_i
    M, e, sm = np.array([1.0, -2.0, 0.5]), 1, 0.3
    fm, km = el.moment_load(beam.geom, q[e], sm, M, e)
    dq = np.zeros_like(q)
    dq[e] = rng.standard_normal(14)
    Fp, Fm, F0 = (el.frames(beam.geom, x, [sm])[e, 0] for x in (q + h * dq, q - h * dq, q))
    dphi = 0.5 * sum(np.cross(F0[:, i], (Fp[:, i] - Fm[:, i]) / (2 * h)) for i in range(3))
    assert fm @ dq[e] == pytest.approx(M @ dphi, rel=1e-7)
    fd = fd_gradient(lambda x: el.moment_load(beam.geom, x, sm, M, e, False)[0], q[e])
    assert rel_err(km, fd) < 1e-7


@pytest.mark.parametrize("axis, angle", [((0, 0, 1), 2.5), ((1, 2, -1), 1.9), ((0, 1, 0), np.pi / 2)])
@pytest.mark.parametrize("rotate_directors", [True, False])
def test_rigid_rotation_has_zero_strain(steel, axis, angle, rotate_directors):
    beam = Beam(BE3D(steel, FLAT), 4, 2.0)
    R = rotation(axis, angle)
    Q = beam.nodal(beam.initial_state()[0])
    Q[:, :3] = Q[:, :3] @ R.T + [0.3, -2.0, 1.0]
    Q[:, 3:6] = Q[:, 3:6] @ R.T
    if rotate_directors:
        beam = beam.bind({"directors": beam.geom["directors"] @ R.T})
    elif angle == np.pi / 2 and axis == (0, 1, 0):
        return   # the axis would lie on the unrotated director: excluded (Eq. 99 singular)
    q = Q.reshape(-1)
    assert beam.energy(0.0, q, 0 * q).strain < 1e-20 * steel.E
    f, _ = beam.internal_forces(q, tangent=False)
    assert np.abs(f).max() < 1e-5   # N, round-off of forces of order EA ~ 1e9


def test_small_load_bending_about_both_axes_axial_and_torsion(steel):
    L, P = 2.0, 1.0
    E, G = steel.E, steel.G
    cases = [(PointForce((0.0, P, 0.0), node=-1), 1, P * L**3 / (3 * E * FLAT.I3)),
             (PointForce((0.0, 0.0, P), node=-1), 2, P * L**3 / (3 * E * FLAT.I2)),
             (PointForce((1e3 * P, 0.0, 0.0), node=-1), 0, 1e3 * P * L / (E * FLAT.A))]
    for load, k, expect in cases:
        beam = Beam(BE3D(steel, FLAT), 4, L, supports={0: "clamp"}, loads=[load])
        res = solve_static(beam, load_steps=1)
        assert res.success, res.message
        assert (beam.position(res.q, L) - [L, 0, 0])[k] == pytest.approx(expect, rel=1e-8)
    T = 10.0
    beam = Beam(BE3D(steel, FLAT), 4, L, supports={0: "clamp"}, loads=[PointMoment((T, 0.0, 0.0), node=-1)])
    res = solve_static(beam, load_steps=1)
    assert res.success, res.message
    theta = beam.nodal(res.q)[:, 6]
    GJk = G * FLAT.J * FLAT.k_t
    assert theta[-1] == pytest.approx(T * L / GJk, rel=1e-8)
    assert np.allclose(theta, T * np.linspace(0, L, 5) / GJk, rtol=1e-8)
    assert np.abs(beam.position(res.q, np.linspace(0, L, 7))[:, 1:]).max() < 1e-12


def _update(beam, q, v):
    """The director update as a model event: new (q, v) and the beam bound to the new directors."""
    q2, v2, state = beam.step_event(0.0, q, v)
    return q2, v2, beam.bind(state)


@pytest.mark.parametrize("variant", ["projected", "post-rotated"])
def test_director_update_keeps_nodal_configuration(steel, variant):
    beam, q = deformed_3d(steel, 4)
    el = beam.element
    v = spin_velocity(beam, q, np.array([0.3, -1.0, 2.0]))
    qe, ve = element_state(beam, q, v)
    ends = [-1.0, 1.0]
    F0, spin0 = el.frames(beam.geom, qe, ends), el.spin(beam.geom, qe, ve, ends)
    el.director_update = variant
    q2, v2, b2 = _update(beam, q, v)
    Q, Q2 = beam.nodal(q), beam.nodal(q2)
    assert np.array_equal(Q2[:, :6], Q[:, :6])                      # positions and slopes
    if variant == "projected":
        assert np.array_equal(Q2[:, 6], Q[:, 6])
    else:
        assert np.abs(Q2[:, 6]).max() == 0.0
    D = b2.geom["directors"]
    assert not np.array_equal(D, beam.geom["directors"])            # the beam itself keeps its directors
    e1 = Q[:, 3:6] / np.linalg.norm(Q[:, 3:6], axis=1)[:, None]
    assert np.abs(np.einsum("ni,ni->n", D, e1)).max() < 1e-14      # directors normal to the axis
    assert np.allclose(np.linalg.norm(D, axis=1), 1.0, rtol=0, atol=1e-14)
    qe2, ve2 = element_state(beam, q2, v2)
    assert np.abs(el.frames(b2.geom, qe2, ends) - F0).max() < 1e-14           # nodal frames
    assert np.allclose(el.spin(b2.geom, qe2, ve2, ends), spin0, rtol=1e-13, atol=1e-13)   # nodal spins
    V, V2 = beam._expand_v(v).reshape(-1, 7), beam._expand_v(v2).reshape(-1, 7)
    assert np.array_equal(V2[:, :6], V[:, :6])
    # the update is idempotent: a second one changes nothing, energies included
    e2 = b2.energy(0.0, q2, v2)
    q3, v3, b3 = _update(b2, q2, v2)
    e3 = b3.energy(0.0, q3, v3)
    assert np.allclose(q3, q2, rtol=0, atol=1e-14) and np.allclose(v3, v2, rtol=0, atol=1e-13)
    assert e3.strain == pytest.approx(e2.strain, rel=1e-12) and e3.kinetic == pytest.approx(e2.kinetic, rel=1e-12)


@pytest.mark.parametrize("variant", ["projected", "post-rotated"])
def test_director_update_energy_change_vanishes_with_the_mesh(steel, variant):
    """Interior frames depend on the interpolated director: an update changes U by O(h^2), exactly 0 in plane."""
    changes = []
    ns = [4, 8, 16, 32]
    for n in ns:
        beam, q = deformed_3d(steel, n)
        U0 = beam.energy(0.0, q, 0 * q).strain
        beam.element.director_update = variant
        q2, v2, b2 = _update(beam, q, 0 * q)
        changes.append(abs(b2.energy(0.0, q2, v2).strain - U0) / U0)
    assert changes[-1] < 1e-5
    order = -np.polyfit(np.log(ns[1:]), np.log(changes[1:]), 1)[0]
    assert 1.8 < order < 2.2
    # bending in the plane normal to the director: the update changes nothing
    F = 3 * steel.E * FLAT.I3 / 4.0
    beam = Beam(BE3D(steel, FLAT, director_update="none"), 4, 2.0, supports={0: "clamp"},
                loads=[PointForce((0.0, F, 0.0), node=-1)])
    q = solve_static(beam).q
    U0 = beam.energy(0.0, q, 0 * q).strain
    beam.element.director_update = variant
    q2, v2, b2 = _update(beam, q, 0 * q)
    assert b2.energy(0.0, q2, v2).strain == pytest.approx(U0, rel=1e-14)


def test_axis_turning_through_the_director(steel):
    """A tip moment curls the beam through the (slightly tilted) initial director; updates keep it regular."""
    L = 2.0
    phi = 1.5 * np.pi
    M = phi * steel.E * FLAT.I2 / L
    R = L / phi
    circle = np.array([R * np.sin(phi), 0.0, R * (1 - np.cos(phi))])
    for variant in ("projected", "post-rotated", "none"):
        el = BE3D(steel, FLAT, director_update=variant, director=(0.0, 0.1, 1.0))
        beam = Beam(el, 8, L, supports={0: "clamp"}, loads=[PointMoment((0.0, -M, 0.0), node=-1)])
        res = solve_static(beam, load_steps=10)
        if variant == "none":
            # the projection of Eq. 99 degenerates once the tip passes 90 degrees
            assert not res.success and "load step 4 of 10" in res.message
        else:
            assert res.success, res.message
            assert np.abs(beam.position(res.q, L) - circle).max() < 2e-3
            assert np.all(np.isfinite(res.q))


def test_rigid_rotation_through_the_director_with_updates(steel):
    el = BE3D(steel, FLAT)
    beam = Beam(el, 3, 1.0)
    Q0 = beam.nodal(beam.initial_state()[0])
    for step in range(1, 19):   # turn the axis e_x about -e_y by 180 degrees, through the director e_z
        R = rotation((0, -1, 0), np.pi * step / 18)
        Q = Q0.copy()
        Q[:, :3], Q[:, 3:6] = Q0[:, :3] @ R.T, Q0[:, 3:6] @ R.T
        q, _, beam = _update(beam, Q.reshape(-1), 0 * Q.reshape(-1))
        assert beam.energy(0.0, q, 0 * q).strain < 1e-20 * steel.E
    assert np.allclose(beam.geom["directors"], [0.0, 0.0, -1.0], atol=1e-14)   # followed the frame: R e_z


def test_clamp_and_pin_coordinates(steel):
    el = BE3D(steel, FLAT)
    assert el.support_coordinates("clamp", np.eye(3)) == ("x", "y", "z", "y'", "z'", "theta")
    assert el.support_coordinates("pin", np.eye(3)) == ("x", "y", "z")
    tilted = rotation((0, 0, 1), 0.3)
    assert el.support_coordinates("clamp", tilted) == ("x", "y", "z", "x'", "y'", "z'", "theta")


def test_bad_input(steel, square):
    with pytest.raises(ValueError, match="director_update"):
        BE3D(steel, square, director_update="rotated")
    with pytest.raises(ValueError, match="director"):
        BE3D(steel, square, director=(0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="director"):
        BE3D(steel, square, director=(0.0, np.nan, 1.0))
    with pytest.raises(ValueError, match="director"):
        BE3D(steel, square, director=(0.0, 1.0))
    with pytest.raises(ValueError, match="parallel to the beam axis"):
        Beam(BE3D(steel, square, director=(2.0, 0.0, 0.0)), 2, 1.0)
    with pytest.raises(ValueError, match="parallel to the beam axis"):
        Beam(BE3D(steel, square, director=(0.0, 0.0, 1.0)), 2, 1.0, direction=(0.0, 0.0, -1.0))
    with pytest.raises(TypeError, match="material"):
        BE3D({"E": 1.0}, square)
    with pytest.raises(TypeError, match="section"):
        BE3D(steel, object())
    with pytest.raises(ValueError, match="inertia_points"):
        BE3D(steel, square, inertia_points=0)
    with pytest.raises(ValueError, match="kind"):
        BE3D(steel, square).support_coordinates("weld", np.eye(3))
    beam = Beam(BE3D(steel, square), 2, 1.0)
    with pytest.raises(ValueError, match="moment"):
        beam.element.moment_load(beam.geom, beam.q_ref[beam.edofs][0], 0.0, (1.0, 2.0), 0)
    # a single step that turns the axis onto the director cannot be followed by the update
    Q = beam.nodal(beam.initial_state()[0])
    Q[:, 3:6] = [0.0, 0.0, 1.0]
    with pytest.raises(FloatingPointError, match="parallel to the beam axis"):
        beam.step_event(0.0, Q.reshape(-1), 0 * Q.reshape(-1))


def test_semi_discrete_equations_conserve_energy():
    """Free motion: with a from r(q, v, a) = 0, d/dt (T + U) = 0 (the equations derive from a Lagrangian).

    Soft material (benchmarks.md B2/B3) so that the gyroscopic terms matter:
    dropping them leaves dE/dt at 6e-4 of dT/dt here.
    """
    soft, sec = Material(1e5, 0.3, 2500.0), RectangularSection(0.05, 0.03)
    beam = Beam(BE3D(soft, sec, director=(0.2, 0.5, 1.0)), 3, 1.0)
    rng = np.random.default_rng(8)
    q = beam.initial_state()[0] + 0.05 * rng.standard_normal(beam.n_dof)
    v = rng.standard_normal(beam.n_dof)
    a = np.linalg.solve(beam.mass(q).toarray(), -beam.residual(0.0, q, v, 0 * v))
    h = 1e-6
    ep, em = beam.energy(0.0, q + h * v, v + h * a), beam.energy(0.0, q - h * v, v - h * a)
    dT, dU = (ep.kinetic - em.kinetic) / (2 * h), (ep.strain - em.strain) / (2 * h)
    assert abs(dT) > 100.0 and abs(dT + dU) < 1e-8 * abs(dT)


def test_cantilever_study_has_the_be3d_and_cable3d_rows():
    from ancfdae.studies import cantilever
    res = cantilever.run(elements=["BE3D", "Cable3D"], n_elements=(2, 4), plots=False, progress=False)
    rows = {(r["element"], r["n_elements"]): r for r in res["rows"]}
    for n in (2, 4):
        dof, err, _, its = cantilever.TABLE2["BE3D"][n]
        assert rows["BE3D", n]["dof"] == dof and rows["BE3D", n]["iterations"] == its
        assert rows["BE3D", n]["error"] == pytest.approx(err, rel=5e-3)
        assert rows["Cable3D", n]["error"] == pytest.approx(rows["BE3D", n]["error"], rel=1e-9)


def test_residual_path_equals_the_jets():
    """The written-out chain rule of the residual path equals the jets' values and gradients."""
    from ancfdae.models.thin.be3d_kinematics import curvature_energy, curvatures, spin_gradient
    rng = np.random.default_rng(9)
    a, b, d, dp, k_ref = rng.standard_normal((5, 4, 3, 3))
    th, dth = rng.standard_normal((2, 4, 3))
    D = np.array([1.3, 0.7, 2.1])
    k = curvatures(a, b, th, dth, d, dp, order=1)
    W, grad = curvature_energy(a, b, th, dth, d, dp, k_ref, D)
    assert np.allclose(W, 0.5 * sum(D[i] * (k[i].v - k_ref[..., i]) ** 2 for i in range(3)), rtol=1e-13)
    assert rel_err(grad, sum(D[i] * (k[i].v - k_ref[..., i])[..., None] * k[i].g for i in range(3))) < 1e-13
    gj = spin_coefficients(a, d, False)
    g, G = spin_gradient(a, d)
    assert rel_err(g, np.stack([x.v for x in gj], -1)) < 1e-14
    assert rel_err(G, np.stack([x.g for x in gj], -2)) < 1e-14


def test_curved_reference_is_stress_free_and_rotation_invariant():
    soft, sec = Material(1e5, 0.3, 2500.0), RectangularSection(0.05, 0.03)
    s = np.linspace(0.0, 1.0, 9)
    beam = Beam(BE3D(soft, sec), nodes=np.stack([np.cos(s), np.sin(s), 0.3 * s], axis=1))   # a helix
    q = beam.initial_state()[0]
    assert np.abs(beam.geom["k_ref"]).max() > 1.0          # curved and twisted reference
    assert beam.energy(0.0, q, 0 * q).strain < 1e-25
    R = rotation((1, 2, 3), 2.0)
    Q = beam.nodal(q)
    Q[:, :3], Q[:, 3:6] = Q[:, :3] @ R.T, Q[:, 3:6] @ R.T
    beam = beam.bind({"directors": beam.geom["directors"] @ R.T})
    q = Q.reshape(-1)
    assert beam.energy(0.0, q, 0 * q).strain < 1e-25
    assert np.abs(beam.internal_forces(q, tangent=False)[0]).max() < 1e-10
