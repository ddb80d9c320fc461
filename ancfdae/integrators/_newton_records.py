"""The records of the Newton solver: its options, its work counters and the outcome of one solve.

Kept apart from the iteration itself (:mod:`ancfdae.integrators._newton`). Only
:class:`NewtonOptions` is public (users pass it to the steppers); the counters and the outcome are the
solver's own: a stepper reports its work as the plain dict of :meth:`NewtonStats.as_stats`, the static
solver likewise.
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass, fields

import numpy as np

from ancfdae import _validate as validate

__all__ = ["NewtonOptions", "NewtonStats", "NewtonOutcome"]

#: Why ``atol`` became ``residual_atol``: the same word meant a tolerance on the state for IDA.
RENAMED_ATOL = ("Newton's absolute tolerance on the residual, in the residual's units; `atol` is IDA's "
                "tolerance on the state")


def _real(name, value, *, low=None, high=None, low_open=False, high_open=False):
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not np.isfinite(value):
        raise ValueError(f"`{name}` must be a finite real number, got {value!r}.")
    if low is not None and (value < low or (low_open and value == low)):
        rule = ">" if low_open else ">="
        raise ValueError(f"`{name}` must be {rule} {low}, got {value!r}.")
    if high is not None and (value > high or (high_open and value == high)):
        rule = "<" if high_open else "<="
        raise ValueError(f"`{name}` must be {rule} {high}, got {value!r}.")
    return float(value)


#: modified Newton's refresh threshold on the contraction rate where neither the user nor the method chose one
CONTRACTION = 0.3


@validate.renamed("atol", "residual_atol", RENAMED_ATOL)
@dataclass(frozen=True)
class NewtonOptions:
    """Tolerances and policy of :class:`NewtonSolver`.

    Parameters
    ----------
    tol : float
        Relative tolerance: converged when ``max|r_k| <= tol * max|r_0|`` with
        ``r_0`` the residual at the initial guess of the solve (the chapter's
        criterion, Sects. 5.1-5.2, with ``tol = 1e-8``). In ``(0, 1)``.
    residual_atol : float or None
        Absolute tolerance on the residual, in the residual's own units
        (forces, for the models of this package): also converged when
        ``max|r_k| <= residual_atol``. It settles solves whose initial
        residual is already negligible (relative reduction of a
        round-off-sized residual is impossible). ``None`` (the default)
        derives it from the problem: a stepper uses
        ``ATOL_ROUNDOFF * eps * force_scale`` of the initial state
        (:func:`ancfdae._scale.absolute_tolerance`), so a 1 um fibre and a
        100 m beam get tolerances of their own size. A number is used as
        given. ``>= 0``. (Formerly ``atol``, renamed because IDA's ``atol``
        is a tolerance on the state.)
    max_iter : int
        Iterations allowed per attempt (per retry as well). ``>= 1``.
    jacobian : {"modified", "full"}
        Refresh policy (see module docstring).
    contraction : float or None
        Modified Newton refreshes the factorisation when the observed rate
        ``max|r_{k+1}| / max|r_k|`` exceeds this value. In ``(0, 1)``. ``None``
        (the default): the method's own, :data:`CONTRACTION` unless the method
        says otherwise (the Newmark family on a constrained model:
        :data:`ancfdae.integrators.newmark.INDEX3_CONTRACTION`).
    retry : bool
        Modified Newton only: retry a failed solve once from the initial guess
        with a fresh matrix when the failed attempt had used a stale one.
    xtol : float
        Also converged when the residual stagnates at round-off level: a
        matrix evaluated in the current attempt, a residual that fell by less
        than half, and a correction ``max|dx| <= xtol * max(1, max|x|)``. Needed on fine meshes of stiff beams, where the
        residual's round-off floor (about ``eps * max|K| * max|x|``: 2e-3 N
        for B1 with 128 BE2D elements) lies above ``tol * max|r_0|``; ``0``
        disables it. ``>= 0``.
    """

    tol: float = 1e-8
    residual_atol: float | None = None
    max_iter: int = 25
    jacobian: str = "modified"
    contraction: float | None = None
    retry: bool = True
    xtol: float = 1e-11

    def __post_init__(self):
        _real("tol", self.tol, low=0.0, high=1.0, low_open=True, high_open=True)
        if self.residual_atol is not None:
            _real("residual_atol", self.residual_atol, low=0.0)
        if isinstance(self.max_iter, bool) or not isinstance(self.max_iter, numbers.Integral) or self.max_iter < 1:
            raise ValueError(f"`max_iter` must be a positive integer, got {self.max_iter!r}.")
        if self.jacobian not in ("modified", "full"):
            raise ValueError(f"`jacobian` must be one of ['full', 'modified'], got {self.jacobian!r}.")
        if self.contraction is not None:
            _real("contraction", self.contraction, low=0.0, high=1.0, low_open=True, high_open=True)
        _real("xtol", self.xtol, low=0.0)
        if not isinstance(self.retry, bool):
            raise ValueError(f"`retry` must be True or False, got {self.retry!r}.")


@dataclass
class NewtonStats:
    """Work counters; ``a + b`` adds them field by field.

    Parameters
    ----------
    iterations : int
        Newton iterations (linear solves with a correction).
    residual_evals : int
        Residual evaluations.
    jacobian_evals : int
        Jacobian evaluations.
    factorizations : int
        LU factorisations.
    solves : int
        Calls of :meth:`NewtonSolver.solve`.
    failed_solves : int
        Solves that did not converge.
    retries : int
        Modified-Newton retries with a fresh matrix.
    """

    iterations: int = 0
    residual_evals: int = 0
    jacobian_evals: int = 0
    factorizations: int = 0
    solves: int = 0
    failed_solves: int = 0
    retries: int = 0

    def __add__(self, other: "NewtonStats") -> "NewtonStats":
        if not isinstance(other, NewtonStats):
            return NotImplemented
        return NewtonStats(**{f.name: getattr(self, f.name) + getattr(other, f.name) for f in fields(self)})

    def as_stats(self) -> dict:
        """The counters under the names of ``Result.stats`` (``newton_iterations``, ``newton_solves``, ...)."""
        return {"newton_iterations": self.iterations, "newton_solves": self.solves,
                "failed_solves": self.failed_solves, "retries": self.retries,
                "residual_evals": self.residual_evals, "jacobian_evals": self.jacobian_evals,
                "factorizations": self.factorizations}


@dataclass(frozen=True)
class NewtonOutcome:
    """Result of one :meth:`NewtonSolver.solve`.

    Attributes
    ----------
    x : ndarray
        Last iterate (the solution when ``converged``).
    converged : bool
    iterations : int
        Iterations of this solve, retries included.
    residual_norm : float
        ``max|r|`` at ``x``.
    message : str
        How the solve ended (the reason when it failed).
    floor : float
        The residual's round-off floor in effect at the end (that of the last
        matrix evaluated, else the one the solve was given).
    """

    x: np.ndarray
    converged: bool
    iterations: int
    residual_norm: float
    message: str
    floor: float = 0.0
