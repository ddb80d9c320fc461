"""The Newmark family's compiled Newton iterations (a BE2D beam's ``compiled_residual``) take the decisions of
the Python loop and reach its states to round-off.

Catches: an iteration counted twice or not at all (``newton_iterations``, ``residual_evals`` and the
model's counter must match the Python path's), a compiled loop that carries on past an iteration that
needs a decision (non-contracting: the Jacobian refresh would be skipped and the counts would differ;
converged: an extra iteration), a weighted state built with the wrong coefficients, the external
force of the wrong time, a beam with point moments (configuration-dependent load) sent to the
compiled path, and a user's model without the offer failing.
"""
import numpy as np
import pytest

from ancfdae import Gravity, Material, PointForce, PointMoment, RectangularSection, simulate
from ancfdae.integrators import newmark
from ancfdae.models import BE2D, Beam

pytest.importorskip("numba")


def _pendulum(n=6, loads=None):
    el = BE2D(Material(2.1e10, 0.3, 4000.0), RectangularSection(0.05))
    loads = [Gravity((0.0, -9.81)), PointForce((0.0, -20.0), node=-1, time=lambda t: np.cos(40 * t))] \
        if loads is None else loads
    return Beam(el, n_elements=n, length=1.0, supports={0: ("x", "y")}, loads=loads)


def _run(beam, method, compiled, monkeypatch, **opts):
    if not compiled:
        monkeypatch.setattr(newmark._AlphaFamily, "_compiled_iteration", lambda self, *a: None)
    res = simulate(beam, (0.0, 0.02), method, h=1e-3, **opts)
    monkeypatch.undo()
    return res


@pytest.mark.parametrize("method, opts", [("generalized-alpha", {"rho_inf": 0.8}), ("newmark", {}),
                                          ("hht", {"alpha": 0.1})])
@pytest.mark.parametrize("contraction", [0.3, 0.9])
def test_compiled_iterations_match_the_python_loop(method, opts, contraction, monkeypatch):
    beam = _pendulum()
    assert beam.compiled_residual() is not None
    newton = {"tol": 1e-10, "contraction": contraction}
    fast = _run(beam, method, True, monkeypatch, newton=newton, **opts)
    slow = _run(beam, method, False, monkeypatch, newton=newton, **opts)
    assert fast.status == slow.status == "success"
    for key in ("newton_iterations", "residual_evals", "jacobian_evals", "factorizations", "retries"):
        assert fast.stats[key] == slow.stats[key], key
    scale = np.abs(slow.q).max()
    assert np.abs(fast.q - slow.q).max() <= 1e-12 * scale
    assert np.abs(fast.a - slow.a).max() <= 1e-9 * np.abs(slow.a).max()


def test_compiled_iterations_are_used(monkeypatch):
    # Catches: the offer silently never taken (then the test above compares the Python path with itself).
    calls = []
    orig = newmark.AlphaIteration.__call__

    def spy(self, *a):
        out = orig(self, *a)
        calls.append(out is not None)
        return out

    monkeypatch.setattr(newmark.AlphaIteration, "__call__", spy)
    simulate(_pendulum(), (0.0, 0.005), "generalized-alpha", h=1e-3)
    assert calls and all(calls)


def test_moments_and_full_newton_keep_the_python_path():
    assert _pendulum(loads=[PointMoment(2.0, node=-1)]).compiled_residual() is None
    beam = _pendulum()
    res = simulate(beam, (0.0, 0.005), "generalized-alpha", h=1e-3, newton={"jacobian": "full"})
    assert res.status == "success"


def test_numpy_kernel_has_no_compiled_iterations():
    beam = _pendulum()
    beam.element.kernel = "numpy"
    assert beam.compiled_residual() is None
