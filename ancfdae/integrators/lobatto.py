"""Lobatto IIIA collocation, fixed step (the chapter's integrator, Sect. 5.2).

The chapter integrates with "a two staged trapezoidal rule (Lobatto), which
means three integration points per time step and a fourth-order global
convergence", i.e. Lobatto IIIA with s = 3 stages, with a modified Newton
method on each step. s = 2 is the trapezoidal rule (order 2).

The s-stage method is applied to ``q' = v, v' = a`` with ``r(t, q, v, a) = 0``
(the Model contract's residual) and the stage accelerations ``A_i`` as unknowns::

    V_i = v_n + h sum_j a_ij A_j
    Q_i = q_n + c_i h v_n + h^2 sum_j (a^2)_ij A_j
    r(t_n + c_i h, Q_i, V_i, A_i) = 0,   i = 2..s

Lobatto IIIA has an explicit first stage (first row of ``a`` zero: ``A_1`` is
the acceleration at ``t_n``, known from the previous step or the consistent
initial acceleration) and is stiffly accurate (last row of ``a`` = ``b``: the
new state is the last stage). The Newton matrix for the unknowns
``X = [A_2 .. A_s]``, stored interleaved (``X[p*(s-1) + i]``) so that it keeps
the band structure of the model's matrices, has the blocks::

    dr_i / dA_k = delta_ik M_i + h a_ik D_i + h^2 (a^2)_ik K_i

with ``K_i, D_i, M_i`` the exact Jacobian blocks at stage ``i`` (full Newton). Modified Newton
evaluates one set of blocks, at the last stage, and factorises the stage system in the eigenbasis
of the tableau (:class:`ancfdae.integrators._linsolve.StageMatrix`): for 3 stages one complex n x n
banded LU instead of a real 2n x 2n one. A model that declares the
capability ``"residual_stages"`` (:mod:`ancfdae.problem`; ``residual_stages(ts, Q, V, A) -> R``,
columns = stages, e.g. :class:`~ancfdae.models.Beam`) has all implicit stages' residuals evaluated
in one call; otherwise one ``residual`` call per stage.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ancfdae import _validate as validate
from ancfdae.integrators._affine import affine2, stage_constants, stage_states
from ancfdae.integrators._linsolve import StageMatrix
from ancfdae.constrained import multipliers
from ancfdae.integrators._newton_records import NewtonOptions
from ancfdae.integrators.lobatto_constrained import GGLStages, ggl_step
from ancfdae.integrators.newton_stepper import NewtonStepper
from ancfdae.integrators.protocol import Quadrature, StepOutcome
from ancfdae.problem import Model, capabilities

__all__ = ["ButcherTableau", "LOBATTO_IIIA_2", "LOBATTO_IIIA_3", "LobattoIIIA", "Lobatto2", "Lobatto3"]


@dataclass(frozen=True)
class ButcherTableau:
    """A Runge-Kutta tableau that checks itself (imitates diffrax's ``ButcherTableau``).

    Checks: square ``a`` of ``s`` stages, ``b`` and ``c`` of length ``s``,
    finite entries, the row-sum condition ``c_i = sum_j a_ij``, and the
    quadrature conditions ``sum_i b_i c_i^(k-1) = 1/k`` for ``k = 1..order``
    (necessary for the declared order).

    Parameters
    ----------
    a : array_like, shape (s, s)
        Runge-Kutta matrix.
    b : array_like, shape (s,)
        Weights.
    c : array_like, shape (s,)
        Nodes.
    order : int
        Declared order of the method.
    name : str
        Label used in messages.
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    order: int
    name: str = ""

    def __post_init__(self):
        a = np.array(self.a, dtype=float)
        b = np.array(self.b, dtype=float)
        c = np.array(self.c, dtype=float)
        if a.ndim != 2 or a.shape[0] != a.shape[1]:
            raise ValueError(f"tableau `a` must be square, got shape {a.shape}.")
        s = a.shape[0]
        if b.shape != (s,) or c.shape != (s,):
            raise ValueError(f"tableau `b` and `c` must have shape ({s},), got {b.shape} and {c.shape}.")
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b)) and np.all(np.isfinite(c))):
            raise ValueError("tableau entries must be finite.")
        if not np.allclose(a.sum(axis=1), c, rtol=0, atol=1e-14):
            raise ValueError(f"tableau violates c_i = sum_j a_ij: c = {c}, row sums = {a.sum(axis=1)}.")
        validate.positive_int("order", self.order)
        for k in range(1, self.order + 1):
            if abs(b @ c ** (k - 1) - 1.0 / k) > 1e-14:
                raise ValueError(f"tableau {self.name!r} violates the order-{self.order} quadrature condition "
                                 f"sum b c^{k - 1} = 1/{k} (got {b @ c ** (k - 1)!r}).")
        for name, arr in (("a", a), ("b", b), ("c", c)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def stages(self) -> int:
        """Number of stages ``s``."""
        return self.a.shape[0]

    @property
    def explicit_first_stage(self) -> bool:
        """True when the first row of ``a`` is zero."""
        return bool(np.all(self.a[0] == 0.0))

    @property
    def stiffly_accurate(self) -> bool:
        """True when the last row of ``a`` equals ``b``."""
        return bool(np.array_equal(self.a[-1], self.b))


LOBATTO_IIIA_2 = ButcherTableau(a=[[0, 0], [0.5, 0.5]], b=[0.5, 0.5], c=[0, 1], order=2,
                                name="Lobatto IIIA (2 stages, trapezoidal rule)")
LOBATTO_IIIA_3 = ButcherTableau(a=[[0, 0, 0], [5 / 24, 1 / 3, -1 / 24], [1 / 6, 2 / 3, 1 / 6]],
                                b=[1 / 6, 2 / 3, 1 / 6], c=[0, 0.5, 1], order=4,
                                name="Lobatto IIIA (3 stages)")
_TABLEAUX = {2: LOBATTO_IIIA_2, 3: LOBATTO_IIIA_3}


def _lagrange_weights(nodes, points):
    """``W[i, j] = l_j(points[i])`` for the Lagrange basis on ``nodes``."""
    nodes, points = np.asarray(nodes, float), np.asarray(points, float)
    W = np.ones((points.size, nodes.size))
    for j, xj in enumerate(nodes):
        for k, xk in enumerate(nodes):
            if k != j:
                W[:, j] *= (points - xk) / (xj - xk)
    return W


def _check_predictor(predictor: str, model) -> None:
    """Refuse ``predictor="extrapolate"`` on a constrained model, whose GGL stage system always starts from
    ``K_i = v_n + c_i h a_n``, ``A_i = a_n``, ``Lam_i = lam_n`` (it used to be ignored there silently).

    Not implemented there because it did not help where it was tried: on B5 (spin-up, BE2D 8 elements)
    stage values continued from the last step stopped h = 0.1 at the same 6.8 s and h = 0.05 earlier
    (docs/studies.md, "B5: why the non-dissipative methods fail").
    """
    if predictor == "extrapolate" and "constraints" in capabilities(model):
        raise ValueError("`predictor` must be 'constant' for a model with constraints (the GGL stage system "
                         "of Lobatto IIIA has no extrapolating predictor), got 'extrapolate'.")


class LobattoIIIA(NewtonStepper):
    """Lobatto IIIA, fixed step, (modified) Newton on the stage accelerations.

    Parameters
    ----------
    model : Model
    h : float
        Step size.
    stages : {2, 3} or ButcherTableau
        3 = the chapter's order-4 method (default); 2 = trapezoidal rule.
        A custom tableau must have an explicit first stage and be stiffly
        accurate.
    newton : NewtonOptions or dict, optional
        Default: modified Newton, relative tolerance 1e-8 (chapter Sect. 5.2).
    predictor : {"constant", "extrapolate"}
        Initial guess of the stage accelerations: ``a_n`` in every stage
        (default), or the previous step's collocation polynomial
        extrapolated. With the relative residual test the iteration count
        depends on the contraction rate, not on the initial residual: on
        the 25-element BE2D pendulum (h = 1e-4) "extrapolate" took 5.0
        instead of 4.7 iterations per step.

    Notes
    -----
    A model with the ``"constraints"`` capability is integrated in the stabilised index-2 (GGL) form
    with a reduced stage system (:mod:`ancfdae.integrators.lobatto_constrained`): order 4 in q and v
    on linear, quadratic and rheonomic constraints, ``g`` and ``G v + g_t`` held at every step to the
    Newton tolerance; the step's multipliers are returned in ``StepOutcome.lam``. There the predictor must
    be "constant" (``ValueError`` otherwise), and a step that modified Newton fails with per-stage blocks
    gets a last attempt with full Newton.
    """

    handles_constraints = True

    def __init__(self, model: Model, h: float, stages: int | ButcherTableau = 3, *,
                 newton: NewtonOptions | dict | None = None, predictor: str = "constant") -> None:
        super().__init__(model, h, newton=newton)
        if isinstance(stages, ButcherTableau):
            tab = stages
        elif not isinstance(stages, bool) and stages in _TABLEAUX:
            tab = _TABLEAUX[stages]
        else:
            raise ValueError(f"`stages` must be 2, 3 or a ButcherTableau, got {stages!r}.")
        if not (tab.explicit_first_stage and tab.stiffly_accurate):
            raise ValueError(f"`stages`: tableau {tab.name!r} must have an explicit first stage and be stiffly "
                             "accurate (Lobatto IIIA type).")
        self.tableau = tab
        self.predictor = validate.choice("predictor", predictor, ("extrapolate", "constant"))
        _check_predictor(self.predictor, model)
        self.name = f"lobatto{tab.stages}"
        self.order = tab.order
        s = tab.stages
        self._m = s - 1
        a2 = tab.a @ tab.a
        self._a_first, self._a_rest = tab.a[1:, 0].copy(), tab.a[1:, 1:].copy()
        self._a2_first, self._a2_rest = a2[1:, 0].copy(), a2[1:, 1:].copy()
        self._c = tab.c[1:].copy()
        self._perm = None

    def options(self) -> dict:
        """The options as a JSON-able dict (stored in the Result).

        Returns
        -------
        dict
            ``h``, the Newton options, ``stages`` and ``predictor``.
        """
        o = super().options()
        o.update(stages=self.tableau.stages, predictor=self.predictor)
        return o

    def _setup(self):
        super()._setup()
        self._prev = None  # (h, stage accelerations (n, s)) of the last step
        self._w_cache = None
        self._stages = "residual_stages" in capabilities(self.model)   # declared, forwarded by the proxy
        self._ggl = None
        if "constraints" in capabilities(self.model):   # constrained: the GGL stage system (lobatto_constrained)
            _check_predictor(self.predictor, self.model)
            if self.lam is None:          # no multipliers given: (a0, lam0) from the KKT system
                self.a, self.lam = multipliers(self.model, self.t, self.q, self.v)
            self._ggl = GGLStages(self)

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model) -> None:
        """After a model event; a constrained model gets ``(a, lam)`` consistent with the changed state (the
        first stage of the next step is ``a``).

        Parameters
        ----------
        t, q, v, a, model
            As for :meth:`~ancfdae.integrators.FixedStepIntegrator.restart`.
        """
        super().restart(t, q, v, a, model)
        if self._ggl is not None:
            self.a, self.lam = multipliers(self.model, self.t, self.q, self.v)

    # -- predictor -------------------------------------------------------------------------
    def _guess(self, h):
        m = self._m
        if self.predictor == "constant" or self._prev is None:
            return np.repeat(self.a[:, None], m, axis=1)
        h_prev, A_prev = self._prev
        ratio = h / h_prev
        if self._w_cache is None or self._w_cache[0] != ratio:
            self._w_cache = (ratio, _lagrange_weights(self.tableau.c, 1.0 + self._c * ratio).T)
        return A_prev @ self._w_cache[1]

    # -- iteration matrix --------------------------------------------------------------------
    def _pattern(self, K):
        """Index map from the per-entry block values (nnz, m, m) to the interleaved CSR data."""
        m, n = self._m, self.n_dof
        indptr, indices = K.indptr, K.indices
        nnz = indices.size
        row = np.repeat(np.arange(n), np.diff(indptr))
        e, i, k = (g.ravel() for g in np.meshgrid(np.arange(nnz), np.arange(m), np.arange(m), indexing="ij"))
        order = np.lexsort((k, e, i, row[e]))
        big_indices = (indices[e] * m + k)[order]
        counts = np.repeat(np.diff(indptr) * m, m)
        big_indptr = np.r_[0, np.cumsum(counts)]
        self._perm = (indptr.copy(), indices.copy(), order, big_indices, big_indptr)

    def _matrix(self, blocks, h):
        m, n = self._m, self.n_dof
        if m == 1:
            J = blocks[0]
            return J.combine(h * h * self._a2_rest[0, 0], h * self._a_rest[0, 0], 1.0)
        cK, cD = h * h * self._a2_rest, h * self._a_rest
        if all(b.same_pattern for b in blocks):
            K0 = blocks[0].K
            if (self._perm is None or self._perm[0].shape != K0.indptr.shape
                    or self._perm[1].shape != K0.indices.shape
                    or not np.array_equal(self._perm[0], K0.indptr)
                    or not np.array_equal(self._perm[1], K0.indices)):
                self._pattern(K0)
            _, _, order, big_indices, big_indptr = self._perm
            if all(np.array_equal(b.K.indices, K0.indices) and np.array_equal(b.K.indptr, K0.indptr)
                   for b in blocks[1:]):
                vals = np.empty((K0.indices.size, m, m))
                for i, b in enumerate(blocks):
                    vals[:, i, :] = b.K.data[:, None] * cK[i] + b.D.data[:, None] * cD[i]
                    vals[:, i, i] += b.M.data
                return sp.csr_matrix((vals.ravel()[order], big_indices, big_indptr), shape=(n * m, n * m))
        # generic: entry ((p, i), (q, k)) of block (i, k) -> kron(B_ik, E_ik)
        out = None
        for i, b in enumerate(blocks):
            for k in range(m):
                B = cK[i, k] * b.K + cD[i, k] * b.D + (b.M if i == k else 0 * b.M)
                E = sp.csr_matrix(([1.0], ([i], [k])), shape=(m, m))
                term = sp.kron(B, E, format="csr")
                out = term if out is None else out + term
        return out.tocsr()

    # -- one step ----------------------------------------------------------------------------
    def _step_impl(self, t, h):
        if self._ggl is not None:
            return ggl_step(self, self._ggl, t, h)
        m, n, model = self._m, self.n_dof, self.model
        ts = t + self._c * h
        # Stage states are affine in X: V = V0 + X @ CV, Q = Q0 + X @ CQ (constant parts once per step).
        Q0, V0 = stage_constants(self.q, self.v, self.a, h * self._a_first, h * self._c, h * h * self._a2_first)
        CV, CQ = (h * self._a_rest).T, (h * h * self._a2_rest).T
        if m == 1:
            v0, q0, cv, cq, t1 = V0[:, 0], Q0[:, 0], CV[0, 0], CQ[0, 0], ts[0]

            def residual(x):
                return model.residual(t1, *affine2(q0, v0, cq, cv, x), x)

            def jacobian(x):
                qs, vs = affine2(q0, v0, cq, cv, x)
                blk = model.jacobian(t1, qs, vs, x)
                return self._matrix([blk], h), self.floor_of(blk.K, qs)
        else:
            stages = model.residual_stages if self._stages else None

            def residual(x):
                Q, V_, X = stage_states(Q0, V0, CQ, CV, x)   # one compiled call for both products
                if stages is not None:   # all stages in one model call (optional Model method)
                    return stages(ts, Q, V_, X).ravel()
                R = np.empty((n, m))
                for i in range(m):
                    R[:, i] = model.residual(ts[i], Q[:, i], V_[:, i], X[:, i])
                return R.ravel()

            eigen = [self.newton.options.jacobian == "modified"]

            def jacobian(x):
                Q, V_, X = stage_states(Q0, V0, CQ, CV, x)
                if eigen[0]:
                    # Modified Newton reuses the matrix across steps anyway: one set of blocks (at
                    # the last stage) lets the stage system split in the tableau's eigenbasis.
                    blk = model.jacobian(ts[-1], Q[:, -1], V_[:, -1], X[:, -1])
                    floor = self.floor_of(blk.K, Q[:, -1])
                    if blk.same_pattern:
                        return StageMatrix(blk, h, self._a_rest), floor
                    blocks = [blk if i == m - 1 else model.jacobian(ts[i], Q[:, i], V_[:, i], X[:, i])
                              for i in range(m)]
                    return self._matrix(blocks, h), floor
                blocks = [model.jacobian(ts[i], Q[:, i], V_[:, i], X[:, i]) for i in range(m)]
                # the residual holds every stage: the floor of the largest
                floor = max(self.floor_of(blk.K, Q[:, i]) for i, blk in enumerate(blocks))
                return self._matrix(blocks, h), floor

        guess = self._guess(h).ravel()
        out = self._solve(residual, jacobian, guess)
        if not out.converged and m > 1 and eigen[0]:
            # The one-state eigenbasis matrix can be too crude where the stages differ much (large
            # steps, strong nonlinearity): before failing, retry the step with the exact per-stage matrix.
            eigen[0] = False
            self.newton.invalidate()
            out = self._solve(residual, jacobian, guess)
        if not out.converged:
            return StepOutcome.failure(f"Newton: {out.message}")
        Q, V_, X = stage_states(Q0, V0, CQ, CV, out.x)
        if self.predictor == "extrapolate":
            self._prev = (h, np.column_stack([self.a, X]))
        quad = None
        if self.want_quadrature:  # the step's Lobatto quadrature, for monitors that integrate over it
            quad = Quadrature(np.r_[t, ts], np.column_stack([self.q, Q]).T, np.column_stack([self.v, V_]).T,
                              h * self.tableau.b)
        return StepOutcome(ok=True, t=t + h, q=Q[:, -1].copy(), v=V_[:, -1].copy(), a=X[:, -1].copy(),
                           quadrature=quad)


class _FixedStages(LobattoIIIA):
    """Lobatto IIIA with the class's number of stages (``STAGES``): a key of ``ancfdae.METHODS``."""

    STAGES = 3

    def __init__(self, model: Model, h: float, *, newton: NewtonOptions | dict | None = None,
                 predictor: str = "constant") -> None:
        super().__init__(model, h, self.STAGES, newton=newton, predictor=predictor)


class Lobatto3(_FixedStages):
    """Lobatto IIIA with 3 stages (order 4; the chapter's integrator), ``METHODS["lobatto3"]``.

    Takes the arguments of :class:`LobattoIIIA` but ``stages``.
    """

    name, STAGES = "lobatto3", 3


class Lobatto2(_FixedStages):
    """Lobatto IIIA with 2 stages (trapezoidal rule, order 2), ``METHODS["lobatto2"]``.

    Takes the arguments of :class:`LobattoIIIA` but ``stages``.
    """

    name, STAGES = "lobatto2", 2
