"""What the driver checks of the code it calls: a stepper's outcome, the hooks' answers; a Ctrl-C's result.

The driver (:mod:`.driver`) runs a user's stepper and callbacks as well as ours; none of them may
corrupt a run. :func:`step_problem` says what is wrong with a step's outcome (not a
:class:`~.protocol.StepOutcome`, a time outside the step or past the end of the run, a state of the
wrong shape or not finite) and the driver ends the run as failed with that reason; :func:`hooks_stop`
asks the hooks with read-only views of the state and stops on any truthy answer (``numpy.bool_``
included); :class:`RunInterrupted` carries the part of a run computed before a KeyboardInterrupt.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ancfdae._scale import max_abs
from ancfdae.integrators.protocol import StepOutcome

if TYPE_CHECKING:
    from ancfdae.result import Result

__all__ = ["step_problem", "hooks_stop", "read_only", "RunInterrupted"]

#: a step may end this many round-offs of the end time past it (grid times are computed, not summed)
_END_ULPS = 8.0


class RunInterrupted(KeyboardInterrupt):
    """A KeyboardInterrupt (Ctrl-C) during a run, re-raised with the run's part computed so far.

    Parameters
    ----------
    message : str
        When the run was interrupted.
    result : ancfdae.Result
        The run so far.

    Attributes
    ----------
    result : ancfdae.Result
        Every output up to the interruption; ``status`` "failed", ``t_fail`` the last time reached.
    """

    def __init__(self, message: str, result: Result) -> None:
        super().__init__(message)
        self.result = result


def _label(stepper) -> str:
    return f"{type(stepper).__name__} ({getattr(stepper, 'name', '?')!r})"


def _plain(x, n_dof: int) -> bool:
    """True for a finite float64 array of shape ``(n_dof,)`` (a NaN or inf makes the compiled max NaN or inf)."""
    return type(x) is np.ndarray and x.dtype == np.float64 and x.shape == (n_dof,) and math.isfinite(max_abs(x))


def step_problem(stepper, out, n_dof: int, t_prev: float, t_end: float) -> tuple[StepOutcome | None, str | None]:
    """Check what ``stepper.step()`` returned; return ``(outcome, None)`` or ``(None, reason)``.

    Parameters
    ----------
    stepper : Stepper
        Named in the reason.
    out : object
        What ``step()`` returned.
    n_dof : int
        The model's number of coordinates.
    t_prev, t_end : float
        The time before the step and the end of the run.

    Returns
    -------
    outcome : StepOutcome or None
        ``out`` with its arrays as float arrays (a failed step unchanged).
    reason : str or None
        What is wrong, naming the stepper: the run ends as failed with it.
    """
    if type(out) is StepOutcome and out.ok and type(out.t) is float and t_prev < out.t <= t_end \
            and _plain(out.q, n_dof) and _plain(out.v, n_dof) and _plain(out.a, n_dof):
        return out, None   # the common case, in a few microseconds: the checks below all pass
    who = f"the stepper {_label(stepper)}"
    if not isinstance(out, StepOutcome):
        return None, (f"{who} returned {type(out).__name__} ({out!r:.80}) from step(), expected a "
                      "StepOutcome (StepOutcome.failure(reason) for a failed step)")
    if not out.ok:
        return out, None
    try:
        t = float(out.t)
    except (TypeError, ValueError):
        return None, f"{who} returned the time {out.t!r}, not a number"
    if not np.isfinite(t):
        return None, f"{who} returned the time t = {t!r} from the step at t = {t_prev:.9g}"
    if not t > t_prev:
        return None, f"the step from t = {t_prev:.9g} made no progress ({who} reported t = {t:.9g})"
    if t > t_end + _END_ULPS * np.spacing(max(abs(t_end), abs(t_prev), 1.0)):
        return None, f"{who} stepped past the end of the run: t = {t:.9g} > tf = {t_end:.9g}"
    arrays = {}
    for name in ("q", "v", "a"):
        value = getattr(out, name)
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            return None, f"{who} returned {name} = {value!r:.80}, not an array of numbers"
        if arr.shape != (n_dof,):
            return None, (f"{who} returned {name} of shape {arr.shape} at t = {t:.9g}, expected ({n_dof},) "
                          "(the model's n_dof)")
        if not math.isfinite(max_abs(arr)):   # one compiled pass (np.all(np.isfinite) costs ~5 us a call)
            bad = np.flatnonzero(~np.isfinite(arr))
            return None, (f"{who} returned a non-finite {name} at t = {t:.9g} (entries {bad[:5].tolist()}"
                          f"{' ...' if bad.size > 5 else ''})")
        arrays[name] = arr
    if t != out.t or any(arrays[k] is not getattr(out, k) for k in arrays):
        out = replace(out, t=t, **arrays)
    return out, None


def read_only(x: np.ndarray) -> np.ndarray:
    """A read-only view of ``x`` (a callback cannot change the stepper's state in place)."""
    view = np.asarray(x).view()
    view.flags.writeable = False
    return view


def hooks_stop(hooks, t: float, q, v, a) -> bool:
    """Call every hook ``hook(t, q, v, a)`` (read-only views); True when one answers truthy.

    Any truthy answer stops the run (``True``, ``numpy.bool_(True)``, ``1``); None and falsy ones
    continue. An answer without a truth value (e.g. an array of several entries) raises a
    ValueError naming the hook, which ends the run as failed.
    """
    if not hooks:
        return False
    q, v, a = read_only(q), read_only(v), read_only(a)
    stop = False
    for hook in hooks:
        answer = hook(t, q, v, a)
        try:
            stop = bool(answer) or stop
        except (TypeError, ValueError) as exc:
            raise ValueError(f"hook {getattr(hook, '__name__', hook)!r} returned {answer!r:.80}, which is neither "
                             f"true nor false ({exc}); return True to stop the run, None or False to go on") \
                from None
    return stop
