"""solve_static's compiled load step (BE2D, full Newton) equals the Python iteration: decisions, counters, messages,
and states to round-off.

The Python iteration is reached by refusing the offer (``CompiledStatic.offer`` returning None), so both runs
solve the same beam. Catches: a residual or tangent computed differently beyond round-off (states to 1e-12 of
their size; bitwise equality with LAPACK's factorisation holds on some CPUs only), a decision taken in another order (converged / round-off stagnation / the rate tests),
a counter or message that differs from the solver's, a wrong load factor or external force (gravity, dead
loads with a time function), and the offer taken where it must not be (moments, modified Newton).
"""
import re

import numpy as np
import pytest

from ancfdae import Gravity, Material, PointForce, PointMoment, RectangularSection, solve_static
from ancfdae import _static_compiled as sc
from ancfdae.models import BE2D, Beam

pytest.importorskip("numba")


def _beam(n=8, loads=None, formulation="structural", supports=None):
    el = BE2D(Material(2.1e11, 0.3, 7800.0), RectangularSection(0.1), formulation=formulation)
    F = 3 * el.material.E * el.section.I3 / 4.0
    loads = [PointForce((0.0, F), node=-1)] if loads is None else loads
    return Beam(el, n, 2.0, supports={0: "clamp"} if supports is None else supports, loads=loads)


def _both(make, monkeypatch, **kw):
    """(compiled, Python) results of solve_static on two equal beams."""
    beam = make()
    assert sc.CompiledStatic.offer(beam, kw.get("t", 0.0), kw.get("jacobian", "full"), False) is not None
    compiled = solve_static(beam, check_stability=False, **kw)
    with monkeypatch.context() as mp:
        mp.setattr(sc.CompiledStatic, "offer", classmethod(lambda cls, *a: None))
        python = solve_static(make(), check_stability=False, **kw)
    return compiled, python


def _same(a, b):
    """Equal decisions, counters and messages; states equal to round-off.

    The Python iteration factorises with LAPACK (scipy), the compiled one with its own banded LU: both
    follow the same pivoting, but OpenBLAS picks its kernels by CPU (AVX-512 and AVX2 round differently),
    so bitwise equality of the states holds on some machines only (seen: an AMD EPYC with AVX-512 differs
    in the last bit). Residuals at the round-off floor are compared to that floor.
    """
    assert a.status == b.status
    assert _no_numbers(a.message) == _no_numbers(b.message)
    assert {k: v for k, v in a.stats.items() if k != "cpu_time"} == {k: v for k, v in b.stats.items() if k != "cpu_time"}
    assert [(s["iterations"], s["converged"]) for s in a.steps] == [(s["iterations"], s["converged"]) for s in b.steps]
    scale = max(np.abs(b.q).max(), 1.0)
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-12 * scale)
    for sa, sb in zip(a.steps, b.steps):
        np.testing.assert_allclose(sa["q"], sb["q"], rtol=0, atol=1e-12 * scale)
        # An unconverged step's residual agrees to many digits; a converged one's lies at the round-off floor,
        # a diverging one's (a near-singular tangent) is round-off amplified: neither is compared.
        if not sa["converged"] and "diverging" not in a.message:
            assert abs(sa["residual"] - sb["residual"]) <= 1e-6 * abs(sb["residual"]), (sa, sb)


def _no_numbers(message):
    """A message with its printed reals removed (residuals at the floor; a near-singular tangent's rate, which
    round-off decides), its integers (iterations, load steps) kept."""
    return re.sub(r"\d+\.\d*(e[+-]?\d+)?|\d+e[+-]?\d+", "*", message)


@pytest.mark.parametrize("formulation", ["structural", "continuum"])
@pytest.mark.parametrize("n", [1, 16, 64])
def test_b1_load_steps_equal_the_python_iteration(monkeypatch, formulation, n):
    a, b = _both(lambda: _beam(n, formulation=formulation), monkeypatch, load_steps=10, tol=1e-8)
    _same(a, b)
    assert a.success and a.iterations > 10


def test_gravity_and_timed_dead_loads_at_t(monkeypatch):
    # a dead load's time function is read at the solve's t, gravity always acts
    def make():
        return _beam(6, loads=[Gravity((0.0, -9.81)), PointForce((2e4, -3e5), s=1.3, time=lambda t: 1.0 + t)],
                     supports={0: "pin", 6: ("y",)})
    a, b = _both(make, monkeypatch, load_steps=3, t=0.7)
    _same(a, b)
    assert a.success and np.abs(a.q - make().initial_state()[0]).max() > 1e-6


@pytest.mark.parametrize("max_iter", [1, 2, 3])
def test_a_step_that_does_not_converge_fails_alike(monkeypatch, max_iter):
    a, b = _both(lambda: _beam(4), monkeypatch, load_steps=1, max_iter=max_iter)
    _same(a, b)
    assert a.status == "failed" and "not converged in" in a.message


def test_far_loads_round_off_and_rigid_motions_alike(monkeypatch):
    F = 3 * 2.1e11 * (0.1 ** 4 / 12) / 4.0
    # a load far beyond the material law's range in one step
    a, b = _both(lambda: _beam(4, loads=[PointForce((F * 1e4, F * 1e4), node=-1)]), monkeypatch, load_steps=1,
                 max_strain=None)
    _same(a, b)
    assert a.success and a.iterations >= 4
    # a tolerance below round-off: the solves end on the stagnation test (correction at round-off level)
    a, b = _both(lambda: _beam(128), monkeypatch, load_steps=2, tol=1e-17, residual_atol=0.0)
    _same(a, b)
    assert a.success
    # a support that leaves rigid motions: the near-singular tangent diverges (twice a rate above 1)
    a, b = _both(lambda: _beam(4, supports={0: ("x",)}), monkeypatch, load_steps=1)
    _same(a, b)
    assert a.status == "failed" and "diverging" in a.message


def test_no_offer_for_moments_or_modified_newton():
    beam = _beam(4, loads=[PointMoment(1e5, node=-1)])
    assert sc.CompiledStatic.offer(beam, 0.0, "full", False) is None
    assert sc.CompiledStatic.offer(_beam(4), 0.0, "modified", False) is None
    assert sc.CompiledStatic.offer(_beam(4), 0.0, "full", True) is None
