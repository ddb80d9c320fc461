"""The words of a Newton solve's ending: one text for each way a solve ends.

The Python iteration (:class:`ancfdae.integrators._newton.NewtonSolver`) and the compiled static load
step (:mod:`ancfdae._static_compiled`) end a solve the same ways; both take their messages from here so
that a user reads the same sentence whichever path solved the step (``tests/test_static_compiled.py``
holds the two equal).
"""
from __future__ import annotations

__all__ = ["converged", "converged_initial", "stagnant", "initial_not_finite", "dx_not_finite",
           "r_not_finite", "diverging", "not_converged", "last_without_residual", "stalled", "at_floor"]


def converged_initial() -> str:
    """The residual test held at the initial guess."""
    return "converged at the initial guess"


def converged(k: int) -> str:
    """The residual test held after ``k`` iterations."""
    return f"converged in {k} iterations"


def stagnant(k: int, err: float) -> str:
    """Round-off stagnation after ``k`` iterations: a fresh matrix, a correction at round-off, ``err`` = max|r|."""
    return f"converged in {k} iterations (correction at round-off level, max|r| = {err:.3e})"


def initial_not_finite() -> str:
    """The residual at the initial guess holds a NaN or an infinity."""
    return "residual at the initial guess is not finite"


def dx_not_finite() -> str:
    """The correction holds a NaN or an infinity: the iteration matrix is singular or overflowed."""
    return "Newton correction is not finite (singular iteration matrix?)"


def r_not_finite(k: int) -> str:
    """The residual became non-finite at iteration ``k``."""
    return f"residual became non-finite at iteration {k}"


def diverging(rate: float, k: int) -> str:
    """Two rates above the divergence limit with a fresh Jacobian, the last ``rate`` at iteration ``k``."""
    return f"diverging (rate {rate:.3g} at iteration {k} with a fresh Jacobian)"


def not_converged(max_iter: int, err: float, threshold: float) -> str:
    """``max_iter`` iterations spent with max|r| = ``err`` above ``threshold``."""
    return f"not converged in {max_iter} iterations (max|r| = {err:.3e}, target {threshold:.3e})"


# The endings of a solve with an acceptance test (``accept``: the error estimate of a stage solve)


def last_without_residual(k: int) -> str:
    """Accepted after one more correction, whose residual was not evaluated (``k`` counts it)."""
    return f"converged in {k} iterations (the last one without its residual)"


def stalled(k: int, dx_max: float) -> str:
    """At the residual's floor the correction stopped halving: round-off reached, max|dx| = ``dx_max``."""
    return f"converged in {k} iterations (the correction stalled at round-off, max|dx| = {dx_max:.3e})"


def at_floor(max_iter: int) -> str:
    """``max_iter`` iterations spent at the residual's floor, the correction still halving."""
    return f"converged in {max_iter} iterations (at the residual's floor, the correction still halving)"
