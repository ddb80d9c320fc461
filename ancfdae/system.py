"""Several bodies joined by joints: :class:`System`, a Model with the ``"constraints"`` capability.

The system stacks the bodies' coordinates (body 0 first), so its mass, stiffness and damping are
block-diagonal with the bodies' fixed patterns, and adds the constraint rows: every body's own (the
``"constraints"`` of a body, e.g. a rigid body's orthonormal directors) first, then the joints' in the order
given (:mod:`ancfdae.joints`). The equations are ``r(t, q, v, a) + G^T lam = 0``, ``g(t, q) = 0``
(:mod:`ancfdae.problem`); the residual has no ``G^T lam`` term: the integrator adds it.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ancfdae.constrained import dependent_rows
from ancfdae.joint_points import describe_joints
from ancfdae.joints.assembled import ConstraintSet
from ancfdae.joints.base import Frame, Joint
from ancfdae.joints.rows import Affine, Rows
from ancfdae.problem import capabilities
from ancfdae.system_stack import BodyStack

if TYPE_CHECKING:
    from ancfdae.joints.assembled_numba import CompiledConstraintSet
    from ancfdae.system_compiled import SystemArrays

__all__ = ["System"]


def _quadratic_rows(body, offset: int, n: int) -> Rows:
    """A body's constraint rows ``1/2 q^T A_r q + b_r . q + c_r`` (its ``constraint_quadratic_form``) placed at
    ``offset`` in the system's ``n`` coordinates."""
    A, b, c = body.constraint_quadratic_form()
    nb = body.n_dof
    place = sp.csr_matrix((np.ones(nb), (np.arange(nb), offset + np.arange(nb))), shape=(nb, n))
    rows = Rows(n)
    b = sp.csr_matrix(b)
    for r in range(len(A)):
        Ar = sp.csr_matrix(place.T @ sp.csr_matrix(A[r]) @ place)
        rows.add(f"body row {r}", b[r] @ place, float(c[r]), Ar if Ar.nnz else None)
    return rows


class System(BodyStack):
    """Bodies (each a Model: :class:`~ancfdae.models.Beam`, a rigid body) joined by joints.

    Parameters
    ----------
    bodies : sequence of Model
        The bodies; a joint names a body by the object itself. A body a joint holds must offer
        ``attachment(where)`` (:class:`ancfdae.attachment.Attachment`).
    joints : sequence of Joint
        :mod:`ancfdae.joints` objects.
    t0 : float
        Time of the initial state, where ground points default and the rank of ``G`` is checked.
    kernel : {"auto", "numba", "numpy"}
        How the constraint rows are evaluated. ``"auto"`` / ``"numba"``: every row of the joints and of the
        bodies that give their rows' quadratic form (``constraint_quadratic_form``: rigid bodies) in one
        compiled pass on fixed patterns (:mod:`ancfdae.joints.assembled_numba`); ``"numpy"``: the readable
        reference, body by body and the joints' rows in NumPy (:mod:`ancfdae.joints.assembled`). Both give
        the same values to round-off and the same row order.

    Attributes
    ----------
    n_dof, n_constraints : int
    offsets : ndarray
        First coordinate of each body in ``q``.
    constraint_labels : tuple of str
        One per row: ``"joint name[k]"`` (body rows: ``"body i: label"``).

    Raises
    ------
    ValueError
        A joint naming a body not in ``bodies`` or a node it lacks, a joint of the wrong dimension, redundant
        joints (rows of ``G`` that depend on earlier rows at the initial state: named).
    """

    def __init__(self, bodies: Sequence, joints: Sequence[Joint] = (), *, t0: float = 0.0,
                 kernel: str = "auto") -> None:
        super().__init__(bodies)
        if kernel not in ("auto", "numba", "numpy"):
            raise ValueError(f"`kernel` must be 'auto', 'numba' or 'numpy', got {kernel!r}.")
        self.kernel = kernel
        joints = list(joints)
        for k, j in enumerate(joints):
            if not isinstance(j, Joint):
                raise TypeError(f"`joints[{k}]` must be a joint of ancfdae.joints, got {j!r:.100}.")
        self.joints = joints
        q0, _ = self.initial_state()
        n = self.n_dof
        rows = Rows(n)
        for k, joint in enumerate(joints):
            frames = tuple(self._frame(k, joint, arg, side) for arg, side in zip(joint.side_args, joint.sides))
            rows.extend(joint.rows(frames, q0, n))
        body_rows = [(b, off, b.n_constraints) for b, off in zip(self.bodies, self.offsets)
                     if "constraints" in capabilities(b)]
        self.n_constraints = sum(m for _, _, m in body_rows) + rows.m
        self.constraint_labels = tuple(
            [f"body {self.bodies.index(b)}: {lab}" for b, _, m in body_rows
             for lab in getattr(b, "constraint_labels", [f"row {i}" for i in range(m)])]
            + list(rows.labels))
        # compiled: the bodies' quadratic rows go first into the one set of rows (the order of the labels)
        fold = kernel != "numpy" and all(callable(getattr(b, "constraint_quadratic_form", None))
                                         for b, _, _ in body_rows)
        if fold:
            folded = Rows(n)
            for b, off, _ in body_rows:
                folded.extend(_quadratic_rows(b, off, n))
            folded.extend(rows)
            rows, body_rows = folded, []
        if kernel == "numpy":
            self._joint_set = ConstraintSet(rows)
        else:
            from ancfdae.joints.assembled_numba import CompiledConstraintSet
            self._joint_set = CompiledConstraintSet(rows)
        self._body_rows = body_rows   # the bodies whose rows are evaluated body by body
        self._compiled = None         # (SystemArrays or None,), made at the first use of compiled_arrays
        if self.n_constraints:
            drop = dependent_rows(self.constraint_jacobian(t0, q0))
            if drop:
                names = ", ".join(self.constraint_labels[i] for i in drop)
                raise ValueError(f"`joints` are redundant: {len(drop)} constraint row(s) depend on earlier ones at "
                                 f"the initial state: {names}. Remove the joint(s) that repeat a constraint "
                                 "(e.g. a pin given twice, or a ground pin on a clamped node).")

    def _frame(self, k: int, joint: Joint, arg: str, side) -> Frame:
        if isinstance(side, str):
            return Frame(None, (), "ground", None)
        body, where = side
        i = next((i for i, b in enumerate(self.bodies) if b is body), None)
        if i is None:
            raise ValueError(f"`joints[{k}]` ({joint.kind}) side `{arg}` names a body that is not in `bodies` "
                             f"(got {type(body).__name__} object); pass the body objects given to System.")
        if not callable(getattr(body, "attachment", None)):
            raise ValueError(f"`joints[{k}]` side `{arg}`: body {i} ({type(body).__name__}) offers no attachment().")
        try:
            att = body.attachment(where)
        except ValueError as exc:
            raise ValueError(f"`joints[{k}]` ({joint.kind}) side `{arg}` on body {i}: {exc}") from None
        n, off, nb = self.n_dof, self.offsets[i], body.n_dof

        def embed(X, x0):
            X = sp.csr_matrix(X)
            cols = sp.csr_matrix((np.ones(nb), (np.arange(nb), off + np.arange(nb))), shape=(nb, n))
            return Affine(sp.csr_matrix(X @ cols), np.asarray(x0, dtype=float))
        return Frame(embed(att.position, att.offset),
                     tuple(embed(D, d0) for D, d0 in zip(att.axes, att.axes_offset)),
                     f"body {i} {att.label}", att.dim)

    # -- the "constraints" capability (ancfdae.problem.CAPABILITIES) -----------------------------
    def constraints(self, t: float, q: np.ndarray) -> np.ndarray:
        """``g(t, q)``, shape (n_constraints,): bodies' rows first, then the joints'."""
        parts = [b.constraints(t, q[o:o + b.n_dof]) for b, o, _ in self._body_rows]
        return np.concatenate(parts + [self._joint_set.g(t, q)])

    def _stack_rows(self, blocks, joint_part):
        if not blocks:
            return joint_part
        n, shifted = self.n_dof, []
        for B, o in blocks:
            B = sp.csr_matrix(B)
            shifted.append(sp.csr_matrix((B.data, B.indices + o, B.indptr), shape=(B.shape[0], n)))
        return sp.vstack(shifted + [joint_part], format="csr")

    def constraint_terms_at(self, t: float) -> Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
        """``(q, lam) -> (g(t, q), G(t, q)^T lam)`` at the time ``t`` (an index-3 step's residuals): one compiled
        pass, the time functions evaluated once, when every row is folded; else :meth:`constraints` and
        :meth:`constraint_force`."""
        if not self._body_rows and hasattr(self._joint_set, "terms_at"):
            return self._joint_set.terms_at(t)
        return lambda q, lam: (self.constraints(t, q), self.constraint_force(t, q, lam))

    @property
    def compiled_rows(self) -> "CompiledConstraintSet | None":
        """The one compiled set of every constraint row (:class:`~ancfdae.joints.assembled_numba.CompiledConstraintSet`,
        the bodies' rows first), or None when some rows are evaluated body by body or by the NumPy reference."""
        return self._joint_set if not self._body_rows and hasattr(self._joint_set, "terms_at") else None

    @property
    def compiled_arrays(self) -> "SystemArrays | None":
        """The system as flat arrays for compiled steps and reactions
        (:class:`ancfdae.system_compiled.SystemArrays`, made once), or None when it has no compiled form."""
        if self._compiled is None:
            from ancfdae.system_compiled import SystemArrays
            self._compiled = (SystemArrays.of(self),)
        return self._compiled[0]

    def compiled_multipliers(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """``(a, lam)`` at ``(t, q, v)`` in one compiled call (:meth:`ancfdae.system_compiled.SystemArrays.multipliers`,
        the fast path of :func:`ancfdae.constrained.multipliers`), or None when the system has no compiled form."""
        arrays = self.compiled_arrays
        return None if arrays is None else arrays.multipliers(t, q, v)

    def constraint_position_terms_at(self, t: float) -> Callable[[np.ndarray], tuple]:
        """``q -> (g, G, g_t)`` at the time ``t`` (a GGL stage's rows): one compiled pass when every row is
        folded, else :meth:`constraints`, :meth:`constraint_jacobian` and :meth:`constraint_rates`."""
        if not self._body_rows and hasattr(self._joint_set, "position_terms_at"):
            return self._joint_set.position_terms_at(t)
        return lambda q: (self.constraints(t, q), self.constraint_jacobian(t, q),
                          self.constraint_rates(t, q, np.zeros_like(q))[0])

    def constraint_jacobian(self, t: float, q: np.ndarray) -> sp.csr_matrix:
        """``G = dg/dq`` on a fixed pattern, shape (n_constraints, n_dof)."""
        blocks = [(b.constraint_jacobian(t, q[o:o + b.n_dof]), o) for b, o, _ in self._body_rows]
        return self._stack_rows(blocks, self._joint_set.G(t, q))

    def constraint_force(self, t: float, q: np.ndarray, lam: np.ndarray) -> np.ndarray:
        """``G(t, q)^T lam`` without forming ``G`` (optional fast path of the capability)."""
        mb = self.n_constraints - self._joint_set.m
        f = self._joint_set.force(t, q, lam[mb:])
        r = 0
        for b, o, m in self._body_rows:
            qb, lb = q[o:o + b.n_dof], lam[r:r + m]
            f[o:o + b.n_dof] += (b.constraint_force(t, qb, lb) if hasattr(b, "constraint_force")
                                 else b.constraint_jacobian(t, qb).T @ lb)
            r += m
        return f

    def constraint_force_jacobian(self, t: float, q: np.ndarray, lam: np.ndarray) -> sp.csr_matrix:
        """``d(G^T lam)/dq``, shape (n_dof, n_dof); constant in ``q`` (every joint is at most quadratic)."""
        mb = self.n_constraints - self._joint_set.m
        H = self._joint_set.H(lam[mb:])
        if not self._body_rows:
            return H
        blocks, r = [], 0
        for b, o, m in self._body_rows:
            blocks.append((b.constraint_force_jacobian(t, q[o:o + b.n_dof], lam[r:r + m]), o))
            r += m
        return sp.csr_matrix(H + self.block_diagonal(blocks))

    def constraint_rates(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(g_t, gamma)``: ``G v + g_t = 0`` and ``G a = gamma = -(Z(v) v + 2 G_t v + g_tt)``."""
        parts = [b.constraint_rates(t, q[o:o + b.n_dof], v[o:o + b.n_dof]) for b, o, _ in self._body_rows]
        gt, gam = self._joint_set.rates(t, q, v)
        return (np.concatenate([p[0] for p in parts] + [gt]), np.concatenate([p[1] for p in parts] + [gam]))

    def constraint_velocity_jacobian(self, t: float, q: np.ndarray, v: np.ndarray) -> sp.csr_matrix:
        """``d(G v + g_t)/dq = Z(v) + G_t`` on G's pattern (index-2 formulations); beyond the contract."""
        blocks = []
        for b, o, _ in self._body_rows:
            fn = getattr(b, "constraint_velocity_jacobian", None)
            if fn is None:
                raise TypeError(f"body {self.bodies.index(b)} ({type(b).__name__}) has no "
                                "constraint_velocity_jacobian(t, q, v).")
            blocks.append((fn(t, q[o:o + b.n_dof], v[o:o + b.n_dof]), o))
        return self._stack_rows(blocks, self._joint_set.velocity_jacobian(t, q, v))

    @property
    def constraint_degree(self) -> int | None:
        """2: every row is at most quadratic in ``q`` with constant ``A_i`` (bodies' rows: their own)."""
        degrees = [getattr(b, "constraint_degree", None) for b, _, _ in self._body_rows]
        return None if any(d is None for d in degrees) else max([2] + degrees)

    @property
    def capabilities(self) -> frozenset:
        """``"constraints"`` and what every body offers (``potential``, ``residual_jacobian``, ...)."""
        return self.shared_capabilities() | {"constraints"}

    def describe(self) -> dict:
        """JSON-able description: the bodies, the constraint rows' labels and the joints (for pictures,
        :mod:`ancfdae.joint_points`)."""
        return {"system": {"bodies": [b.describe() if callable(getattr(b, "describe", None)) else
                                      {"type": type(b).__name__} for b in self.bodies],
                           "offsets": [int(o) for o in self.offsets],
                           "constraint_labels": list(self.constraint_labels),
                           "joints": describe_joints(self.bodies, self.joints)}}
