"""IDA against Lobatto IIIA-3 on B2: CPU time to reach a time-integration error eps_T.

``python -m benchmarks.ida_vs_lobatto [--target 1e-6] [--repeats 3] [--orders 2 5] [--linsolvers sparse band]``

Problem: B2 revision 2 -- the free beam flying in the plane, L = 1 m, square section a = 0.05 m,
E = 1e5, nu = 0.3, rho = 2500, straight along (0.6, 0.8) at rest, force f(t) (0.24, 0) N and moment
f(t) 0.24 N m at the end B (s = 0), pulse f = (1 - cos(2 pi t / 2.5)) / 2 on [0, 2.5] s -- with 8 BE2D
elements over [0, 4] s. Error: eps_T of chapter Eq. 115 on the tip B, output every 0.01 s, against a
converged fine-step reference on the same mesh (Lobatto IIIA-3, full Newton, tolerance 1e-10, step
``--h-ref``), so that it measures the time integration alone.

For each integrator the accuracy parameter is swept (Lobatto: h; IDA: rtol) and each run's CPU
seconds (process time, median of ``--repeats`` runs interleaved across the integrators in one
process) and eps_T are printed; the CPU time at ``--target`` is interpolated on the log-log line
through the two bracketing runs. The machine may be shared: compare medians, not single runs.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import Material, PointForce, PointMoment, PointSensor, RectangularSection, pulse, simulate
from ancfdae.integrators import NewtonOptions
from ancfdae.models import BE2D, Beam

T_END, DT_OUT = 4.0, 0.01


def b2(n_elements: int = 8) -> Beam:
    """B2 revision 2 with BE2D elements."""
    f = pulse(2.5)
    el = BE2D(Material(E=1e5, nu=0.3, rho=2500.0), RectangularSection(0.05))
    return Beam(el, n_elements, 1.0, start=(0.0, 0.0), direction=(0.6, 0.8),
                loads=[PointForce((0.24, 0.0), node=0, time=f), PointMoment(0.24, node=0, time=f)])


def run(method, t_end=T_END, n=8, **options):
    """One run: (tip history, CPU seconds, Result)."""
    beam = b2(n)
    t_eval = np.linspace(0.0, t_end, int(round(t_end / DT_OUT)) + 1)
    c0 = time.process_time()
    res = simulate(beam, (0.0, t_end), method, t_eval=t_eval, monitors=[PointSensor(s=0.0, name="tip")],
                   **options)
    return res.monitors["tip"]["position"], time.process_time() - c0, res


def eps_T(tip, ref, dt=DT_OUT):
    """Chapter Eq. 115 by the trapezoidal rule on the common output grid."""
    e2 = np.sum((tip - ref[:len(tip)]) ** 2, axis=1)
    return float(np.sqrt(np.sum(0.5 * (e2[1:] + e2[:-1]) * dt)))


def at_target(points, target):
    """CPU time at eps_T = target on the log-log line through the bracketing (eps, cpu) points."""
    pts = sorted(points)   # by eps
    for (e0, c0), (e1, c1) in zip(pts, pts[1:]):
        if e0 <= target <= e1:
            w = np.log(target / e0) / np.log(e1 / e0)
            return float(np.exp((1 - w) * np.log(c0) + w * np.log(c1)))
    return float("nan")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--target", type=float, default=1e-6)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--h-ref", type=float, default=2.5e-4)
    p.add_argument("--steps", type=float, nargs="+", default=[4e-3, 2e-3, 1e-3])
    p.add_argument("--rtols", type=float, nargs="+", default=[1e-6, 1e-7, 1e-8, 1e-9])
    p.add_argument("--orders", type=int, nargs="+", default=[5, 2])
    p.add_argument("--linsolvers", nargs="+", default=["sparse"])
    a = p.parse_args(argv)
    ref, cpu, res = run("lobatto3", h=a.h_ref, newton=NewtonOptions(tol=1e-10, jacobian="full"))
    print(f"reference: lobatto3 h = {a.h_ref:g} (full Newton, tol 1e-10): {cpu:.1f} s CPU, {res.message}")
    cases = [(f"lobatto3 h={h:g}", "lobatto3", {"h": h}) for h in a.steps]
    cases += [(f"ida order<={o} {ls} rtol={r:g}", "ida", {"rtol": r, "max_order": o, "linsolver": ls})
              for o in a.orders for ls in a.linsolvers for r in a.rtols]
    cpus = {label: [] for label, _, _ in cases}
    errs, stats = {}, {}
    for _ in range(a.repeats):   # interleaved repeats: a shared machine slows every integrator alike
        for label, method, opts in cases:
            tip, cpu, res = run(method, **opts)
            cpus[label].append(cpu)
            errs[label] = eps_T(tip, ref) if res.success else float("nan")
            stats[label] = res.stats
    print(f"{'case':40s} {'eps_T':>10s} {'CPU s':>8s} {'steps':>8s} {'Newton it':>10s}")
    groups = {}
    for label, method, opts in cases:
        c = float(np.median(cpus[label]))
        print(f"{label:40s} {errs[label]:10.3e} {c:8.2f} {stats[label]['steps']:8d} "
              f"{stats[label]['newton_iterations']:10d}")
        groups.setdefault(label.rsplit(" ", 1)[0], []).append((errs[label], c))
    print(f"\nCPU seconds to reach eps_T = {a.target:g} (log-log interpolation):")
    for g, pts in groups.items():
        print(f"  {g:36s} {at_target([x for x in pts if np.isfinite(x[0])], a.target):8.2f}")


if __name__ == "__main__":
    main()
