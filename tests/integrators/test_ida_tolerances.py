"""IDA's absolute tolerances reach the right coordinates: per group (positions, velocities), in the
solver's node-interleaved ordering, with the documented default over a span other than 1 s.

The earlier IDA tests all ran over [0, 1] s, where the default position and velocity tolerances are
equal (``rtol L`` and ``rtol L / (tf - t0)``), so swapping the groups or not permuting them into the
band solver's ordering passed every test (mutation-checked, see tests/README.md). Here the groups
differ by six orders of magnitude, and the step count shows which coordinates got which tolerance.
"""
import numpy as np
import pytest

from ancfdae import simulate
from support.toy_models import SpringChain

RTOL = 1e-5


def _run(atol, linsolver="band", span=(0.0, 0.5)):
    model = SpringChain(3, force=(1.0, 0.0), T=0.3)
    res = simulate(model, span, "ida", rtol=RTOL, atol=atol, linsolver=linsolver, t_eval=np.linspace(*span, 6))
    assert res.success, res.message
    return res


@pytest.mark.parametrize("atol", [(1e-9, 1e-3), (1e-3, 1e-9)])
def test_band_ordering_gets_the_same_tolerances_as_the_plain_ordering(atol):
    """Catches the tolerances not permuted into the node-interleaved ordering of the band solver (half the
    positions would get the velocity tolerance): band and dense must take the same steps (measured: 54
    and 125 steps for the two tolerance pairs, results equal to 1e-14)."""
    band, dense = _run(atol, "band"), _run(atol, "dense")
    assert band.stats["steps"] == dense.stats["steps"]
    np.testing.assert_allclose(band.q, dense.q, rtol=0, atol=1e-12)


def test_the_groups_are_positions_then_velocities():
    """Catches the pair (atol_q, atol_v) applied the other way round: it must equal the array form
    ``[atol_q] * n + [atol_v] * n`` bit for bit, and differ from the swapped pair (54 against 125 steps)."""
    n = SpringChain(3).n_dof
    pair = _run((1e-9, 1e-3))
    array = _run(np.r_[np.full(n, 1e-9), np.full(n, 1e-3)])
    swapped = _run((1e-3, 1e-9))
    assert pair.stats["steps"] == array.stats["steps"] and np.array_equal(pair.q, array.q)
    assert swapped.stats["steps"] > 1.5 * pair.stats["steps"]


def test_the_default_tolerances_over_a_span_other_than_one_second():
    """Catches the default (rtol L, rtol L / (tf - t0)) swapped or divided the wrong way: over 0.25 s the
    default must equal the explicit pair bit for bit and differ from its swap (29 against 34 steps)."""
    span = (0.0, 0.25)
    L = max(1.0, float(np.max(np.abs(SpringChain(3).initial_state()[0]))))
    default = _run(None, span=span)
    explicit = _run((RTOL * L, RTOL * L / 0.25), span=span)
    swapped = _run((RTOL * L / 0.25, RTOL * L), span=span)
    assert default.stats["steps"] == explicit.stats["steps"] and np.array_equal(default.q, explicit.q)
    assert not np.array_equal(default.q, swapped.q)
