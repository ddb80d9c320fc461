"""BE3DSR (BE3D with interior frames transported from the nodal frames): twins, derivatives, invariants.

The property it exists for: a director update is a change of chart that keeps ``T`` and ``U`` to round-off,
where BE3D's changes them (the energy jumps behind its blow-up on B3).
"""
import numpy as np
import pytest

from ancfdae import Material, PointForce, PointMoment, RectangularSection, solve_static
from ancfdae.models import BE3D, BE3DSR, Beam
from support.numerics import assert_forces_and_tangent_fd, fd_gradient, rel_err
from test_be3d import FLAT, REF_BE, TABLE2_BE3D, deformed_3d, element_state, rotation, spin_velocity

B3_MAT = Material(E=1e5, nu=0.3, rho=2500.0)


def _state(el, n=3, seed=5):
    beam = Beam(el, n, 1.0, start=(0, 0, 0), direction=(0.6, 0.8, 0.0))
    rng = np.random.default_rng(seed)
    q = beam.q_ref[beam.edofs] + 0.05 * rng.standard_normal((n, 14))
    q[:, [6, 13]] += 0.3 * rng.standard_normal((n, 2))
    v, a = rng.standard_normal((2, n, 14))
    return beam, q, v, a


def test_compiled_kernels_equal_the_numpy_reference():
    """Catches: the numba twin drifting from the readable reference (any term, any block)."""
    sec = RectangularSection(0.05)
    ref, comp = BE3DSR(B3_MAT, sec, kernel="numpy"), BE3DSR(B3_MAT, sec, kernel="numba")
    beam, q, v, a = _state(ref)
    g = beam.geom
    assert rel_err(comp.strain_energy(g, q), ref.strain_energy(g, q)) < 1e-13
    for x, y in zip(comp.internal_forces(g, q), ref.internal_forces(g, q)):
        assert rel_err(x, y) < 1e-13
    for x, y in zip(comp.inertia(g, q, v, a), ref.inertia(g, q, v, a)):
        assert rel_err(x, y) < 1e-13
    assert rel_err(comp.kinetic_energy_extra(g, q, v), ref.kinetic_energy_extra(g, q, v)) < 1e-13


def test_compiled_mass_bilinear_equals_the_numpy_reference():
    """The energy-momentum method's ``1/2 u^T M_rot(q) w`` with dB/dq and d2B/dq2 on a bent, twisted state, at
    every ``order`` (the compiled spin runs a lower-order branch below 2).

    Catches the compiled form drifting from the reference (a wrong spin coefficient row, a lost Hessian term, a
    lower-order branch that differs); a formula error shared by both passes here, the beam-level finite
    differences of these forms hold that (tests/integrators/test_energy_momentum_variable_mass.py).
    """
    sec = RectangularSection(0.05, 0.03)
    ref, comp = BE3DSR(B3_MAT, sec, kernel="numpy"), BE3DSR(B3_MAT, sec, kernel="numba")
    beam, q, v, a = _state(ref, seed=11)
    g = beam.geom
    full = comp.mass_bilinear(g, q, v, a, 2)
    for order in (0, 1, 2):
        got, want = comp.mass_bilinear(g, q, v, a, order), ref.mass_bilinear(g, q, v, a, order)
        assert len(got) == len(want) == order + 1
        for x, y, z in zip(got, want, full):
            assert rel_err(x, y) < 1e-13 and np.array_equal(x, z)


def test_forces_tangent_and_inertia_against_finite_differences():
    """Catches: a force that is not dU/dq, a tangent or inertia block that is not the derivative."""
    el = BE3DSR(B3_MAT, FLAT, kernel="numpy")
    beam, q, v, a = _state(el, n=2, seed=7)
    g = beam.geom
    assert_forces_and_tangent_fd(el, g, q)
    T = lambda x, y: el.kinetic_energy_extra(g, x.reshape(q.shape), y.reshape(q.shape)).sum()
    dTdv = lambda x, y: fd_gradient(lambda z: T(x, z), y.ravel(), h=1e-4)
    h = 1e-5
    ddt = (dTdv(q + h * v, v + h * a) - dTdv(q - h * v, v - h * a)) / (2 * h)
    f, dq, dv, da = el.inertia(g, q, v, a)
    assert rel_err(f.ravel(), ddt - fd_gradient(lambda z: T(z, v), q.ravel())) < 1e-6
    for blk, arg in ((dq, 0), (dv, 1), (da, 2)):
        for e in range(q.shape[0]):
            def force(x, e=e, arg=arg):
                args = [q.copy(), v.copy(), a.copy()]
                args[arg][e] = x
                return el.inertia(g, *args, tangent=False)[0][e]
            assert rel_err(blk[e], fd_gradient(force, (q, v, a)[arg][e])) < 1e-7
    assert T(q, v) == pytest.approx(0.5 * np.einsum("ei,eij,ej", v, da, v), rel=1e-13)


@pytest.mark.parametrize("axis, angle", [((0, 0, 1), 2.5), ((1, 2, -1), 1.9)])
def test_rigid_motion_has_zero_strain_and_spin_energy(steel, axis, angle):
    """Catches: a reference twist or curvature that a rigid motion changes (transport not objective)."""
    beam = Beam(BE3DSR(steel, FLAT), 4, 2.0, start=(0.1, 0.2, 0.3), direction=(0.6, 0.8, 0.0))
    R = rotation(axis, angle)
    Q = beam.nodal(beam.initial_state()[0])
    Q[:, :3] = Q[:, :3] @ R.T + [0.3, -2.0, 1.0]
    Q[:, 3:6] = Q[:, 3:6] @ R.T
    moved = beam.bind({"directors": beam.geom["directors"] @ R.T})
    q = Q.reshape(-1)
    assert moved.energy(0.0, q, 0 * q).strain < 1e-20 * steel.E
    assert np.abs(moved.internal_forces(q, tangent=False)[0]).max() < 1e-5
    # a rigid rotation about the axis direction: the rotary energy is that of a uniform spin
    omega = 3.0 * R @ np.array([0.6, 0.8, 0.0])
    v = spin_velocity(moved, q, omega)
    T_rot = moved.element.kinetic_energy_extra(moved.geom, *element_state(moved, q, v)).sum()
    assert T_rot == pytest.approx(0.5 * steel.rho * FLAT.J * 2.0 * 9.0, rel=1e-12)


@pytest.mark.parametrize("variant", ["projected", "post-rotated"])
def test_director_update_keeps_strain_and_kinetic_energy(steel, variant):
    """Catches: interior frames that depend on the directors (BE3D's do: its update changes U by 1e-4 here)."""
    for cls, bound in ((BE3DSR, 1e-13), (BE3D, None)):
        beam, q = deformed_3d(steel, 4)
        if cls is BE3DSR:
            beam = Beam(BE3DSR(steel, FLAT, director_update="none"), 4, 2.0, supports={0: "clamp"})
        v = spin_velocity(beam, q, np.array([0.3, -1.0, 2.0])) + 0.01 * np.sin(np.arange(beam.n_dof))
        e0 = beam.energy(0.0, q, v)
        beam.element.director_update = variant
        beam.element.update_below = None
        q2, v2, state = beam.step_event(0.0, q, v)
        e1 = beam.bind(state).energy(0.0, q2, v2)
        dU, dT = abs(e1.strain - e0.strain) / e0.strain, abs(e1.kinetic - e0.kinetic) / e0.kinetic
        if bound is None:
            assert dU > 1e-6          # BE3D: the check can fail
        else:
            assert dU < bound and dT < bound


def test_b1_in_plane_equals_be3d_and_table2(steel, square):
    """In the plane the transported frames are BE3D's: the same tip to round-off, Table 2's errors."""
    F = 3 * steel.E * square.I3 / 4.0
    for n in (2, 4, 8):
        tips = []
        for cls in (BE3D, BE3DSR):
            beam = Beam(cls(steel, square), n, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, F, 0.0), node=-1)])
            res = solve_static(beam)
            assert res.success, res.message
            tips.append(beam.position(res.q, 2.0) - [2.0, 0.0, 0.0])
        assert np.abs(tips[1] - tips[0]).max() < 1e-11
        assert np.linalg.norm(tips[1] - REF_BE) == pytest.approx(TABLE2_BE3D[n], rel=2e-3)


def test_tip_moment_in_space_converges_at_order_4(steel, square):
    """A clamped beam under a tip moment with bending and torsion parts (a helix-like curl, quarter turn).

    Measured tip errors against 64 elements: BE3DSR 4.9e-3, 2.7e-4, 1.7e-5, 1.1e-6 (n = 2 ... 16; order 4.0),
    BE3D 5.3e-3, 5.4e-4, 1.2e-4, 3.0e-5 (order 2.1: its interpolated director twists the interior frames).
    Catches: a twist or transport that converges at a lower order, or to another beam than BE3D's.
    """
    EI, L = steel.E * square.I3, 2.0
    M = np.array([0.6, 0.0, 1.0]) * EI * np.pi / (2 * L)

    def tip(cls, n):
        beam = Beam(cls(steel, square), n, L, supports={0: "clamp"}, loads=[PointMoment(M, node=-1)])
        res = solve_static(beam, load_steps=10)
        assert res.success, res.message
        return beam.position(res.q, L)

    ref = tip(BE3DSR, 32)
    errs = [np.linalg.norm(tip(BE3DSR, n) - ref) for n in (2, 4, 8)]
    orders = -np.diff(np.log(errs)) / np.log(2)
    assert np.all(orders > 3.8), orders
    assert np.linalg.norm(tip(BE3D, 32) - ref) < 1e-5      # BE3D's own error at 32 elements: 7e-6
