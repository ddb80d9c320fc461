"""Where the compiled index-3 steps of B5 and B6 spend their time (no peer).

``python -m benchmarks.index3_cost [--cases b5 b6] [--repeats 3]``

Per case and step (generalized-alpha rho_inf 0.9, Newton rtol 1e-8, as ``benchmarks.multibody_vs_exudyn``, on
``[0, t_end]``): Newton iterations and matrix refreshes per step, the CPU per step of a run that outputs only at the
end (the compiled steps, ``ancfdae.integrators._index3_steps``) and the CPU each output time adds (the run with the
benchmark's output period minus that one, per output: the driver, the tables, the reactions); then the dense LU and
one solve of the KKT matrix's size (``ancfdae.integrators._index3_steps_numba``). Process-CPU medians of
``--repeats`` interleaved runs.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import simulate
from ancfdae.integrators._index3_steps_numba import dense_lu, dense_solve
from ancfdae.studies._multibody_models import slider_crank, spinup

CASES = {"b5": dict(t_end=5.0, dt_out=0.02, steps=(2e-2, 1e-2, 5e-3, 2.5e-3)),
         "b6": dict(t_end=0.1, dt_out=1e-3, steps=(2e-4, 1e-4, 5e-5))}


def _run(system, h, t_end, t_eval):
    c0 = time.process_time()
    res = simulate(system, (0.0, t_end), "generalized-alpha", h=h, rho_inf=0.9, t_eval=t_eval, newton={"tol": 1e-8})
    return time.process_time() - c0, res


def _dense(N, repeats=200):
    rng = np.random.default_rng(0)
    A = rng.random((N, N)) + N * np.eye(N)
    piv = np.zeros(N, dtype=np.int64)
    LU = A.copy()
    dense_lu(LU, piv)
    b = rng.random(N)
    dense_solve(LU, piv, b.copy())
    c0 = time.process_time()
    for _ in range(repeats):
        LU[:] = A
        dense_lu(LU, piv)
    t_lu = (time.process_time() - c0) / repeats
    c0 = time.process_time()
    for _ in range(20 * repeats):
        dense_solve(LU, piv, b.copy())
    return t_lu, (time.process_time() - c0) / (20 * repeats)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", choices=tuple(CASES), default=list(CASES))
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args(argv)
    for case in a.cases:
        c = CASES[case]
        system = (spinup("BE2D", 8, w_s=4.0) if case == "b5" else slider_crank("BE2D", 8)).system
        t_end = c["t_end"]
        every = np.linspace(0.0, t_end, int(round(t_end / c["dt_out"])) + 1)
        _run(system, c["steps"][0], min(t_end, 20 * c["steps"][0]), [0.0, min(t_end, 20 * c["steps"][0])])  # JIT
        print(f"\n== {case.upper()}, [0, {t_end:g}] s, output every {c['dt_out']:g} s ({every.size - 1} outputs), "
              f"n + m = {system.n_dof + system.n_constraints}")
        for h in c["steps"]:
            ends, outs = [], []
            for _ in range(a.repeats):
                cpu_end, res = _run(system, h, t_end, [0.0, t_end])
                cpu_out, _ = _run(system, h, t_end, every)
                ends.append(cpu_end)
                outs.append(cpu_out)
            st, steps = res.stats, res.stats["steps"]
            e, o = float(np.median(ends)), float(np.median(outs))
            print(f"  h = {h:g}: {st['newton_iterations'] / steps:.2f} iterations and {st['jacobian_evals'] / steps:.3f} "
                  f"refreshes a step; {e / steps * 1e6:.1f} us a step (output at the end only), "
                  f"{(o - e) / (every.size - 1) * 1e6:.0f} us more per output time")
        N = system.n_dof + system.n_constraints
        t_lu, t_solve = _dense(N)
        print(f"  dense LU of {N} unknowns {t_lu * 1e6:.1f} us, one solve {t_solve * 1e6:.2f} us")


if __name__ == "__main__":
    main()
