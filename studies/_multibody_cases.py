"""One case of the multibody study: a benchmark (B5-B7) run by one integrator, and what the study keeps of it.

Kept apart from :mod:`ancfdae.studies.multibody` (the sweep, the tables, the orders) because the study's case
store keys a stored case on the source of the case function's module and of the study modules it uses:
only what defines the computation -- the benchmark models, their sizes, the integrator options -- lives
here, so that a change of a table or a figure does not make every case run again.
"""
from __future__ import annotations

import os
import time

import numpy as np

from ancfdae.simulate import METHODS

from . import _multibody_models as models    # a module object: its source enters the stored cases' key

__all__ = ["MODELS", "OPTIONS", "MULTIPLIER_OUTPUTS", "INVARIANTS", "fixed_step", "benchmark", "run_case",
           "outputs"]

#: benchmark -> (element, elements, builder options)
MODELS = {"B5": ("BE2D", 8, {"w_s": 4.0}), "B6": ("BE2D", 8, {}), "B7": ("Cable3D", 4, {"E": 5.0e7})}
#: options per method (beyond h)
OPTIONS = {"hht": {"alpha": 0.05}, "generalized-alpha": {"rho_inf": 0.8}}
#: the outputs that are multipliers (reactions); the others but the invariants are positions
MULTIPLIER_OUTPUTS = ("hub_torque", "slider_normal_force", "crank_torque", "pivot_force_mean_z")
INVARIANTS = ("energy", "angular_momentum_z")


def fixed_step(method: str) -> bool:
    """Whether ``method`` takes a step ``h`` (else it is variable-step and runs at a tolerance ``rtol``)."""
    return bool(getattr(METHODS[method], "fixed_step", True))


def benchmark(name: str, t_end: float):
    """The benchmark ``name`` (:data:`MODELS`) built for the span ``[0, t_end]``."""
    element, n, opts = MODELS[name]
    opts = dict(opts, t_end=t_end) if name == "B7" else opts
    return models.BUILDERS[name](element, n, **opts)


def run_case(case: dict) -> dict:
    """One run: ``case = {benchmark, integrator, h, t_end, n_out}``; ``h`` is ``rtol`` for a variable-step method."""
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from ancfdae import simulate
    b = benchmark(case["benchmark"], case["t_end"])
    t_eval = np.linspace(0.0, case["t_end"], case["n_out"])
    t0 = time.process_time()
    step = {"h": case["h"]} if fixed_step(case["integrator"]) else {"rtol": case["h"]}
    res = simulate(b.system, (0.0, case["t_end"]), case["integrator"], t_eval=t_eval, **step,
                   **OPTIONS.get(case["integrator"], {}))
    return {"result": res, "cpu": time.process_time() - t0, **case}


def outputs(record: dict) -> dict:
    """The benchmark's outputs, the constraint drift (largest and per output time) and (B7) the invariants
    of a stored run; the coordinate history itself is dropped."""
    res = record["result"]
    b = benchmark(record["benchmark"], record["t_end"])
    s = b.system
    out = {k: np.asarray(f(res.t, res.q, res.v, res.lam)) for k, f in b.outputs.items()}
    g = np.array([s.constraints(t, q) for t, q in zip(res.t, res.q)])
    gv = np.array([s.constraint_jacobian(t, q) @ v + s.constraint_rates(t, q, v)[0]
                   for t, q, v in zip(res.t, res.q, res.v)])
    g_t = np.abs(g).max(axis=1) if g.size else np.zeros(res.t.size)
    gv_t = np.abs(gv).max(axis=1) if gv.size else np.zeros(res.t.size)
    rec = {k: v for k, v in record.items() if k != "result"}
    rec.update(t=res.t, out=out, status=res.status, message=res.message, t_fail=res.t_fail, drift_q_t=g_t,
               drift_v_t=gv_t, drift_q=float(g_t.max()) if g.size else float("nan"),
               drift_v=float(gv_t.max()) if gv.size else float("nan"))
    if "energy" in out and res.t.size:
        T = np.array([s.energy(t, q, v).kinetic for t, q, v in zip(res.t, res.q, res.v)])
        rec["energy_error_t"] = (out["energy"] - out["energy"][0]) / T.max()
        rec["energy_error"] = float(np.abs(rec["energy_error_t"]).max())
        L = out["angular_momentum_z"]
        rec["momentum_error"] = float(np.abs(L - L[0]).max() / abs(L[0]))
    return rec
