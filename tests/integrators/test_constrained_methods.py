"""The constrained Newmark family (index 3, Arnold-Bruls) and energy-momentum on the point-mass toy.

Cheap (n = 4, m = 2, quadratic constraints): Newton matrices against finite differences of the step
residuals, convergence orders of q and of the method's own multipliers, exact energy and constraints of
energy-momentum, the work of a prescribed motion in the energy balance, and the protocol (lam0, lam).
"""
import numpy as np
import pytest

from ancfdae import ConstraintMonitor, EnergyMonitor, simulate
from ancfdae.constrained import consistent_state
from ancfdae.integrators import EnergyMomentum, GeneralizedAlpha, HHTAlpha, Newmark
from ancfdae.integrators._alpha_index3 import index3_equations
from ancfdae.integrators._em_constrained import constrained_em_equations
from support.numerics import fd_gradient, rel_err
from support.pendulum_toy import PointPendulum


def _started(cls, model, h, **kw):
    q0, v0 = model.initial_state()
    cs = consistent_state(model, 0.0, q0, v0 + np.array([0.0, 0.3, 0.0, -0.2]))
    st = cls(model, h, **kw)
    st.initialize(model, 0.0, cs.q, cs.v, cs.a, 1.0, lam0=cs.lam)
    for _ in range(3):                     # off the initial state: a general step
        st.accept(st.step())
    return st


@pytest.mark.parametrize("cls, equations", [(GeneralizedAlpha, lambda st: index3_equations(st, st.t, 0.01)[:3]),
                                            (EnergyMomentum, lambda st: constrained_em_equations(st, st.t, 0.01))],
                         ids=["generalized-alpha", "energy-momentum"])
def test_newton_matrix_is_the_derivative_of_the_step_residual(cls, equations):
    """Block by block against central differences (catches a dropped H(lam), a G at the wrong time or state,
    a wrong scale between the rows and the multipliers' unknowns)."""
    model = PointPendulum(amplitude=0.2)
    st = _started(cls, model, 0.01)
    residual, jacobian, x0 = equations(st)
    x = x0 + 1e-3 * np.random.default_rng(0).standard_normal(x0.size) * np.abs(x0).max()
    J = jacobian(x)[0]
    J = J.toarray() if hasattr(J, "toarray") else np.asarray(J)
    Jfd = fd_gradient(residual, x, h=1e-7)
    n = model.n_dof
    for rows, cols in ((slice(0, n), slice(0, n)), (slice(0, n), slice(n, None)), (slice(n, None), slice(0, n))):
        assert rel_err(J[rows, cols], Jfd[rows, cols]) < 1e-6
    assert np.abs(J[n:, n:]).max() == 0.0


def _orders(errors, hs):
    return np.diff(np.log(errors)) / np.diff(np.log(hs))


def test_generalized_alpha_index3_is_second_order_in_q_and_its_own_lam():
    """Self-convergence at T = 1 s (differences of successive halvings): q and the method's own multipliers
    at t_{n+1} both of order 2 (a state-averaged scheme, with lam at t_{n+1-af}, gives 1 for lam)."""
    model = PointPendulum()
    T, hs = 0.5, [1 / 40, 1 / 80, 1 / 160, 1 / 320]
    runs = []
    for h in hs:
        st = GeneralizedAlpha(model, h, rho_inf=0.8)
        res = st.run((0.0, T), t_eval=[T])
        assert res.success, res.message
        runs.append((res.q[-1], st.lam.copy(), res.lam[-1]))
    eq = [np.abs(a[0] - b[0]).max() for a, b in zip(runs, runs[1:])]
    el = [np.abs(a[1] - b[1]).max() for a, b in zip(runs, runs[1:])]
    ek = [np.abs(a[2] - b[2]).max() for a, b in zip(runs, runs[1:])]
    for e in (eq, el, ek):
        assert np.all(_orders(e, hs[1:]) > 1.8), e


@pytest.mark.parametrize("cls, kw", [(Newmark, {}), (HHTAlpha, {"alpha": 0.1}), (GeneralizedAlpha, {"rho_inf": 0.5})])
def test_newmark_family_keeps_the_position_constraints(cls, kw):
    """Index 3: g(t_n, q_n) = 0 to the Newton tolerance at every step, with every member of the family
    (catches a scheme that imposes only the velocity or acceleration constraint: its g drifts)."""
    model = PointPendulum()
    res = simulate(model, (0.0, 0.5), method=cls, h=0.01, monitors=[ConstraintMonitor()], **kw)
    assert res.success
    assert res.monitors["constraints"]["max_position"] < 1e-10


def test_energy_momentum_keeps_energy_and_constraints_exactly():
    """Quadratic constraints, 100 steps of 10 ms: energy to 1e-13 relative, g to 1e-14 (catches G(q1) or
    G(q0) in place of the midpoint Jacobian: the energy then drifts)."""
    model = PointPendulum()
    res = simulate(model, (0.0, 1.0), method="energy-momentum", h=0.01, monitors=[EnergyMonitor(), ConstraintMonitor()])
    assert res.success, res.message
    assert res.monitors["energy"]["relative_drift"] < 1e-13
    assert res.monitors["constraints"]["max_position"] < 1e-14


def test_energy_balance_includes_the_work_of_a_prescribed_motion():
    """A driven pivot: T + V changes by the work of the driving force; the energy monitor's balance
    (with int lam . g_t dt) stays at the quadrature's accuracy (catches a missing or sign-flipped power)."""
    model = PointPendulum(amplitude=0.3, omega=4.0)
    runs = {}
    for h in (0.01, 0.005):
        res = simulate(model, (0.0, 0.5), method="energy-momentum", h=h, monitors=[EnergyMonitor()])
        assert res.success
        runs[h] = res.monitors["energy"]
    e = runs[0.005]
    assert np.abs(e["total"] - e["total"][0]).max() > 100 * np.abs(e["drift"]).max()   # the drive does work
    assert np.abs(runs[0.01]["drift"]).max() / np.abs(e["drift"]).max() > 3.0            # quadrature error, O(h^2)


def test_driver_hands_lam0_and_reports_kkt_multipliers():
    """Result.lam are the KKT multipliers of the output states (their own equations hold), the stepper
    received lam0 and keeps its own multipliers."""
    model = PointPendulum()
    st = GeneralizedAlpha(model, 0.01)
    res = st.run((0.0, 0.2), t_eval=[0.0, 0.1, 0.2])
    assert res.lam.shape == (3, 2)
    for t, q, v, lam in zip(res.t, res.q, res.v, res.lam):
        G = model.constraint_jacobian(t, q)
        a = np.linalg.solve(model.M.toarray(), -model.residual(t, q, v, 0 * q) - G.T @ lam)
        assert abs(G @ a - model.constraint_rates(t, q, v)[1]).max() < 1e-9
    assert st.lam.shape == (2,) and np.all(np.isfinite(st.lam))
    assert np.abs(st.lam - res.lam[-1]).max() < 1e-2 * np.abs(res.lam[-1]).max()
