"""BE3D under IDA: director update after every step or only near the singular projection (Eq. 99).

``python -m benchmarks.be3d_ida_updates [--n 2] [--t-end 0.5] [--thresholds 0.9 0.5 0.2] [--rss-steps 0]``

Problem: B3 revision 2 -- free beam in space, L = 1 m, square a = 0.05 m, E = 1e5, nu = 0.3,
rho = 2500, straight along (0.6, 0.8, 0), moment f(t) (0.1, 0.05, 0.2) N m at B with the hat
f = t / 1.5 up to 1.5 s, 2 - t / 1.5 up to 3 s -- with ``--n`` BE3D elements ("projected" update).
For IDA (rtol ``--rtol``) with the update after every step, with ``update_below`` thresholds on the
sine between director and axis, and without update, it prints CPU seconds (process time), steps,
restarts and the largest distance of the tip B from a Lobatto IIIA-3 run (h = 1e-3, update after
every step). ``--rss-steps N`` adds a run of N IDA steps (threshold 0.5) that logs the resident
set size every N/10 steps.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import Material, PointMoment, PointSensor, RectangularSection, hat, simulate
from ancfdae.models import BE3D, Beam


def b3(n, **element_options):
    """B3 revision 2 with BE3D elements."""
    el = BE3D(Material(E=1e5, nu=0.3, rho=2500.0), RectangularSection(0.05), **element_options)
    return Beam(el, n, 1.0, start=(0.0, 0.0, 0.0), direction=(0.6, 0.8, 0.0),
                loads=[PointMoment((0.1, 0.05, 0.2), node=0, time=hat(1.5))])


def rss_mb():
    """Resident set size of this process in MB (Linux /proc)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS"):
                return int(line.split()[1]) / 1024
    return float("nan")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=2)
    p.add_argument("--t-end", type=float, default=0.5)
    p.add_argument("--rtol", type=float, default=1e-6)
    p.add_argument("--thresholds", type=float, nargs="+", default=[0.9, 0.5, 0.2])
    p.add_argument("--every-step", action="store_true", help="also run IDA with an update after every step")
    p.add_argument("--rss-steps", type=int, default=0)
    a = p.parse_args(argv)
    t_eval = np.linspace(0.0, a.t_end, int(round(a.t_end / 0.01)) + 1)
    mon = [PointSensor(s=0.0, name="tip")]
    c0 = time.process_time()
    ref = simulate(b3(a.n), (0, a.t_end), "lobatto3", h=1e-3, t_eval=t_eval, monitors=mon)
    print(f"lobatto3 h=1e-3: {time.process_time() - c0:.2f} s CPU, {ref.stats['steps']} steps, {ref.message}")
    tip_ref = ref.monitors["tip"]["position"]
    cases = ([("every step", {})] if a.every_step else []) + \
        [(f"update_below={x:g}", {"update_below": x}) for x in a.thresholds] + \
        [("no update", {"director_update": "none"})]
    for label, opts in cases:
        c0 = time.process_time()
        res = simulate(b3(a.n, **opts), (0, a.t_end), "ida", rtol=a.rtol, t_eval=t_eval, monitors=mon,
                       max_steps=200_000)
        cpu = time.process_time() - c0
        tip = res.monitors["tip"]["position"]
        dev = np.abs(tip - tip_ref[:len(tip)]).max()
        print(f"ida {label:20s}: {cpu:7.2f} s CPU, {res.stats['steps']:7d} steps, {res.stats['restarts']:6d} "
              f"restarts, max|tip - lobatto| = {dev:.2e}, {res.status}: {res.message}")
    if a.rss_steps:
        marks = []

        def log(t, q, v, acc, k=[0]):
            k[0] += 1
            if k[0] % max(1, a.rss_steps // 10) == 0:
                marks.append((k[0], t, rss_mb()))
        # max_step: at rest under a load that starts from zero IDA's first step scales with the span
        res = simulate(b3(a.n, update_below=0.5), (0, 1e4), "ida", rtol=a.rtol, t_eval=[0.0], max_step=0.01,
                       hooks=[log], max_steps=a.rss_steps)
        print(f"RSS over {a.rss_steps} IDA steps ({res.stats['restarts']} restarts, t reached "
              f"{res.t_fail if res.t_fail is not None else res.t[-1]:.4g} s):")
        for k, t, r in marks:
            print(f"  step {k:8d}  t = {t:10.4g} s  RSS = {r:8.1f} MB")


if __name__ == "__main__":
    main()
