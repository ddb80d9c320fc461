"""Kernel cost of the thin elements: BE2D, Cable3D, BE3D residual and Jacobian evaluations.

``python -m benchmarks.thin3d_kernels [--repeats 7] [--calls 50]`` prints, per element type and mesh,
the median (over repeats) time per call of the element kernels on a perturbed B1 cantilever state:
internal forces alone (the residual path), forces with tangent stiffness, and for BE3D the rotary
inertia force alone and with its three Jacobian blocks; then the whole-model ``residual`` and
``jacobian`` of the Beam. Timings only; nothing is asserted.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae.studies.cantilever import build


def _median_call(fn, calls: int, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        times.append((time.perf_counter() - t0) / calls)
    return float(np.median(times))


def case(name: str, n_elements: int, calls: int, repeats: int) -> dict:
    beam = build(name, n_elements)
    el, geom = beam.element, beam.geom
    rng = np.random.default_rng(0)
    q = beam.initial_state()[0] + 1e-3 * rng.standard_normal(beam.n_dof)
    v, a = rng.standard_normal((2, beam.n_dof))
    qe, ve, ae = beam.expand(q)[beam.edofs], beam._expand_v(v)[beam.edofs], beam._expand_v(a)[beam.edofs]
    out = {"f": _median_call(lambda: el.internal_forces(geom, qe, False), calls, repeats),
           "f+K": _median_call(lambda: el.internal_forces(geom, qe, True), calls, repeats),
           "residual": _median_call(lambda: beam.residual(0.0, q, v, a), calls, repeats),
           "jacobian": _median_call(lambda: beam.jacobian(0.0, q, v, a), calls, repeats)}
    if not el.mass_is_constant:
        out["inertia"] = _median_call(lambda: el.inertia(geom, qe, ve, ae, False), calls, repeats)
        out["inertia+jac"] = _median_call(lambda: el.inertia(geom, qe, ve, ae, True), calls, repeats)
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--calls", type=int, default=50)
    p.add_argument("--elements", nargs="*", default=["BE2D", "Cable3D", "BE3D"])
    p.add_argument("--meshes", nargs="*", type=int, default=[8, 32, 128])
    args = p.parse_args(argv)
    keys = ["f", "f+K", "inertia", "inertia+jac", "residual", "jacobian"]
    print(f"time per call in microseconds, median of {args.repeats} x {args.calls} calls")
    print(f"{'element':>8} {'n_el':>5} " + " ".join(f"{k:>12}" for k in keys))
    for name in args.elements:
        for n in args.meshes:
            r = case(name, n, args.calls, args.repeats)
            cells = " ".join(f"{r[k] * 1e6:12.0f}" if k in r else f"{'-':>12}" for k in keys)
            print(f"{name:>8} {n:5d} {cells}", flush=True)


if __name__ == "__main__":
    main()
