"""The energy balance ``E = T + U + V - W_ext`` of a run and its drift (:class:`EnergyMonitor`)."""
from __future__ import annotations

from typing import Any

import numpy as np

from ancfdae import _validate as validate
from ancfdae.constrained import constraint_power
from ancfdae.monitors.base import Monitor
from ancfdae.problem import capabilities

__all__ = ["EnergyMonitor"]


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

    ``log()`` adds the scalars ``max_abs_drift`` and ``scale`` (over the finite output rows),
    ``relative_drift = max_abs_drift / scale`` -- ``inf`` when an energy overflowed or became
    NaN, never a finite number computed around the overflow --, ``blow_up`` and ``t_blow_up``.
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
        finite = np.all(np.isfinite(rows), axis=1)
        drift = np.abs(out["drift"][finite])
        max_drift = float(np.max(drift)) if drift.size else float("nan")
        # the scale of the rows that are finite: an overflow (inf energies) must not divide the drift to 0
        scale = float(np.max(np.abs(rows[finite, :3]).sum(axis=1) + np.abs(rows[finite, 3]))) if drift.size else 0.0
        relative = max_drift / scale if scale > 0 else float("nan")
        if not np.all(finite):
            relative = float("inf")         # the energy itself overflowed: no finite drift describes that
        out.update(max_abs_drift=max_drift, scale=scale, relative_drift=relative,
                   blow_up=self._blow is not None, t_blow_up=self._blow)
        return out
