"""System of beams and joints: bad input, redundancy, the driver's refusals and projections, and the
issue's runs on beams (a clamp by elimination and by a Rigid joint; planar and spatial double pendulums)."""
import numpy as np
import pytest

from ancfdae import ConstraintMonitor, EnergyMonitor, Gravity, Material, RectangularSection, System, simulate
from ancfdae.integrators import FixedStepIntegrator, StepOutcome
from ancfdae.joints import Distance, Prescribed, Revolute, Rigid, Spherical
from ancfdae.models import BE2D, SQ2D, Beam, Cable3D

MAT = Material(E=1e9, nu=0.3, rho=1000.0)
SEC = RectangularSection(0.02)
G2, G3 = Gravity((0.0, -9.81)), Gravity((0.0, -9.81, 0.0))


def pendulum2d(n_el=4):
    b1 = Beam(BE2D(MAT, SEC), n_el, 1.0, loads=[G2])
    b2 = Beam(BE2D(MAT, SEC), n_el, 1.0, start=(1.0, 0.0), loads=[G2])
    return System([b1, b2], [Spherical("ground", (b1, 0)), Spherical((b1, -1), (b2, 0))])


def test_bad_joints_raise_clear_errors():
    b1 = Beam(BE2D(MAT, SEC), 2, 1.0)
    b2 = Beam(BE2D(MAT, SEC), 2, 1.0, start=(1.0, 0.0))
    c = Beam(Cable3D(MAT, SEC), 2, 1.0)
    stranger = Beam(BE2D(MAT, SEC), 2, 1.0)
    with pytest.raises(ValueError, match="not in `bodies`"):
        System([b1], [Spherical("ground", (stranger, 0))])
    with pytest.raises(ValueError, match=r"node index must lie in \[-3, 2\].*got 7"):
        System([b1], [Spherical("ground", (b1, 7))])
    with pytest.raises(ValueError, match=r"`where` must lie on the beam"):
        System([b1], [Spherical("ground", (b1, 1.5))])
    with pytest.raises(ValueError, match="applies to 3D bodies, got a 2D body"):
        System([b1, b2], [Revolute((b1, -1), (b2, 0), normals=(0, 0))])
    with pytest.raises(ValueError, match="joins a 2D and a 3D body"):
        System([b1, c], [Spherical((b1, 0), (c, 0))])
    with pytest.raises(ValueError, match="`angle` drives a planar slope"):
        System([c], [Prescribed((c, 0), angle=lambda t: (0.0, 0.0, 0.0))])
    with pytest.raises(ValueError, match="'ground' or a pair"):
        Spherical("floor", (b1, 0))
    with pytest.raises(ValueError, match="`length` must be a positive number"):
        Distance((b1, 0), (b2, 0), length=-1.0)


def test_redundant_joints_are_named():
    """The later duplicate is the one named (catches a rank test that would report the first joint)."""
    b1 = Beam(BE2D(MAT, SEC), 2, 1.0)
    with pytest.raises(ValueError, match=r"redundant: 2 constraint row\(s\).*pin again\[0\], pin again\[1\]"):
        System([b1], [Spherical("ground", (b1, 0)), Spherical("ground", (b1, 0), name="pin again")])
    clamped = Beam(BE2D(MAT, SEC), 2, 1.0, supports={0: "clamp"})
    with pytest.raises(ValueError, match="redundant"):      # a pin on an eliminated (clamped) node: G rows vanish
        System([clamped], [Spherical("ground", (clamped, 0))])


class _Euler(FixedStepIntegrator):
    """A user's explicit stepper that knows nothing of constraints."""

    name = "euler"

    def _step_impl(self, t, h):
        return StepOutcome(ok=True, t=t + h, q=self.q + h * self.v, v=self.v + h * self.a, a=self.a)


def test_driver_refuses_a_stepper_without_constraints_and_a_far_initial_state():
    s = pendulum2d(2)
    with pytest.raises(TypeError, match="cannot integrate constrained models"):
        simulate(s, (0.0, 0.1), method=_Euler, h=0.01)
    q0, v0 = s.initial_state()
    with pytest.raises(ValueError, match=r"`q0` is .* from the constraints.*Spherical\(ground, body 0 node 0\)"):
        simulate(s, (0.0, 0.1), method="generalized-alpha", h=0.01, q0=q0 + 0.01)
    # a small misfit is projected, logged and recorded (position and velocity)
    res = simulate(s, (0.0, 0.02), method="generalized-alpha", h=0.01, q0=q0 + 1e-6, v0=v0 + 1e-3)
    assert res.success and 0 < res.stats["initial_correction_q"] < 1e-4 and res.stats["initial_correction_v"] > 0
    assert np.abs(s.constraints(0.0, res.q[0])).max() < 1e-14


@pytest.mark.parametrize("element, method, h", [(BE2D, "generalized-alpha", 2e-3), (BE2D, "hht", 2e-3),
                                                (BE2D, "energy-momentum", 2e-3), (SQ2D, "generalized-alpha", 2e-3)])
def test_clamp_by_elimination_and_by_rigid_joint_give_the_same_motion(element, method, h):
    """A cantilever under gravity, clamped by elimination and free with a Rigid joint to the ground:
    the same free coordinates (catches a Rigid joint that fixes what the clamp leaves free -- BE2D's
    axial slope -- or frees what it fixes -- SQ2D's director length -- and multipliers that enter the
    equations with the wrong sign or scale)."""
    elim = Beam(element(MAT, SEC), 2, 1.0, supports={0: "clamp"}, loads=[G2])
    free = Beam(element(MAT, SEC), 2, 1.0, loads=[G2])
    joined = System([free], [Rigid("ground", (free, 0), fix_lengths=element is SQ2D)])
    ra = simulate(elim, (0.0, 0.04), method=method, h=h, t_eval=[0.02, 0.04])
    rb = simulate(joined, (0.0, 0.04), method=method, h=h, t_eval=[0.02, 0.04])
    assert ra.success and rb.success
    scale = np.abs(ra.q[-1] - elim.initial_state()[0]).max()
    assert scale > 1e-4                                        # the beam moved
    # energy-momentum: one scheme on both (Newton tolerance); the Newmark family: its unconstrained form is
    # state-averaged, its constrained one Arnold-Bruls -- both second order, equal to the discretisation error
    rtol = 1e-7 if method == "energy-momentum" else 1e-3
    assert np.abs(rb.q[:, elim.free] - ra.q).max() < rtol * scale
    # the reaction is the clamp's: vertical force = weight minus inertia, nonzero
    assert abs(rb.lam[-1][1]) > 0.1


@pytest.mark.parametrize("method, h", [("generalized-alpha", 1e-2), ("energy-momentum", 5e-3)])
def test_planar_double_pendulum(method, h):
    """Two 4-element BE2D beams, pins, gravity, released horizontally. Energy-momentum: energy to 1e-10
    relative and g to 1e-12 m; generalized-alpha: g to the Newton tolerance and dissipative energy.
    (Spans shortened for the suite: 1 s and 0.3 s; docs/constraints.md reports the 2 s runs.)"""
    s = pendulum2d()
    T = 1.0 if method == "generalized-alpha" else 0.3
    res = simulate(s, (0.0, T), method=method, h=h, monitors=[EnergyMonitor(), ConstraintMonitor()],
                   t_eval=np.linspace(0.0, T, 6))
    assert res.success, res.message
    cons, energy = res.monitors["constraints"], res.monitors["energy"]
    assert cons["max_position"] < 1e-12
    tip = res.q[-1][-4:-2]
    assert tip[1] < -0.4                               # it fell
    if method == "energy-momentum":
        assert energy["relative_drift"] < 1e-10
    else:
        assert energy["drift"][-1] < 0 and energy["relative_drift"] < 1e-2


def test_spatial_double_pendulum_of_cables():
    """Cable3D beams with Spherical joints, released horizontally with a sideways push: energy-momentum
    keeps energy and g; the motion leaves the plane."""
    c1 = Beam(Cable3D(MAT, SEC), 3, 1.0, loads=[G3], initial_velocity=lambda x: np.tile([0.0, 0.0, 0.5], (len(x), 1)))
    c2 = Beam(Cable3D(MAT, SEC), 3, 1.0, start=(1.0, 0.0, 0.0), loads=[G3])
    s = System([c1, c2], [Spherical("ground", (c1, 0)), Spherical((c1, -1), (c2, 0))])
    res = simulate(s, (0.0, 0.2), method="energy-momentum", h=2e-3, monitors=[EnergyMonitor(), ConstraintMonitor()])
    assert res.success, res.message
    assert res.monitors["energy"]["relative_drift"] < 1e-10
    assert res.monitors["constraints"]["max_position"] < 1e-12
    assert abs(res.q[-1][-4]) > 1e-2                   # z of the last node: out of the plane


def test_a_body_with_its_own_constraints_comes_first():
    """A body that declares 'constraints' itself (a rigid body's orthonormal directors, issue 19; here the
    point-mass toy) contributes its rows before the joints', on its own coordinates (catches a missing
    column offset or a body's rows dropped)."""
    from support.numerics import fd_gradient, rel_err
    from support.pendulum_toy import PointPendulum
    beam = Beam(BE2D(MAT, SEC), 2, 1.0)
    toy = PointPendulum(amplitude=0.2)
    s = System([beam, toy], [Spherical("ground", (beam, 0))])
    assert s.n_constraints == 4 and s.constraint_labels[:2] == ("body 1: row 0", "body 1: row 1")
    rng = np.random.default_rng(5)
    q = s.initial_state()[0] + 0.01 * rng.standard_normal(s.n_dof)
    v, lam = rng.standard_normal(s.n_dof), rng.standard_normal(4)
    n = beam.n_dof
    assert np.allclose(s.constraints(0.3, q)[:2], toy.constraints(0.3, q[n:]))
    assert rel_err(s.constraint_jacobian(0.3, q).toarray(), fd_gradient(lambda x: s.constraints(0.3, x), q)) < 1e-7
    H = s.constraint_force_jacobian(0.3, q, lam).toarray()
    assert rel_err(H, fd_gradient(lambda x: s.constraint_jacobian(0.3, x).T @ lam, q)) < 1e-7
    assert np.allclose(s.constraint_force(0.3, q, lam), s.constraint_jacobian(0.3, q).T @ lam, atol=1e-13)
    assert np.allclose(s.constraint_rates(0.3, q, v)[1][:2], toy.constraint_rates(0.3, q[n:], v[n:])[1])
