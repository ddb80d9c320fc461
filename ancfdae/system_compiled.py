"""A System's equations as flat arrays for compiled code: one compiled beam, rigid bodies, the compiled rows.

:class:`SystemArrays` packs, once, what compiled loops need to evaluate a :class:`ancfdae.System` of one beam
whose element offers compiled system entry points (BE2D: ``be2d_index3_steps``, ``be2d_multipliers``) and any
number of rigid bodies, with every constraint row in the one compiled set (:attr:`ancfdae.System.compiled_rows`):

* ``cons``: the rows' flat arrays (:class:`~ancfdae.joints.assembled.ConstraintSet`: linear entries, constants,
  quadratic entries, their slots in ``G``'s pattern, that pattern);
* ``rigid``: the rigid bodies' coordinates, mass entries, gravity, timed forces and timed moment matrices
  (:meth:`ancfdae.bodies.rigid.RigidBody.residual_parts`) on the system's coordinates;
* ``beam``: the beam's offset, size, fused-kernel arrays, its mass in the tangent's pattern and without stored
  zeros (:func:`ancfdae.models.beam.compiled.compiled_residual`);
* ``kkt``: the band order of the KKT matrix ``[[K + s M + H, G^T], [G, 0]]`` (its pattern from the arrays above):
  ``(pos, kl, ku, ...)``, unknown ``i`` at ``pos[i]``, ``kl``/``ku`` its sub- and super-diagonals in that order,
  then each part's entries' positions in the band storage (:mod:`ancfdae.integrators._index3_kkt_numba`).
  The System's order puts the multipliers after every coordinate (B6: 57 sub-diagonals of 62 unknowns); reverse
  Cuthill-McKee of the symmetric pattern puts each next to its coordinates (B6: 8 and 8, B5: 9 and 9 of 39), and
  the compiled loops factorise in band storage: fill and LU of B6's matrix 11 us where the dense LU took ~50 us
  (``python -m benchmarks.index3_cost``).

The time functions stay Python: :meth:`SystemArrays.weights` tabulates them at given times (the rows' weights,
:meth:`~ancfdae.joints.assembled.ConstraintSet.weight_table`, then one column per rigid-body load) and
:meth:`SystemArrays.external` the beam's external force. :meth:`SystemArrays.multipliers` is the compiled twin of
:func:`ancfdae.constrained.multipliers` (the reactions at output times).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ancfdae._scale import max_abs

__all__ = ["SystemArrays"]

#: the compiled paths hold the KKT matrix in band storage of ``n + m`` rows: offered up to this many unknowns
#: (a band that fills the matrix costs N^3, as a dense LU)
DENSE_MAX = 200


def _coo(block: np.ndarray, offset: int):
    i, j = np.nonzero(block)
    return i + offset, j + offset, block[i, j]


class SystemArrays:
    """The flat arrays of a System (module docstring); use :meth:`of`.

    Attributes
    ----------
    rows : CompiledConstraintSet
    cons, rigid, beam : tuple
        The arrays of the module docstring, in the order the compiled loops unpack them.
    element_args : tuple
        The beam element's kernel arguments.
    compiled : CompiledResidual
        The beam's offer (its ``index3_steps`` and ``multipliers`` entry points).
    n_weights : int
        Columns of :meth:`weights`.
    """

    def __init__(self, system, beam_at, compiled, rigid_bodies) -> None:
        n = system.n_dof
        rows = self.rows = system.compiled_rows
        cons = (rows.lin_term, rows.lin_row, rows.lin_col, rows.lin_val, rows.const_term, rows.const_row,
                rows.const_val, rows.qi, rows.qj, rows.qk, rows.qa, rows.lin_slot, rows._q_slot,
                rows.G_pattern.indptr.astype(np.int64), rows.G_pattern.indices.astype(np.int64))
        self.cons = tuple(np.ascontiguousarray(a) for a in cons)
        n_w = 1 + len(rows.timed)
        times, mi, mj, mv, ci, cj, cv, ccol, fvec, fcol = [], [], [], [], [], [], [], [], [], []
        grav, ridx = np.zeros(n), []
        for body, off in rigid_bodies:
            M, fg, forces, moments = body.residual_parts()
            nb = M.shape[0]
            ridx.extend(range(off, off + nb))
            for lst, arr in zip((mi, mj, mv), _coo(M, off)):
                lst.append(arr)
            grav[off:off + nb] = fg
            for time, f in forces:
                fv = np.zeros(n)
                fv[off:off + nb] = f
                fvec.append(fv)
                fcol.append(n_w + len(times))
                times.append(time)
            for time, C in moments:
                i, j, c = _coo(C, off)
                ci.append(i)
                cj.append(j)
                cv.append(c)
                ccol.append(np.full(i.size, n_w + len(times)))
                times.append(time)
        cat = (lambda x, dt: np.concatenate(x).astype(dt) if x else np.zeros(0, dt))
        self.rigid = (np.array(ridx, dtype=np.int64), cat(mi, np.int64), cat(mj, np.int64), cat(mv, float), grav,
                      np.array(fvec, dtype=float).reshape(len(fvec), n), np.array(fcol, dtype=np.int64),
                      cat(ci, np.int64), cat(cj, np.int64), cat(cv, float), cat(ccol, np.int64))
        self._times = times
        self.n_weights = n_w + len(times)
        beam, off = beam_at
        q_fixed, gather, vec_slot, mat_slot = compiled.arrays[:4]
        # the mass in the assembly's own pattern (stored zeros kept): the KKT fill adds the tangent's data
        # and the mass's entry by entry, so both must share one pattern (compiled.arrays holds the mass
        # without its zeros, for products only)
        # (compiled.arrays' zero-free mass: the residual's product M a, as the Python path's)
        asm = beam._asm
        self.beam = (int(off), int(beam.n_dof), q_fixed, gather, vec_slot, mat_slot, beam._M_data,
                     asm.indptr, asm.indices, *compiled.arrays[4:7])
        self.element_args = compiled.element_args
        self.compiled, self._beam_model = compiled, beam
        # the beam's external force: gravity alone is constant; dead loads need their time functions
        self._dead = bool(compiled.dead_times)
        self._E = np.ascontiguousarray(compiled.external(0.0)[None, :], dtype=float)
        self._last = (np.zeros(0), np.zeros((0, 3, self.n_weights)))
        self.kkt = self._band_order(n, rows.m)

    def _band_order(self, n: int, m: int) -> tuple:
        """``kkt`` of the KKT matrix's pattern (module docstring): the band order of every entry the compiled fill
        writes, and each part's band positions (:mod:`ancfdae.integrators._index3_kkt_numba`)."""
        ob, nb, indptr, indices = self.beam[0], self.beam[1], self.beam[7], self.beam[8]
        ridx, mi, mj, mv, grav, fvec, fcol, ci, cj = self.rigid[:9]
        qi, qj, qk = self.cons[7:10]
        g_indptr, g_indices = self.cons[13], self.cons[14]
        g_rows = n + np.repeat(np.arange(m), np.diff(g_indptr))
        parts = ((ob + np.repeat(np.arange(nb), np.diff(indptr)), ob + indices), (mi, mj), (ci, cj), (qj, qk),
                 (g_rows, g_indices), (g_indices, g_rows))
        rows = np.concatenate([r for r, _ in parts]).astype(np.int64)
        cols = np.concatenate([c for _, c in parts]).astype(np.int64)
        N = n + m
        pattern = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(N, N))
        pos = np.empty(N, dtype=np.int64)
        pos[reverse_cuthill_mckee(pattern, symmetric_mode=True)] = np.arange(N)
        off = pos[rows] - pos[cols]
        kl, ku = int(max(off.max(initial=0), 0)), int(max(-off.min(initial=0), 0))
        # A[i, j] at AB[pos[j], kl + ku + pos[i] - pos[j]] of the (N, 2 kl + ku + 1) band storage, flat
        at = [pos[c] * (2 * kl + ku + 1) + kl + ku + pos[r] - pos[c] for r, c in parts]
        return (pos, kl, ku, *(np.ascontiguousarray(a, dtype=np.int64) for a in at))

    @property
    def load_factor(self) -> float:
        """The beam's load factor now (read at each use: a static solve steps it)."""
        return float(self._beam_model.load_factor)

    @classmethod
    def of(cls, system) -> "SystemArrays | None":
        """The arrays of ``system``, or None when it is not such a System (module docstring) or has more than
        :data:`DENSE_MAX` unknowns."""
        if getattr(system, "compiled_rows", None) is None or not system.n_constraints:
            return None
        if system.n_dof + system.n_constraints > DENSE_MAX:
            return None
        beams, rigid = [], []
        for body, off in zip(system.bodies, system.offsets):
            offer = getattr(body, "compiled_residual", None)
            if offer is not None:
                compiled = offer()
                if compiled is None or compiled.index3_steps is None or compiled.multipliers is None:
                    return None
                beams.append(((body, int(off)), compiled))
            elif callable(getattr(body, "residual_parts", None)):
                rigid.append((body, int(off)))
            else:
                return None
        if len(beams) != 1:
            return None
        (beam_at, compiled), = beams
        return cls(system, beam_at, compiled, rigid)

    def weights(self, times: np.ndarray, derivatives: bool = False) -> np.ndarray:
        """The time weights at ``times``: (k, n_weights), the rows' row 0 then the rigid loads' factors; with
        ``derivatives`` (k, 3, n_weights), the rows' first and second derivatives in rows 1, 2 (the loads': 0).
        The last table is kept: :meth:`multipliers` at one of its times reads it (an output time is a step's end).

        Raises ValueError (naming the time and the fault) when a time function returns bad values."""
        W = self.rows.weight_table(times, True)
        if self._times:
            extra = np.zeros((times.size, 3, len(self._times)))
            extra[:, 0] = [[float(time(t)) for time in self._times] for t in times]
            W = np.concatenate((W, extra), axis=-1)
        self._last = (times, W)
        return W if derivatives else np.ascontiguousarray(W[:, 0])

    def _weights_at(self, t: float) -> np.ndarray:
        """(3, n_weights) at ``t``: from the last table when ``t`` is one of its times, else evaluated."""
        times, W = self._last
        i = int(np.searchsorted(times, t)) if times.size else 0
        if i < times.size and times[i] == t:
            return W[i]
        return self.weights(np.array([t]), True)[0]

    def external(self, times: np.ndarray) -> np.ndarray:
        """The beam's external force at ``times`` (k, nb), or its constant value (1, nb) without dead loads."""
        if not self._dead:
            return self._E
        return np.ascontiguousarray([self.compiled.external(t) for t in times], dtype=float)

    def multipliers(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(a, lam)`` at ``(t, q, v)`` as :func:`ancfdae.constrained.multipliers`, in one compiled call.

        Raises
        ------
        numpy.linalg.LinAlgError
            When the KKT solve gives non-finite values (a singular matrix).
        """
        W = np.ascontiguousarray(self._weights_at(float(t)))
        n, m = q.size, self.rows.m
        a, lam = np.empty(n), np.empty(m)
        self.compiled.multipliers(W, self.external(np.array([float(t)]))[0], np.ascontiguousarray(q, dtype=float),
                                  np.ascontiguousarray(v, dtype=float), a, lam, self.cons, self.rigid, self.beam,
                                  self.element_args, self.load_factor, self.kkt)
        if not (math.isfinite(max_abs(a)) and math.isfinite(max_abs(lam))):
            raise np.linalg.LinAlgError(f"multipliers at t = {t:g}: the KKT solve gave non-finite values (singular "
                                        "matrix? are constraints redundant (see ancfdae.constrained.dependent_rows)?)")
        return a, lam
