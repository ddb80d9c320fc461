"""Same method, same model, same step: our generalized-alpha and trapezoidal rule against Exudyn's, per step.

``python -m benchmarks.same_method [--elements 25 100 400] [--t-end 0.05] [--h 1e-4] [--tol 1e-6] [--repeats 3]``

The hinged flexible pendulum of Exudyn's flexiblePendulumANCF (``benchmarks.dynamics``: BE2D against
ObjectANCFCable2D, 25/100/400 elements), the same constant step ``h`` and the same Newton tolerance
``tol`` (ours: relative max-norm residual test, modified Newton; Exudyn: its relative and absolute
tolerance, modified Newton). Pairs: ``generalized-alpha`` (rho_inf 0.8) with Exudyn's generalized-alpha,
``newmark`` (beta 1/4, gamma 1/2) with Exudyn's trapezoidal rule (TrapezoidalIndex2). Runs of both
codes interleaved in one process; printed: median CPU microseconds per step of each, Newton
iterations per step of each, our CPU per Newton iteration, and the ratio of CPU per step
(ours / Exudyn; goal of issue 22: <= 0.5). The model is built outside the timed part. Ours runs with one output
time (``t_eval=[t_end]``), so the Newmark family takes its steps in one compiled call between outputs
(``ancfdae.integrators._alpha_steps``); Exudyn records its tip sensor every 1e-3 s.

At 400 elements Exudyn's generalized-alpha at Newton tolerance 1e-6 slows to a crawl after about
0.005 s (its adaptive step; 0.0075 s did not finish in 100 s of CPU) while its trapezoidal rule finishes;
at tolerance 1e-4 both finish the 0.05 s. So at 400 elements compare generalized-alpha with
``--tol 1e-4`` (the same tolerance on both sides), the trapezoidal rule at the default 1e-6 too.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import simulate

from .dynamics import pendulum

try:
    from . import _exudyn_peer as peer
except ImportError:  # pragma: no cover
    peer = None

PAIRS = {"generalized-alpha": ({"rho_inf": 0.8}, "generalized_alpha"), "newmark": ({}, "trapezoidal")}


def ours(method, n_elements, t_end, h, tol):
    """CPU seconds per step, Newton iterations per step and CPU per iteration of one run."""
    beam = pendulum(n_elements)
    opts = dict(PAIRS[method][0], h=h, newton={"tol": tol})
    t0 = time.process_time()
    res = simulate(beam, (0.0, t_end), method, t_eval=[t_end], **opts)
    cpu = time.process_time() - t0
    if res.status != "success":
        raise RuntimeError(f"ancfdae {method} with {n_elements} elements failed: {res.message}")
    st = res.stats
    return cpu / st["steps"], st["newton_iterations"] / st["steps"], cpu / max(st["newton_iterations"], 1)


def exudyn(integrator, n_elements, t_end, h, tol):
    """Exudyn's CPU seconds per step and Newton iterations per step (None without Exudyn)."""
    if peer is None or not peer.available():
        return None
    r = peer.pendulum(n_elements, integrator=integrator, t_end=t_end, h=h, repeats=1, newton_tol=tol)
    return r["cpu"] / r["steps"], r["newton_iterations_per_step"]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, nargs="+", default=[25, 100, 400])
    ap.add_argument("--methods", nargs="+", default=list(PAIRS), choices=list(PAIRS))
    ap.add_argument("--t-end", type=float, default=0.05)
    ap.add_argument("--h", type=float, default=1e-4)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args(argv)
    print(f"hinged flexible pendulum, t_end {a.t_end} s, h {a.h} s, Newton tol {a.tol}")
    print(f"{'method':18s} {'n_el':>5s} {'ours us/step':>13s} {'it/step':>8s} {'us/it':>7s} "
          f"{'Exudyn us/step':>15s} {'it/step':>8s} {'ratio':>6s}")
    for n in a.elements:
        for method in a.methods:
            ours(method, n, 10 * a.h, a.h, a.tol)      # compile / load caches outside the timing
            mine, theirs = [], []
            for _ in range(a.repeats):                 # interleaved
                mine.append(ours(method, n, a.t_end, a.h, a.tol))
                ex = exudyn(PAIRS[method][1], n, a.t_end, a.h, a.tol)
                if ex is not None:
                    theirs.append(ex)
            per_step, it, per_it = (float(np.median([m[i] for m in mine])) for i in range(3))
            line = f"{method:18s} {n:5d} {1e6 * per_step:13.1f} {it:8.2f} {1e6 * per_it:7.1f}"
            if theirs:
                ex_step, ex_it = (float(np.median([e[i] for e in theirs])) for i in range(2))
                ratio = float(np.median([m[0] / e[0] for m, e in zip(mine, theirs)]))
                line += f" {1e6 * ex_step:15.1f} {ex_it:8.2f} {ratio:6.2f}"
            print(line, flush=True)


if __name__ == "__main__":
    main()
