"""The Newmark family's compiled whole steps (the driver's ``steps_until`` between output times, a BE2D beam's
``compiled_residual().steps``) reach the states of the step-by-step path and count the same work.

Catches: a step's work counted twice or not at all, or the work of a step handed back to Python counted
(``newton_iterations``, ``residual_evals``, ``newton_solves``, ``jacobian_evals``, ``factorizations``,
``retries`` must match); a compiled step that skips a decision of the solver (a non-contracting
iteration that must refresh the matrix: the counts differ); the predictor, the weighted state or the
update with the wrong coefficients, the dead loads' time functions at the wrong times, the grid's last
shortened step taken with the old matrix (the states differ); an output time skipped or taken from
the wrong step (``t_eval`` off the grid: the interpolant needs the step before); a failure inside the
steps losing the outputs before it or its time and reason; a hook or monitor that no longer sees every
step.
"""
import numpy as np
import pytest

from ancfdae import Gravity, Material, PointForce, RectangularSection, simulate
from ancfdae.integrators import _alpha_steps, newmark
from ancfdae.models import BE2D, Beam

pytest.importorskip("numba")

COUNTS = ("steps", "newton_iterations", "newton_solves", "residual_evals", "jacobian_evals", "factorizations",
          "retries", "failed_solves")


def _beam(n=6, time=lambda t: np.cos(40 * t)):
    el = BE2D(Material(2.1e10, 0.3, 4000.0), RectangularSection(0.05))
    loads = [Gravity((0.0, -9.81)), PointForce((0.0, -20.0), node=-1, time=time), PointForce((5.0, 0.0), node=3)]
    return Beam(el, n_elements=n, length=1.0, supports={0: ("x", "y")}, loads=loads)


def _both(beam, monkeypatch, method, t_end, **kw):
    fast = simulate(beam, (0.0, t_end), method, **kw)
    monkeypatch.setattr(newmark._AlphaFamily, "steps_until", None)   # the driver's step-by-step loop
    slow = simulate(beam, (0.0, t_end), method, **kw)
    monkeypatch.undo()
    return fast, slow


def _same(fast, slow):
    for key in COUNTS:
        assert fast.stats[key] == slow.stats[key], key
    np.testing.assert_array_equal(fast.t, slow.t)
    for name in ("q", "v", "a"):
        f, s = getattr(fast, name), getattr(slow, name)
        assert f.shape == s.shape
        assert np.abs(f - s).max() <= 1e-12 * np.abs(s).max(), name


@pytest.mark.parametrize("method, opts", [("generalized-alpha", {"rho_inf": 0.8}), ("newmark", {}),
                                          ("hht", {"alpha": 0.1})])
@pytest.mark.parametrize("contraction", [0.3, 0.9])
def test_compiled_steps_match_step_by_step(method, opts, contraction, monkeypatch):
    # t_end off the grid: the last step is shortened (a new matrix); outputs on and off the grid
    t_eval = [0.0, 0.0035, 0.01, 0.0123, 0.0205]
    fast, slow = _both(_beam(), monkeypatch, method, 0.0205, h=1e-3, t_eval=t_eval,
                       newton={"tol": 1e-10, "contraction": contraction}, **opts)
    assert fast.status == slow.status == "success"
    _same(fast, slow)
    assert fast.t.tolist() == t_eval


def test_compiled_steps_are_used(monkeypatch):
    # Catches: the compiled steps silently never taken (the test above would compare the Python path with itself).
    taken = []
    run = _alpha_steps.AlphaSteps.run

    def spy(self, *a):
        out = run(self, *a)
        taken.append(out[1])
        return out

    monkeypatch.setattr(_alpha_steps.AlphaSteps, "run", spy)
    res = simulate(_beam(), (0.0, 0.05), "generalized-alpha", h=1e-3, t_eval=[0.025, 0.05])
    assert res.status == "success"
    # Python steps: the first, each one with a refreshed matrix, the one before each output time
    assert sum(taken) > res.stats["steps"] // 2


def test_a_long_stretch_without_outputs_returns_to_python_now_and_then(monkeypatch):
    # Catches: one compiled call for the whole run (Ctrl-C and the progress bar wait until it ends).
    monkeypatch.setattr(_alpha_steps, "STEPS_PER_CALL", 7)
    fast, slow = _both(_beam(), monkeypatch, "generalized-alpha", 0.03, h=1e-3, t_eval=[0.03])
    _same(fast, slow)
    calls = []
    run = _alpha_steps.AlphaSteps.run
    monkeypatch.setattr(_alpha_steps.AlphaSteps, "run", lambda self, *a: calls.append(1) or run(self, *a))
    monkeypatch.setattr(_alpha_steps, "STEPS_PER_CALL", 7)
    simulate(_beam(), (0.0, 0.03), "generalized-alpha", h=1e-3, t_eval=[0.03])
    assert len(calls) >= 30 // 7


def test_failure_inside_the_steps_keeps_the_outputs(monkeypatch):
    # the dead load turns NaN at t = 0.0131: the compiled steps hand that step to Python, which fails it
    def time(t):
        return np.nan if t > 0.0131 else np.cos(40 * t)

    fast, slow = _both(_beam(time=time), monkeypatch, "generalized-alpha", 0.03, h=1e-3,
                       t_eval=[0.005, 0.01, 0.02, 0.03])
    assert fast.status == slow.status == "failed"
    assert fast.message == slow.message and "not finite" in fast.message
    assert fast.t_fail == slow.t_fail == pytest.approx(0.013)
    _same(fast, slow)
    assert fast.t.tolist() == [0.005, 0.01]


def test_hooks_see_every_step():
    seen = []
    res = simulate(_beam(), (0.0, 0.01), "newmark", h=1e-3, t_eval=[0.01], hooks=[lambda t, q, v, a: seen.append(t)])
    assert res.status == "success" and res.stats["steps"] == 10
    assert len(seen) == 9    # every step but the last (the run ends there)


def test_a_model_without_the_offer_keeps_the_python_step():
    beam = _beam()
    beam.element.kernel = "numpy"
    assert beam.compiled_residual() is None
    res = simulate(beam, (0.0, 0.005), "generalized-alpha", h=1e-3, t_eval=[0.005])
    assert res.status == "success" and res.stats["steps"] == 5
