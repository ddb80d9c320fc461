"""Cost of BE2D's ``potential`` (strain energy + gravity), compiled (numba) against the NumPy reference, interleaved.

``python -m benchmarks.be2d_potential [--repeats 7] [--calls 2000] [--meshes 4 8 64]`` prints, per mesh of the
flying beam B2 (free, BE2D structural) and each ``kernel`` option, the median (over repeats, the two kernels
alternating) CPU time per call of ``beam.potential(t, q)`` on a perturbed state, the call energy-collocation's
energy balance makes once per step: with ``kernel="numba"`` one compiled pass reading the beam's gather
(:mod:`ancfdae.models.thin.be2d_energy_numba`), with ``"numpy"`` the reference's array operations. Also the
per-element entry point ``element.strain_energy`` on element coordinates. Timings only; nothing is asserted.
"""
from __future__ import annotations

import argparse

import numpy as np

from ancfdae.studies._flying import b2_beam

from ._kernel_timing import interleaved_medians


def case(n_elements: int, calls: int, repeats: int) -> dict:
    """{kernel: {measure: median seconds per call}} on B2 with ``n_elements`` BE2D."""
    beam = b2_beam("BE2D", n_elements)
    el = beam.element
    q = beam.initial_state()[0] + 1e-3 * np.random.default_rng(0).standard_normal(beam.n_dof)
    qe = beam._element_q(q)
    fns = {"potential": lambda: beam.potential(0.0, q), "strain_energy": lambda: el.strain_energy(beam.geom, qe)}
    return interleaved_medians(el, fns, calls, repeats)


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--calls", type=int, default=2000)
    p.add_argument("--meshes", nargs="*", type=int, default=[4, 8, 64])
    args = p.parse_args(argv)
    print(f"CPU time per call in microseconds, median of {args.repeats} x {args.calls} calls (kernels alternating)")
    print(f"{'n_el':>5} {'measure':>14} {'numpy':>9} {'numba':>9} {'ratio':>7}")
    for n in args.meshes:
        out = case(n, args.calls, args.repeats)
        for m in out["numpy"]:
            a, b = out["numpy"][m] * 1e6, out["numba"][m] * 1e6
            print(f"{n:>5} {m:>14} {a:>9.2f} {b:>9.2f} {a / b:>7.1f}")


if __name__ == "__main__":
    main()
