"""Newmark family: Newmark (beta, gamma), HHT-alpha, generalized-alpha.

All three are one scheme, the generalized-alpha method of Chung and Hulbert
(J. Appl. Mech. 60:371, 1993), written on the residual of the Model contract
(the Model contract's residual) with the unknown ``a_{n+1}``::

    q_{n+1} = q_n + h v_n + h^2 ((1/2 - beta) a_n + beta a_{n+1})
    v_{n+1} = v_n + h ((1 - gamma) a_n + gamma a_{n+1})
    r(t_{n+1-af}, q_{n+1-af}, v_{n+1-af}, a_{n+1-am}) = 0,   x_{n+1-al} = (1-al) x_{n+1} + al x_n

* Newmark: ``am = af = 0`` (default ``beta = 1/4, gamma = 1/2``: the
  trapezoidal rule, energy-conserving on linear problems, order 2).
* HHT-alpha (Hilber, Hughes, Taylor 1977): ``am = 0, af = alpha`` with
  ``alpha`` in [0, 1/3] (Hilber's ``-alpha``), ``gamma = 1/2 + alpha``,
  ``beta = (1 + alpha)^2 / 4``.
* generalized-alpha: from the spectral radius at infinite frequency
  ``rho_inf`` in [0, 1]: ``am = (2 rho - 1)/(rho + 1)``, ``af = rho/(rho + 1)``,
  ``gamma = 1/2 - am + af``, ``beta = (1 - am + af)^2 / 4`` (order 2,
  unconditionally stable, high-frequency dissipation controlled by rho_inf).

Constrained models (capability ``"constraints"``): index 3 in the Arnold-Bruls form, scaled, with the
true acceleration in the equilibrium at ``t_{n+1}`` (:mod:`ancfdae.integrators._alpha_index3`); ``q``,
``v`` and the multipliers second order for ``rho_inf < 1``. Newmark with ``gamma = 1/2`` has no
numerical dissipation and its multipliers carry an undamped period-2h oscillation on index 3: a warning
is logged.

The residual is evaluated at the weighted state (not as weighted forces),
which keeps the scheme on the contract alone, with one residual call per
Newton iteration; for nonlinear problems it is the state-averaged variant of
these methods (second order as well). ``a`` reported for ``am, af != 0`` is
the algorithmic acceleration. Newton matrix:
``(1 - af)(h^2 beta K + h gamma D) + (1 - am) M``.
"""
from __future__ import annotations

import logging
import numbers

import numpy as np

from ancfdae.integrators._affine import affine2, affine3, newmark_predict
from ancfdae.integrators._alpha_index3 import index3_step, mass_scale
from ancfdae.kkt import KKTAssembler
from ancfdae.integrators._alpha_iteration import AlphaIteration
from ancfdae.integrators._alpha_steps import AlphaSteps
from ancfdae.integrators._index3_steps import Index3Steps
from ancfdae.integrators._newton_records import CONTRACTION, NewtonOptions
from ancfdae.integrators.driver import consistent_acceleration
from ancfdae.integrators.newton_stepper import NewtonStepper
from ancfdae.integrators.protocol import StepOutcome
from ancfdae import _validate as validate
from ancfdae.problem import Model, capabilities

__all__ = ["Newmark", "HHTAlpha", "GeneralizedAlpha"]

_log = logging.getLogger("ancfdae")

#: modified Newton's refresh threshold on a constrained model (index 3) unless the user gives ``contraction``:
#: the matrix's error grows with its age as the joints turn (B6's crank: 0.02 rad a step at h = 2e-4), so the
#: iterations of a stale matrix slow down step by step; a refresh (the KKT matrix in band order, about three
#: iterations' cost) pays at a lower rate than on a beam alone. B6 over 0.5 s at h = 2e-4 / 1e-4 / 5e-5:
#: 7.8-8.7 iterations a step at 0.3, 3.6-4.5 at 0.03 (0.12-0.41 refreshes), 26-35 % less CPU; B5 within noise
#: (``python -m benchmarks.index3_cost --contraction 0.3 0.03``)
INDEX3_CONTRACTION = 0.03
#: Newton's start on a constrained model: "auto" and "extrapolate" extrapolate ``(ah, lam)`` linearly from the last
#: two steps (:func:`ancfdae.integrators._alpha_index3.predictor`), "constant" starts from the current ones
PREDICTORS = ("auto", "extrapolate", "constant")


def _param(name, value, low, high):
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not (low <= value <= high):
        raise ValueError(f"`{name}` must be a real number in [{low}, {high}], got {value!r}.")
    return float(value)


class _AlphaFamily(NewtonStepper):
    """The shared generalized-alpha step (parameters validated by the subclasses)."""

    order = 2
    handles_constraints = True

    def __init__(self, model, h, beta, gamma, alpha_m, alpha_f, newton, predictor="auto"):
        super().__init__(model, h, newton=newton)
        self.beta, self.gamma, self.alpha_m, self.alpha_f = beta, gamma, alpha_m, alpha_f
        self.predictor = validate.choice("predictor", predictor, PREDICTORS)
        if self.predictor == "extrapolate" and "constraints" not in capabilities(model):
            raise ValueError("`predictor` 'extrapolate' is the index-3 step's (a model with the 'constraints' "
                             "capability); this model's steps start from a_n: use 'auto' or 'constant'.")
        self._offer = (None, None)   # (model, its compiled_residual), taken at the first step of a run
        self._steps = (None, None)   # (model, its AlphaSteps or Index3Steps or None), made at the first steps_until

    def options(self) -> dict:
        """The options as a JSON-able dict (stored in the Result).

        Returns
        -------
        dict
            ``h``, the Newton options and the four parameters of the scheme.
        """
        o = super().options()
        o.update(beta=self.beta, gamma=self.gamma, alpha_m=self.alpha_m, alpha_f=self.alpha_f,
                 predictor=self.predictor)
        return o

    def _setup(self) -> None:
        """The Newton set-up (the model's compiled offer taken afresh); on a constrained model the algorithmic
        acceleration starts at ``a0``."""
        super()._setup()
        self._offer = self._steps = (None, None)
        self._constrained = "constraints" in capabilities(self.model)
        self.newton.choose_contraction(INDEX3_CONTRACTION if self._constrained else CONTRACTION)
        if self._constrained:
            self._ah = self.a.copy()
            self._last = None   # (h, ah, lam) at the start of the last step: the index-3 predictor's second point
            self._kkt = KKTAssembler()
            self._mscale = mass_scale(self.model.mass(self.q))
            if self.lam is None:
                self.lam = np.zeros(self.model.n_constraints)
            if self.alpha_m == self.alpha_f and self.gamma == 0.5:
                _log.warning("%s on a constrained model (index 3) without numerical dissipation: the multipliers "
                             "carry an undamped period-2h oscillation; prefer rho_inf < 1.", self.name)

    def accept(self, outcome: StepOutcome) -> None:
        """Make ``outcome`` the current state (and, constrained, its algorithmic acceleration).

        Parameters
        ----------
        outcome : StepOutcome
            A successful step.
        """
        if self._constrained:
            self._last = (outcome.t - self.t, self._ah, self.lam)
        super().accept(outcome)
        if self._constrained:
            self._ah = self._ah_next

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model) -> None:
        """Carry on after a model event, keeping the algorithmic acceleration's offset.

        For ``am, af != 0`` the carried ``a`` is the algorithmic acceleration, which differs from the
        physical one by O(h); the event changes the physical part only, so the stepper restarts with
        ``a + (a_alg - a_old)``, ``a_old`` the physical acceleration of the model before the event at the
        state before it (one more mass solve). Restarting with ``a`` itself resets the offset at every
        event: on B3 (BE3D, 8 elements, update every step, ``rho_inf = 0.8``, h = 1e-3 s) that put
        -5.7e-5 J into the balance in 2 s where keeping it leaves 8.6e-7 J, the method's own error.

        Parameters
        ----------
        t, q, v, a, model
            As for :meth:`~ancfdae.integrators.Integrator.restart` (``a`` consistent with ``model``).
        """
        if self.alpha_m != 0.0 or self.alpha_f != 0.0:
            a_old, reason = consistent_acceleration(self.model, t, self.q, self.v)
            if a_old is None:
                raise FloatingPointError(f"the acceleration before the model event failed: {reason}")
            a = a + (self.a - a_old)
        super().restart(t, q, v, a, model)
        if self._constrained:
            self._last = None   # the event changed the state: nothing to extrapolate from

    def _step_impl(self, t, h):
        if self._constrained:
            return index3_step(self, t, h)
        am, af, b, g, model = self.alpha_m, self.alpha_f, self.beta, self.gamma, self.model
        ta = t + (1.0 - af) * h
        # q_{n+1}, v_{n+1} and the weighted state are affine in x = a_{n+1}: their constant parts
        # once per step, in one compiled pass (as NumPy each operation costs ~1 us at these sizes).
        q_pred, v_pred, qa0, va0, aa0 = newmark_predict(self.q, self.v, self.a, h, b, g, am, af)
        cq, cv = h * h * b, h * g
        cqa, cva, caa = (1 - af) * cq, (1 - af) * cv, 1.0 - am

        # one compiled call forms the three weighted states (bit-for-bit the NumPy expressions)
        def residual(x):
            return model.residual(ta, *affine3(qa0, va0, aa0, cqa, cva, caa, x))

        def jacobian(x):
            qa, va, aa = affine3(qa0, va0, aa0, cqa, cva, caa, x)
            J = model.jacobian(ta, qa, va, aa)
            return J.combine(cqa, cva, caa), self.floor_of(J.K, qa)

        iterate = self._compiled_iteration(ta, qa0, va0, aa0, cqa, cva, caa)
        out = self._solve(residual if iterate is None else iterate.residual, jacobian, self.a, iterate=iterate)
        if not out.converged:
            return StepOutcome.failure(f"Newton: {out.message}")
        x = out.x
        q, v = affine2(q_pred, v_pred, cq, cv, x)
        return StepOutcome(ok=True, t=t + h, q=q, v=v, a=x)

    def steps_until(self, t_stop: float, max_count: int) -> tuple[StepOutcome, int]:
        """Steps up to the first that reaches ``t_stop``, in one compiled call where the model offers it.

        The driver calls this instead of :meth:`step` when nothing needs the state between its stops
        (:mod:`ancfdae.integrators._alpha_steps`). Of the steps taken, all but the last are accepted
        here; the last one's outcome is returned for the driver to accept, as from :meth:`step` (a
        failure: the step after the accepted ones failed). Without the compiled path (a user's model,
        point moments, full Newton, no cached banded factors yet; constrained: a model other than a System of
        one compiled beam and rigid bodies, :mod:`ancfdae.integrators._index3_steps`) it is one :meth:`step`.

        Parameters
        ----------
        t_stop : float
            The driver's next output time (or the end of the run).
        max_count : int
            At most this many steps, the returned one included (>= 1).

        Returns
        -------
        outcome : StepOutcome
            The last step's outcome, not yet accepted.
        taken : int
            Steps accepted here before it.
        """
        steps = self._compiled_steps()
        if self._constrained:
            return steps.run(float(t_stop), int(max_count))[:2] if steps is not None and max_count >= 1 else (self.step(), 0)
        lu = self.newton._lu
        band = getattr(lu, "_lu", None)
        if (steps is None or max_count < 1 or self._h_matrix is None or getattr(band, "lub", None) is None
                or not band._compiled or band.dtype != np.float64):
            return self.step(), 0
        return steps.run(band, float(t_stop), int(max_count))

    def steps_sampling(self, t_out: np.ndarray, t_end: float, max_count: int) -> tuple[StepOutcome, int, tuple | None]:
        """:meth:`steps_until` across several output times: ``(outcome, taken, samples)``.

        On a System with compiled index-3 steps (:mod:`ancfdae.integrators._index3_steps`) one compiled call takes
        the steps up to the last of the coming output times ``t_out`` (or ``t_end``) that it can, and records the
        state and the reactions at each output time an accepted step ends on: ``samples = (t, q, v, a, lam)``
        (rows), what the driver would record there. Otherwise ``samples`` is None and this is :meth:`steps_until`
        up to ``t_out[0]``.
        """
        steps = self._compiled_steps() if self._constrained else None
        t_stop = float(t_out[-1]) if len(t_out) else float(t_end)
        if steps is None or max_count < 1:
            return (*self.steps_until(float(t_out[0]) if len(t_out) else float(t_end), max_count), None)
        return steps.run(t_stop, int(max_count), t_out)

    def _compiled_steps(self):
        """The model's compiled steps for this run (:class:`._alpha_steps.AlphaSteps`; constrained:
        :class:`._index3_steps.Index3Steps`), or None."""
        if self.newton.options.jacobian != "modified":
            return None
        model = self.model.wrapped
        if self._constrained:
            if self._steps[0] is not model:
                self._steps = (model, Index3Steps.offer(self))
            return self._steps[1]
        if self._steps[0] is not model:
            offer = getattr(model, "compiled_residual", None)
            compiled = offer() if offer is not None else None
            made = AlphaSteps(compiled, self) if compiled is not None and compiled.steps is not None else None
            self._steps = (model, made)
        return self._steps[1]

    def _compiled_iteration(self, ta, qa0, va0, aa0, cqa, cva, caa):
        """The step's iteration as one compiled call (:mod:`._alpha_iteration`) when the model offers a compiled
        residual (:meth:`ancfdae.models.Beam.compiled_residual`) and Newton is modified; else None."""
        if self.newton.options.jacobian != "modified":
            return None
        model = self.model.wrapped
        if self._offer[0] is not model:   # the model's offer, once per run and bound model
            offer = getattr(model, "compiled_residual", None)
            self._offer = (model, offer() if offer is not None else None)
        compiled = self._offer[1]
        if compiled is None:
            return None
        return AlphaIteration(compiled, self.model, ta, qa0, va0, aa0, cqa, cva, caa)


class Newmark(_AlphaFamily):
    """Newmark's method (``am = af = 0``).

    Parameters
    ----------
    model : Model
    h : float
    beta : float
        In [0, 1/2]; default 1/4 (average acceleration / trapezoidal rule).
    gamma : float
        In [0, 1]; default 1/2 (no numerical dissipation; order 2 only for
        gamma = 1/2, order 1 otherwise).
    newton : NewtonOptions or dict, optional
    predictor : {"auto", "extrapolate", "constant"}
        Newton's start on a constrained model (index 3): "auto" (default) and "extrapolate" take ``ah`` and the
        multipliers extrapolated linearly from the last two steps of equal size, "constant" the current ones
        (:func:`ancfdae.integrators._alpha_index3.predictor`). An unconstrained model's steps start from ``a_n``
        ("auto", "constant"; "extrapolate" raises).
    """

    name = "newmark"

    def __init__(self, model: Model, h: float, beta: float = 0.25, gamma: float = 0.5, *,
                 newton: NewtonOptions | dict | None = None, predictor: str = "auto") -> None:
        super().__init__(model, h, _param("beta", beta, 0.0, 0.5), _param("gamma", gamma, 0.0, 1.0),
                         0.0, 0.0, newton, predictor)
        self.order = 2 if self.gamma == 0.5 else 1


class HHTAlpha(_AlphaFamily):
    """Hilber-Hughes-Taylor alpha method.

    Parameters
    ----------
    model : Model
        The equations of motion.
    h : float
        Step size.
    alpha : float
        In [0, 1/3] (Hilber's parameter with the sign flipped); 0 is the
        trapezoidal rule, larger values damp high frequencies more.
    newton : NewtonOptions or dict, optional
        Newton options (default: modified Newton, tolerance 1e-8).
    predictor : {"auto", "extrapolate", "constant"}
        Newton's start on a constrained model, as for :class:`Newmark`.
    """

    name = "hht"

    def __init__(self, model: Model, h: float, alpha: float = 0.05, *,
                 newton: NewtonOptions | dict | None = None, predictor: str = "auto") -> None:
        alpha = _param("alpha", alpha, 0.0, 1.0 / 3.0)
        super().__init__(model, h, (1 + alpha) ** 2 / 4, 0.5 + alpha, 0.0, alpha, newton, predictor)
        self.alpha = alpha

    def options(self) -> dict:
        """The options as a JSON-able dict (stored in the Result).

        Returns
        -------
        dict
            Those of the family and ``alpha``.
        """
        o = super().options()
        o["alpha"] = self.alpha
        return o


class GeneralizedAlpha(_AlphaFamily):
    """Generalized-alpha method of Chung and Hulbert.

    Parameters
    ----------
    model : Model
        The equations of motion.
    h : float
        Step size.
    rho_inf : float
        Spectral radius at infinite frequency, in [0, 1]; 1 = no dissipation
        (the trapezoidal rule), 0 = asymptotic annihilation.
    newton : NewtonOptions or dict, optional
        Newton options (default: modified Newton, tolerance 1e-8).
    predictor : {"auto", "extrapolate", "constant"}
        Newton's start on a constrained model, as for :class:`Newmark`.
    """

    name = "generalized-alpha"

    def __init__(self, model: Model, h: float, rho_inf: float = 0.8, *,
                 newton: NewtonOptions | dict | None = None, predictor: str = "auto") -> None:
        rho = _param("rho_inf", rho_inf, 0.0, 1.0)
        am, af = (2 * rho - 1) / (rho + 1), rho / (rho + 1)
        super().__init__(model, h, (1 - am + af) ** 2 / 4, 0.5 - am + af, am, af, newton, predictor)
        self.rho_inf = rho

    def options(self) -> dict:
        """The options as a JSON-able dict (stored in the Result).

        Returns
        -------
        dict
            Those of the family and ``rho_inf``.
        """
        o = super().options()
        o["rho_inf"] = self.rho_inf
        return o
