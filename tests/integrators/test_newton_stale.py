"""Modified Newton keeps a slowly contracting matrix when it reaches the target soon
(``NewtonOptions.stale_iterations``), and refreshes otherwise.

On ``r(x) = x - 1`` with a matrix ``s`` the iteration contracts at exactly ``|1 - 1/s|``, so the
iterations to the target are known. Catches: the option ignored (a refresh where none is due), a
matrix kept at a rate that cannot reach the target within the allowed iterations, or at a rate >= 1.
"""
import numpy as np
import pytest

from ancfdae.integrators import NewtonOptions
from ancfdae.integrators._newton import NewtonSolver


def _solve(rate, stale_iterations, tol):
    """One solve from x = 0 whose first matrix contracts at ``rate``; later matrices are exact."""
    calls = []

    def jacobian(x):
        calls.append(x.copy())
        return np.array([[1.0 / (1.0 - rate)]]) if len(calls) == 1 else np.array([[1.0]])

    solver = NewtonSolver(NewtonOptions(tol=tol, residual_atol=0.0, xtol=0.0, contraction=0.3,
                                        stale_iterations=stale_iterations))
    out = solver.solve(lambda x: x - 1.0, jacobian, np.zeros(1))
    assert out.converged, out.message
    return len(calls), out.iterations


def test_default_refreshes_at_once():
    assert _solve(0.5, 0, 1e-2) == (2, 2)        # one slow iteration, then the exact matrix


def test_keeps_the_matrix_that_reaches_the_target():
    # rate 0.5 from 1: 0.5, 0.25, ... <= 1e-2 after 7 iterations; after the first, 6 more are needed
    assert _solve(0.5, 6, 1e-2) == (1, 7)
    assert _solve(0.5, 5, 1e-2) == (2, 2)        # 0.5 * 0.5**5 > 1e-2: refreshed


@pytest.mark.parametrize("rate", [1.0, 1.5])
def test_never_keeps_a_matrix_that_does_not_contract(rate):
    calls, _ = _solve(-rate, 50, 1e-2)          # s = 1 / (1 + rate): |1 - 1/s| = rate
    assert calls == 2


def test_rejects_bad_values():
    for bad in (-1, 1.5, True):
        with pytest.raises(ValueError, match="stale_iterations"):
            NewtonOptions(stale_iterations=bad)
