"""Why SQ2D/SQ3D need 56 Newton iterations on B1 where the chapter's Table 2 gives 49 (SQ3D: 55).

``python -m benchmarks.b1_newton_variants [--elements 8]`` solves B1 (chapter Sect. 5.1: ten uniform
load steps, full Newton, stop when ``max|r| / max|r_0| < 1e-8``) with a plain Newton loop and varies
one ingredient at a time -- the element (BE2D for comparison), the quadrature rules, the clamp, the
norm of the stopping rule, its tolerance, and the Newton start (the previous load step's solution, or
its linear extrapolation from the two previous steps) -- printing the iterations per load step, their
total and the tip error against chapter Eq. 113. The findings are in docs/newton_iterations.md.
"""
from __future__ import annotations

import argparse

import numpy as np
import scipy.sparse.linalg as spla

from ancfdae import Material, PointForce, RectangularSection
from ancfdae.models import BE2D, SQ2D, SQ3D, Beam

STEEL, SQUARE = Material(E=2.07e11, nu=0.3, rho=7800.0), RectangularSection(0.1)
REFERENCE = {"BE2D": np.array([-0.50853730436, 1.20723985455]),       # chapter Eq. 113
             "SQ": np.array([-0.50946471774, 1.20882282955])}


def cantilever(cls, n, supports="clamp", **options):
    """B1: 2 m steel cantilever, square 0.1 m, tip force 3 EI / L^2."""
    el = cls(STEEL, SQUARE, **options)
    F = 3 * STEEL.E * SQUARE.I3 / 4.0
    force = (0.0, F) if el.dim == 2 else (0.0, F, 0.0)
    return Beam(el, n, 2.0, supports={0: supports}, loads=[PointForce(force, node=-1)])


def newton_b1(beam, *, norm="max", tol=1e-8, start="previous", steps=10, max_iter=30):
    """Ten load steps of full Newton; returns (iterations per step, tip error)."""
    measure = (lambda r: np.abs(r).max()) if norm == "max" else np.linalg.norm
    q = beam.initial_state()[0].copy()
    z = np.zeros_like(q)
    history, per_step = [q.copy()], []
    try:
        for i in range(1, steps + 1):
            beam.load_factor = i / steps
            if start == "extrapolated" and len(history) >= 2:
                q = 2 * history[-1] - history[-2]
            r, J = beam.residual_jacobian(0.0, q, z, z)
            r0, k = measure(r), 0
            while k < max_iter:
                q = q + spla.spsolve(J.K.tocsc(), -r)
                k += 1
                r, J = beam.residual_jacobian(0.0, q, z, z)
                if measure(r) < tol * r0:
                    break
            per_step.append(k)
            history.append(q.copy())
    finally:
        beam.load_factor = 1.0
    ref = REFERENCE["BE2D" if isinstance(beam.element, BE2D) else "SQ"]
    return per_step, float(np.linalg.norm(beam.position(q, 2.0)[:2] - [2.0, 0.0] - ref))


def variants(n):
    """(label, beam factory, newton options) of every variant compared."""
    return [
        ("SQ2D, defaults", lambda: cantilever(SQ2D, n), {}),
        ("SQ3D, defaults", lambda: cantilever(SQ3D, n), {}),
        ("BE2D, defaults", lambda: cantilever(BE2D, n), {}),
        ("SQ2D, cross_section 2-pt Gauss", lambda: cantilever(SQ2D, n, quadrature={"cross_section": 2}), {}),
        ("SQ2D, shear 3-pt Gauss", lambda: cantilever(SQ2D, n, quadrature={"shear": 3}), {}),
        ("SQ2D, bending 3-pt Gauss", lambda: cantilever(SQ2D, n, quadrature={"bending": 3}), {}),
        ("SQ2D, axial 3-pt Gauss", lambda: cantilever(SQ2D, n, quadrature={"axial": 3}), {}),
        ("SQ2D, clamp leaves y_eta free", lambda: cantilever(SQ2D, n, supports=("x", "y", "x_eta")), {}),
        ("SQ2D, 2-norm", lambda: cantilever(SQ2D, n), {"norm": "2"}),
        ("SQ2D, tol 1e-7", lambda: cantilever(SQ2D, n), {"tol": 1e-7}),
        ("SQ2D, tol 1e-9", lambda: cantilever(SQ2D, n), {"tol": 1e-9}),
        ("SQ2D, extrapolated start", lambda: cantilever(SQ2D, n), {"start": "extrapolated"}),
        ("BE2D, extrapolated start", lambda: cantilever(BE2D, n), {"start": "extrapolated"}),
    ]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elements", type=int, default=8)
    args = parser.parse_args(argv)
    print(f"B1, {args.elements} elements")
    print(f"{'variant':34s} {'total':>5s}  per load step                  tip error (m)")
    for label, factory, options in variants(args.elements):
        per_step, err = newton_b1(factory(), **options)
        print(f"{label:34s} {sum(per_step):5d}  {' '.join(map(str, per_step)):30s} {err:.4e}")


if __name__ == "__main__":
    main()
