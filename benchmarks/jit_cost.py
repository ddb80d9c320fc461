"""JIT first-call cost of the compiled element kernels, with a cold and a warm on-disk cache.

``python -m benchmarks.jit_cost [--runs 3]`` starts fresh interpreters with an empty numba cache
directory (cold: compile) and again with the directory the first one filled (warm: load), and prints
the median first-call time (wall clock and CPU time) of each compiled kernel -- BE2D forces,
Cable3D energy/forces/tangent, BE3D energy/forces/tangent, rotary inertia with its Jacobian blocks,
rotary kinetic energy, dead-moment load -- and their sum. The first kernel's time includes importing
numba. Timings only; nothing is asserted.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

_CHILD = r"""
import json, time
import numpy as np
from ancfdae import Material, RectangularSection
from ancfdae.models import BE2D, BE3D, Beam, Cable3D
steel, sec = Material(2.07e11, 0.3, 7800.0), RectangularSection(0.1, 0.05)
out = {}
def first(name, fn):
    t0, c0 = time.perf_counter(), time.process_time()
    fn()
    out[name] = (time.perf_counter() - t0, time.process_time() - c0)
for cls, s in ((BE2D, RectangularSection(0.1)), (Cable3D, RectangularSection(0.1)), (BE3D, sec)):
    beam = Beam(cls(steel, s), 2, 1.0)
    el, g, qe = beam.element, beam.geom, beam.q_ref[beam.edofs]
    first(cls.__name__ + " forces+tangent", lambda: el.internal_forces(g, qe, True))
    if cls is BE3D:
        first("BE3D inertia+blocks", lambda: el.inertia(g, qe, qe, qe, True))
        first("BE3D kinetic energy", lambda: el.kinetic_energy_extra(g, qe, qe))
        first("BE3D moment load", lambda: el.moment_load(g, qe[0], 0.3, np.ones(3), 0, True))
print(json.dumps(out))
"""


def run(cache_dir: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    res = subprocess.run([sys.executable, "-c", _CHILD], env=env, capture_output=True, text=True, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=3)
    args = p.parse_args(argv)
    cold, warm = [], []
    for _ in range(args.runs):
        with tempfile.TemporaryDirectory() as d:
            cold.append(run(d))
            warm.append(run(d))
    print(f"first-call time in seconds (wall / CPU of the process), median of {args.runs} fresh interpreters")
    print(f"{'kernel':>24} {'cold wall':>10} {'cold CPU':>9} {'warm wall':>10} {'warm CPU':>9}")

    def cells(k):
        med = lambda runs, i: np.median([r[k][i] if k != "all" else sum(x[i] for x in r.values()) for r in runs])
        return f"{med(cold, 0):10.2f} {med(cold, 1):9.2f} {med(warm, 0):10.3f} {med(warm, 1):9.3f}"
    for k in list(cold[0]) + ["all"]:
        print(f"{k:>24} {cells(k)}")


if __name__ == "__main__":
    main()
