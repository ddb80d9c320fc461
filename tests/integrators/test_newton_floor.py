"""How the Newton steppers carry the residual's round-off floor (issue 17): the policy, pinned.

The floor ``FACTOR * eps * max|K| * max(1, max|q|)`` (``ancfdae._scale``) comes with every Jacobian
evaluation. Two policies were measured on the quick studies: a running maximum over the run and the
floor of the latest Jacobian. Lobatto IIIA and the Newmark family keep the running maximum (the
latest-Jacobian floor changed flying2d's eps_T at round-off level, 1e-13 to 5e-11 relative); the
energy-momentum stepper keeps the latest (a running maximum changed energy and flying3d, and raised
the SQ3D run's energy balance error from 1.4e-15 to 1.3e-13 J). Either is the stepper's own state, passed to every
solve and returned by it, not a field of the solver written from outside. These tests fail if
someone switches either policy (checked by switching it).
"""
import numpy as np
import pytest
import scipy.sparse as sp

from ancfdae import simulate
from ancfdae.integrators import NewtonOptions
from ancfdae.integrators._newton import NewtonSolver
from ancfdae.problem import JacobianBlocks

K_STIFF, T_DROP = 1e14, 0.05


class SofteningSpring:
    """``a + k(t) q = f(t)`` on one coordinate, from rest: ``k = 1e14, f = 1`` until ``T_DROP``, then 1 and 10.

    The stiff phase barely moves (``q ~ 1e-14``) but its Jacobians bring the floor
    ``10 eps 1e14 = 0.22``. The load step at the drop makes Newton iterate there (a Jacobian of the
    soft spring, floor ``10 eps``); afterwards the soft spring swings with predictor residuals
    ``|a_{n+1} - a_n| < 0.1``: below the stiff floor, far above the soft one.
    """

    n_dof, mass_is_constant = 1, True

    def initial_state(self):
        return np.array([0.0]), np.array([0.0])

    def k(self, t):
        return K_STIFF if t < T_DROP else 1.0

    def mass(self, q):
        return sp.identity(1, format="csr")

    def residual(self, t, q, v, a):
        return a + self.k(t) * q - (1.0 if t < T_DROP else 10.0)

    def jacobian(self, t, q, v, a):
        eye = sp.identity(1, format="csr")
        return JacobianBlocks(K=self.k(t) * eye, D=0.0 * eye, M=eye, same_pattern=True)


def test_solver_raises_the_floor_never_lowers_it():
    # Catches a solver that replaces the floor it was given by a smaller one from a new Jacobian.
    def jac(x, f):
        return lambda x: (sp.identity(1, format="csr"), f)
    s = NewtonSolver(NewtonOptions(jacobian="full"))
    assert s.solve(lambda x: x - 2.0, jac(None, 1e-3), np.array([0.0]), floor=1e-9).floor == 1e-3
    assert s.solve(lambda x: x - 2.0, jac(None, 1e-3), np.array([0.0]), floor=0.5).floor == 0.5
    # a plain matrix brings no floor: the one given stays
    out = s.solve(lambda x: x - 2.0, lambda x: sp.identity(1, format="csr"), np.array([0.0]), floor=0.25)
    assert out.floor == 0.25 and out.converged


@pytest.mark.parametrize("method", ["newmark", "lobatto3"])
def test_the_floor_of_the_stiff_phase_stays_after_the_stiffness_drops(method):
    # Once the spring has been 1e14 stiff, residuals below 10 eps 1e14 (0.22) are round-off for the
    # rest of the run: later steps stop there (a latest-Jacobian floor would drive them to ~1e-15).
    seen = []
    model = SofteningSpring()

    def hook(t, q, v, a):
        if t > T_DROP + 0.02:
            seen.append(abs(model.residual(t, q, v, a)[0]) if method == "newmark" else 0.0)
    res = simulate(model, (0.0, 0.3), method, h=0.01, hooks=[hook],
                   newton=NewtonOptions(residual_atol=0.0, jacobian="full"))
    assert res.success, res.message
    floor = 10 * np.finfo(float).eps * K_STIFF
    if method == "newmark":    # its accepted state is Newton's last iterate: the residual is observable
        assert 1e-6 < max(seen) <= floor
    # iterations in the 23 steps after the drop: only when the accepted residuals have piled up to the
    # old floor (measured: 1, at t = 0.25, both methods); a latest-Jacobian floor iterates at every step
    its = simulate(model, (0.0, 0.3), method, h=0.01, newton=NewtonOptions(residual_atol=0.0, jacobian="full"),
                   t_eval=[0.3]).stats["newton_iterations"]
    before = simulate(model, (0.0, T_DROP + 0.02), method, h=0.01,
                      newton=NewtonOptions(residual_atol=0.0, jacobian="full")).stats["newton_iterations"]
    assert its - before <= 2


def test_the_floor_starts_at_zero_in_every_run():
    # Catches a maximum carried over from an earlier run of the same stepper: a soft spring after the
    # stiff run must be solved to its own round-off.
    from ancfdae.integrators import Newmark
    model = SofteningSpring()
    stepper = Newmark(model, 0.01, newton=NewtonOptions(residual_atol=0.0, jacobian="full"))
    first = stepper.run((0.0, 0.3))
    soft = stepper.run((0.1, 0.4))             # k = 1 throughout
    fresh = Newmark(model, 0.01, newton=NewtonOptions(residual_atol=0.0, jacobian="full")).run((0.1, 0.4))
    assert fresh.success, fresh.message
    assert first.success and soft.success
    np.testing.assert_array_equal(soft.q, fresh.q)
    assert soft.stats["newton_iterations"] == fresh.stats["newton_iterations"] > 0


class SofteningPotential:
    """:class:`SofteningSpring` with the "potential" capability: ``P = k(t) q^2 / 2``, ``f`` a dead load.

    The energy-momentum stepper's floor in the stiff phase is ``0.1 eps 1e14 / 2 = 1e-3`` (its Jacobian
    is ``K(midpoint) / 2``); the load step at the drop makes Newton evaluate a soft one there.
    """

    n_dof, mass_is_constant, potential_degree = 1, True, None
    capabilities = frozenset({"potential"})
    k = SofteningSpring.k

    def initial_state(self):
        return np.array([0.0]), np.array([0.0])

    def mass(self, q):
        return sp.identity(1, format="csr")

    residual = SofteningSpring.residual
    jacobian = SofteningSpring.jacobian

    def potential(self, t, q):
        return 0.5 * self.k(t) * float(q @ q)

    def potential_gradient(self, t, q, tangent=True):
        return self.k(t) * q, self.k(t) * sp.identity(1, format="csr") if tangent else None

    def nonconservative_force(self, t, q, tangent=True):
        return np.full(1, 1.0 if t < T_DROP else 10.0), sp.csr_matrix((1, 1)) if tangent else None


def test_energy_momentum_takes_the_floor_of_the_latest_jacobian():
    # Catches the energy-momentum stepper switched to a running maximum: after the stiffness drops,
    # the soft phase must still keep its energy balance T + P - f q to round-off (measured 4.4e-15 J
    # with the latest Jacobian's floor; a floor kept from the stiff phase: 1.0e-5 J).
    res = simulate(SofteningPotential(), (0.0, 0.5), "energy-momentum", h=0.01)
    assert res.success, res.message
    soft = res.t > T_DROP + 0.015
    q, v = res.q[soft, 0], res.v[soft, 0]
    balance = 0.5 * v ** 2 + 0.5 * q ** 2 - 10.0 * q
    assert np.ptp(balance) < 1e-12
