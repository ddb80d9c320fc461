"""Where the compiled index-3 steps of B5 and B6 spend their time (no peer).

``python -m benchmarks.index3_cost [--cases b5 b6] [--repeats 3] [--contraction 0.3 0.03] [--t-end-b6 0.5]``

Per case, step and refresh threshold (generalized-alpha rho_inf 0.9, Newton rtol 1e-8, as
``benchmarks.multibody_vs_exudyn``, on ``[0, t_end]``; ``--contraction``: modified Newton's refresh thresholds to
compare, interleaved): Newton iterations and matrix refreshes per step, the CPU per step of a run that outputs only
at the end (the compiled steps, ``ancfdae.integrators._index3_steps``) and the CPU each output time adds (the run
with the benchmark's output period minus that one, per output: the driver, the tables, the reactions); then the
pieces of one iteration and of one refresh as compiled calls on the state at the run's end (the residual, the solve
with the band factors; the KKT fill, of which the beam's fused tangent, the band LU; ``SystemArrays.kkt``) and the
reactions at an output time. Process-CPU medians of ``--repeats`` interleaved runs; the pieces: best of 7 rounds of
2000 calls.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from numba import njit

from ancfdae import simulate
from ancfdae.integrators._alpha_index3 import mass_scale
from ancfdae.integrators import _index3_kkt_numba as kn, _index3_steps_numba as sn
from ancfdae.integrators._linsolve_numba import band_factor
from ancfdae.models.thin.be2d_numba import be2d_fused
from ancfdae.studies._multibody_models import slider_crank, spinup

CASES = {"b5": dict(t_end=5.0, dt_out=0.02, steps=(2e-2, 1e-2, 5e-3, 2.5e-3)),
         "b6": dict(t_end=0.1, dt_out=1e-3, steps=(2e-4, 1e-4, 5e-5))}


def _run(system, h, t_end, t_eval, contraction):
    c0 = time.process_time()
    res = simulate(system, (0.0, t_end), "generalized-alpha", h=h, rho_inf=0.9, t_eval=t_eval,
                   newton={"tol": 1e-8, "contraction": contraction})
    return time.process_time() - c0, res


@njit
def _pieces_loop(which, reps, AB, AB0, piv, x, q, s, sm, W3, ext, cons, rigid, beam, eargs, kkt):
    """``reps`` calls of one piece (``which``: residual, solve, the beam's fused tangent, KKT fill, band LU,
    reactions) on the state ``x, q``."""
    n, m = q.size, x.size - q.size
    nb, w = beam[1], W3[0]
    rbuf, kbuf = np.empty(nb + 1), np.empty(beam[6].size + 1)
    r, d, b, zero = np.empty(n + m), np.empty(n + m), np.empty(n + m), np.zeros(n)
    work = (np.empty(n), np.empty(n), np.empty(n), np.empty(m), np.empty(m), np.empty(n), np.empty(n), np.empty(n))
    lam_w, gdata, a_out, lam_out = np.empty(m), np.empty(cons[14].size), np.empty(n), np.empty(m)
    mwork = kn.multiplier_work(n, m, nb, AB.shape[1], cons[14].size)
    for _ in range(reps):
        if which == 0:
            sn._residual(be2d_fused, x, r, n, m, q, zero, s, sm, w, ext, 1.0, cons, rigid, beam, eargs,
                         rbuf, kbuf, work)
        elif which == 1:
            kn.kkt_solve(AB, piv, kkt, x, d, b)
        elif which == 2:
            be2d_fused(q[beam[0]:beam[0] + nb], beam[2], beam[3], beam[4], beam[5], True, rbuf, kbuf, *eargs)
        elif which == 3:
            kn.kkt_fill(be2d_fused, AB0, x, q, n, m, s, sm, w, cons, rigid, beam, eargs, rbuf, kbuf, kkt, lam_w, gdata)
        elif which == 4:
            AB[:, :] = AB0
            band_factor(AB, kkt[1], kkt[2], piv)
        elif which == 5:
            AB[:, :] = AB0
        else:
            kn.system_multipliers(be2d_fused, W3, ext, q, zero, a_out, lam_out, cons, rigid, beam, eargs, 1.0, kkt,
                                  mwork, np.empty(0))


def _best(which, *args):
    _pieces_loop(which, 2, *args)
    best = np.inf
    for _ in range(7):
        c0 = time.process_time()
        _pieces_loop(which, 2000, *args)
        best = min(best, (time.process_time() - c0) / 2000)
    return best * 1e6


def _pieces(system, res, h):
    """Microseconds of the pieces of :func:`_pieces_loop` (compiled, at the run's end, the step's coefficients of
    generalized-alpha rho_inf 0.9 at ``h``) and the band widths."""
    a = system.compiled_arrays
    n, m = system.n_dof, system.n_constraints
    q, lam, t = np.asarray(res.q)[-1].copy(), np.asarray(res.lam)[-1], float(res.t[-1])
    W3, ext = a.weights(np.array([t]), True)[0], a.external(np.array([t]))[0]
    rho = 0.9   # generalized-alpha's coefficients, as the run's
    am, af = (2 * rho - 1) / (rho + 1), rho / (rho + 1)
    beta = 0.25 * (1 - am + af) ** 2
    s = (1 - am) / ((1 - af) * beta * h * h)
    sm = s * mass_scale(system.mass(q))
    kl, ku = a.kkt[1:3]
    AB, piv = np.zeros((n + m, 2 * kl + ku + 1)), np.zeros(3 * (n + m), dtype=np.int64)
    x = np.concatenate([np.zeros(n), lam / sm])
    args = (AB, AB.copy(), piv, x, q, s, sm, W3, ext, a.cons, a.rigid, a.beam, a.element_args, a.kkt)
    _pieces_loop(3, 1, *args)                  # the KKT matrix into AB0,
    _pieces_loop(4, 1, *args)                  # its factors into AB, piv
    resid, solve, tangent, fill, lu, copy, reactions = (_best(k, *args) for k in range(7))
    return resid, solve, tangent, fill, lu - copy, reactions, kl, ku


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", choices=tuple(CASES), default=list(CASES))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--contraction", nargs="+", type=float, default=[None],
                    help="refresh thresholds to compare (default: the method's own)")
    ap.add_argument("--t-end-b6", type=float, default=CASES["b6"]["t_end"])
    a = ap.parse_args(argv)
    for case in a.cases:
        c = CASES[case]
        system = (spinup("BE2D", 8, w_s=4.0) if case == "b5" else slider_crank("BE2D", 8)).system
        t_end = a.t_end_b6 if case == "b6" else c["t_end"]
        every = np.linspace(0.0, t_end, int(round(t_end / c["dt_out"])) + 1)
        _, res = _run(system, c["steps"][0], min(t_end, 20 * c["steps"][0]), [0.0, min(t_end, 20 * c["steps"][0])],
                      a.contraction[0])   # JIT
        print(f"\n== {case.upper()}, [0, {t_end:g}] s, output every {c['dt_out']:g} s ({every.size - 1} outputs), "
              f"n + m = {system.n_dof + system.n_constraints}")
        for h in c["steps"]:
            ends, outs, last = {k: [] for k in a.contraction}, {k: [] for k in a.contraction}, {}
            for _ in range(a.repeats):
                for k in a.contraction:
                    cpu_end, last[k] = _run(system, h, t_end, [0.0, t_end], k)
                    cpu_out, _ = _run(system, h, t_end, every, k)
                    ends[k].append(cpu_end)
                    outs[k].append(cpu_out)
            for k in a.contraction:
                res = last[k]
                st, steps = res.stats, res.stats["steps"]
                e, o = float(np.median(ends[k])), float(np.median(outs[k]))
                print(f"  h = {h:g}, contraction {res.options['newton']['contraction']:g}: "
                      f"{st['newton_iterations'] / steps:.2f} iterations and {st['jacobian_evals'] / steps:.3f} "
                      f"refreshes a step; {e / steps * 1e6:.1f} us a step (output at the end only), "
                      f"{(o - e) / (every.size - 1) * 1e6:.0f} us more per output time", flush=True)
        resid, solve, tangent, fill, lu, reactions, kl, ku = _pieces(system, res, c["steps"][-1])
        print(f"  one iteration: residual {resid:.2f} us, solve {solve:.2f} us; one refresh: KKT fill {fill:.2f} us "
              f"(of which the beam's fused tangent {tangent:.2f} us), band LU {lu:.2f} us (band order: {kl} sub-, {ku} "
              f"super-diagonals); reactions at an output time {reactions:.2f} us")


if __name__ == "__main__":
    main()
