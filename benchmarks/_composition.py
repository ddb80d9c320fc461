"""The composition route to a fourth-order energy-conserving method: energy-momentum steps composed.

A symmetric method of order 2 composed with symmetric substeps ``gamma_i h`` (``sum gamma_i = 1``)
is of order 4: the triple jump (Yoshida, Phys. Lett. A 150:262, 1990; 3 substeps, the middle one
negative) and Suzuki's fractal (Phys. Lett. A 146:319, 1990; 5 substeps). Each substep is one
:class:`~ancfdae.integrators.EnergyMomentum` step, so energy (and momenta) stay exact. A measuring
device for ``benchmarks.energy_collocation`` (the route lost everywhere there, so it is not in the
package): each substep size keeps its own Newton solver (its matrix depends on ``2 / (gamma h)^2``).
"""
from __future__ import annotations

import numpy as np

from ancfdae.integrators import EnergyMomentum, Quadrature, StepOutcome
from ancfdae.integrators._newton import NewtonSolver

__all__ = ["ComposedEnergyMomentum", "TRIPLE_JUMP", "SUZUKI"]

_g = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
TRIPLE_JUMP = (_g, 1.0 - 2.0 * _g, _g)
_s = 1.0 / (4.0 - 4.0 ** (1.0 / 3.0))
SUZUKI = (_s, _s, 1.0 - 4.0 * _s, _s, _s)


class ComposedEnergyMomentum(EnergyMomentum):
    """Energy-momentum composed with the substeps ``gammas`` (order 4 for TRIPLE_JUMP and SUZUKI)."""

    order = 4

    def __init__(self, model, h, gammas=SUZUKI, **options):
        super().__init__(model, h, **options)
        self.gammas = tuple(gammas)
        self.name = "em-suzuki" if len(self.gammas) == 5 else "em-triple-jump"
        self._solvers = {round(g, 14): NewtonSolver(self.newton.options) for g in set(self.gammas)}

    def _setup(self):
        super()._setup()
        for s in self._solvers.values():
            s.invalidate()

    def _step_impl(self, t0, h):
        saved = (self.t, self.q, self.v, self.a, self.previous, self.newton)
        if abs(h - self.h) > 1e-12 * self.h:           # a shortened last step: fresh matrices
            for s in self._solvers.values():
                s.invalidate()
        t, quads = t0, []
        try:
            for g in self.gammas:
                self.newton = self._solvers[round(g, 14)]
                self.previous = None                       # no predictor slope across substeps
                out = super()._step_impl(t, g * h)
                if not out.ok:
                    return out
                t = t + g * h
                self.t, self.q, self.v, self.a = t, out.q, out.v, out.a
                quads.append(out.quadrature)
        finally:
            self.t, self.q, self.v, self.a, self.previous, self.newton = saved
        quad = None
        if self.want_quadrature:
            quad = Quadrature(np.concatenate([x.t for x in quads]), np.vstack([x.q for x in quads]),
                              np.vstack([x.v for x in quads]), np.concatenate([x.w for x in quads]))
        return StepOutcome(ok=True, t=t0 + h, q=out.q, v=out.v, a=out.a, quadrature=quad)

    @property
    def stats(self):
        st = super().stats
        for key in ("newton_iterations", "factorizations"):
            st[key] = sum(s.stats.as_stats().get(key, 0) for s in self._solvers.values())
        return st
