"""Monitors: energy balance and point sensors, logged at the output times.

Every integrator drives a monitor through four calls:

``start(model, t0, q0, v0, a0)``
    once, before the first step;
``advance(t, q, v, a, nodes=None)``
    after every accepted step (on IDA: every internal step), with the
    step's quadrature when the integrator has one, an
    :class:`ancfdae.integrators.protocol.Quadrature` ``(t, q, v, w)`` (node
    times, coordinates and velocities as rows, weights that sum to the step
    size), for integrals over the step;
``sample(t, q, v, a)``
    at every output time (``t`` lies in the last advanced step);
``rebind(model)`` (optional)
    after a model event (BE3D's director update) with the model bound to
    the new event state, so that later evaluations use it;
``log()``
    the arrays (one entry per output time) and scalars stored in
    ``Result.monitors[name]``.

``stop_reason()`` returns a string when the monitor asks the run to end.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ancfdae import _validate as validate
from ancfdae.constrained import constraint_power
from ancfdae.problem import capabilities

__all__ = ["Monitor", "EnergyMonitor", "PointSensor", "Probe", "ConstraintMonitor"]


class Monitor:
    """Base class: no-op hooks; subclasses set ``name`` and override what they need."""

    name = "monitor"

    def start(self, model: Any, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        """Begin a run: the model and the initial state.

        Parameters
        ----------
        model : Model
        t : float
        q, v, a : ndarray, shape (n_dof,)
        """
        self.model = model

    def advance(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, nodes: tuple | None = None) -> None:
        """Account for one accepted step ending at ``t``.

        Parameters
        ----------
        t : float
        q, v, a : ndarray, shape (n_dof,)
            State at the end of the step.
        nodes : Quadrature, optional
            ``(t, q, v, w)``: the step's quadrature (node times, coordinates
            and velocities as rows, weights summing to the step size).
        """

    def rebind(self, model: Any) -> None:
        """Use ``model`` (bound to a new event state) from now on.

        Parameters
        ----------
        model : Model
        """
        self.model = model

    def sample(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        """Record the state at an output time (inside the last advanced step).

        Parameters
        ----------
        t : float
        q, v, a : ndarray, shape (n_dof,)
        """

    def log(self) -> dict:
        """The recorded data: arrays with one entry per output time, and scalars.

        Returns
        -------
        dict
            Stored as ``Result.monitors[name]``.
        """
        return {}

    def stop_reason(self) -> str | None:
        """A message when the monitor asks the run to end, else None.

        Returns
        -------
        str or None
        """
        return None


class EnergyMonitor(Monitor):
    """Energy balance ``E(t) = T + U + V - W_ext`` logged at the output times.

    ``T, U, V`` come from ``model.energy`` (kinetic, strain, potential of the
    conservative loads). ``W_ext(t) = int_t0^t P_ext dt`` is the work of the
    non-conservative loads, integrated from ``model.external_power`` over the
    integrator's steps: with the step's own quadrature when the integrator
    supplies one (Lobatto IIIA: its Lobatto nodes and weights, exact for
    polynomials of degree 2s-3, error O(h^(2s-2)) on smooth power histories),
    otherwise with the trapezoidal rule over the step grid (error O(h^2); on
    IDA the grid of its internal steps). Output times that fall inside a step
    interpolate ``W_ext`` linearly. For the exact solution ``E`` is constant;
    ``drift = E(t) - E(t0)``.

    Parameters
    ----------
    name : str
        Key in ``Result.monitors``.
    blowup : float
        Relative drift above which the run is flagged as blown up:
        ``drift > blowup * scale`` with ``scale`` the largest
        ``|T| + |U| + |V| + |W_ext|`` logged so far; non-finite energies
        always count.
    stop_on_blowup : bool
        Ask the integrator to end the run (status "failed") at a blow-up.

    Notes
    -----
    Internal damping is not a load: a damped model loses ``E``. On a constrained model (capability
    ``"constraints"``) ``W_ext`` includes the work of the forces that drive prescribed motions,
    ``int lam . g_t dt`` with ``lam`` from the KKT system at the quadrature nodes
    (:func:`ancfdae.constrained.constraint_power`); scleronomic joints do no work.
    """

    def __init__(self, name: str = "energy", blowup: float = 0.1, stop_on_blowup: bool = False) -> None:
        self.name = str(name)
        self.blowup = validate.positive("blowup", blowup)
        if not isinstance(stop_on_blowup, bool):
            raise ValueError(f"`stop_on_blowup` must be True or False, got {stop_on_blowup!r}.")
        self.stop_on_blowup = stop_on_blowup

    def start(self, model: Any, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        for attr in ("energy", "external_power"):
            if not callable(getattr(model, attr, None)):
                raise TypeError(f"EnergyMonitor needs `model.{attr}(t, q, v)`; "
                                f"{type(model).__name__} has none.")
        self.model = model
        self._constrained = "constraints" in capabilities(model)
        self._rows: list[tuple] = []
        self._work = 0.0
        self._t_prev = self._t_cur = float(t)
        self._w_prev = self._w_cur = 0.0
        self._p_cur = self._power(t, q, v)
        self._scale = 0.0
        self._e0 = None
        self._blow = None

    def _power(self, t, q, v):
        p = float(self.model.external_power(t, q, v))
        return p + constraint_power(self.model, t, q, v) if self._constrained else p

    def advance(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, nodes: tuple | None = None) -> None:
        p_end = self._power(t, q, v)
        if nodes is None:
            dw = 0.5 * (t - self._t_cur) * (self._p_cur + p_end)
        else:
            dw = sum(wj * self._power(tj, qj, vj) for tj, qj, vj, wj in zip(*nodes))
        self._t_prev, self._w_prev = self._t_cur, self._w_cur
        self._t_cur, self._w_cur, self._p_cur = float(t), self._w_cur + dw, p_end

    def _work_at(self, t):
        if t >= self._t_cur or self._t_cur == self._t_prev:
            return self._w_cur
        theta = (t - self._t_prev) / (self._t_cur - self._t_prev)
        return self._w_prev + theta * (self._w_cur - self._w_prev)

    def sample(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        e = self.model.energy(t, q, v)
        w = self._work_at(float(t))
        total = e.kinetic + e.strain + e.potential
        balance = total - w
        if self._e0 is None:
            self._e0 = balance
        self._scale = max(self._scale, abs(e.kinetic) + abs(e.strain) + abs(e.potential) + abs(w))
        drift = balance - self._e0
        if self._blow is None and (not np.isfinite(balance) or drift > self.blowup * self._scale):
            self._blow = float(t)
        self._rows.append((e.kinetic, e.strain, e.potential, w, total, balance, drift))

    def stop_reason(self) -> str | None:
        if self.stop_on_blowup and self._blow is not None:
            return f"energy blow-up detected at t = {self._blow:.6g} by monitor {self.name!r}"
        return None

    def log(self) -> dict:
        rows = np.array(self._rows, dtype=float).reshape(-1, 7)
        keys = ("kinetic", "strain", "potential", "work", "total", "balance", "drift")
        out = {k: rows[:, i].copy() for i, k in enumerate(keys)}
        finite = out["drift"][np.isfinite(out["drift"])]
        max_drift = float(np.max(np.abs(finite))) if finite.size else float("nan")
        out.update(max_abs_drift=max_drift, scale=float(self._scale),
                   relative_drift=max_drift / self._scale if self._scale > 0 else float("nan"),
                   blow_up=self._blow is not None, t_blow_up=self._blow)
        return out


class PointSensor(Monitor):
    """Position and velocity of a point of the beam axis at the output times.

    Parameters
    ----------
    s : float, optional
        Reference arc length of the point; uses ``model.position(q, s)``.
        The velocity is then ``position(q + v, s) - position(q, s)``, exact
        because ANCF positions are affine in the coordinates (``r = S(s) e``
        with the fixed coordinates filled in, chapter Eq. 54).
    function : callable, optional
        ``function(q) -> position`` for models without ``position``; its
        velocity is logged only when ``velocity_function(q, v)`` is given.
    name : str, optional
        Key in ``Result.monitors`` (default ``"point@s"`` or ``"point"``).
    velocity_function : callable, optional
    """

    def __init__(self, s: float | None = None, *, function: Callable | None = None, name: str | None = None,
                 velocity_function: Callable | None = None) -> None:
        if (s is None) == (function is None):
            raise ValueError("PointSensor needs exactly one of `s` (arc length) or `function`, "
                             f"got s={s!r}, function={function!r}.")
        if s is not None:
            s = validate.nonnegative("s", s)
        if function is not None and not callable(function):
            raise ValueError(f"`function` must be callable, got {function!r}.")
        if velocity_function is not None and not callable(velocity_function):
            raise ValueError(f"`velocity_function` must be callable, got {velocity_function!r}.")
        self.s, self.function, self.velocity_function = s, function, velocity_function
        self.name = name if name is not None else (f"point@{s:g}" if s is not None else "point")

    def start(self, model: Any, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        if self.s is not None and not callable(getattr(model, "position", None)):
            raise TypeError(f"PointSensor(s=...) needs `model.position(q, s)`; {type(model).__name__} has "
                            "none: pass `function=` instead.")
        self.model = model
        self._pos, self._vel = [], []

    def sample(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        if self.s is not None:
            p = np.asarray(self.model.position(q, self.s), dtype=float)
            self._pos.append(p)
            self._vel.append(np.asarray(self.model.position(q + v, self.s), dtype=float) - p)
        else:
            self._pos.append(np.atleast_1d(np.asarray(self.function(q), dtype=float)))
            if self.velocity_function is not None:
                self._vel.append(np.atleast_1d(np.asarray(self.velocity_function(q, v), dtype=float)))

    def log(self) -> dict:
        out = {"position": np.array(self._pos)}
        if self._vel:
            out["velocity"] = np.array(self._vel)
        if self.s is not None:
            out["s"] = self.s
        return out


class Probe(Monitor):
    """Any quantity logged at the output times.

    Parameters
    ----------
    name : str
        Key in ``Result.monitors``.
    function : callable
        ``function(t, q, v, a) -> array``, logged as ``"value"``.
    """

    def __init__(self, name: str, function: Callable) -> None:
        if not callable(function):
            raise ValueError(f"`function` must be callable, got {function!r}.")
        self.name, self.function = str(name), function

    def start(self, model: Any, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        self.model = model
        self._rows = []

    def sample(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        self._rows.append(np.asarray(self.function(t, q, v, a), dtype=float))

    def log(self) -> dict:
        return {"value": np.array(self._rows)}


class ConstraintMonitor(Monitor):
    """Drift of the position and velocity constraints of a constrained model, at every output time.

    Logs ``position`` = ``max|g(t, q)|`` and ``velocity`` = ``max|G v + g_t|`` at the output times, and
    ``step_position``/``step_velocity``: their largest values over the steps that ended since the
    previous output. Output times inside a step hold interpolated states (the integrator's interpolant
    does not satisfy ``g = 0`` exactly); the step values measure the method itself. Scalars
    ``max_position`` and ``max_velocity`` over the run (step ends and outputs).

    Parameters
    ----------
    name : str
        Key in ``Result.monitors``.
    """

    def __init__(self, name: str = "constraints") -> None:
        self.name = str(name)

    def start(self, model: Any, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        if "constraints" not in capabilities(model):
            raise TypeError(f"ConstraintMonitor needs a model with the 'constraints' capability; "
                            f"{type(model).__name__} has none.")
        self.model = model
        self._rows: list[tuple] = []
        self._step = self._drift(t, q, v)
        self._max = self._step

    def _drift(self, t, q, v):
        g = self.model.constraints(t, q)
        g_t, _ = self.model.constraint_rates(t, q, v)
        gv = self.model.constraint_jacobian(t, q) @ v + g_t
        return float(np.max(np.abs(g), initial=0.0)), float(np.max(np.abs(gv), initial=0.0))

    def advance(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, nodes: tuple | None = None) -> None:
        d = self._drift(t, q, v)
        self._step = (max(self._step[0], d[0]), max(self._step[1], d[1]))

    def sample(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        d = self._drift(t, q, v)
        self._rows.append(d + self._step)
        self._max = (max(self._max[0], d[0], self._step[0]), max(self._max[1], d[1], self._step[1]))
        self._step = (0.0, 0.0)

    def log(self) -> dict:
        rows = np.array(self._rows, dtype=float).reshape(-1, 4)
        out = {k: rows[:, i].copy() for i, k in enumerate(("position", "velocity", "step_position",
                                                            "step_velocity"))}
        out.update(max_position=self._max[0], max_velocity=self._max[1])
        return out
