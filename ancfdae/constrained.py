"""Consistent states and multipliers of a constrained model (the ``"constraints"`` capability).

The equations ``M a + r(t, q, v, 0) + G^T lam = 0``, ``g(t, q) = 0`` (:mod:`ancfdae.problem`) hide two more:
``G v + g_t = 0`` and ``G a = gamma``. Everything here is built on the KKT matrix ``[[M, G^T], [G, 0]]``:

* :func:`multipliers` -- ``(a, lam)`` at a state from ``[[M, G^T], [G, 0]] [a; lam] = [-r(t, q, v, 0); gamma]``
  (the reaction forces at output times: their order is that of ``(q, v)``, whatever the method's own
  multipliers converge like);
* :func:`project_positions` -- the ``M``-nearest ``q`` on ``g(t, q) = 0``, Newton on the KKT conditions of
  ``min 1/2 |q - q0|_M^2 + nu.g`` (matrix ``[[M + H(nu), G^T], [G, 0]]``);
* :func:`project_velocities` -- the ``M``-orthogonal projection of ``v`` onto ``G v + g_t = 0``;
* :func:`consistent_state` -- all three, with the size of the corrections and a clear error when the given
  state is far from the constraints (a misplaced joint is a modelling error, not round-off);
* :func:`dependent_rows` -- redundant constraint rows (rank of ``G``), the later duplicates named;
* :func:`constraint_power` -- ``lam . g_t``, the power of the forces that drive prescribed motions.

Only the contract is used (no integrator), so the driver, monitors and a user's stepper can share it.
"""
from __future__ import annotations

import logging
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ancfdae.kkt import KKTAssembler

__all__ = ["kkt_matrix", "multipliers", "project_positions", "project_velocities", "consistent_state",
           "dependent_rows", "constraint_power", "ConsistentState", "PROJECTION_LIMIT"]

_log = logging.getLogger("ancfdae")

#: largest correction of q0 accepted silently-but-logged, relative to max(1, max|q0|); beyond it the
#: initial state is refused
PROJECTION_LIMIT = 1e-3


def kkt_matrix(M, G, upper_left=None, assembler: KKTAssembler | None = None) -> sp.csc_matrix:
    """``[[M (+ upper_left), G^T], [G, 0]]`` as CSC (for SuperLU); ``assembler`` reuses its fixed pattern."""
    blocks = [M] if upper_left is None else [M, upper_left]
    return (assembler or KKTAssembler()).assemble(blocks, G, 1.0, G, 1.0).tocsc()


def _solve(K, rhs, what):
    try:
        x = spla.splu(K).solve(rhs)
    except RuntimeError as exc:          # "Factor is exactly singular"
        raise np.linalg.LinAlgError(f"{what}: the KKT matrix [[M, G^T], [G, 0]] is singular ({exc}); "
                                    "are constraints redundant (see ancfdae.constrained.dependent_rows)?") from None
    if not np.all(np.isfinite(x)):
        raise np.linalg.LinAlgError(f"{what}: the KKT solve gave non-finite values (singular matrix?)")
    return x


def multipliers(model, t: float, q: np.ndarray, v: np.ndarray, *,
                assembler: KKTAssembler | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(a, lam)`` consistent with ``(t, q, v)``: ``M a + r(t, q, v, 0) + G^T lam = 0``, ``G a = gamma``.

    Parameters
    ----------
    model : Model with the ``"constraints"`` capability
    t : float
    q, v : ndarray, shape (n,)
    assembler : KKTAssembler, optional
        Reused across calls (the KKT pattern is found once); a run's recorder keeps one.

    Returns
    -------
    a : ndarray, shape (n,)
    lam : ndarray, shape (m,)
    """
    fast = getattr(model, "compiled_multipliers", None)   # a System of one compiled beam and rigid bodies
    out = fast(t, q, v) if callable(fast) else None
    if out is not None:
        return out
    n = q.size
    r0 = np.asarray(model.residual(t, q, v, np.zeros(n)), dtype=float)
    _, gamma = model.constraint_rates(t, q, v)
    M, G, what = model.mass(q), model.constraint_jacobian(t, q), f"multipliers at t = {t:g}"
    rhs = np.concatenate([-r0, gamma])
    if n + G.shape[0] <= DENSE_KKT_LIMIT:
        x = _solve_dense(M, G, rhs, what)
    else:
        x = _solve(kkt_matrix(M, G, assembler=assembler), rhs, what)
    return x[:n], x[n:]


#: largest KKT system (n + m) :func:`multipliers` solves densely (LAPACK): at the sizes of B5/B6 (39, 62
#: unknowns) the sparse assembly and SuperLU took about 1 ms an output time, the dense solve 0.1 ms
DENSE_KKT_LIMIT = 128


def _solve_dense(M, G, rhs, what):
    """``[[M, G^T], [G, 0]] x = rhs`` by a dense LU (small systems), with the errors of :func:`_solve`."""
    n, m = M.shape[0], G.shape[0]
    K = np.zeros((n + m, n + m))
    K[:n, :n] = M.toarray() if sp.issparse(M) else M
    Gd = G.toarray() if sp.issparse(G) else np.asarray(G, dtype=float)
    K[n:, :n] = Gd
    K[:n, n:] = Gd.T
    try:
        x = np.linalg.solve(K, rhs)
    except np.linalg.LinAlgError as exc:
        raise np.linalg.LinAlgError(f"{what}: the KKT matrix [[M, G^T], [G, 0]] is singular ({exc}); "
                                    "are constraints redundant (see ancfdae.constrained.dependent_rows)?") from None
    if not np.all(np.isfinite(x)):
        raise np.linalg.LinAlgError(f"{what}: the KKT solve gave non-finite values (singular matrix?)")
    return x


def project_positions(model, t: float, q0: np.ndarray, *, tol: float = 1e-14,
                      max_iter: int = 20) -> tuple[np.ndarray, int, float]:
    """The ``M``-nearest ``q`` with ``g(t, q) = 0`` (Newton on the KKT conditions, quadratic convergence).

    Returns
    -------
    q : ndarray
    iterations : int
    max_g : float
        ``max|g(t, q)|`` reached.

    Raises
    ------
    ValueError
        When Newton does not reach ``tol * max(1, max|q0|)``.
    """
    n = q0.size
    M = sp.csr_matrix(model.mass(q0))
    q = np.array(q0, dtype=float)
    nu = np.zeros(model.n_constraints)
    scale = max(1.0, float(np.max(np.abs(q0), initial=0.0)))
    g = model.constraints(t, q)
    for it in range(max_iter + 1):
        G = model.constraint_jacobian(t, q)
        r1 = M @ (q - q0) + G.T @ nu
        err = float(np.max(np.abs(g), initial=0.0))
        if err <= tol * scale and float(np.max(np.abs(r1), initial=0.0)) <= 1e-12 * max(1.0, abs(M).max()) * scale:
            return q, it, err
        if it == max_iter:
            break
        K = kkt_matrix(M, G, model.constraint_force_jacobian(t, q, nu))
        dx = _solve(K, -np.concatenate([r1, g]), f"projection of q0 at t = {t:g}")
        q, nu = q + dx[:n], nu + dx[n:]
        g = model.constraints(t, q)
    raise ValueError(f"the initial coordinates could not be projected onto the constraints g(t0, q) = 0: "
                     f"max|g| = {err:.3g} after {max_iter} Newton iterations (target {tol * scale:.3g}).")


def project_velocities(model, t: float, q: np.ndarray, v0: np.ndarray) -> np.ndarray:
    """The ``M``-orthogonal projection of ``v0`` onto ``G v + g_t = 0``."""
    n = q.size
    G = model.constraint_jacobian(t, q)
    g_t, _ = model.constraint_rates(t, q, v0)
    # [[M, G^T], [G, 0]] [dv; mu] = [0; -(G v0 + g_t)]
    x = _solve(kkt_matrix(model.mass(q), G), np.concatenate([np.zeros(n), -(G @ v0 + g_t)]),
               f"projection of v0 at t = {t:g}")
    return v0 + x[:n]


class ConsistentState(NamedTuple):
    """A state satisfying ``g = 0``, ``G v + g_t = 0`` and the equations of motion, and the corrections made."""

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    lam: np.ndarray
    dq: float          #: max|q - q0|
    dv: float          #: max|v - v0|


def consistent_state(model, t: float, q0: np.ndarray, v0: np.ndarray, *,
                     limit: float = PROJECTION_LIMIT) -> ConsistentState:
    """Project ``(q0, v0)`` onto the constraints and solve ``(a, lam)``; log the corrections.

    Parameters
    ----------
    model : Model with the ``"constraints"`` capability
    t : float
    q0, v0 : ndarray
    limit : float
        Largest accepted ``max|q - q0|`` relative to ``max(1, max|q0|)``.

    Raises
    ------
    ValueError
        When ``q0`` is farther than ``limit`` from the constraints (naming the worst rows).
    """
    q0 = np.asarray(q0, dtype=float)
    v0 = np.asarray(v0, dtype=float)
    g0 = model.constraints(t, q0)
    scale = max(1.0, float(np.max(np.abs(q0), initial=0.0)))
    q, _, _ = project_positions(model, t, q0)
    dq = float(np.max(np.abs(q - q0), initial=0.0))
    if dq > limit * scale:
        labels = getattr(model, "constraint_labels", None) or [f"row {i}" for i in range(g0.size)]
        worst = np.argsort(-np.abs(g0))[:3]
        raise ValueError(f"`q0` is {dq:.3g} from the constraints g(t0, q) = 0 (limit {limit:g} * {scale:g}): "
                         "largest violations " + ", ".join(f"{labels[i]} = {g0[i]:.3g}" for i in worst)
                         + "; a joint misplaced? Give q0 on the constraints.")
    v = project_velocities(model, t, q, v0)
    dv = float(np.max(np.abs(v - v0), initial=0.0))
    a, lam = multipliers(model, t, q, v)
    if dq > 0 or dv > 0:
        _log.info("initial state projected onto the constraints at t = %g: max|dq| = %.3g, max|dv| = %.3g",
                  t, dq, dv)
    return ConsistentState(q, v, a, lam, dq, dv)


def dependent_rows(G, rtol: float = 1e-10) -> list[int]:
    """Rows of ``G`` that depend on the rows before them (Gram-Schmidt in row order, twice for stability).

    Parameters
    ----------
    G : sparse or dense matrix, shape (m, n)
    rtol : float
        A row is dependent when its part orthogonal to the kept rows is below ``rtol`` times its norm.

    Returns
    -------
    list of int
        The dependent rows: the later of two duplicates is the one reported.
    """
    W = G.toarray() if sp.issparse(G) else np.asarray(G, dtype=float)
    basis, drop = [], []
    for k, w in enumerate(W):
        r = w.copy()
        for _ in range(2):
            for b in basis:
                r -= (b @ r) * b
        norm = np.linalg.norm(r)
        if norm > rtol * max(np.linalg.norm(w), 1e-300):
            basis.append(r / norm)
        else:
            drop.append(k)
    return drop


def constraint_power(model, t: float, q: np.ndarray, v: np.ndarray) -> float:
    """``lam . g_t``: the power of the forces that drive the prescribed (rheonomic) motions; 0 when none."""
    g_t, _ = model.constraint_rates(t, q, v)
    if not np.any(g_t):
        return 0.0
    _, lam = multipliers(model, t, q, v)
    return float(lam @ g_t)
