"""The energy-preserving collocation HBVM(k, 2) against Lobatto IIIA-3, energy-momentum and its compositions.

``python -m benchmarks.energy_collocation wp --problem B2-4 [--t-end 4] [--out DIR]``
    work-precision on B2 (``B2-4``, ``B2-8``: 4 or 8 BE2D) or B3 (``B3-8``, ``B3-16``: SQ3D, default
    structural formulation; ``B3-8c``: continuum): every method over its steps, error eps_T of the tip
    (``(int_0^T |x_B - x_B,ref|^2 dt)^(1/2)``, all components, samples every 20 ms) against a reference
    run of energy-collocation at a quarter of its finest step (or ``--h-ref``), process CPU time, Newton iterations per
    step, the energy's spread after the load relative to the energy; then the CPU time at equal
    eps_T (log-log interpolation along each method's sweep, no extrapolation) and its ratio to
    Lobatto IIIA-3's. Runs are cached as JSON in ``--out`` (rerun to complete a sweep).
``python -m benchmarks.energy_collocation long [--steps 10000] [--elements 1] [--silent-stages auto]``
    energy drift over ``--steps`` free steps (h = 10 ms) after a short load, every constant-mass
    element and formulation (as ``tests/integrators/test_energy_collocation.py`` with fewer steps).
``python -m benchmarks.energy_collocation ratio --problem B3-8 [--h 5e-3] [--t-end 5] [--reps 3] [--methods ...]``
    CPU time of energy-collocation (and any other ``--methods`` label) over Lobatto IIIA-3's at one step: medians
    of ``--reps`` runs of each, interleaved in one process, and the median of the per-repetition ratios (equal h is
    equal accuracy: see ``wp``). ``energy-collocation-k5-rule``: the defaults before the potential's defect (k = 5
    for smooth potentials, the rule's defect, refresh at rate 0.3).
``python -m benchmarks.energy_collocation equal --problem B3-8 [--h 5e-3] [--reps 5] [--methods ...]``
    the ratio at equal accuracy: Lobatto IIIA-3 at ``--h``, every ``--methods`` label (default energy-collocation)
    at ``--h`` and at a second step aimed by order 4 at Lobatto's eps_T (at least 2 % apart); eps_T against a
    reference run (``--ref-method`` at ``--h-ref``, default ``--h`` / 8); CPU medians of ``--reps`` interleaved
    runs; the method's CPU at Lobatto's eps_T log-log interpolated between its two steps (also printed: its cost per
    step at ``--h`` times the steps at the interpolated step, and the ratio at equal step); the load average.
``python -m benchmarks.energy_collocation stages [--problem B3-8] [--h 1e-2] [--t-end 10]``
    the energy's spread after the load against the number of silent stages ``k`` (with the default energy defect:
    for a non-polynomial potential the potential's own, which keeps the energy whatever ``k``).

Lobatto IIIA-3 runs with the chapter's Newton settings (modified, relative tolerance 1e-8), the
energy-conserving methods with their own (round-off). One run per configuration (a shared machine:
read ratios, not absolute times).
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from ancfdae import EnergyMonitor, simulate
from ancfdae.integrators import NewtonOptions
from ancfdae.studies._flying import T_HAT, T_PULSE, b2_beam, b3_beam

from ._composition import SUZUKI, TRIPLE_JUMP, ComposedEnergyMomentum

DT_OUT = 0.02
PROBLEMS = {
    "B2-4": (lambda: b2_beam("BE2D", 4), T_PULSE),
    "B2-8": (lambda: b2_beam("BE2D", 8), T_PULSE),
    "B3-8": (lambda: b3_beam("SQ3D", 8), T_HAT),
    "B3-16": (lambda: b3_beam("SQ3D", 16), T_HAT),
    "B3-8c": (lambda: b3_beam("SQ3D", 8, formulation="continuum"), T_HAT),
}
#: method label -> steps of its sweep
SWEEP_B2 = {"lobatto3": (1e-2, 5e-3, 2.5e-3), "energy-collocation": (2e-2, 1e-2, 5e-3, 2.5e-3),
            "energy-collocation-exact": (1e-2, 5e-3), "energy-momentum": (5e-3, 2.5e-3),
            "em-suzuki": (1e-2, 5e-3), "em-triple-jump": (1e-2,)}
SWEEP_B3 = {"lobatto3": (5e-3, 2.5e-3, 1.25e-3), "energy-collocation": (1e-2, 5e-3, 2.5e-3),
            "energy-collocation-exact": (5e-3,), "energy-momentum": (5e-3,)}


def method_of(label, model, h):
    """``simulate`` keyword arguments of a method label; ``label:tol=X``: that label with Newton's relative
    tolerance X (``lobatto3``, ``energy-collocation``); ``:contraction=X`` likewise Newton's refresh rate (modified
    Newton, tolerance 1e-8 unless given)."""
    if ":" in label:
        base, *given = label.split(":")
        kw = method_of(base, model, h)
        options = dict(jacobian="modified")
        options.update((key, float(value)) for key, value in (g.split("=") for g in given))
        kw["newton"] = NewtonOptions(**options)
        return kw
    if label == "lobatto3":
        return dict(method="lobatto3", h=h, newton=NewtonOptions(tol=1e-8, jacobian="modified"))
    if label == "energy-collocation":
        return dict(method="energy-collocation", h=h)
    if label == "energy-collocation-newton":          # Newton to the energy's round-off, no velocity correction
        return dict(method="energy-collocation", h=h, energy_correction="newton")
    if label == "energy-collocation-k5-rule":
        k = "auto" if getattr(model, "potential_degree", None) is not None else 5
        return dict(method="energy-collocation", h=h, silent_stages=k, energy_defect="rule",
                    newton=NewtonOptions(tol=1e-8))
    if label == "energy-collocation-exact":
        return dict(method="energy-collocation", h=h, iteration_matrix="exact")
    if label.startswith("energy-collocation-k"):
        return dict(method="energy-collocation", h=h, silent_stages=int(label.rsplit("k", 1)[1]))
    if label == "energy-momentum":
        return dict(method="energy-momentum", h=h)
    if label in ("em-suzuki", "em-triple-jump"):
        return dict(method=ComposedEnergyMomentum(model, h, SUZUKI if label == "em-suzuki" else TRIPLE_JUMP))
    raise ValueError(f"unknown method label {label!r}")


def run_one(problem, label, h, t_end, out: Path, force=False):
    """One run (cached): tip history, energy after the load, CPU time, Newton work."""
    path = out / f"{problem}_{label}_{h:.6g}_{t_end:g}.json"
    if path.exists() and not force:
        return json.loads(path.read_text())
    build, t_load = PROBLEMS[problem]
    model = build()
    t_eval = np.round(np.arange(0.0, t_end + 1e-9, DT_OUT), 10)
    kw = method_of(label, model, h)
    c0 = time.process_time()
    res = simulate(model, (0.0, t_end), t_eval=t_eval, monitors=[EnergyMonitor()], **kw)
    cpu = time.process_time() - c0
    tip = np.array([model.position(q, 0.0) for q in res.q])
    total = np.asarray(res.monitors["energy"]["total"])
    after = res.t >= t_load - 1e-9
    e_after = total[after]
    st = res.stats
    rec = dict(problem=problem, method=label, h=h, t_end=t_end, ok=bool(res.success), message=res.message,
               t=res.t.tolist(), tip=tip.tolist(), cpu=cpu, steps=int(st["steps"]),
               its=st.get("newton_iterations", 0) / max(st["steps"], 1),
               lu=st.get("factorizations", 0) / max(st["steps"], 1),
               dE=float(np.ptp(e_after) / np.abs(e_after).max()) if e_after.size > 1 else float("nan"))
    out.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(rec))
    return rec


def eps(run, ref):
    """``(int |tip - tip_ref|^2 dt)^(1/2)`` over the common samples (trapezoidal rule)."""
    t, tr = np.asarray(run["t"]), np.asarray(ref["t"])
    n = min(t.size, tr.size)
    d = np.asarray(run["tip"])[:n] - np.asarray(ref["tip"])[:n]
    e2 = np.sum(d * d, axis=1)
    return float(np.sqrt(np.sum(0.5 * (e2[1:] + e2[:-1]) * np.diff(t[:n]))))


def equal_accuracy(rows):
    """CPU at Lobatto IIIA-3's eps_T levels, log-log interpolated per method; ratio to Lobatto's."""
    curves = {}
    for r in rows:
        if r["ok"] and r["eps"] > 0:
            curves.setdefault(r["method"], []).append((r["eps"], r["cpu"]))
    curves = {m: sorted(v) for m, v in curves.items() if len(v) >= 2}

    def cpu_at(m, e):
        pts = curves.get(m)
        if not pts:
            return float("nan")
        E, C = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
        if np.log(e) < E.min() - 1e-9 or np.log(e) > E.max() + 1e-9:
            return float("nan")
        return float(np.exp(np.interp(np.log(e), E, C)))

    others = [m for m in curves if m != "lobatto3"]
    print(f"\nCPU s at equal eps_T (ratio to Lobatto IIIA-3; '-': outside the method's sweep)")
    print(f"{'eps_T':>10} {'lobatto3':>9} " + " ".join(f"{m:>26}" for m in others))
    for e, base in curves.get("lobatto3", []):
        cells = []
        for m in others:
            c = cpu_at(m, e)
            cells.append(f"{'-':>26}" if not np.isfinite(c) else f"{c:>17.1f} ({c / base:4.2f}x)")
        print(f"{e:>10.2e} {base:>9.1f} " + " ".join(cells))


def work_precision(a):
    sweep = SWEEP_B2 if a.problem.startswith("B2") else SWEEP_B3
    if a.methods:
        sweep = {m: sweep.get(m.split(":")[0], sweep["energy-collocation"]) for m in a.methods}   # other labels: EC's
    t_end = a.t_end
    h_ref = a.h_ref or min(sweep.get("energy-collocation", (2.5e-3,))) / 4
    for m in sweep:                                # compile every kernel before the timed runs
        model = PROBLEMS[a.problem][0]()
        simulate(model, (0.0, 0.05), **method_of(m, model, 1e-2), monitors=[EnergyMonitor()])
    print(f"{a.problem}, [0, {t_end:g}] s; reference: {a.ref_method}, h = {h_ref:g}", flush=True)
    ref = run_one(a.problem, a.ref_method, h_ref, t_end, a.out)
    if not ref["ok"]:
        raise SystemExit(f"reference failed: {ref['message']}")
    hs = sorted({h for v in sweep.values() for h in v if not a.hs or h in a.hs}, reverse=True)
    rows = []
    for h in hs:                                  # interleaved: every method at one step, then the next step
        for m, steps in sweep.items():
            if h in steps:
                r = run_one(a.problem, m, h, t_end, a.out)
                r["eps"] = eps(r, ref) if r["ok"] else float("nan")
                rows.append(r)
                print(f"{m:<26}{h:>9.3g}{'ok' if r['ok'] else 'FAILED':>7}{r['eps']:>11.2e}{r['cpu']:>9.1f}"
                      f"{r['its']:>7.2f}{r['lu']:>7.3f}{r['dE']:>10.1e}" + ("" if r["ok"] else f"  {r['message']}"),
                      flush=True)
    equal_accuracy(rows)


def long_runs(a):
    from ancfdae import Material, PointForce, PointMoment, RectangularSection, hat, models, pulse
    mat, sec = Material(E=1e5, nu=0.3, rho=2500.0), RectangularSection(0.05)
    cases = [("BE2D", {}), ("BE2D", {"formulation": "continuum"}), ("Cable3D", {}), ("SQ2D", {}),
             ("SQ2D", {"formulation": "continuum"}), ("SQ2D", {"formulation": "continuum-locking"}),
             ("SQ3D", {}), ("SQ3D", {"formulation": "continuum"})]
    h = 1e-2
    for name, kw in cases:
        label = name + ("-" + kw["formulation"] if kw else "")
        if a.cases and label not in a.cases:
            continue
        el = getattr(models, name)(mat, sec, **kw)
        if name.endswith("2D"):
            t_load, f = 0.3, pulse(0.3)
            loads = [PointMoment(0.24, node=0, time=f), PointForce((0.24, 0.0), node=0, time=f)]
            beam = models.Beam(el, a.elements, 1.0, start=(0.0, 0.0), direction=(0.6, 0.8), loads=loads)
        else:
            t_load = 0.4
            beam = models.Beam(el, a.elements, 1.0, start=(0.0, 0.0, 0.0), direction=(0.6, 0.8, 0.0),
                               loads=[PointMoment((0.1, 0.05, 0.2), node=0, time=hat(t_load / 2))])
        c0 = time.process_time()
        res = simulate(beam, (0.0, t_load + a.steps * h), "energy-collocation", h=h, silent_stages=a.silent_stages,
                       energy_defect=a.energy_defect)
        E = np.array([beam.energy(t, q, v).total for t, q, v in zip(res.t, res.q, res.v) if t >= t_load - 1e-12])
        print(f"{name:<8}{kw.get('formulation', 'default'):<18}k = {res.options['silent_stages']} {res.options['energy_defect']:<9}  "
              f"{'ok' if res.success else 'FAILED'}  free steps {E.size - 1}  "
              f"max|E - E0|/|E| = {np.ptp(E) / np.abs(E).max():.2e}  "
              f"its/step {res.stats['newton_iterations'] / res.stats['steps']:.2f}  "
              f"CPU {time.process_time() - c0:.0f} s", flush=True)


def ratio(a):
    build = PROBLEMS[a.problem][0]
    labels = ["lobatto3"] + [m for m in (a.methods or ["energy-collocation"]) if m != "lobatto3"]
    for m in labels:                                             # compile before timing
        model = build()
        simulate(model, (0.0, 0.05), **method_of(m, model, a.h), monitors=[EnergyMonitor()])
    cpu = {m: [] for m in labels}
    for _ in range(a.reps):
        for m in cpu:
            model = build()
            c0 = time.process_time()
            res = simulate(model, (0.0, a.t_end), **method_of(m, model, a.h), monitors=[EnergyMonitor()])
            cpu[m].append(time.process_time() - c0)
            st = res.stats
            print(f"{m:<26}{'ok' if res.success else 'FAILED'}  CPU {cpu[m][-1]:6.2f} s  it/step "
                  f"{st['newton_iterations'] / st['steps']:.2f}  LU/step {st['factorizations'] / st['steps']:.3f}",
                  flush=True)
    lo = np.median(cpu["lobatto3"])
    for m in labels[1:]:
        ec, pairs = np.median(cpu[m]), np.median(np.array(cpu[m]) / np.array(cpu["lobatto3"]))
        print(f"{a.problem} h = {a.h:g}, [0, {a.t_end:g}] s: median CPU Lobatto IIIA-3 {lo:.2f} s, {m} "
              f"{ec:.2f} s, ratio {ec / lo:.2f} (median of the {a.reps} pairs' ratios {pairs:.2f})")


def _timed(build, label, h, t_end):
    """One run of ``label`` at ``h``: (CPU s, tip samples every DT_OUT as run_one's record, it/step, LU/step)."""
    model = build()
    t_eval = np.round(np.arange(0.0, t_end + 1e-9, DT_OUT), 10)
    c0 = time.process_time()
    res = simulate(model, (0.0, t_end), t_eval=t_eval, monitors=[EnergyMonitor()], **method_of(label, model, h))
    cpu = time.process_time() - c0
    if not res.success:
        raise SystemExit(f"{label} at h = {h:g} failed: {res.message}")
    st = res.stats
    return cpu, dict(t=res.t.tolist(), tip=[model.position(q, 0.0).tolist() for q in res.q]), \
        st["newton_iterations"] / st["steps"], st["factorizations"] / st["steps"]


def equal(a):
    """Ratio to Lobatto IIIA-3 at equal eps_T (module docstring); every run interleaved, medians."""
    import os
    build = PROBLEMS[a.problem][0]
    labels = [m for m in (a.methods or ["energy-collocation"]) if m != "lobatto3"]
    for m in ["lobatto3"] + labels:                              # compile before timing
        model = build()
        simulate(model, (0.0, 0.05), **method_of(m, model, a.h), monitors=[EnergyMonitor()])
    h_ref = a.h_ref or a.h / 8
    ref = run_one(a.problem, a.ref_method, h_ref, a.t_end, a.out)
    load = [os.getloadavg()[0]]
    cpu_l, run, its, lus = _timed(build, "lobatto3", a.h, a.t_end)
    e_l = eps(run, ref)
    print(f"{a.problem} [0, {a.t_end:g}] s, reference {a.ref_method} h = {h_ref:g}; lobatto3 h = {a.h:g}: eps_T "
          f"{e_l:.4e}, {its:.2f} it/step, {lus:.3f} LU/step", flush=True)
    steps = {}
    for m in labels:                                             # the second step, aimed at Lobatto's eps_T
        cpu, run, its, lus = _timed(build, m, a.h, a.t_end)
        e = eps(run, ref)
        f = min(max((e_l / e) ** 0.25, 0.8), 1.25)
        f = f if abs(f - 1.0) >= 0.02 else (0.98 if f < 1.0 else 1.02)
        h2 = float(f"{a.h * f:.4g}")
        steps[m] = {a.h: e}
        steps[m][h2] = eps(_timed(build, m, h2, a.t_end)[1], ref)
        print(f"{m}: eps_T {e:.4e} at h = {a.h:g} ({its:.2f} it/step, {lus:.3f} LU/step), "
              f"{steps[m][h2]:.4e} at h = {h2:g}", flush=True)
    cpu = {("lobatto3", a.h): []}
    cpu.update({(m, h): [] for m in labels for h in steps[m]})
    for _ in range(a.reps):
        for key in cpu:
            cpu[key].append(_timed(build, key[0], key[1], a.t_end)[0])
        load.append(os.getloadavg()[0])
    lo = float(np.median(cpu["lobatto3", a.h]))
    print(f"load average (1 min) during the runs: {min(load):.2f}-{max(load):.2f}; CPU medians of {a.reps} runs")
    print(f"lobatto3 h = {a.h:g}: eps_T {e_l:.3e}, CPU {lo:.3f} s")
    for m in labels:
        (h1, e1), (h2, e2) = sorted(steps[m].items(), reverse=True)
        c1, c2 = float(np.median(cpu[m, h1])), float(np.median(cpu[m, h2]))
        w = (np.log(e_l) - np.log(e1)) / (np.log(e2) - np.log(e1))
        c_eq = float(np.exp(np.log(c1) + w * (np.log(c2) - np.log(c1))))
        h_eq = float(np.exp(np.log(h1) + w * (np.log(h2) - np.log(h1))))    # the step with Lobatto's eps_T
        c_h = float(np.median(cpu[m, a.h])) * a.h / h_eq        # the cost per step at h, times the steps at h_eq
        print(f"{m}: h = {h1:g} eps_T {e1:.3e} CPU {c1:.3f} s; h = {h2:g} eps_T {e2:.3e} CPU {c2:.3f} s; "
              f"Lobatto's eps_T at h = {h_eq:.5g}{'' if 0.0 <= w <= 1.0 else ' (extrapolated)'}: CPU {c_eq:.3f} s, "
              f"ratio at equal eps_T {c_eq / lo:.3f} (with the cost per step at h {c_h / lo:.3f}; at equal h "
              f"{float(np.median(cpu[m, a.h])) / lo:.3f})", flush=True)


def stages(a):
    for k in a.k:
        r = run_one(a.problem, f"energy-collocation-k{k}", a.h, a.t_end, a.out)
        print(f"{a.problem} h = {a.h:g} k = {k}: {'ok' if r['ok'] else 'FAILED ' + r['message']}, energy spread "
              f"after the load {r['dE']:.2e} (relative), {r['its']:.2f} its/step, CPU {r['cpu']:.1f} s", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("what", choices=("wp", "long", "stages", "ratio", "equal"))
    ap.add_argument("--problem", default="B2-4", choices=tuple(PROBLEMS))
    ap.add_argument("--methods", nargs="+", default=None)
    ap.add_argument("--t-end", type=float, default=None)
    ap.add_argument("--h", type=float, default=1e-2)
    ap.add_argument("--k", type=int, nargs="+", default=[4, 5, 6])
    ap.add_argument("--steps", type=int, default=10_000)
    ap.add_argument("--reps", type=int, default=3, help="ratio: runs of each method")
    ap.add_argument("--elements", type=int, default=1)
    ap.add_argument("--silent-stages", default="auto", type=lambda x: x if x == "auto" else int(x),
                    help="long: k (default 'auto')")
    ap.add_argument("--cases", nargs="+", default=None, help="long: only these (e.g. SQ3D SQ3D-continuum)")
    ap.add_argument("--energy-defect", default="auto", help="long: energy_defect ('auto', 'rule', 'potential')")
    ap.add_argument("--h-ref", type=float, default=None, help="step of the reference run (default: a quarter of the finest)")
    ap.add_argument("--hs", type=float, nargs="+", default=None, help="wp: only these steps of the sweep")
    ap.add_argument("--ref-method", default="energy-collocation", help="wp: the reference run's method label")
    ap.add_argument("--out", type=Path, default=Path("out/energy_collocation"))
    a = ap.parse_args(argv)
    if a.t_end is None:
        a.t_end = 4.0 if a.problem.startswith("B2") else 5.0
    {"wp": work_precision, "long": long_runs, "stages": stages, "ratio": ratio, "equal": equal}[a.what](a)


if __name__ == "__main__":
    main()
