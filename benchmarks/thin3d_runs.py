"""Whole runs with the thin spatial elements, compiled kernels against the NumPy reference, interleaved.

``python -m benchmarks.thin3d_runs [--repeats 5] [--dyn-repeats 3]`` prints median wall and CPU times of

* B1 static (10 load steps, full Newton, tol 1e-8) with Cable3D and BE3D at 16 and 64 elements, and
* the B3 (revision 2: moment (0.1, 0.05, 0.2) N m, hat ramp to 3 s) BE3D run with 8 elements,
  Lobatto IIIA-3, h = 1e-3, over 1 s (modified Newton, tol 1e-8, projected director update),

for ``kernel="numpy"`` and ``kernel="numba"`` alternating, with the ratio and the largest difference of
the results between the kernels. Timings only; nothing is asserted. JIT compilation happens in an untimed
warm-up.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import solve_static
from ancfdae.studies._flying import b3_beam, simulate_case
from ancfdae.studies.cantilever import L, build

KERNELS = ("numpy", "numba")
B3_REV2_SCALE = 0.25          # revision 2 moment = 0.25 (0.4, 0.2, 0.8) N m


def static_case(name: str, n: int, repeats: int) -> dict:
    beams = {k: build(name, n, kernel=k) for k in KERNELS}
    times, cpus, tips = {k: [] for k in KERNELS}, {k: [] for k in KERNELS}, {}
    for k, beam in beams.items():          # warm-up (compiles)
        solve_static(beam, load_steps=1, tol=1e-8)
    for _ in range(repeats):
        for k, beam in beams.items():
            t0, c0 = time.perf_counter(), time.process_time()
            res = solve_static(beam, load_steps=10, tol=1e-8, check_stability=False, max_strain=None)
            times[k].append(time.perf_counter() - t0)
            cpus[k].append(time.process_time() - c0)
            tips[k] = (beam.position(res.q, L), res.iterations)
    diff = float(np.abs(tips["numba"][0] - tips["numpy"][0]).max())
    return {k: float(np.median(v)) for k, v in times.items()} | {
        "cpu " + k: float(np.median(v)) for k, v in cpus.items()} | {
        "iterations": (tips["numpy"][1], tips["numba"][1]), "tip_diff": diff}


def dynamic_case(n: int, t_end: float, h: float, repeats: int) -> dict:
    times, cpus, tips, stats = {k: [] for k in KERNELS}, {k: [] for k in KERNELS}, {}, {}
    for k in KERNELS:                      # warm-up (compiles)
        simulate_case(b3_beam("BE3D", n, scale=B3_REV2_SCALE, kernel=k), 10 * h, h=h, energy=False)
    for _ in range(repeats):
        for k in KERNELS:
            beam = b3_beam("BE3D", n, scale=B3_REV2_SCALE, kernel=k)
            rec = simulate_case(beam, t_end, h=h, energy=False)
            times[k].append(rec["wall"])
            cpus[k].append(rec["cpu"])
            tips[k], stats[k] = rec["tip"], rec["stats"]
    diff = float(np.abs(tips["numba"] - tips["numpy"]).max())
    return {k: float(np.median(v)) for k, v in times.items()} | {
        "cpu " + k: float(np.median(v)) for k, v in cpus.items()} | {"tip_diff": diff, "stats": stats["numba"]}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--dyn-repeats", type=int, default=3)
    p.add_argument("--meshes", nargs="*", type=int, default=[16, 64])
    p.add_argument("--skip-static", action="store_true")
    p.add_argument("--skip-dynamic", action="store_true")
    args = p.parse_args(argv)
    if not args.skip_static:
        print(f"B1 static, median wall (CPU) time of {args.repeats} solves (ms)")
        print(f"{'element':>8} {'n_el':>5} {'numpy':>17} {'numba':>17} {'ratio wall/CPU':>14} {'iters':>9} "
              f"{'|tip diff|':>10}")
        for name in ("Cable3D", "BE3D"):
            for n in args.meshes:
                r = static_case(name, n, args.repeats)
                print(f"{name:>8} {n:5d} {r['numpy'] * 1e3:8.1f} ({r['cpu numpy'] * 1e3:6.1f}) "
                      f"{r['numba'] * 1e3:8.1f} ({r['cpu numba'] * 1e3:6.1f}) "
                      f"{r['numba'] / r['numpy']:7.3f}/{r['cpu numba'] / r['cpu numpy']:6.3f} "
                      f"{str(r['iterations']):>9} {r['tip_diff']:10.2e}", flush=True)
    if not args.skip_dynamic:
        r = dynamic_case(8, 1.0, 1e-3, args.dyn_repeats)
        print(f"B3 rev. 2, BE3D 8 el, lobatto3, h = 1e-3, 1 s: median wall of {args.dyn_repeats} runs: "
              f"numpy {r['numpy']:.2f} s (CPU {r['cpu numpy']:.2f} s), "
              f"numba {r['numba']:.2f} s (CPU {r['cpu numba']:.2f} s), "
              f"ratio wall {r['numba'] / r['numpy']:.3f}, CPU {r['cpu numba'] / r['cpu numpy']:.3f}, "
              f"|tip diff| {r['tip_diff']:.2e}; stats {r['stats']}")


if __name__ == "__main__":
    main()
