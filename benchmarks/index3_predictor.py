"""The Newmark family's predictor on B5 and B6: constant against extrapolated start (no peer).

``python -m benchmarks.index3_predictor [--cases b5 b6] [--repeats 3] [--t-end-b5 5] [--t-end-b6 0.5]``

Per case and step (generalized-alpha, rho_inf 0.9, Newton rtol 1e-8 as ``benchmarks.multibody_vs_exudyn``, output
at its periods): Newton iterations and matrix refreshes per step with ``predictor="constant"`` and
``"extrapolate"`` (:func:`ancfdae.integrators._alpha_index3.predictor`), the process CPU of each (median of
``--repeats`` interleaved runs, the compiled steps) and the largest difference of the two solutions' ``q``.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import simulate
from ancfdae.studies._multibody_models import slider_crank, spinup

CASES = {"b5": dict(dt_out=0.02, steps=(2e-2, 1e-2, 5e-3, 2.5e-3)), "b6": dict(dt_out=1e-3, steps=(2e-4, 1e-4, 5e-5))}
PREDICTORS = ("constant", "extrapolate")


def _run(system, h, t_end, dt_out, predictor):
    t_eval = np.linspace(0.0, t_end, int(round(t_end / dt_out)) + 1)
    c0 = time.process_time()
    res = simulate(system, (0.0, t_end), "generalized-alpha", h=h, rho_inf=0.9, t_eval=t_eval,
                   newton={"tol": 1e-8}, predictor=predictor)
    cpu = time.process_time() - c0
    if res.status != "success":
        raise RuntimeError(f"h = {h:g}, predictor {predictor}: {res.message}")
    return cpu, res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", choices=tuple(CASES), default=list(CASES))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--t-end-b5", type=float, default=5.0)
    ap.add_argument("--t-end-b6", type=float, default=0.5)
    a = ap.parse_args(argv)
    for case in a.cases:
        c = CASES[case]
        system = (spinup("BE2D", 8, w_s=4.0) if case == "b5" else slider_crank("BE2D", 8)).system
        t_end = a.t_end_b5 if case == "b5" else a.t_end_b6
        print(f"\n== {case.upper()}, 8 BE2D, [0, {t_end:g}] s (its, refreshes: per step; CPU: median of {a.repeats})")
        print(f"{'h':>9} {'predictor':>12} {'its':>6} {'refr':>6} {'CPU s':>8} {'ratio':>6} {'max |dq| m':>11}")
        for h in c["steps"]:
            _run(system, h, min(t_end, 20 * h), c["dt_out"] if 20 * h >= c["dt_out"] else 20 * h, "constant")  # compile
            cpu = {p: [] for p in PREDICTORS}
            res = {}
            for _ in range(a.repeats):
                for p in PREDICTORS:
                    t, res[p] = _run(system, h, t_end, c["dt_out"], p)
                    cpu[p].append(t)
            dq = np.abs(res["extrapolate"].q - res["constant"].q).max()
            base = np.median(cpu["constant"])
            for p in PREDICTORS:
                st = res[p].stats
                print(f"{h:9.2e} {p:>12} {st['newton_iterations'] / st['steps']:6.2f} "
                      f"{st['jacobian_evals'] / st['steps']:6.3f} {np.median(cpu[p]):8.3f} "
                      f"{np.median(cpu[p]) / base:6.2f} {dq if p == 'extrapolate' else 0.0:11.1e}", flush=True)


if __name__ == "__main__":
    main()
