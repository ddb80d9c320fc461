"""Several bodies as one Model: stacked coordinates, block-diagonal matrices on the bodies' fixed patterns.

:class:`BodyStack` is the unconstrained part of :class:`ancfdae.System`: the Model contract and the
capabilities every body shares (``potential``, ``residual_jacobian``, ``residual_stages``), each evaluated
body by body on its slice of ``q``. The block-diagonal CSR matrices are formed by concatenating the bodies'
``data``/``indices``/``indptr`` (no sparse addition), so when each body's ``K``, ``D``, ``M`` share one
pattern the system's do too.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

from ancfdae.problem import Energy, JacobianBlocks, capabilities

__all__ = ["BodyStack"]

_CONTRACT = ("initial_state", "mass", "residual", "jacobian", "energy", "external_power")
#: capabilities the stack offers when every body does
_SHARED = ("residual_jacobian", "residual_stages", "potential")


def _diag(mats, n) -> sp.csr_matrix:
    """Block-diagonal CSR of square blocks that tile the diagonal in order."""
    mats = [sp.csr_matrix(A) for A in mats]
    data = np.concatenate([A.data for A in mats])
    offs = np.cumsum([0] + [A.shape[0] for A in mats])
    indices = np.concatenate([A.indices + o for A, o in zip(mats, offs)])
    nnz = np.cumsum([0] + [A.nnz for A in mats])
    indptr = np.concatenate([[0]] + [A.indptr[1:] + z for A, z in zip(mats, nnz)])
    return sp.csr_matrix((data, indices, indptr), shape=(n, n))


class BodyStack:
    """The bodies' Model contract, stacked (see the module docstring).

    Parameters
    ----------
    bodies : sequence of Model
    """

    def __init__(self, bodies: Sequence) -> None:
        if isinstance(bodies, (str, bytes)) or not isinstance(bodies, Sequence) or len(bodies) == 0:
            raise ValueError(f"`bodies` must be a non-empty sequence of models (e.g. Beams), got {bodies!r:.100}.")
        for k, b in enumerate(bodies):
            missing = [m for m in _CONTRACT if not callable(getattr(b, m, None))]
            if missing or not isinstance(getattr(b, "n_dof", None), (int, np.integer)):
                raise TypeError(f"`bodies[{k}]` must be a Model (ancfdae.problem.Model) with energy and "
                                f"external_power; {type(b).__name__} lacks {missing or ['n_dof']}.")
            if "step_events" in capabilities(b):
                raise ValueError(f"`bodies[{k}]` ({type(b).__name__}) has an event state ('step_events', e.g. BE3D's "
                                 "director update), which a System does not carry yet; use Cable3D or SQ3D.")
        if len({id(b) for b in bodies}) != len(bodies):
            raise ValueError("`bodies` must not hold the same body twice.")
        self.bodies = list(bodies)
        sizes = [int(b.n_dof) for b in self.bodies]
        self.offsets = np.cumsum([0] + sizes[:-1])
        self._slices = [slice(o, o + s) for o, s in zip(self.offsets, sizes)]
        self.n_dof = int(sum(sizes))
        self.mass_is_constant = all(bool(b.mass_is_constant) for b in self.bodies)
        self._mass = None   # the constant mass matrix, formed at the first mass() call

    def shared_capabilities(self) -> set:
        """The capabilities of :data:`_SHARED` every body declares, and ``variable_mass`` if any body has it."""
        caps = [capabilities(b) for b in self.bodies]
        out = {c for c in _SHARED if all(c in cb for cb in caps)}
        if not self.mass_is_constant:
            out.discard("potential")
            out.add("variable_mass")
        return out

    def block_diagonal(self, blocks: Sequence[tuple]) -> sp.csr_matrix:
        """``sum_k`` block ``B_k`` placed at ``(o_k, o_k)``; ``blocks`` = [(B_k, o_k)] (any subset of bodies)."""
        n = self.n_dof
        parts = []
        for B, o in blocks:
            C = sp.coo_matrix(B)
            parts.append(sp.csr_matrix((C.data, (C.row + o, C.col + o)), shape=(n, n)))
        return sum(parts[1:], parts[0]) if parts else sp.csr_matrix((n, n))

    # -- the Model contract ------------------------------------------------------------------------
    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """The bodies' initial states, stacked."""
        states = [b.initial_state() for b in self.bodies]
        return (np.concatenate([np.asarray(s[0], dtype=float) for s in states]),
                np.concatenate([np.asarray(s[1], dtype=float) for s in states]))

    def mass(self, q: np.ndarray | None = None) -> sp.csr_matrix:
        """Block-diagonal mass matrix; when every body's is constant, formed once and returned read-only
        (the multipliers at each output time need it: forming it took 0.38 ms of 48 coordinates on B6)."""
        if self.mass_is_constant and self._mass is not None:
            return self._mass
        M = _diag([b.mass(None if q is None else q[s]) for b, s in zip(self.bodies, self._slices)], self.n_dof)
        if self.mass_is_constant:
            for arr in (M.data, M.indices, M.indptr):
                arr.flags.writeable = False
            self._mass = M
        return M

    def residual(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """The bodies' residuals, stacked (no ``G^T lam``)."""
        return np.concatenate([b.residual(t, q[s], v[s], a[s]) for b, s in zip(self.bodies, self._slices)])

    def _stack_blocks(self, blocks) -> JacobianBlocks:
        n = self.n_dof
        same = all(J.same_pattern for J in blocks)
        return JacobianBlocks(_diag([J.K for J in blocks], n), _diag([J.D for J in blocks], n),
                              _diag([J.M for J in blocks], n), same_pattern=same)

    def jacobian(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> JacobianBlocks:
        """Block-diagonal ``K``, ``D``, ``M`` (one shared pattern when each body's share one)."""
        return self._stack_blocks([b.jacobian(t, q[s], v[s], a[s]) for b, s in zip(self.bodies, self._slices)])

    def residual_jacobian(self, t: float, q: np.ndarray, v: np.ndarray,
                          a: np.ndarray) -> tuple[np.ndarray, JacobianBlocks]:
        """``(residual, jacobian)`` from each body's one pass (capability ``"residual_jacobian"``)."""
        out = [b.residual_jacobian(t, q[s], v[s], a[s]) for b, s in zip(self.bodies, self._slices)]
        return np.concatenate([o[0] for o in out]), self._stack_blocks([o[1] for o in out])

    def residual_stages(self, ts: np.ndarray, Q: np.ndarray, V: np.ndarray, A: np.ndarray) -> np.ndarray:
        """Residuals of several stages (columns), body by body (capability ``"residual_stages"``)."""
        return np.vstack([b.residual_stages(ts, Q[s], V[s], A[s]) for b, s in zip(self.bodies, self._slices)])

    def energy(self, t: float, q: np.ndarray, v: np.ndarray) -> Energy:
        """Sums of the bodies' kinetic, strain and potential energies."""
        es = [b.energy(t, q[s], v[s]) for b, s in zip(self.bodies, self._slices)]
        return Energy(kinetic=sum(e.kinetic for e in es), strain=sum(e.strain for e in es),
                      potential=sum(e.potential for e in es))

    def external_power(self, t: float, q: np.ndarray, v: np.ndarray) -> float:
        """Sum of the bodies' non-conservative load powers (the joints' reactions are not loads)."""
        return float(sum(b.external_power(t, q[s], v[s]) for b, s in zip(self.bodies, self._slices)))

    # -- the "potential" capability, when every body has it ---------------------------------------------
    @property
    def potential_degree(self) -> int | None:
        """The largest of the bodies' degrees, None when any is None."""
        degrees = [getattr(b, "potential_degree", None) for b in self.bodies]
        return None if any(d is None for d in degrees) else max(degrees)

    def potential(self, t: float, q: np.ndarray) -> float:
        """Sum of the bodies' potentials."""
        return float(sum(b.potential(t, q[s]) for b, s in zip(self.bodies, self._slices)))

    def potential_gradient(self, t: float, q: np.ndarray,
                           tangent: bool = True) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Stacked gradients and the block-diagonal Hessian (or None)."""
        out = [b.potential_gradient(t, q[s], tangent) for b, s in zip(self.bodies, self._slices)]
        grad = np.concatenate([o[0] for o in out])
        return grad, (_diag([o[1] for o in out], self.n_dof) if tangent else None)

    def nonconservative_force(self, t: float, q: np.ndarray,
                              tangent: bool = True) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Stacked non-conservative forces and their block-diagonal tangent (or None)."""
        out = [b.nonconservative_force(t, q[s], tangent) for b, s in zip(self.bodies, self._slices)]
        f = np.concatenate([o[0] for o in out])
        if not tangent:
            return f, None
        mats = [o[1] if o[1] is not None else sp.csr_matrix((b.n_dof, b.n_dof)) for o, b in zip(out, self.bodies)]
        return f, _diag(mats, self.n_dof)

    def symmetry_generators(self) -> tuple[np.ndarray, list]:
        """None: joints and gravity break the bodies' rigid motions as symmetries of the system.

        The energy-momentum method's Gonzalez gradient then makes the plain mass-metric correction.
        Measured on the double pendulum of two 4-element BE2D beams (E = 1 GPa, h = 5 ms): passing each
        body's own rigid motions instead made Newton diverge at t = 0.14 s (rotations: the correction's
        coefficient becomes a ratio of small numbers on nearly rigid steps); translations alone changed
        nothing (686 against 630 iterations over 60 steps).
        """
        return np.zeros((self.n_dof, 0)), []
