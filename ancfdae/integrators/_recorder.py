"""The output record of a run: samples at the output times, the monitors, the :class:`Result`."""
from __future__ import annotations

import numpy as np

from ancfdae.constrained import multipliers
from ancfdae.kkt import KKTAssembler
from ancfdae.result import Result

__all__ = ["Recorder"]


class Recorder:
    """Collect output samples (with the model's event state) and drive the monitors.

    Parameters
    ----------
    model : Model
        Passed to the monitors' ``start``.
    monitors : sequence of Monitor
        Objects with ``start/advance/sample/log`` (names unique).
    constrained : bool
        Record the multipliers at every output, recomputed from ``(t, q, v)`` by the KKT system
        (:func:`ancfdae.constrained.multipliers`).
    """

    def __init__(self, model, monitors=(), constrained=False):
        monitors = list(monitors or ())
        names = set()
        for m in monitors:
            if not all(callable(getattr(m, k, None)) for k in ("start", "advance", "sample", "log")):
                raise TypeError(f"`monitors` entries must be Monitor objects (start/advance/sample/log), got {m!r}.")
            if m.name in names:
                raise ValueError(f"monitor names must be unique, got {m.name!r} twice.")
            names.add(m.name)
        self.model, self.monitors = model, monitors
        self.t, self.q, self.v, self.a, self.state = [], [], [], [], []
        self.constrained, self.lam = constrained, []
        self._kkt = KKTAssembler() if constrained else None

    def start(self, t, q, v, a):
        """Start every monitor at the initial state."""
        for m in self.monitors:
            m.start(self.model, t, q, v, a)

    def advance(self, t, q, v, a, quadrature=None):
        """Tell every monitor that a step ended at ``t`` (with the step's quadrature, if any)."""
        for m in self.monitors:
            m.advance(t, q, v, a, quadrature)

    def rebind(self, model):
        """Hand the model bound to a new event state to the monitors that accept it."""
        for m in self.monitors:
            hook = getattr(m, "rebind", None)
            if callable(hook):
                hook(model)

    def sample(self, t, q, v, a, state=None):
        """Record one output time; ``state`` is the model's event state valid at ``t``.

        The multipliers are solved and the monitors sample before anything is appended: when either
        raises (a singular KKT system, a probe whose value changed shape), the output time is not
        recorded and every log keeps one row per recorded time.
        """
        lam = None
        if self.constrained:
            lam = multipliers(self.model, float(t), np.asarray(q, float), np.asarray(v, float),
                              assembler=self._kkt)[1]
        for m in self.monitors:
            m.sample(t, q, v, a)
        if lam is not None:
            self.lam.append(lam)
        self.t.append(float(t))
        self.q.append(np.array(q, dtype=float))
        self.v.append(np.array(v, dtype=float))
        self.a.append(np.array(a, dtype=float))
        if state is not None:
            self.state.append(state)

    def record(self, t, q, v, a, lam):
        """Record one output time whose multipliers the stepper solved as :meth:`sample` does (no monitors, no
        event state: :meth:`ancfdae.integrators.newmark._AlphaFamily.steps_sampling`)."""
        if self.constrained:
            self.lam.append(np.array(lam, dtype=float))
        self.t.append(float(t))
        self.q.append(np.array(q, dtype=float))
        self.v.append(np.array(v, dtype=float))
        self.a.append(np.array(a, dtype=float))

    def stop_reason(self):
        """The first monitor's request to end the run, or None."""
        for m in self.monitors:
            reason = m.stop_reason() if callable(getattr(m, "stop_reason", None)) else None
            if reason:
                return reason
        return None

    def result(self, n_dof, state_keys=(), **kw) -> Result:
        """Build the :class:`Result` from what was recorded."""
        def stack(rows):
            return np.array(rows) if rows else np.zeros((0, n_dof))
        model_state = {k: np.array([s[k] for s in self.state]) for k in state_keys} if self.state else {}
        m = getattr(self.model, "n_constraints", 0) if self.constrained else 0
        lam = np.array(self.lam).reshape(len(self.t), m) if self.constrained else None
        return Result(t=np.array(self.t), q=stack(self.q), v=stack(self.v), a=stack(self.a), lam=lam,
                      monitors={m.name: m.log() for m in self.monitors}, model_state=model_state, **kw)
