"""SQ3D dynamics cost against the number of elements: is it linear, and how often is the Jacobian refreshed?

``python -m benchmarks.sq3d_scaling [--elements 64 256 1024 4096] [--h 1e-4] [--steps 50] [--predictor constant]
[--contraction 0.3]``

The free-flying beam of :mod:`benchmarks.sq3d_dynamics` (same data and initial velocity) with Lobatto
IIIA-3, modified Newton at tolerance 1e-6, for a fixed number of steps. Printed per mesh: CPU per step
and per element (process time, model built untimed), Newton iterations, Jacobian evaluations and
factorisations per step, failed solves. Linear cost means a flat CPU per step and element.
"""
from __future__ import annotations

import argparse
import time

from ancfdae import Material, RectangularSection, simulate
from ancfdae.integrators.lobatto import LobattoIIIA
from ancfdae.models import SQ3D, Beam

from .sq3d_dynamics import MATERIAL, SIDE, _v0


def run(n, h, steps, predictor, contraction=0.3, tol=1e-6):
    """One run; returns (cpu seconds, status, stats dict)."""
    beam = Beam(SQ3D(Material(**MATERIAL), RectangularSection(SIDE)), n_elements=n, length=1.0,
                initial_velocity=lambda p: _v0(p[:, 0]))
    stepper = LobattoIIIA(beam, h, 3, newton={"tol": tol, "contraction": contraction},
                          predictor=predictor)
    c0 = time.process_time()
    res = simulate(beam, (0.0, steps * h), stepper)
    return time.process_time() - c0, res.status, res.stats


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, nargs="+", default=[64, 256, 1024, 4096])
    ap.add_argument("--h", type=float, default=1e-4)
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--predictor", default="constant", choices=["constant", "extrapolate"])
    ap.add_argument("--contraction", type=float, default=0.3, help="modified Newton's refresh rate")
    a = ap.parse_args(argv)
    print(f"CPU = process time; Lobatto IIIA-3, h = {a.h:g}, {a.steps} steps, predictor {a.predictor}, "
          f"refresh above rate {a.contraction:g}")
    print(f"{'el':>6} {'status':>8} {'us/step/el':>11} {'iter/step':>10} {'jac/step':>9} {'fact/step':>10} "
          f"{'failed':>7}")
    for n in a.elements:
        cpu, status, s = run(n, a.h, a.steps, a.predictor, a.contraction)
        k = max(s["steps"], 1)
        print(f"{n:>6} {status:>8} {cpu / k / n * 1e6:>11.1f} {s['newton_iterations'] / k:>10.2f} "
              f"{s['jacobian_evals'] / k:>9.2f} {s['factorizations'] / k:>10.2f} {s['failed_solves']:>7}",
              flush=True)


if __name__ == "__main__":
    main()
