"""What a point moment adds to a small model's step: the same beam with and without a tip moment.

``python -m benchmarks.moment_load [--elements 8 32] [--steps 400] [--repeats 5]``

A cantilever of BE2D (and of Cable3D) elements, clamped at node 0, tip force ``(0, -F)`` (Cable3D:
``(0, -F, 0)``) with or without a tip moment of the same size in F L; fixed-step runs of
``generalized-alpha`` and ``lobatto3`` from rest, ``h = 1e-4``. Printed per element type, mesh and
method: the median CPU milliseconds per step of the run with the moment and without (runs
interleaved in one process), and their ratio. The issue this benchmark belongs to measured
0.08 -> 0.50 ms per step (ratio 6) for BE2D with 8 elements, when the moment's generalised force
recomputed its shape functions in NumPy on every residual call.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import Material, PointForce, PointMoment, RectangularSection, simulate
from ancfdae.models import BE2D, Beam, Cable3D

MATERIAL = dict(E=2.1e11, nu=0.3, rho=7850.0)
SIDE, LENGTH = 0.02, 1.0
F = 50.0


def beam(element: str, n_elements: int, moment: bool) -> Beam:
    """The cantilever, with or without the tip moment."""
    mat, sec = Material(**MATERIAL), RectangularSection(SIDE)
    if element == "BE2D":
        el, force, mom = BE2D(mat, sec), (0.0, -F), F * LENGTH
    else:
        el, force, mom = Cable3D(mat, sec), (0.0, -F, 0.0), (0.0, 0.0, F * LENGTH)
    loads = [PointForce(force, node=-1)]
    if moment:
        loads.append(PointMoment(mom, node=-1))
    return Beam(el, n_elements=n_elements, length=LENGTH, supports={0: "clamp"}, loads=loads)


def per_step(model: Beam, method: str, steps: int, h: float) -> float:
    """CPU seconds per step of one run (the model built outside)."""
    t0 = time.process_time()
    res = simulate(model, (0.0, steps * h), method=method, h=h, t_eval=[steps * h])
    cpu = time.process_time() - t0
    if res.status != "success":
        raise RuntimeError(f"{method} on {model.element.name}: {res.message}")
    return cpu / steps


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, nargs="+", default=[8, 32])
    ap.add_argument("--types", nargs="+", default=["BE2D", "Cable3D"])
    ap.add_argument("--methods", nargs="+", default=["generalized-alpha", "lobatto3"])
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--h", type=float, default=1e-4)
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args(argv)
    print(f"{'element':8s} {'n_el':>5s} {'method':18s} {'with M ms/step':>15s} {'without':>9s} {'ratio':>6s}")
    for name in a.types:
        for n in a.elements:
            for method in a.methods:
                models = {m: beam(name, n, m) for m in (True, False)}
                for m in models.values():   # compile / warm up outside the timing
                    per_step(m, method, 5, a.h)
                times = {True: [], False: []}
                for _ in range(a.repeats):      # interleaved
                    for m, model in models.items():
                        times[m].append(per_step(model, method, a.steps, a.h))
                w, wo = np.median(times[True]), np.median(times[False])
                print(f"{name:8s} {n:5d} {method:18s} {1e3 * w:15.4f} {1e3 * wo:9.4f} {w / wo:6.2f}", flush=True)


if __name__ == "__main__":
    main()
