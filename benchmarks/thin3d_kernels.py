"""Kernel cost of the thin elements, compiled (numba) against the NumPy reference, interleaved.

``python -m benchmarks.thin3d_kernels [--repeats 7] [--calls 50]`` prints, per element type and mesh and
for each ``kernel`` option, the median (over repeats, the two kernels alternating) CPU time per call of the
element kernels on a perturbed B1 cantilever state: internal forces alone (the residual path), forces with
tangent stiffness, and for BE3D the rotary inertia force alone and with its three Jacobian blocks; then the
whole-model ``residual`` and ``jacobian`` of the Beam; and the kernel times per element x quadrature point
(axial + bending points for the forces, inertia points for the inertia). Timings only; nothing is asserted.
"""
from __future__ import annotations

import argparse

import numpy as np

from ancfdae.studies.cantilever import build

from ._kernel_timing import KERNELS, interleaved_medians


def case(name: str, n_elements: int, calls: int, repeats: int) -> dict:
    """{kernel: {measure: median seconds per call}} for one element type and mesh."""
    beam = build(name, n_elements)
    el, geom = beam.element, beam.geom
    rng = np.random.default_rng(0)
    q = beam.initial_state()[0] + 1e-3 * rng.standard_normal(beam.n_dof)
    v, a = rng.standard_normal((2, beam.n_dof))
    qe, ve, ae = beam.expand(q)[beam.edofs], beam._expand_v(v)[beam.edofs], beam._expand_v(a)[beam.edofs]
    fns = {"f": lambda: el.internal_forces(geom, qe, False),
           "f+K": lambda: el.internal_forces(geom, qe, True),
           "residual": lambda: beam.residual(0.0, q, v, a),
           "jacobian": lambda: beam.jacobian(0.0, q, v, a)}
    if not el.mass_is_constant:
        fns["inertia"] = lambda: el.inertia(geom, qe, ve, ae, False)
        fns["inertia+jac"] = lambda: el.inertia(geom, qe, ve, ae, True)
    out = interleaved_medians(el, fns, calls, repeats)
    points = {"f": el.axial_points + el.bending_points}
    points["f+K"] = points["f"]
    if not el.mass_is_constant:
        points["inertia"] = points["inertia+jac"] = el.inertia_points
    for k in KERNELS:
        for m, n in points.items():
            out[k][m + " /el/pt"] = out[k][m] / (n_elements * n)
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--calls", type=int, default=50)
    p.add_argument("--elements", nargs="*", default=["BE2D", "Cable3D", "BE3D"])
    p.add_argument("--meshes", nargs="*", type=int, default=[8, 32, 128])
    args = p.parse_args(argv)
    keys = ["f", "f+K", "inertia", "inertia+jac", "residual", "jacobian"]
    per = ["f /el/pt", "f+K /el/pt", "inertia /el/pt", "inertia+jac /el/pt"]
    print(f"CPU time per call in microseconds, median of {args.repeats} x {args.calls} calls; "
          "the last four columns per element x quadrature point")
    print(f"{'element':>8} {'n_el':>5} {'kernel':>6} " + " ".join(f"{k:>11}" for k in keys)
          + " " + " ".join(f"{k.split()[0] + '/pt':>14}" for k in per))
    for name in args.elements:
        for n in args.meshes:
            r = case(name, n, args.calls, args.repeats)
            for kernel in KERNELS:
                rk = r[kernel]
                cells = " ".join(f"{rk[k] * 1e6:11.1f}" if k in rk else f"{'-':>11}" for k in keys)
                cells += " " + " ".join(f"{rk[k] * 1e6:14.3f}" if k in rk else f"{'-':>14}" for k in per)
                print(f"{name:>8} {n:5d} {kernel:>6} {cells}", flush=True)


if __name__ == "__main__":
    main()
