"""Fixed cost of a Newton iteration of the fixed-step integrators (issue 10: aim < 10 us).

``python -m benchmarks.newton_overhead [--steps 2000] [--repeats 7] [--elements 1]``

Problem: Exudyn's flexible pendulum (1 m, rho A = 10 kg/m, EA = 5.25e7 N, EI = 10937.5 N m^2,
BE2D, hinged, gravity, released horizontally) with few elements, h = 1e-4, so that the model's own
work is small and the integrator's Python overhead shows. Per method: the CPU time of
``step() + accept()`` over ``--steps`` steps divided by the Newton iterations, the time of one
``model.residual`` call (one per iteration; Lobatto IIIA-3 evaluates its two implicit stages in
one ``residual_stages`` call where the model has it) and of one LU solve with the cached factor;
"fixed" is per-iteration minus residual minus solve: the integrator's and the Newton loop's own
cost (with the per-step work -- predictor, acceptance -- spread over the iterations). CPU medians
of ``--repeats`` runs, the methods interleaved in one process.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import Gravity, Material, RectangularSection
from ancfdae.integrators import GeneralizedAlpha, LobattoIIIA
from ancfdae.integrators.driver import consistent_acceleration
from ancfdae.models import BE2D, Beam

METHODS = {"generalized-alpha": lambda m, h: GeneralizedAlpha(m, h),
           "lobatto3": lambda m, h: LobattoIIIA(m, h, 3)}


def pendulum(n_el):
    """The flexible pendulum with ``n_el`` BE2D elements."""
    mat, sec = Material(E=2.1e10, nu=0.3, rho=4000.0), RectangularSection(0.05)
    return Beam(BE2D(mat, sec), n_el, 1.0, supports={0: "pin"}, loads=[Gravity((0.0, -9.81))])


def _cpu(fn, n):
    t0 = time.process_time()
    for _ in range(n):
        fn()
    return (time.process_time() - t0) / n


def run_once(model, name, h, steps):
    """CPU seconds per Newton iteration, the iterations, and one state on the way (for checks)."""
    q0, v0 = model.initial_state()
    a0, _ = consistent_acceleration(model, 0.0, q0, v0)
    integ = METHODS[name](model, h)
    integ.initialize(model, 0.0, q0, v0, a0, 1e9)
    integ.step()                                    # warm up: JIT, factorisation
    integ.initialize(model, 0.0, q0, v0, a0, 1e9)
    t0 = time.process_time()
    for _ in range(steps):
        out = integ.step()
        if not out.ok:
            raise RuntimeError(out.message)
        integ.accept(out)
    cpu = time.process_time() - t0
    it = integ.stats["newton_iterations"]
    lu, r = integ.newton._lu, np.ones(q0.size * (2 if name == "lobatto3" else 1))
    t_sol = np.median([_cpu(lambda: lu.solve(r), 500) for _ in range(3)])
    return cpu / it, it, integ.q.copy(), t_sol


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=2000)
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--elements", type=int, default=1)
    p.add_argument("--h", type=float, default=1e-4)
    a = p.parse_args(argv)
    model = pendulum(a.elements)
    q, v = model.initial_state()
    acc = np.zeros_like(q)
    # the model's share of an iteration: one residual (generalized-alpha), the two implicit stages
    # in one residual_stages call (lobatto3, where the model has it; else two residuals)
    model.residual(0.0, q, v, acc)                  # warm up (JIT) before timing
    t_res = {"generalized-alpha": np.median([_cpu(lambda: model.residual(0.0, q, v, acc), 2000)
                                             for _ in range(a.repeats)])}
    Q, ts = np.column_stack([q, q]), np.array([0.5 * a.h, a.h])
    model.residual(0.0, q, v, acc)                  # warm up (JIT) before timing
    if hasattr(model, "residual_stages"):
        t_res["lobatto3"] = np.median([_cpu(lambda: model.residual_stages(ts, Q, Q * 0, Q * 0), 2000)
                                       for _ in range(a.repeats)])
    else:
        t_res["lobatto3"] = 2 * t_res["generalized-alpha"]
    times = {n: [] for n in METHODS}
    iters, states, t_sol = {}, {}, {}
    for _ in range(a.repeats):
        for name in METHODS:                        # interleaved
            t_it, it, qf, t_sol[name] = run_once(model, name, a.h, a.steps)
            times[name].append(t_it)
            iters[name], states[name] = it, qf
    print(f"{a.elements} BE2D element(s), {model.n_dof if hasattr(model, 'n_dof') else q.size} DOF, "
          f"h = {a.h:g}, {a.steps} steps, CPU medians of {a.repeats}")
    for name in METHODS:
        t = float(np.median(times[name]))
        print(f"{name:18s} {1e6 * t:7.2f} us/iteration ({iters[name]} iterations): residual "
              f"{1e6 * t_res[name]:.2f}, solve {1e6 * t_sol[name]:.2f}, fixed ~"
              f"{1e6 * (t - t_res[name] - t_sol[name]):6.2f} us; final q[-4:] = "
              f"{np.array2string(states[name][-4:], precision=17)}")


if __name__ == "__main__":
    main()
