"""Observed convergence orders, regressed on log-log data (imitates diffrax's test_ode_order).

Problem: the double pendulum of toy_models (configuration-dependent mass, velocity-dependent
inertia forces, a pulse torque for 0.5 s), integrated to t = 1 s; reference: Lobatto IIIA-3
with h = 1/2560. Newton is driven to 1e-13 so that its error stays below the truncation error.
"""
import numpy as np
import pytest

from ancfdae import simulate
from ancfdae.integrators import NewtonOptions
from support.toy_models import DoublePendulum

T = 1.0
NEWTON = NewtonOptions(tol=1e-13, residual_atol=0.0)


def _model():
    return DoublePendulum(torque=1.0, T=0.5)


def _final(res):
    """The state at T of a run that must have succeeded (a failed run is a failure, not an IndexError)."""
    assert res.success, res.message
    return res.q[-1]


@pytest.fixture(scope="module")
def reference():
    return _final(simulate(_model(), (0, T), "lobatto3", h=1 / 2560, newton=NEWTON, t_eval=[T]))


@pytest.mark.parametrize("method, declared, hs, opts", [
    ("lobatto3", 4, [1 / 20, 1 / 40, 1 / 80, 1 / 160], {}),
    ("lobatto2", 2, [1 / 40, 1 / 80, 1 / 160, 1 / 320], {}),
    ("newmark", 2, [1 / 40, 1 / 80, 1 / 160, 1 / 320], {}),
    ("hht", 2, [1 / 40, 1 / 80, 1 / 160, 1 / 320], {"alpha": 0.1}),
    ("generalized-alpha", 2, [1 / 40, 1 / 80, 1 / 160, 1 / 320], {"rho_inf": 0.6}),
])
def test_observed_order(reference, method, declared, hs, opts):
    errs = []
    for h in hs:
        res = simulate(_model(), (0, T), method, h=h, newton=NEWTON, t_eval=[T], **opts)
        assert res.success, res.message
        errs.append(np.max(np.abs(res.q[-1] - reference)))
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert abs(slope - declared) < 0.15, (method, slope, errs)


def test_newmark_with_gamma_off_half_is_first_order(reference):
    hs = [1 / 40, 1 / 80, 1 / 160, 1 / 320]
    errs = [np.max(np.abs(_final(simulate(_model(), (0, T), "newmark", h=h, beta=0.3025, gamma=0.6, newton=NEWTON,
                                          t_eval=[T])) - reference)) for h in hs]
    assert abs(np.polyfit(np.log(hs), np.log(errs), 1)[0] - 1.0) < 0.2


def test_ida_error_shrinks_with_rtol(reference):
    rtols = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
    errs = [np.max(np.abs(_final(simulate(_model(), (0, T), "ida", rtol=r, t_eval=[T])) - reference))
            for r in rtols]
    assert np.all(np.diff(np.log(errs)) < 0), errs
    # max_order 2 (undamped default): error ~ rtol^p with p about 1/2..1
    slope = np.polyfit(np.log(rtols), np.log(errs), 1)[0]
    assert 0.3 < slope < 1.2, slope
