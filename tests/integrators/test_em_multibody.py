"""Energy-momentum on multibody systems: the body-wise discrete gradient, its symmetries, the B7 invariants;
both energy methods (energy-momentum, energy-collocation) on a lamina payload."""
import math

import numpy as np
import pytest

pytest.importorskip("ancfdae.joints")

from ancfdae import CircularSection, Gravity, Material, System, simulate  # noqa: E402
from ancfdae.integrators._body_gradient import BodyWiseGradient, system_symmetries  # noqa: E402
from ancfdae.joints import Spherical  # noqa: E402
from ancfdae.models import Beam, Cable3D  # noqa: E402
from ancfdae.studies._multibody_models import spatial_pendulum, spinup  # noqa: E402
from support.numerics import fd_gradient  # noqa: E402


def _rod(loads=()):
    el = Cable3D(Material(E=5e7, nu=0.3, rho=1000.0), CircularSection(0.02))
    return Beam(el, 2, 1.0, direction=[math.sin(0.5), 0.0, -math.cos(0.5)], loads=list(loads))


def _ranks(out):
    return [(T.shape[1], len(A)) for T, A in out]


def test_system_symmetries_are_the_rigid_motions_that_gravity_and_joints_leave_free():
    # Catches: projecting off a rotation that gravity or a joint breaks (Newton then sees a ratio of small
    # numbers on nearly rigid steps) or missing the one they leave (angular momentum about it drifts).
    free = System([_rod()])
    q = free.initial_state()[0]
    assert _ranks(system_symmetries(free, 0.0, q)) == [(3, 3)]
    heavy = System([_rod([Gravity([0.0, 0.0, -9.81])])])
    (T, A), = system_symmetries(heavy, 0.0, q)
    assert T.shape[1] == 2 and len(A) == 1
    rod = heavy.bodies[0]
    grad = rod.potential_gradient(0.0, q, False)[0]
    assert abs(grad @ (A[0] @ q)) < 1e-12 * np.abs(grad).max()            # the rotation about e_z
    assert np.abs(grad @ T).max() < 1e-12 * np.abs(grad).max()            # horizontal translations
    r = _rod([Gravity([0.0, 0.0, -9.81])])
    pinned = System([r], [Spherical((r, 0), "ground")])                     # pivot on the vertical axis
    assert _ranks(system_symmetries(pinned, 0.0, q)) == [(0, 1)]
    r = _rod([Gravity([0.0, 0.0, -9.81])])
    off = System([r], [Spherical((r, -1), "ground")])     # the rotation about the vertical through the pivot
    (T, A), = system_symmetries(off, 0.0, q)
    assert T.shape[1] == 1 and len(A) == 1
    p = r.point_matrix(r.s_nodes[-1]) @ q
    assert abs(T[:3, 0] @ p) < 1e-12 and abs(T[2, 0]) < 1e-12             # its translation part: e_z x p
    r = _rod([Gravity([0.0, 0.0, -9.81])])
    both = System([r], [Spherical((r, 0), "ground"), Spherical((r, -1), "ground")])   # a tilted axis: none
    assert _ranks(system_symmetries(both, 0.0, q)) == [(0, 0)]


def test_body_wise_gradient_is_a_discrete_gradient_with_its_exact_jacobian():
    # Catches: a body's slice or correction applied to another body's coordinates, a Jacobian block missing
    # the Gonzalez correction's dense part (Newton would still converge, slowly).
    b = spatial_pendulum("Cable3D", 2, E=5e7)
    s = b.system
    q0, v0 = s.initial_state()
    rng = np.random.default_rng(3)
    q1 = q0 + 0.01 * v0 + 1e-3 * rng.standard_normal(q0.size)
    dg = BodyWiseGradient(s)
    dg.start(0.0, q0)
    G = dg.gradient(q1)
    dP = s.potential(0.0, q1) - s.potential(0.0, q0)
    assert G @ (q1 - q0) == pytest.approx(dP, rel=1e-10, abs=1e-13 * np.abs(G).max())
    J = dg.jacobian(q1).toarray()
    J_fd = fd_gradient(dg.gradient, q1, 1e-7)
    assert np.abs(J - J_fd).max() < 1e-5 * np.abs(J_fd).max()
    assert np.abs(dg.gradient(q0) - s.potential_gradient(0.0, q0, False)[0]).max() < 1e-9 * np.abs(G).max()


def test_b7_energy_momentum_keeps_energy_vertical_angular_momentum_and_constraints():
    # Catches: a discrete gradient that is not rotation-equivariant (the whole-system Gonzalez correction
    # along M d drifted L_z by 2.8e-4 relative over 0.5 s on this run) or a constraint force that does work.
    b = spatial_pendulum("Cable3D", 4, E=5e7, t_end=0.5)
    res = simulate(b.system, (0.0, 0.5), "energy-momentum", h=0.01)
    assert res.success, res.message
    s = b.system
    E = b.outputs["energy"](res.t, res.q, res.v, res.lam)
    Lz = b.outputs["angular_momentum_z"](res.t, res.q, res.v, res.lam)
    T = np.array([s.energy(t, q, v).kinetic for t, q, v in zip(res.t, res.q, res.v)])
    assert np.abs(E - E[0]).max() < 1e-10 * T.max()
    assert np.abs(Lz - Lz[0]).max() < 1e-10 * abs(Lz[0])
    assert np.abs([s.constraints(t, q) for t, q in zip(res.t, res.q)]).max() < 1e-12


@pytest.mark.parametrize("method", ["energy-momentum", "energy-collocation"])
def test_a_lamina_payload_runs_on_the_saddle_point_system(method):
    # Catches: a factorisation of M alone (a thin disk's axis director carries no mass: M is singular and
    # splu raised "Factor is exactly singular", for energy-collocation until its constrained step took the
    # acceleration from the KKT system too); the KKT system is regular on the constraint manifold. The
    # accelerations must satisfy the acceleration-level constraint G a = gamma (an a1 from M a1 = -r - G^T lam
    # with any other multiplier would not).
    b = spatial_pendulum("Cable3D", 2, E=5e7, t_end=0.2, thickness=0.0)
    s = b.system
    o = s.offsets[1]
    assert np.linalg.eigvalsh(s.mass(s.initial_state()[0]).toarray()[o:, o:]).min() < 1e-12
    res = simulate(s, (0.0, 0.2), method, h=0.01)
    assert res.success, res.message
    E = b.outputs["energy"](res.t, res.q, res.v, res.lam)
    assert np.abs(E - E[0]).max() < 1e-12 * np.abs(E).max()
    assert np.abs([s.constraints(t, q) for t, q in zip(res.t, res.q)]).max() < 1e-12
    assert np.all(np.isfinite(res.a))
    t, q, v, a = res.t[-1], res.q[-1], res.v[-1], res.a[-1]
    gamma = s.constraint_rates(t, q, v)[1]
    assert np.abs(s.constraint_jacobian(t, q) @ a - gamma).max() < 1e-8 * np.abs(a).max()
    if method == "energy-momentum":     # energy-collocation's L_z is not an invariant with constraints
        Lz = b.outputs["angular_momentum_z"](res.t, res.q, res.v, res.lam)
        assert np.abs(Lz - Lz[0]).max() < 1e-10 * abs(Lz[0])


def test_b5_energy_momentum_predicts_with_the_discrete_acceleration():
    # Catches: the step's predictor from a(t0), which carries the stiff axial modes the scheme keeps (B5,
    # BE2D 8 elements, h = 0.05: Newton's first residual 1.8e6, divergence at t = 1.85-1.9 s).
    b = spinup("BE2D", 8)
    res = simulate(b.system, (0.0, 2.5), "energy-momentum", h=0.05)
    assert res.success, res.message
    assert res.stats["newton_iterations"] < 12 * res.stats["steps"]
