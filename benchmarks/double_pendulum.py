"""The double pendulum of issue 18: two beams pinned to the ground and to each other, released horizontally.

``python -m benchmarks.double_pendulum [--span 2] [--steps 4e-3 2e-3 1e-3 5e-4] [--methods ...] [--spatial | --toy]``

Two 1 m beams of 4 elements each (BE2D; ``--spatial``: Cable3D with a sideways push on the first beam),
E = 1 GPa, rho = 1000 kg/m^3, square section 20 mm (EA = 4e5 N: axial modes unresolved at every step
used, bending ~20 Hz), gravity, joined by ``Spherical`` joints. Per method and step size: the largest
position and velocity drift at the step ends (ConstraintMonitor), the largest energy error relative to
the energy scale (EnergyMonitor), process-CPU time, Newton iterations per step; then the self-convergence
orders (differences of successive halvings at the end time) of q, of the multipliers recomputed from
(q, v) (Result.lam) and of the method's own multipliers, and the largest difference between the methods
at the finest step. ``--toy``: the point-mass double pendulum of the test suite
(``tests/support/pendulum_toy.py``: smooth, no fast modes, quadratic constraints), where orders read cleanly.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import ConstraintMonitor, EnergyMonitor, Gravity, Material, RectangularSection, System
from ancfdae.integrators import EnergyMomentum, GeneralizedAlpha, HHTAlpha, Newmark
from ancfdae.joints import Spherical
from ancfdae.models import BE2D, Beam, Cable3D

METHODS = {"generalized-alpha": (GeneralizedAlpha, {"rho_inf": 0.8}), "hht": (HHTAlpha, {"alpha": 0.05}),
           "newmark": (Newmark, {}), "energy-momentum": (EnergyMomentum, {})}


def pendulum(spatial: bool = False) -> System:
    """The two beams and their joints."""
    mat, sec = Material(E=1e9, nu=0.3, rho=1000.0), RectangularSection(0.02)
    if spatial:
        g = Gravity((0.0, -9.81, 0.0))
        b1 = Beam(Cable3D(mat, sec), 4, 1.0, loads=[g],
                  initial_velocity=lambda x: np.tile([0.0, 0.0, 0.5], (len(x), 1)))
        b2 = Beam(Cable3D(mat, sec), 4, 1.0, start=(1.0, 0.0, 0.0), loads=[g])
    else:
        g = Gravity((0.0, -9.81))
        b1 = Beam(BE2D(mat, sec), 4, 1.0, loads=[g])
        b2 = Beam(BE2D(mat, sec), 4, 1.0, start=(1.0, 0.0), loads=[g])
    return System([b1, b2], [Spherical("ground", (b1, 0)), Spherical((b1, -1), (b2, 0))])


def run(model, method, h, span):
    """One run: (end q, KKT lam, own lam, row of the table)."""
    cls, kw = METHODS[method]
    st = cls(model, h, **kw)
    t0 = time.process_time()
    res = st.run((0.0, span), t_eval=np.linspace(0.0, span, 11), monitors=[EnergyMonitor(), ConstraintMonitor()])
    cpu = time.process_time() - t0
    if not res.success:
        return None, None, None, f"{method:18s} h={h:8.1e}  FAILED: {res.message}"
    c, e = res.monitors["constraints"], res.monitors["energy"]
    row = (f"{method:18s} h={h:8.1e}  max|g|={c['max_position']:8.1e}  max|Gv|={c['max_velocity']:8.1e}  "
           f"energy={e['relative_drift']:8.1e}  cpu={cpu:7.2f} s  it/step={res.stats['newton_iterations'] / res.stats['steps']:5.2f}")
    return res.q[-1], res.lam[-1], st.lam.copy(), row


def orders(values, steps):
    """Slopes of log|x_h - x_{h/2}| against log h."""
    d = [float(np.max(np.abs(a - b))) for a, b in zip(values, values[1:])]
    return d, [float(x) for x in np.diff(np.log(d)) / np.diff(np.log(steps[1:]))]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--span", type=float, default=2.0)
    ap.add_argument("--steps", type=float, nargs="+", default=[4e-3, 2e-3, 1e-3, 5e-4])
    ap.add_argument("--methods", nargs="+", default=list(METHODS))
    ap.add_argument("--spatial", action="store_true")
    ap.add_argument("--toy", action="store_true")
    args = ap.parse_args(argv)
    if args.toy:
        import sys   # noqa: PLC0415 - the toy lives with the tests
        from pathlib import Path  # noqa: PLC0415
        sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
        from support.pendulum_toy import PointPendulum  # noqa: PLC0415
        model = PointPendulum()
    else:
        model = pendulum(args.spatial)
    finest = {}
    for method in args.methods:
        runs = []
        for h in args.steps:
            q, lam, own, row = run(model, method, h, args.span)
            print(row, flush=True)
            if q is None:
                break
            runs.append((q, lam, own))
        if len(runs) == len(args.steps) and len(runs) >= 3:
            for k, name in enumerate(("q", "lam (KKT)", "lam (own)")):
                d, p = orders([r[k] for r in runs], args.steps)
                print(f"  {name:10s} differences {' '.join(f'{x:8.1e}' for x in d)}   orders "
                      f"{' '.join(f'{x:5.2f}' for x in p)}", flush=True)
        if runs:
            finest[method] = runs[-1]
    names = list(finest)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            print(f"finest step: |q_{a} - q_{b}| = {np.max(np.abs(finest[a][0] - finest[b][0])):8.1e}   "
                  f"|lam| diff = {np.max(np.abs(finest[a][1] - finest[b][1])):8.1e}")


if __name__ == "__main__":
    main()
