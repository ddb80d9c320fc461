"""SQ2D/SQ3D kernels: compiled (numba) against the NumPy reference -- kernel GFLOP/s and B1 static wall time.

``python -m benchmarks.sq_kernels [--repeats 7] [--elements 64] [--b1-meshes 8 16 32 64]`` prints

* the floating-point operations per element of each compiled SQ3D kernel (energy + force + tangent),
  counted by running the kernel's Python source on counting numbers (:mod:`benchmarks.flop_counter`,
  in a subprocess with ``NUMBA_DISABLE_JIT=1``): every ``+ - * /`` and ``sqrt`` the loop bodies
  execute ("flop/el", zeros included) and the useful ones ("useful/el": without products by 0 or
  +-1 and sums with 0);
* the median and the fastest time of one force + tangent evaluation of all elements with each kernel
  (the two kernels interleaved in one process) and the compiled kernel's rate in GFLOP/s of useful flops;
* B1 (the chapter's Sect. 5.1 cantilever, 10 load steps, tol 1e-8) with SQ3D at 8, 16, 32, 64
  elements: median wall time of the static solve with each kernel, interleaved.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

from ancfdae import Material, RectangularSection, solve_static
from ancfdae.models import SQ3D, Beam
from ancfdae.studies.cantilever import build

FORMULATIONS = ("structural", "continuum", "continuum-locking")


def _model(formulation, n_el, nodes=3):
    el = SQ3D(Material(2.07e11, 0.3, 7800.0), RectangularSection(0.1, 0.06, shear_factors=(0.83, 0.79)),
              formulation, nodes=nodes)
    beam = Beam(el, n_el, 2.0)
    q = beam.q_ref[beam.edofs] + 1e-3 * np.random.default_rng(0).standard_normal(beam.edofs.shape)
    return el, beam, q


def _count_child():
    """In a NUMBA_DISABLE_JIT=1 process: flops of one element per formulation, as JSON on stdout."""
    from ancfdae.models.jets import vector_numba as _vector_jet_numba
    from ancfdae.models.shear import kernels_numba as _sq_numba
    from ancfdae.models.shear import structural3d_numba as _sq3d_numba
    from . import flop_counter as fc
    fc.patch_numpy(_sq_numba, _sq3d_numba, _vector_jet_numba)
    out = {}
    for form in FORMULATIONS:
        el, beam, q = _model(form, 1)
        el.kernel = "numpy"                        # builds the geometry; the compiled arrays below
        nbg = beam.geom.get("_numba") or _geometry(el, beam)
        fn = _sq_numba.sq_structural if form == "structural" else _sq_numba.sq_continuum
        start, start_useful = fc.count(), fc.useful()
        fn(fc.counting(q), *[fc.counting(a) for a in nbg], 3, 2)
        n_pts = nbg[0].shape[1]
        out[form] = {"flops_per_element": fc.count() - start, "useful_per_element": fc.useful() - start_useful,
                     "points": int(n_pts)}
    print(json.dumps(out))


def _geometry(el, beam):
    from ancfdae.models.shear.kernels_numba import compiled_geometry
    return compiled_geometry(el.formulation, el.dim, len(el._terms), beam.geom)


def count_flops() -> dict:
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-m", "benchmarks.sq_kernels", "--count-child"], env=env,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def kernel_times(formulation, n_el, repeats):
    """Seconds of one internal_forces(tangent=True) call, NumPy and numba kernels interleaved.

    Each call is timed on its own (the compiled call is under a millisecond, shorter than a time
    slice of a shared machine, so its fastest runs are free of waiting for the CPU); the compiled
    kernel is timed 30 times per repeat. Returns (median, fastest) per kernel.
    """
    el, beam, q = _model(formulation, n_el)
    times = {"numpy": [], "numba": []}
    for kernel in times:                           # warm up (compile or load the cache)
        el.kernel = kernel
        el.internal_forces(beam.geom, q)
    for _ in range(repeats):
        for kernel in times:
            el.kernel = kernel
            for _ in range(1 if kernel == "numpy" else 30):
                t0 = time.perf_counter()
                el.internal_forces(beam.geom, q)
                times[kernel].append(time.perf_counter() - t0)
    return ({k: float(np.median(v)) for k, v in times.items()}, {k: float(np.min(v)) for k, v in times.items()})


def b1_times(n_el, repeats):
    """Median wall seconds of the B1 static solve with SQ3D, NumPy and numba kernels interleaved."""
    beams = {k: build("SQ3D", n_el, kernel=k) for k in ("numpy", "numba")}
    walls = {k: [] for k in beams}
    iters = {}
    for k, b in beams.items():
        solve_static(b, load_steps=10, tol=1e-8)  # warm up
    for _ in range(repeats):
        for k, b in beams.items():
            t0 = time.perf_counter()
            res = solve_static(b, load_steps=10, tol=1e-8, check_stability=False, max_strain=None)
            walls[k].append(time.perf_counter() - t0)
            iters[k] = res.iterations
    return ({k: float(np.median(v)) for k, v in walls.items()}, {k: float(np.min(v)) for k, v in walls.items()},
            iters)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--elements", type=int, default=64)
    p.add_argument("--b1-meshes", type=int, nargs="*", default=[8, 16, 32, 64],
                   help="B1 meshes (none: kernels only)")
    p.add_argument("--count-child", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.count_child:
        return _count_child()
    flops = count_flops()
    print(f"SQ3D kernels, {args.elements} elements, force + tangent, median of {args.repeats} "
          "(machine shared: see load average)")
    print("(median; in brackets the fastest run, the closest to an unloaded machine)")
    print(f"{'formulation':>18} {'pts/el':>6} {'flop/el':>9} {'useful/el':>9} {'numpy ms':>9} {'numba ms':>17} "
          f"{'speed-up':>8} {'GFLOP/s':>12}")
    for form in FORMULATIONS:
        t, tmin = kernel_times(form, args.elements, args.repeats)
        fl = flops[form]["useful_per_element"] * args.elements / 1e9
        print(f"{form:>18} {flops[form]['points']:>6} {flops[form]['flops_per_element']:>9} "
              f"{flops[form]['useful_per_element']:>9} "
              f"{t['numpy'] * 1e3:>9.3f} {t['numba'] * 1e3:>8.3f} ({tmin['numba'] * 1e3:>6.3f}) "
              f"{t['numpy'] / t['numba']:>8.1f} {fl / t['numba']:>5.2f} ({fl / tmin['numba']:>4.2f})")
    if args.b1_meshes:
        print(f"\nB1 static SQ3D (10 load steps, tol 1e-8), wall seconds, median (fastest) of {args.repeats}")
        print(f"{'n_el':>5} {'numpy s':>17} {'numba s':>17} {'speed-up':>8} {'its':>4}")
    for n in args.b1_meshes:
        w, wmin, its = b1_times(n, args.repeats)
        print(f"{n:>5} {w['numpy']:>8.4f} ({wmin['numpy']:>6.4f}) {w['numba']:>8.4f} ({wmin['numba']:>6.4f}) "
              f"{w['numpy'] / w['numba']:>8.2f} {its['numba']:>4}")
    print(f"load average: {os.getloadavg()}")


if __name__ == "__main__":
    main()
