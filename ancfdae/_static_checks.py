"""What a converged static solution is: stable or not (inertia of the tangent), plausible or not.

Newton's method converges to *any* equilibrium near its start: a cantilever held by a pin only
under a tip force can converge to the beam pointing against the force (an equilibrium, but an
unstable one), a huge load to a beam stretched a hundredfold. :func:`inertia` counts the negative
eigenvalues of the tangent stiffness without computing them (Sylvester's law of inertia: the signs
of the pivots of a symmetric ``L D L^T`` factorisation); a stable equilibrium has none.
:func:`plausibility` reports axial strains beyond the range the elements are meant for and
elements folded back on themselves. :func:`ancfdae.solve_static` calls both.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["inertia", "plausibility", "MAX_STRAIN", "DENSE_LIMIT"]

#: axial strain |lambda - 1| above which a solution is flagged: the chapter's elements use the Green strain
#: with St. Venant-Kirchhoff's law, meant for large rotations but small strains (chapter Sects. 3-4)
MAX_STRAIN = 0.1
#: up to this many coordinates a dense L D L^T (Bunch-Kaufman) is the fallback when the sparse one fails
DENSE_LIMIT = 3000
#: pivots within this fraction of the largest one count as zero (neither sign)
_ZERO = 1e-10


def _count(pivots: np.ndarray) -> tuple[int, int]:
    scale = float(np.max(np.abs(pivots))) if pivots.size else 0.0
    tol = _ZERO * scale
    return int(np.sum(pivots < -tol)), int(np.sum(np.abs(pivots) <= tol))


def _dense(K: np.ndarray) -> tuple[int, int]:
    """Negative and zero counts from scipy's Bunch-Kaufman ``L D L^T`` (1x1 and 2x2 blocks in D)."""
    _, d, _ = sla.ldl(K, lower=True, hermitian=True)
    off = np.diag(d, -1).copy()
    diag = np.diag(d).copy()
    eig = diag.copy()
    for i in np.flatnonzero(off):          # 2x2 blocks: their two eigenvalues replace the diagonal
        eig[i:i + 2] = np.linalg.eigvalsh(d[i:i + 2, i:i + 2])
    return _count(eig)


def inertia(K) -> tuple[int | None, int | None, str]:
    """Negative and zero eigenvalue counts of the symmetric part of ``K``.

    Parameters
    ----------
    K : ndarray or sparse matrix, shape (n, n)
        The tangent stiffness ``dr/dq`` at the solution.

    Returns
    -------
    n_negative, n_zero : int or None
        None when neither factorisation succeeded.
    how : str
        Which factorisation counted: ``"sparse LDL^T"`` (SuperLU in symmetric mode: a symmetric
        fill-reducing ordering and diagonal pivots, so ``U``'s diagonal is ``D``), ``"dense LDL^T"``
        (Bunch-Kaufman, the fallback up to :data:`DENSE_LIMIT` coordinates) or why none did.

    Notes
    -----
    A conservative problem has a symmetric tangent, the Hessian of its potential energy; its
    equilibrium is stable when the Hessian is positive definite (no negative and no zero
    eigenvalue). For follower (non-conservative) loads the symmetric part is used, a static
    criterion only.
    """
    Ks = sp.csc_matrix(K, dtype=float)
    Ks = (0.5 * (Ks + Ks.T)).tocsc()
    n = Ks.shape[0]
    try:
        lu = spla.splu(Ks, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
        if np.array_equal(lu.perm_r, lu.perm_c):        # no row pivoting: D = diag(U)
            return (*_count(lu.U.diagonal()), "sparse LDL^T")
    except RuntimeError:
        pass
    if n <= DENSE_LIMIT:
        return (*_dense(Ks.toarray()), "dense LDL^T")
    return None, None, f"not determined (the sparse factorisation pivoted and n_dof = {n} > {DENSE_LIMIT})"


def plausibility(model, q: np.ndarray, max_strain: float = MAX_STRAIN) -> list[str]:
    """Warnings about a solution ``q`` outside what the elements are meant for (empty when none).

    Axial stretch ``lambda = |r'(s)| / |r0'(s)|`` at three points of every element (central
    differences of ``model.position`` along ``s``; ANCF positions are cubic in ``s`` per element,
    so the difference is exact to round-off at the step used): a strain ``|lambda - 1|`` above
    ``max_strain`` is flagged, and an element whose axis turns back on itself (tangents at two of
    its points more than 90 degrees apart) as folded. Models without ``position`` and ``lengths``
    (not beams) are not checked.
    """
    lengths = getattr(model, "lengths", None)
    if lengths is None or not callable(getattr(model, "position", None)) or not callable(
            getattr(model, "initial_state", None)):
        return []
    lengths = np.asarray(lengths, dtype=float)
    start = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
    xi = np.array([0.2, 0.5, 0.8])
    s = (start[:, None] + lengths[:, None] * xi).ravel()
    ds = np.repeat(1e-3 * lengths, xi.size)
    q_ref = model.initial_state()[0]

    def tangent(x):
        return (model.position(x, s + ds) - model.position(x, s - ds)) / (2 * ds)[:, None]
    t, t0 = tangent(q), tangent(q_ref)
    stretch = np.linalg.norm(t, axis=1) / np.linalg.norm(t0, axis=1)
    out = []
    strain = np.abs(stretch - 1.0)
    if np.any(strain > max_strain):
        k = int(np.argmax(strain))
        out.append(f"axial strain up to {stretch[k] - 1.0:+.3g} (stretch {stretch[k]:.4g} at s = {s[k]:.4g}, "
                   f"element {k // xi.size}), beyond {max_strain:g}, the range of the elements' small-strain "
                   "material law: the load may be far beyond what the model represents")
    unit = t / np.maximum(np.linalg.norm(t, axis=1), np.finfo(float).tiny)[:, None]
    unit = unit.reshape(lengths.size, xi.size, -1)
    folded = np.flatnonzero(np.einsum("ej,ej->e", unit[:, 0], unit[:, -1]) < 0.0)
    if folded.size:
        out.append(f"element(s) {folded[:5].tolist()}{' ...' if folded.size > 5 else ''} folded back on "
                   "themselves (the axis turns by more than 90 degrees inside one element): refine the mesh "
                   "or reduce the load")
    return out
