"""Energy-momentum integrator against Lobatto IIIA-3 and generalized-alpha on the flying beams.

``python -m benchmarks.energy_momentum [--case b3] [--elements 8] [--h 1e-2] [--t-end 10]
[--methods energy-momentum lobatto3 generalized-alpha] [--repeats 1]``

``python -m benchmarks.energy_momentum --case long [--elements 1] [--h 1e-2] [--steps 10000]``: every
element with a constant mass matrix in each formulation (BE2D, SQ2D structural/continuum/continuum-locking,
SQ3D structural/continuum, Cable3D) on ``--elements`` elements, a short load (0.3 s pulse of the B2
magnitudes in 2D, 0.4 s hat of the B3 moment in 3D), then ``--steps`` free steps of the energy-momentum
method; printed per case: wall seconds, the discrete gradient used, and the energy drift over every step
after the load ``(max E - min E) / max|E|``.

Problems (revision 2): B3, SQ3D, moment f(t) (0.1, 0.05, 0.2) N m at B with the hat ending at
3 s; B2, BE2D (or any planar element), pulse force 0.24 N and moment 0.24 N m for 2.5 s. L = 1 m,
a = 0.05 m, E = 1e5, nu = 0.3, rho = 2500, straight along (0.6, 0.8[, 0]), at rest.

Printed per method (interleaved when ``--repeats`` > 1; median wall time): status, steps, wall
seconds, milliseconds per step, Newton iterations per step, factorisations, the relative energy
drift after the load ``max|E - E(t_load)| / E(t_load)`` over outputs every 50 ms, and the drift of
the linear and angular momentum after the load relative to their size.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import Material, PointForce, PointMoment, RectangularSection, hat, models, pulse, simulate

MAT = Material(E=1e5, nu=0.3, rho=2500.0)
SEC = RectangularSection(0.05)


def beam(case, element, n):
    """The revision-2 beam of ``case`` ("b2" or "b3") with ``n`` elements of type ``element``."""
    el = getattr(models, element)(MAT, SEC)
    if case == "b3":
        return models.Beam(el, n, 1.0, start=(0.0, 0.0, 0.0), direction=(0.6, 0.8, 0.0),
                           loads=[PointMoment((0.1, 0.05, 0.2), node=0, time=hat(1.5))]), 3.0
    f = pulse(2.5)
    return models.Beam(el, n, 1.0, start=(0.0, 0.0), direction=(0.6, 0.8),
                       loads=[PointForce((0.24, 0.0), node=0, time=f), PointMoment(0.24, node=0, time=f)]), 2.5


def measure(model, t_load, method, h, t_end):
    """One run; returns a dict of the printed figures."""
    t_eval = np.round(np.arange(0.0, t_end + 1e-9, 0.05), 12)
    wall = time.perf_counter()
    res = simulate(model, (0.0, t_end), method, h=h, t_eval=t_eval)
    wall = time.perf_counter() - wall
    after = res.t >= t_load - 1e-9
    E = np.array([model.energy(t, q, v).total for t, q, v in zip(res.t[after], res.q[after], res.v[after])])
    T, A = model.symmetry_generators()
    M = model.mass(None)
    p = np.array([T.T @ (M @ v) for v in res.v[after]])
    L = np.array([[(M @ v) @ (Ak @ q) for Ak in A] for q, v in zip(res.q[after], res.v[after])])
    st = res.stats
    steps = max(st.get("steps", 1), 1)
    nan = float("nan")
    scale = max(float(np.abs(M @ res.v[-1]).sum()), 1e-300)
    return dict(status=res.status, t_end=float(res.t[-1]) if res.t.size else 0.0, steps=steps, wall=wall,
                ms_step=1e3 * wall / steps, it_step=st.get("newton_iterations", 0) / steps,
                fact=st.get("factorizations", 0),
                dE=float(np.max(np.abs(E - E[0])) / abs(E[0])) if E.size else nan,
                E0=float(E[0]) if E.size else nan,
                dp=float(np.max(np.abs(p - p[0]))) / scale if p.size else nan,
                dL=float(np.max(np.abs(L - L[0])) / np.abs(L[0]).max()) if L.size else nan)

LONG_CASES = [("BE2D", {}), ("BE2D", {"formulation": "continuum"}), ("SQ2D", {}),
              ("SQ2D", {"formulation": "continuum"}), ("SQ2D", {"formulation": "continuum-locking"}),
              ("SQ3D", {}), ("SQ3D", {"formulation": "continuum"}), ("Cable3D", {})]


def short_load_beam(element, n, **options):
    """The beam of B2 (planar types: 0.3 s pulse) or B3 (spatial types: 0.4 s hat); returns it and t_load."""
    el = getattr(models, element)(MAT, SEC, **options)
    if el.dim == 2:
        f = pulse(0.3)
        return models.Beam(el, n, 1.0, start=(0.0, 0.0), direction=(0.6, 0.8),
                           loads=[PointForce((0.24, 0.0), node=0, time=f), PointMoment(0.24, node=0, time=f)]), 0.3
    return models.Beam(el, n, 1.0, start=(0.0, 0.0, 0.0), direction=(0.6, 0.8, 0.0),
                       loads=[PointMoment((0.1, 0.05, 0.2), node=0, time=hat(0.2))]), 0.4


def long_drift(element, options, n, h, steps):
    """Energy drift over ``steps`` free energy-momentum steps after the short load (every step sampled)."""
    model, t_load = short_load_beam(element, n, **options)
    wall = time.perf_counter()
    res = simulate(model, (0.0, t_load + steps * h), "energy-momentum", h=h)
    wall = time.perf_counter() - wall
    after = res.t >= t_load - 1e-9
    E = np.array([model.energy(t, q, v).total for t, q, v in zip(res.t[after], res.q[after], res.v[after])])
    return dict(status=res.status, wall=wall, dg=res.options.get("discrete_gradient"), free=int(after.sum()) - 1,
                E=float(np.abs(E).max()), dE=float(np.ptp(E) / np.abs(E).max()))


def main_long(a):
    print(f"energy-momentum, {a.elements} element(s), h = {a.h:g}, {a.steps} free steps after a short load "
          f"(machine shared)")
    print(f"{'element':10s} {'formulation':18s} {'dg':9s} {'status':8s} {'free':>6s} {'wall s':>7s} "
          f"{'E (J)':>10s} {'dE/E':>9s}")
    for element, options in LONG_CASES:
        r = long_drift(element, options, a.elements, a.h, a.steps)
        print(f"{element:10s} {options.get('formulation', 'structural'):18s} {r['dg']:9s} {r['status']:8s} "
              f"{r['free']:6d} {r['wall']:7.1f} {r['E']:10.4g} {r['dE']:9.2e}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", choices=("b2", "b3", "long"), default="b3")
    ap.add_argument("--element", default=None)
    ap.add_argument("--elements", type=int, default=8)
    ap.add_argument("--h", type=float, default=1e-2)
    ap.add_argument("--t-end", type=float, default=10.0)
    ap.add_argument("--methods", nargs="+", default=["energy-momentum", "lobatto3", "generalized-alpha"])
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--steps", type=int, default=10_000, help="free steps of --case long")
    a = ap.parse_args(argv)
    if a.case == "long":
        return main_long(a)
    element = a.element or ("SQ3D" if a.case == "b3" else "BE2D")
    rows = {m: [] for m in a.methods}
    for _ in range(a.repeats):
        for m in a.methods:
            model, t_load = beam(a.case, element, a.elements)
            rows[m].append(measure(model, t_load, m, a.h, a.t_end))
    print(f"{a.case.upper()} {element} x {a.elements}, h = {a.h:g}, to {a.t_end:g} s, "
          f"median of {a.repeats} (machine shared)")
    print(f"{'method':18s} {'status':8s} {'steps':>6s} {'wall s':>8s} {'ms/step':>8s} {'it/step':>7s} "
          f"{'fact':>5s} {'dE/E':>9s} {'dp':>9s} {'dL/L':>9s}")
    for m, rs in rows.items():
        r = dict(rs[0])
        r["wall"] = float(np.median([x["wall"] for x in rs]))
        r["ms_step"] = 1e3 * r["wall"] / r["steps"]
        print(f"{m:18s} {r['status']:8s} {r['steps']:6d} {r['wall']:8.1f} {r['ms_step']:8.2f} {r['it_step']:7.2f} "
              f"{r['fact']:5d} {r['dE']:9.2e} {r['dp']:9.2e} {r['dL']:9.2e}   "
              f"(E = {r['E0']:.6g} J, t = {r['t_end']:g})")


if __name__ == "__main__":
    main()
