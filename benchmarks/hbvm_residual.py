"""Where one Newton residual of energy-collocation (and of Lobatto IIIA-3) spends its time.

``python -m benchmarks.hbvm_residual [--problem B3-8] [--h 5e-3] [--t-end 5]`` runs each method once over
``[0, t_end]`` (after a short compiling run) with wall-clock counters around the pieces of the residual
callback and prints, per residual evaluation (one Newton iteration):

* ``residual``: the whole callback the Newton solver calls;
* ``forces``: the model's conservative-force call at the configurations (energy-collocation:
  ``potential_gradient_projection`` or ``potential_gradient_stages``; Lobatto IIIA-3: ``residual_stages`` without
  its external loads), of which ``kernel`` is the compiled element pass itself (the fused entry point);
* ``loads``: the non-conservative loads (dead moments at the nodes, evaluated in Python per node);
* ``rest``: everything else (the nodes' configurations, the projection, the mass term, the callback's
  Python).

The counters (``time.perf_counter`` around each call, about 0.1 us each) add a little to every piece; read
the split, and take CPU ratios from ``python -m benchmarks.energy_collocation ratio``.

``python -m benchmarks.hbvm_residual --micro [--problem B3-8] [--at 1.0] [--repeats 2000]`` times one residual
callback of energy-collocation at the state of time ``--at`` (a run to there first) with each path of the
conservative force, interleaved call by call: ``projection`` (``potential_gradient_projection``: one
compiled call forms, evaluates and weights the ``k`` configurations), ``stages`` (``potential_gradient_stages``:
the configurations in NumPy, one stacked element pass, the projection in NumPy) and ``per-node`` (one model
call per configuration); medians and fastest, microseconds.

``python -m benchmarks.hbvm_residual --kernel-orders [--elements 40] [--repeats 2000]`` times the compiled SQ3D
structural and continuum kernels (``sq_structural``, ``sq_continuum``) at order 0 (energy), 1 (plus force: what
every residual evaluates) and 2 (plus tangent) on a deformed mesh, interleaved; microseconds per element.
"""
from __future__ import annotations

import argparse
import time
from collections import defaultdict

from ancfdae import EnergyMonitor, simulate
from ancfdae.integrators import EnergyCollocation, LobattoIIIA

from .energy_collocation import PROBLEMS, method_of


def _timed(fn, acc, key):
    def wrapper(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            acc[key] += time.perf_counter() - t0
            acc[key + "#"] += 1
    return wrapper


def _instrument(model, acc):
    """Counters on the model's force and load calls and on the element's fused entry point."""
    el = model.element
    fused_kernel = el.fused_kernel

    def timed_fused(geom):
        hit = fused_kernel(geom)
        return None if hit is None else (_timed(hit[0], acc, "kernel"), hit[1])

    el.fused_kernel = timed_fused
    kernels = getattr(el, "kernels", None)
    entry = getattr(kernels, "fused_projection", None)
    if entry is not None:
        kernels.fused_projection = lambda geom: (_timed(entry(geom)[0], acc, "kernel"), entry(geom)[1])
    for name, key in (("potential_gradient_stages", "forces"), ("potential_gradient_projection", "forces"),
                      ("nonconservative_force", "loads"), ("_f_external", "loads")):
        if hasattr(model, name):
            setattr(model, name, _timed(getattr(model, name), acc, key))


def _instrument_residuals(cls, acc):
    """Wrap the residual callbacks that ``cls`` builds per step; returns the undo."""
    if cls is EnergyCollocation:
        original = cls.stage_equations

        def stage_equations(self, t0, h, split):
            residual, jacobian = original(self, t0, h, split)
            return _timed(residual, acc, "residual"), jacobian

        cls.stage_equations = stage_equations
        return lambda: setattr(cls, "stage_equations", original)
    original = cls._solve

    def solve(self, residual, jacobian, x0, iterate=None, accept=None):
        return original(self, _timed(residual, acc, "residual"), jacobian, x0, iterate, accept)

    cls._solve = solve
    return lambda: setattr(cls, "_solve", original)


def split(problem, label, h, t_end):
    """Per-residual means (microseconds) of the pieces, and the run's Newton iterations per step."""
    build = PROBLEMS[problem][0]
    model = build()
    simulate(model, (0.0, 0.05), **method_of(label, model, h), monitors=[EnergyMonitor()])    # compile
    acc = defaultdict(float)
    model = build()
    _instrument(model, acc)
    cls = EnergyCollocation if label.startswith("energy-collocation") else LobattoIIIA
    undo = _instrument_residuals(cls, acc)
    try:
        c0 = time.process_time()
        res = simulate(model, (0.0, t_end), **method_of(label, model, h), monitors=[EnergyMonitor()])
        cpu = time.process_time() - c0
    finally:
        undo()
    n = max(acc["residual#"], 1)
    # Lobatto's residual_stages is not wrapped (its loads are inside): its force = the kernel's time.
    forces = acc["forces"] if acc["forces#"] else acc["kernel"]
    out = dict(residual=acc["residual"] / n * 1e6, forces=forces / n * 1e6, kernel=acc["kernel"] / n * 1e6,
               loads=acc["loads"] / n * 1e6)
    out["rest"] = out["residual"] - out["forces"] - out["loads"]
    out.update(cpu=cpu, residuals=int(acc["residual#"]), its=res.stats["newton_iterations"] / res.stats["steps"],
               ok=res.success)
    return out


def micro(problem, h, at, repeats):
    """Medians and minima (us) of one residual callback per force path, interleaved; see the module docstring."""
    import numpy as np
    build = PROBLEMS[problem][0]
    model = build()
    res = simulate(model, (0.0, at), **method_of("energy-collocation", model, h))
    q, v = res.q[-1], res.v[-1]
    a = np.zeros_like(q)
    st = EnergyCollocation(model, h)
    st.initialize(model, float(res.t[-1]), q, v, a, float(res.t[-1]) + 1.0)
    st._setup()
    x = st._predict(h).ravel() + 1e-6 * np.random.default_rng(0).standard_normal(q.size * 2)
    paths = {}
    for name, proj, stages in (("projection", True, True), ("stages", False, True), ("per-node", False, False)):
        st._projection, st._stages = proj, stages
        paths[name] = st.stage_equations(st.t, h, [True])[0]
    out = {name: [] for name in paths}
    ref = paths["per-node"](x)
    for name, fn in paths.items():
        d = np.abs(fn(x) - ref).max() / np.abs(ref).max()
        print(f"{name:<12} differs from per-node by {d:.1e} (relative to max|R|)")
    for _ in range(repeats):
        for name, fn in paths.items():
            t0 = time.perf_counter()
            fn(x)
            out[name].append(time.perf_counter() - t0)
    for name, ts in out.items():
        print(f"{problem} at t = {at:g}: {name:<12} median {np.median(ts) * 1e6:8.1f} us   fastest "
              f"{np.min(ts) * 1e6:8.1f} us")


def kernel_orders(n_el, repeats):
    """Median and fastest time per element of the compiled SQ3D kernels at orders 0, 1, 2 (see the docstring)."""
    import numpy as np
    from ancfdae.models.shear.kernels_numba import sq_continuum, sq_structural
    from .sq_kernels import _model
    for form, fn in (("structural", sq_structural), ("continuum", sq_continuum)):
        el, beam, q = _model(form, n_el)
        arrays = el.kernels._arrays(beam.geom)
        times = {order: [] for order in (0, 1, 2)}
        for order in times:
            fn(q, *arrays, 3, order)
        for _ in range(repeats):
            for order, ts in times.items():
                t0 = time.perf_counter()
                fn(q, *arrays, 3, order)
                ts.append(time.perf_counter() - t0)
        for order, ts in times.items():
            print(f"SQ3D {form:<11} order {order}: median {np.median(ts) / n_el * 1e6:6.2f} us/element, fastest "
                  f"{np.min(ts) / n_el * 1e6:6.2f}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--problem", default="B3-8", choices=tuple(PROBLEMS))
    ap.add_argument("--h", type=float, default=5e-3)
    ap.add_argument("--t-end", type=float, default=None)
    ap.add_argument("--methods", nargs="+", default=["energy-collocation", "lobatto3"])
    ap.add_argument("--micro", action="store_true", help="time one residual per force path (module docstring)")
    ap.add_argument("--at", type=float, default=1.0, help="--micro: the state's time")
    ap.add_argument("--repeats", type=int, default=2000)
    ap.add_argument("--kernel-orders", action="store_true", help="time the SQ3D kernels per order (docstring)")
    ap.add_argument("--elements", type=int, default=40, help="--kernel-orders: elements of the mesh")
    a = ap.parse_args(argv)
    if a.kernel_orders:
        return kernel_orders(a.elements, a.repeats)
    if a.micro:
        return micro(a.problem, a.h, a.at, a.repeats)
    t_end = a.t_end if a.t_end is not None else (4.0 if a.problem.startswith("B2") else 5.0)
    print(f"{a.problem} h = {a.h:g}, [0, {t_end:g}] s; microseconds per residual evaluation")
    print(f"{'method':<22}{'residual':>9}{'forces':>9}{'kernel':>9}{'loads':>9}{'rest':>9}{'res/run':>9}"
          f"{'it/step':>8}{'CPU s':>8}")
    for label in a.methods:
        r = split(a.problem, label, a.h, t_end)
        print(f"{label:<22}{r['residual']:>9.1f}{r['forces']:>9.1f}{r['kernel']:>9.1f}{r['loads']:>9.1f}"
              f"{r['rest']:>9.1f}{r['residuals']:>9d}{r['its']:>8.2f}{r['cpu']:>8.2f}"
              + ("" if r["ok"] else "  FAILED"),
              flush=True)


if __name__ == "__main__":
    main()
