"""Exudyn runs of constrained (multibody) models: integrator settings, a checked and timed solve.

Shared by the peer models of the multibody benchmarks (B5 spin-up, B6 slider-crank, B7 spatial
pendulum). Exudyn integrates constrained systems with two implicit methods:

- ``generalized_alpha``: Chung-Hulbert generalized-alpha on the index-3 system (position
  constraints), spectral radius ``rho_inf`` (Exudyn's default 0.9);
- ``trapezoidal_index2``: Newmark beta = 1/4, gamma = 1/2 (the trapezoidal rule) on the index-2
  system (velocity constraints; what ``DynamicSolverType.TrapezoidalIndex2`` switches on). The
  position constraints then drift; the runners measure that drift.

Each run is checked: the solver must report success *and* have reached the end time; a failed or
truncated run is never timed (:func:`solve_checked` returns the reason and the time reached,
:func:`timed_runs` raises).
"""
from __future__ import annotations

import time

import numpy as np

from ._exudyn_base import _base_settings, _exu

__all__ = ["INTEGRATORS", "constrained_settings", "solve_checked", "timed_runs", "history",
           "observed_orders", "richardson"]

#: Exudyn's implicit integrators for constrained systems (module docstring)
INTEGRATORS = ("generalized_alpha", "trapezoidal_index2")

#: Newton tolerances of every constrained run: Exudyn tests ||R||_2 <= rtol * R_ref or
#: ||R||_2 <= atol. On these beam systems the residual has a round-off floor near 1e-9 ... 1e-8 and a
#: smooth start has R_ref near 1e-5, so relative 1e-8 alone cannot be met; absolute 1e-6 is as tight
#: as it goes (measured for the Exudyn peer of the pendulum and spin-up runs).
NEWTON_RTOL = 1e-8
NEWTON_ATOL = 1e-6


def constrained_settings(t_end, h, integrator, *, rho_inf=0.9, modified_newton=True,
                         newton_rtol=NEWTON_RTOL, newton_atol=NEWTON_ATOL, output_period=None):
    """Exudyn ``SimulationSettings`` for a fixed-step constrained run.

    Parameters
    ----------
    t_end, h : float
        End time and constant step size (s); ``t_end / h`` must be an integer to round-off.
    integrator : {'generalized_alpha', 'trapezoidal_index2'}
        See the module docstring.
    rho_inf : float
        Spectral radius at infinity of generalized-alpha (ignored by the trapezoidal rule).
    modified_newton : bool
        Exudyn's modified Newton (Jacobian kept while the iteration contracts) or full Newton.
    newton_rtol, newton_atol : float
        Exudyn's Newton ``relativeTolerance`` and ``absoluteTolerance``.
    output_period : float, optional
        Sampling period of the sensors (stored in memory); default ``h``.

    Notes
    -----
    ``adaptiveStep`` is off: a step whose Newton iteration fails ends the run (reported by
    :func:`solve_checked`) instead of being silently halved, so that every run of a given ``h``
    takes the same steps.
    """
    if integrator not in INTEGRATORS:
        raise ValueError(f"`integrator` must be one of {INTEGRATORS}, got {integrator!r}.")
    n_steps = t_end / h
    if not (h > 0 and abs(n_steps - round(n_steps)) < 1e-9 * n_steps):
        raise ValueError(f"`h` must divide `t_end` = {t_end} into whole steps, got {h!r}.")
    s = _base_settings()
    ti = s.timeIntegration
    ti.numberOfSteps = int(round(n_steps))
    ti.endTime = t_end
    ti.adaptiveStep = False
    ti.newton.useModifiedNewton = bool(modified_newton)
    ti.newton.relativeTolerance = newton_rtol
    ti.newton.absoluteTolerance = newton_atol
    ga = ti.generalizedAlpha
    ga.computeInitialAccelerations = True
    if integrator == "trapezoidal_index2":
        ga.useNewmark, ga.useIndex2Constraints = True, True
        ga.newmarkBeta, ga.newmarkGamma = 0.25, 0.5
    else:
        ga.useNewmark, ga.useIndex2Constraints = False, False
        ga.spectralRadius = rho_inf
    s.solution.sensors.writePeriod = h if output_period is None else output_period
    return s


def solve_checked(mbs, settings):
    """Run Exudyn's implicit solver on an assembled ``mbs``; time it and check it.

    Returns
    -------
    dict
        ``ok`` (solver success and end time reached), ``reason`` ('' or why not), ``t_reached``
        (s), ``wall`` and ``cpu`` (s, the solve call only), ``steps``, ``newton_iterations``,
        ``jacobians`` (Jacobian evaluations).
    """
    t_end = settings.timeIntegration.endTime
    solver = _exu.MainSolverImplicitSecondOrder()
    reason = ""
    c0, t0 = time.process_time(), time.perf_counter()
    try:
        ok = bool(solver.SolveSystem(mbs, settings))
    except Exception as err:  # Exudyn raises on Newton failure when adaptiveStep is off
        ok, reason = False, f"{type(err).__name__}: {str(err).strip()[:200]}"
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    t_reached = float(mbs.systemData.GetTime())
    if ok and abs(t_reached - t_end) > 1e-9 * max(1.0, t_end):
        ok, reason = False, f"stopped at t = {t_reached:.6g} s before the end time {t_end:.6g} s"
    if not ok and not reason:
        reason = f"Exudyn reported failure at t = {t_reached:.6g} s"
    it = solver.it
    return dict(ok=ok, reason=reason, t_reached=t_reached, wall=wall, cpu=cpu,
                steps=int(it.currentStepIndex) - 1, newton_iterations=int(it.newtonStepsCount),
                jacobians=int(it.newtonJacobiCount))


def timed_runs(run, repeats):
    """Call ``run()`` (a fresh model and solve each time) ``repeats`` times; median timings.

    ``run`` returns the dict of a peer runner (with the keys of :func:`solve_checked`). Raises
    ``RuntimeError`` if any run failed: a failed or truncated run is never timed.
    """
    outs = []
    for _ in range(repeats):
        out = run()
        if not out["ok"]:
            raise RuntimeError(f"peer run failed ({out['reason']}); not timed")
        outs.append(out)
    last = dict(outs[-1])
    last["walls"] = [o["wall"] for o in outs]
    last["wall"] = float(np.median(last["walls"]))
    last["cpu"] = float(np.median([o["cpu"] for o in outs]))
    return last


def history(mbs, sensor):
    """A sensor's stored samples as an array (rows: t, values...)."""
    return np.asarray(mbs.GetSensorStoredData(sensor))


def observed_orders(differences, ratio=2.0):
    """Orders log_ratio(d_k / d_{k+1}) of successive differences between refinements."""
    d = np.asarray(differences, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.log(d[:-1] / d[1:]) / np.log(ratio)


def richardson(coarse, fine, keys, order=2, ratio=2.0):
    """Richardson extrapolation of sampled histories of two runs with steps h and h / ratio.

    ``fine[k] + (fine[k] - coarse[k]) / (ratio**order - 1)`` for each key; both runs must share
    their sample times. Removes the leading O(h^order) term of a smooth global error.
    """
    if coarse["t"].shape != fine["t"].shape or np.max(np.abs(coarse["t"] - fine["t"])) > 1e-9:
        raise ValueError("`coarse` and `fine` must be sampled at the same times.")
    c = ratio**order - 1.0
    return {k: fine[k] + (fine[k] - coarse[k]) / c for k in keys}
