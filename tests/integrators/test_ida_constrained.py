"""IDA on constrained models (GGL, y = [q, v, lam, mu], ``ida_constrained``)."""
import numpy as np
import pytest

from ancfdae.integrators import IDA
from ancfdae.integrators.ida_constrained import MULTIPLIER_ATOL, GGLResidual
from support.numerics import fd_gradient
from support.toy_constrained import (WithoutVelocityJacobian, consistent_start, double_pendulum, hanging_link, hub,
                                     reference, step_to)

T = 0.25
PROBLEMS = {"pendulum": double_pendulum, "link": hanging_link, "hub": hub,
            "link-fallback": lambda: WithoutVelocityJacobian(hanging_link())}


def run(model, rtol, linsolver="auto"):
    """Step IDA to T; returns the stepper and the largest |g| and |G v + g_t| after a step."""
    st = IDA(model, rtol=rtol, linsolver=linsolver)
    q0, v0, a0, l0 = consistent_start(model)
    st.initialize(model, 0.0, q0, v0, a0, T, lam0=l0)
    g, gv = step_to(st, model, T)
    return st, g, gv


@pytest.mark.parametrize("name", ["link", "hub", "link-fallback"])
def test_iteration_matrix_against_finite_differences(name):
    """dF/dy + cj dF/dy' against finite differences of the residual at a state with lam, mu != 0, in the
    solver's (permuted) ordering. Catches a missing H(lam), H(mu), Z(v) or G_t (hub), a wrong sign, and a
    permutation applied inconsistently between residual and matrix."""
    model = PROBLEMS[name]()
    q0, v0, a0, l0 = consistent_start(model)
    sysm = GGLResidual(model, 0.0, q0, v0, a0, l0, "dense")
    rng = np.random.default_rng(0)
    y, yp = rng.standard_normal(sysm.N) * 0.3, rng.standard_normal(sysm.N)
    y += sysm.join(q0, v0, a0, l0)[0]

    def F(yy, yyp):
        res = np.empty(sysm.N)
        sysm.resfn(0.31, yy, yyp, res)
        return res

    cj = 37.0
    ref = fd_gradient(lambda z: F(z, yp), y) + cj * fd_gradient(lambda z: F(y, z), yp)
    JJ = np.full((sysm.N, sysm.N), np.nan)
    sysm.jacfn(0.31, y, yp, None, cj, JJ)
    assert np.abs(JJ - ref).max() < 1e-7 * np.abs(ref).max()


def test_layout_and_error_test_weights():
    """join/split round trip; the multipliers (and only they) carry MULTIPLIER_ATOL in the solver's order."""
    model = hanging_link()
    q0, v0, a0, l0 = consistent_start(model)
    sysm = GGLResidual(model, 0.0, q0, v0, a0, l0, "band")
    q, v, a, lam = sysm.split(*sysm.join(q0, v0, a0, l0))
    assert all(np.array_equal(x, y) for x, y in ((q, q0), (v, v0), (a, a0), (lam, l0)))
    atol = sysm.atol(1e-6)
    assert np.all(atol[sysm.algebraic_idx] == MULTIPLIER_ATOL)
    assert np.sum(atol == MULTIPLIER_ATOL) == 2 * model.n_constraints


@pytest.mark.parametrize("name", ["link", "hub"])
def test_accuracy_and_constraint_drift(name):
    """rtol 1e-6: q within 20 rtol of DOP853 on the index-1 ODE (measured 1.2e-5 link, 2.0e-6 hub); band,
    dense and sparse solvers give the same run; max|g| stays below the position tolerance
    (the multipliers are out of the error *and* Newton tests: measured 4.7e-8 link, 1.6e-9 hub against
    atol_q = 1.8e-6 / 1.2e-6)."""
    model = PROBLEMS[name]()
    qr, _, _ = reference(model, np.array([0.0, T]))
    st, g, gv = run(model, 1e-6)
    assert st.t == T and np.abs(st.q - qr[-1]).max() < 20e-6
    atol_q = 1e-6 * max(1.0, np.abs(model.initial_state()[0]).max())
    assert g < atol_q
    for ls in ("dense", "sparse"):
        other = run(model, 1e-6, ls)[0]
        assert np.abs(other.q - st.q).max() < 1e-9


def test_tighter_tolerance_tightens_everything():
    """rtol 1e-8 on the distance link: q error 3.1e-8, lam error 1.1e-4 (from 1.2e-5 and 7.6e-3 at 1e-6),
    max|g| 1.1e-9 -- the multipliers converge although they are out of the error test."""
    model = hanging_link()
    qr, _, lr = reference(model, np.array([0.0, T]))
    coarse, g1, _ = run(model, 1e-6)
    fine, g2, _ = run(model, 1e-8)
    assert np.abs(fine.q - qr[-1]).max() < 0.05 * np.abs(coarse.q - qr[-1]).max()
    assert np.abs(fine.lam - lr[-1]).max() < 0.05 * np.abs(coarse.lam - lr[-1]).max()
    assert g2 < 0.1 * g1


def test_through_the_driver_and_without_multipliers():
    """``Integrator.run`` (the driver passes no lam0: the stepper solves the KKT system itself)."""
    model = hanging_link()
    res = IDA(model, rtol=1e-6).run((0.0, 0.1), t_eval=np.linspace(0.0, 0.1, 5))
    assert res.success
    assert max(np.abs(model.constraints(t, q)).max() for t, q in zip(res.t, res.q)) < 1e-6
