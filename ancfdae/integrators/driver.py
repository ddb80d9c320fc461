"""The one driver loop around every integrator (the steppers of :mod:`.protocol`).

:func:`integrate` owns everything that is not the step itself: validation of the run's arguments,
the consistent initial acceleration, output times (grid hits and the stepper's interpolation inside
a step), monitors (each step's :class:`~.protocol.Quadrature` is passed to ``Monitor.advance``),
hooks, model events (the ``"step_events"`` capability of :mod:`ancfdae.problem`: BE3D's director
update; after each the stepper restarts with the acceleration consistent with the changed state and
model, one mass solve per event), failure handling and the :class:`~ancfdae.result.Result` with the model's description.
It hands the stepper everything through arguments: ``initialize(model, t0, q0, v0, a0, t_bound,
want_quadrature=...)`` and ``restart(t, q, v, a, model)``. It needs only the :mod:`.protocol`, so
the stepper base (:mod:`.integrator`, whose ``run`` calls this driver) stands above it.

Failure handling: a failed step, a monitor asking to stop, or an exception raised by anything
called during the run -- the model (e.g. a load's time function), a hook, a monitor, the stepper --
ends the run with status "failed", the exception's type and text in ``message``, ``t_fail`` the
last time reached and every output up to it. What a stepper returns is checked
(:mod:`._checks`: a StepOutcome, a time inside the step and the span, finite states of the model's
shape); a bad outcome ends the run as failed with a message naming the stepper. Hooks see
read-only views of the state and stop the run with any truthy answer. Exceptions are never
propagated out of the loop, except a KeyboardInterrupt: it is re-raised as
:class:`~._checks.RunInterrupted` carrying the run so far; bad *arguments* still raise before the
run starts.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import ArrayLike

from ancfdae import _validate as validate
from ancfdae._resultfile import describe_model
from ancfdae.constrained import consistent_state
from ancfdae.integrators import _checks
from ancfdae.integrators._recorder import Recorder
from ancfdae.integrators.protocol import Stepper
from ancfdae.problem import Model, capabilities

if TYPE_CHECKING:                       # for annotations only (monitors are named, not imported: they stand
    from ancfdae.result import Result   # above the integrators, e.g. DirectorGeometry reads BE3D's directors)

__all__ = ["check_model", "consistent_acceleration", "output_times", "integrate", "GRID_TOL",
           "DEFAULT_MAX_STEPS"]

_CONTRACT = ("initial_state", "mass", "residual", "jacobian")
#: output times within this fraction of a step from the step's end are on the grid
GRID_TOL = 1e-9
#: default limit of accepted steps per run
DEFAULT_MAX_STEPS = 10_000_000


def check_model(model: Model) -> int:
    """Check that ``model`` offers the Model contract and valid capabilities; return ``n_dof``."""
    missing = [m for m in _CONTRACT if not callable(getattr(model, m, None))]
    if missing:
        raise TypeError(f"`model` must implement the Model contract (ancfdae.problem.Model); "
                        f"{type(model).__name__} lacks {missing}.")
    n = getattr(model, "n_dof", None)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise TypeError(f"`model.n_dof` must be a positive integer, got {n!r}.")
    capabilities(model)
    return int(n)


def consistent_acceleration(model: Model, t: float, q: np.ndarray,
                            v: np.ndarray) -> tuple[np.ndarray, None] | tuple[None, str]:
    """Solve ``M(q) a = -r(t, q, v, 0)``; return ``(a, None)`` or ``(None, reason)``."""
    rhs = -np.asarray(model.residual(t, q, v, np.zeros_like(q)), dtype=float)
    M = model.mass(q)
    try:
        if sp.issparse(M):
            a = spla.splu(sp.csc_matrix(M)).solve(rhs)
        else:
            a = np.linalg.solve(np.asarray(M, dtype=float), rhs)
    except (RuntimeError, np.linalg.LinAlgError) as exc:
        return None, f"mass matrix at t = {t:g} is singular ({exc})"
    if not np.all(np.isfinite(a)):
        return None, f"acceleration at t = {t:g} is not finite"
    return a, None


def output_times(t_span: tuple[float, float],
                 t_eval: ArrayLike | None) -> tuple[float, float, np.ndarray | None]:
    """Validate ``t_span = (t0, tf)`` and ``t_eval``; return ``(t0, tf, t_out or None)``."""
    try:
        if isinstance(t_span, (str, bytes)) or any(isinstance(x, (str, bytes)) for x in t_span):
            raise TypeError("text")     # float("1") would accept it: times are numbers
        t0, tf = (float(x) for x in t_span)
    except (TypeError, ValueError):
        raise ValueError(f"`t_span` must be a pair (t0, tf) of numbers, got {t_span!r}.") from None
    if not (np.isfinite(t0) and np.isfinite(tf)) or tf <= t0:
        raise ValueError(f"`t_span` must satisfy t0 < tf (finite), got {t_span!r}.")
    if t_eval is None:
        return t0, tf, None
    te = validate.finite_vector("t_eval", t_eval)
    if te.size == 0:
        raise ValueError("`t_eval` must hold at least one time, got an empty array.")
    if np.any(np.diff(te) <= 0):
        raise ValueError("`t_eval` must be strictly increasing.")
    if te[0] < t0 or te[-1] > tf:
        raise ValueError(f"`t_eval` must lie within t_span [{t0}, {tf}], got [{te[0]}, {te[-1]}].")
    return t0, tf, te


def _initial_state(model, n, q0, v0, state0, events):
    q_i, v_i = model.initial_state() if (q0 is None or v0 is None) else (None, None)
    q0 = validate.finite_vector("q0", q_i if q0 is None else q0, n).copy()
    v0 = validate.finite_vector("v0", v_i if v0 is None else v0, n).copy()
    if not events:
        if state0 is not None:
            raise ValueError(f"`state0` is only for models with the 'step_events' capability; "
                             f"{type(model).__name__} has no event state.")
        return q0, v0, None
    initial = model.event_state()
    if state0 is None:
        return q0, v0, initial
    if not isinstance(state0, dict) or set(state0) != set(initial):
        raise ValueError(f"`state0` must be a dict with the keys {sorted(initial)} (e.g. a row of "
                         f"Result.model_state), got {state0!r:.200}.")
    state = {}
    for k, ref in initial.items():
        arr = np.array(state0[k], dtype=float)
        if arr.shape != np.shape(ref) or not np.all(np.isfinite(arr)):
            raise ValueError(f"`state0[{k!r}]` must be finite with shape {np.shape(ref)}, got shape {arr.shape}.")
        arr.setflags(write=False)
        state[k] = arr
    return q0, v0, state


def _constrained_start(stepper, model, caps, events, t0, q0, v0):
    """For a constrained model: check the stepper, project ``(q0, v0)`` and solve ``(a0, lam0)``; else None."""
    if "constraints" not in caps:
        return None
    name = getattr(stepper, "name", type(stepper).__name__)
    if not getattr(stepper, "handles_constraints", False):
        raise TypeError(f"method {name!r} cannot integrate constrained models ({type(model).__name__} declares "
                        f"'constraints', {model.n_constraints} rows): its stepper does not declare "
                        "handles_constraints = True. Use a built-in method (ancfdae.METHODS), or eliminate the "
                        "supports instead of joining them.")
    if events:
        raise ValueError(f"{type(model).__name__} has both constraints and an event state ('step_events'); "
                         "the driver does not carry constraints across model events yet.")
    return consistent_state(model, t0, q0, v0)


def _every_step(stepper) -> np.ndarray | None:
    """The start and every step's end of an initialised fixed-step stepper that takes steps across output times
    (``steps_sampling``), as output times; None for any other stepper.

    Output at every step (no ``t_eval``) is then the same run as ``t_eval`` on the step grid: the compiled steps
    record the samples themselves instead of returning to Python after each step (B6, 8 BE2D, h = 1e-4: 0.8 ms a
    step in Python, ~40 us compiled). The times are those of :meth:`FixedStepIntegrator.next_time`, computed the
    same way (``t0 + k h``, the last one moved to the end of the run)."""
    if not getattr(stepper, "fixed_step", False) or getattr(stepper, "steps_sampling", None) is None:
        return None
    t0, h, tb = stepper.t0, stepper.h, stepper.t_bound
    t = t0 + np.arange(1, math.ceil((tb - t0) / h) + 2) * h
    t[t >= tb - GRID_TOL * h] = tb
    return np.concatenate(([t0], t[:int(np.searchsorted(t, tb)) + 1]))


def _check_max_steps(stepper, t0, tf, max_steps):
    if max_steps is None:
        max_steps = DEFAULT_MAX_STEPS
    max_steps = validate.positive_int("max_steps", max_steps)
    if getattr(stepper, "fixed_step", False) and stepper.h is not None:
        need = (tf - t0) / stepper.h
        if need > max_steps + GRID_TOL:
            raise ValueError(f"a fixed step h = {stepper.h:g} over t_span = ({t0:g}, {tf:g}) needs "
                             f"{math.ceil(need - GRID_TOL)} steps, more than max_steps = {max_steps}; "
                             "use a larger h or raise max_steps.")
    return max_steps


class _Progress:
    """A tqdm bar of simulated time with the step rate (only when asked for)."""

    def __init__(self, enabled, t0, tf, label):
        self.bar = None
        if enabled:
            from tqdm.auto import tqdm  # noqa: PLC0415 - optional display
            self.bar = tqdm(total=tf - t0, unit="s(sim)", desc=label, leave=True,
                            bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s [{elapsed}<{remaining}{postfix}]")
            self.t, self.wall, self.last = t0, time.perf_counter(), 0.0

    def update(self, t, steps):
        if self.bar is None:
            return
        self.bar.update(t - self.t)
        self.t = t
        now = time.perf_counter() - self.wall
        if now - self.last > 0.5:
            self.last = now
            self.bar.set_postfix_str(f"{steps / max(now, 1e-9):.0f} steps/s", refresh=False)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def integrate(stepper: Stepper, model: Model, t_span: tuple[float, float], t_eval: ArrayLike | None = None,
              monitors: Sequence["ancfdae.monitors.Monitor"] = (), hooks: Sequence[Callable] = (),
              q0: ArrayLike | None = None, v0: ArrayLike | None = None, state0: dict | None = None, max_steps: int | None = None,
              progress: bool = False) -> Result:
    """Run ``stepper`` (a :class:`~.protocol.Stepper`) on ``model`` over ``t_span``.

    Parameters
    ----------
    stepper : Stepper
        The stepper, constructed on ``model`` (e.g. an :class:`~ancfdae.integrators.Integrator`).
    model : Model
        The equations of motion.
    t_span : (t0, tf)
        Time interval.
    t_eval : array_like, optional
        Output times (default: every step).
    monitors : sequence of Monitor
        Logged at the output times.
    hooks : sequence of callables
        ``hook(t, q, v, a)`` after every accepted step; True ends the run.
    q0, v0 : array_like, optional
        Initial state (default ``model.initial_state()``).
    state0 : dict, optional
        The model's event state to start from (a dict like one row of ``Result.model_state``).
    max_steps : int, optional
        Limit on the number of steps.
    progress : bool
        Show a progress bar.

    These are the parameters of :func:`ancfdae.simulate`, which builds the stepper.

    Returns
    -------
    Result
        Never raises once the run has started (but re-raises a KeyboardInterrupt, see below); see
        the module docstring. ``stats`` are the
        stepper's with the driver's ``model_events``, ``restarts``, ``wall_time`` and ``cpu_time``;
        ``model`` is ``model``'s description (``describe()`` and ``dof_labels()``, when it has them).

    Raises
    ------
    RunInterrupted
        (a KeyboardInterrupt) when Ctrl-C interrupts the run; its ``result`` holds every output up
        to the interruption (status "failed").

    Notes
    -----
    A model with the ``"constraints"`` capability (:class:`ancfdae.problem.ConstrainedModel`) needs a
    stepper with ``handles_constraints``. Its initial state is made consistent before the run
    (:func:`ancfdae.constrained.consistent_state`: ``q0`` projected onto ``g = 0``, ``v0`` onto
    ``G v + g_t = 0``, ``(a0, lam0)`` from the KKT system; the corrections are logged and stored as
    ``stats["initial_correction_q"]``/``["initial_correction_v"]``, a ``q0`` far from the constraints
    raises), and ``Result.lam`` holds the multipliers at the output times recomputed from ``(t, q, v)``
    by the KKT system (:func:`ancfdae.constrained.multipliers`), whose accuracy is that of ``(q, v)``.
    """
    n = check_model(model)
    caps = capabilities(model)
    events = "step_events" in caps
    t0, tf, t_out = output_times(t_span, t_eval)
    hooks = list(hooks or ())
    for k in hooks:
        if not callable(k):
            raise TypeError(f"`hooks` entries must be callables hook(t, q, v, a), got {k!r}.")
    max_steps = _check_max_steps(stepper, t0, tf, max_steps)
    q0, v0, state = _initial_state(model, n, q0, v0, state0, events)
    bound = model.bind(state) if events else model
    start = _constrained_start(stepper, bound, caps, events, t0, q0, v0)   # bad input raises here
    rec = Recorder(bound, monitors, constrained=start is not None)
    state_keys = tuple(state) if events else ()

    wall, cpu = time.perf_counter(), time.process_time()
    status, message, t_fail, interrupted = "failed", "", None, None
    steps = restarts = events_n = 0
    t = t0
    bar = _Progress(progress, t0, tf, getattr(stepper, "name", "run"))
    try:
        if start is None:
            a0, reason = consistent_acceleration(bound, t0, q0, v0)
            if a0 is None:
                raise _Failed(f"initial acceleration at t = {t0:g} failed: {reason}")
            stepper.initialize(bound, t0, q0, v0, a0, tf, want_quadrature=bool(rec.monitors))
        else:
            q0, v0, a0 = start.q, start.v, start.a
            stepper.initialize(bound, t0, q0, v0, a0, tf, want_quadrature=bool(rec.monitors), lam0=start.lam)
        rec.start(t0, q0, v0, a0)
        if t_out is None and not rec.monitors and not hooks and not events:
            t_out = _every_step(stepper)
        j = 0
        if t_out is None or t_out[0] <= t0:
            rec.sample(t0, q0, v0, a0, state)
            j = 1
        # nothing needs the state between output times: a stepper may take the steps up to the next one at once
        until = getattr(stepper, "steps_until", None) if (
            t_out is not None and not rec.monitors and not hooks and not events) else None
        sampling = getattr(stepper, "steps_sampling", None) if until is not None else None
        while True:
            if steps >= max_steps:
                raise _Failed(f"more than max_steps = {max_steps} steps before t = {tf:g}")
            if sampling is not None:   # across output times: the samples it recorded (on steps it accepted), then as until
                out, taken, samples = sampling(t_out[j:], tf, max_steps - steps)
                if taken:
                    steps, t = steps + taken, stepper.t
                if samples is not None:
                    for row in zip(*samples):
                        rec.record(*row)
                    j += len(samples[0])
            elif until is not None:   # the steps it accepted itself, then the last one's outcome
                out, taken = until(float(t_out[j]) if j < t_out.size else tf, max_steps - steps)
                if taken:
                    steps, t = steps + taken, stepper.t
            else:
                out = stepper.step()
            out, problem = _checks.step_problem(stepper, out, n, t, tf)
            if problem:
                raise _Failed(problem)
            if not out.ok:
                raise _Failed(f"step from t = {t:.9g} failed: {out.message}")
            t_prev, t = t, out.t
            stepper.accept(out)
            steps += 1
            rec.advance(t, out.q, out.v, out.a, out.quadrature)
            tol = GRID_TOL * (t - t_prev)
            on_grid = False
            if t_out is None:
                on_grid = True
            else:
                while j < t_out.size and t_out[j] <= t + tol:
                    if abs(t_out[j] - t) <= tol:
                        on_grid = True
                    else:  # inside the step: the stepper's interpolant, before any model event
                        rec.sample(t_out[j], *stepper.interpolate(float(t_out[j])), state)
                    j += 1
            if events:
                ev = bound.step_event(t, stepper.q, stepper.v)
                if ev is not None:
                    q_e, v_e, state = ev
                    events_n += 1
                    bound = model.bind(state)
                    q_e, v_e = np.asarray(q_e, float), np.asarray(v_e, float)
                    # the step's own acceleration belongs to the old state and model (a remapped
                    # torsion rate, a new director field): one mass solve gives the consistent one
                    a_e, reason = consistent_acceleration(bound, t, q_e, v_e)
                    if a_e is None:
                        raise _Failed(f"acceleration after the model event at t = {t:.9g} failed: {reason}")
                    stepper.restart(t, q_e, v_e, a_e, bound)
                    restarts += 1
                    rec.rebind(bound)
            if on_grid:
                rec.sample(t, stepper.q, stepper.v, stepper.a, state)
            bar.update(t, steps)
            reason = rec.stop_reason()
            if reason:
                raise _Failed(reason)
            if t >= tf:
                status, message = "success", f"reached tf = {tf:g} in {steps} steps"
                break
            if _checks.hooks_stop(hooks, t, stepper.q, stepper.v, stepper.a):
                status, message = "success", f"stopped by a hook at t = {t:.9g}"
                break
    except _Failed as exc:
        message, t_fail = str(exc), t
    except Exception as exc:  # noqa: BLE001 - a user's callback must not lose the results
        message, t_fail = f"run ended at t = {t:.9g} by an exception: {type(exc).__name__}: {exc}", t
    except KeyboardInterrupt as exc:    # Ctrl-C: re-raised below, with the part computed so far
        message, t_fail, interrupted = f"interrupted (KeyboardInterrupt) at t = {t:.9g}", t, exc
    finally:
        bar.close()
    stats = dict(stepper.stats)     # the stepper's counters, "steps" among them; the driver's beside
    stats.update(model_events=events_n, restarts=restarts,
                 wall_time=time.perf_counter() - wall, cpu_time=time.process_time() - cpu)
    if start is not None:
        stats.update(initial_correction_q=start.dq, initial_correction_v=start.dv)
    result = rec.result(n, state_keys=state_keys, status=status, message=message, stats=stats, t_fail=t_fail,
                        method=getattr(stepper, "name", type(stepper).__name__), options=stepper.options(),
                        model=describe_model(model))
    if interrupted is not None:
        raise _checks.RunInterrupted(f"{message}; the run so far is on this exception's `result`", result) \
            from interrupted
    return result


class _Failed(Exception):
    """A run ending as failed (not a bug): the message goes into the Result."""
