"""Exudyn's side of the multibody benchmarks: converged references, self-convergence, CPU times.

``python -m benchmarks.multibody_peer {references,convergence,timings} [--case b5-4 b5-10 b6]
[--repeats 3] [--save] [--newton full]``

Cases (benchmarks B5-B7; peer models in ``_exudyn_spinup``, ``_exudyn_slider_crank`` and
``_exudyn_spatial_pendulum``): ``b5-4`` and ``b5-10`` the spin-up at w_s = 4 and 10 rad/s, ``b6``
the slider-crank and ``b7`` the spatial pendulum with Cable3D (revision 1 each).

references
    The converged reference of each case: Richardson extrapolation (order 2) of two
    generalized-alpha runs on a fine mesh with steps h and h/2, printed at a few times, with the
    difference between the two runs and the extrapolation's change as error estimates. B5 takes
    minutes, so ``--save`` stores it (``tests/data/exudyn_b5_reference.npz``, sampled every 0.01 s)
    and later commands load it; B6 and B7 are recomputed (about 10 s and 1 min).
convergence
    Self-convergence: max differences over the samples between successive meshes (fixed h) and
    between successive steps (fixed mesh, both integrators), with the observed orders; Newton
    absolute tolerance as for the reference (B6: 1e-8, below which the multipliers of the finest
    steps are not polluted by the Newton tolerance).
timings
    Median CPU time (``time.process_time`` of the solve call; wall time beside it) of ``--repeats``
    runs per integrator and step on the timing mesh, with each run's max error against the
    reference; ``--newton full`` times Exudyn's full instead of its modified Newton. Failed or
    truncated runs are reported, never timed.
"""
from __future__ import annotations

import argparse
import pathlib

import numpy as np

from ._exudyn_base import _exu, available, module_variant
from ._exudyn_constrained import INTEGRATORS, observed_orders, richardson
from ._exudyn_slider_crank import slider_crank
from ._exudyn_spatial_pendulum import spatial_pendulum
from ._exudyn_spinup import spinup

DATA = pathlib.Path(__file__).resolve().parents[1] / "tests" / "data" / "exudyn_b5_reference.npz"

#: per case: runner and its fixed arguments; compared channels; report times; reference mesh, steps
#: and Newton absolute tolerance; convergence ladders; timing mesh and steps.
CASES = {
    "b5-4": dict(run=spinup, kw=dict(w_s=4.0), keys=("deflection", "deflection_root", "torque"),
                 times=(2.5, 5.0, 7.5, 10.0, 15.0, 20.0, 25.0, 30.0),
                 ref=dict(n=32, h=(6.25e-4, 3.125e-4), atol=1e-6),
                 mesh=((4, 8, 16, 32), 1e-3), steps=(16, (1e-2, 5e-3, 2.5e-3, 1.25e-3, 6.25e-4)),
                 timing=(8, (1e-2, 5e-3, 2.5e-3, 1.25e-3))),
    "b5-10": dict(run=spinup, kw=dict(w_s=10.0), keys=("deflection", "deflection_root", "torque"),
                  times=(2.5, 5.0, 7.5, 10.0, 15.0, 20.0, 25.0, 30.0),
                  ref=dict(n=32, h=(6.25e-4, 3.125e-4), atol=1e-6),
                  mesh=((4, 8, 16, 32), 1e-3), steps=(16, (5e-3, 2.5e-3, 1.25e-3, 6.25e-4)),
                  timing=(16, (5e-3, 2.5e-3, 1.25e-3))),
    "b6": dict(run=slider_crank, kw={}, keys=("mid_deflection", "slider_x", "normal_force", "crank_torque"),
               times=(0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5),
               ref=dict(n=32, h=(2.5e-5, 1.25e-5), atol=1e-8),
               mesh=((2, 4, 8, 16, 32), 2.5e-5), steps=(8, (4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5, 1.25e-5)),
               timing=(8, (2e-4, 1e-4, 5e-5, 2.5e-5))),
    "b7": dict(run=spatial_pendulum, kw={}, keys=("payload", "energy", "momentum_z"),
               times=(0.5, 1.0, 2.0, 3.0, 4.0, 5.0),
               ref=dict(n=8, h=(5e-4, 2.5e-4), atol=1e-6),
               mesh=((2, 4, 8, 16), 5e-4), steps=(4, (2e-3, 1e-3, 5e-4, 2.5e-4)),
               timing=(4, (2e-3, 1e-3, 5e-4))),
}
UNITS = dict(deflection="m", deflection_root="m", torque="N m", mid_deflection="m", slider_x="m",
             normal_force="N", crank_torque="N m", payload="m", energy="J", momentum_z="kg m^2/s")


def _run(case, n, h, integrator="generalized_alpha", atol=1e-6, repeats=1, modified_newton=True):
    c = CASES[case]
    return c["run"](n, h, integrator, newton_atol=atol, repeats=repeats, strict=repeats > 1,
                    modified_newton=modified_newton, **c["kw"])


def compute_reference(case):
    """Richardson-extrapolated reference of ``case`` (module docstring) and its error estimates."""
    c, r = CASES[case], CASES[case]["ref"]
    coarse, fine = (_run(case, r["n"], h, atol=r["atol"], repeats=1) for h in r["h"])
    for run in (coarse, fine):
        if not run["ok"]:
            raise RuntimeError(f"{case}: reference run failed ({run['reason']})")
    ref = richardson(coarse, fine, c["keys"])
    ref["t"] = fine["t"]
    ref["difference"] = {k: float(np.max(np.abs(fine[k] - coarse[k]))) for k in c["keys"]}
    ref["extrapolation"] = {k: float(np.max(np.abs(ref[k] - fine[k]))) for k in c["keys"]}
    return ref


def save_references(refs):
    """Store the B5 references (t and channels per case, sampled every 0.01 s) for later runs."""
    arrays = {"t": refs["b5-4"]["t"], "exudyn_version": np.array(_exu.__version__)}
    for case, ref in refs.items():
        for k in CASES[case]["keys"]:
            arrays[f"{case}/{k}"] = ref[k]
            arrays[f"{case}/{k}/difference"] = ref["difference"][k]
    DATA.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(DATA, **arrays)


def reference(case):
    """The reference of ``case``: loaded from the stored file for B5 if present, else computed."""
    if case.startswith("b5") and DATA.exists():
        with np.load(DATA) as z:
            ref = {k: z[f"{case}/{k}"] for k in CASES[case]["keys"]}
            ref["t"] = z["t"]
            ref["difference"] = {k: float(z[f"{case}/{k}/difference"]) for k in CASES[case]["keys"]}
            ref["source"] = f"stored (Exudyn {z['exudyn_version']})"
        return ref
    ref = compute_reference(case)
    ref["source"] = "computed"
    return ref


def _errors(run, ref, keys):
    return {k: float(np.max(np.abs(run[k] - ref[k]))) for k in keys}


def cmd_references(cases, save):
    refs = {}
    for case in cases:
        c = CASES[case]
        ref = compute_reference(case) if save else reference(case)
        refs[case] = ref
        r = c["ref"]
        print(f"\n{case}: reference {r['n']} elements, generalized-alpha h = {r['h'][0]:g} and {r['h'][1]:g} s"
              f" (Richardson), Newton atol {r['atol']:g}; {ref.get('source', 'computed')}")
        diff = ref["difference"]
        print("  max |run(h/2) - run(h)|: " + ", ".join(f"{k} {v:.2e} {UNITS[k]}" for k, v in diff.items()))
        print("  t [s]   " + "".join(f"{k + ' [' + UNITS[k] + ']':>26}" for k in c["keys"]))
        for tt in c["times"]:
            i = int(np.argmin(np.abs(ref["t"] - tt)))
            print(f"  {ref['t'][i]:6.3f}  " + "".join(_cells(ref[k][i]) for k in c["keys"]))
        for k in c["keys"]:
            if ref[k].ndim == 1:
                i, j = int(np.argmax(np.abs(ref[k]))), int(np.argmax(np.abs(ref[k] - ref[k][0])))
                print(f"  max |{k}| = {abs(ref[k][i]):.8g} {UNITS[k]} at t = {ref['t'][i]:.3f} s;"
                      f" max |{k} - {k}(0)| = {abs(ref[k][j] - ref[k][0]):.3e} at t = {ref['t'][j]:.3f} s")
    if save:
        b5 = {k: v for k, v in refs.items() if k.startswith("b5")}
        if set(b5) == {"b5-4", "b5-10"}:
            save_references(b5)
            print(f"\nstored {DATA.name} ({DATA.stat().st_size / 1e3:.0f} kB)")


def _cells(v):
    """A value as one 26-wide cell, or a vector as its components (3 digits fewer each)."""
    v = np.atleast_1d(v)
    if v.size == 1:
        return f"{float(v[0]):26.10g}"
    return "  " + " ".join(f"{x:.7g}" for x in v)


def _ladder(case, runs, label, ratio=2.0):
    keys = CASES[case]["keys"]
    ok = [(x, r) for x, r in runs if r["ok"]]
    for x, r in runs:
        if not r["ok"]:
            print(f"  {label} {x:g}: FAILED ({r['reason']})")
    if len(ok) < 2:
        return
    diffs = np.array([[np.max(np.abs(a[k] - b[k])) for k in keys] for (_, a), (_, b) in zip(ok[:-1], ok[1:])])
    orders = observed_orders(diffs, ratio) if len(diffs) > 1 else np.zeros((0, len(keys)))
    print(f"  {label + ' pair':>18}" + "".join(f"{k:>16}{'order':>7}" for k in keys))
    for i, ((xa, _), (xb, _)) in enumerate(zip(ok[:-1], ok[1:])):
        cells = "".join(f"{diffs[i, j]:16.3e}{(f'{orders[i - 1, j]:7.2f}' if i else ''):>7}" for j in range(len(keys)))
        print(f"  {f'{xa:g} -> {xb:g}':>18}{cells}")


def cmd_convergence(cases):
    for case in cases:
        c = CASES[case]
        meshes, h = c["mesh"]
        atol = c["ref"]["atol"]
        print(f"\n{case}: mesh refinement at h = {h:g} s (generalized-alpha), Newton atol {atol:g}")
        _ladder(case, [(n, _run(case, n, h, atol=atol)) for n in meshes], "elements")
        n, steps = c["steps"]
        for integ in INTEGRATORS:
            print(f"{case}: step refinement, {n} elements, {integ}")
            _ladder(case, [(h, _run(case, n, h, integ, atol=atol)) for h in steps], "h")


def cmd_timings(cases, repeats, newton):
    for case in cases:
        c, ref = CASES[case], reference(case)
        n, steps = c["timing"]
        print(f"\n{case}: {n} elements, Newton rtol 1e-8 atol 1e-6, {newton} Newton, median of {repeats}"
              f" (errors: max over the samples against the reference)")
        print(f"  {'integrator':<20}{'h [s]':>10}{'cpu [s]':>10}{'wall [s]':>10}{'it/step':>9}"
              + "".join(f"{'err ' + k:>22}" for k in c["keys"]))
        for integ in INTEGRATORS:
            for h in steps:
                try:
                    r = _run(case, n, h, integ, repeats=repeats, modified_newton=newton == "modified")
                except RuntimeError as err:
                    print(f"  {integ:<20}{h:10.2e}  {err}")
                    continue
                e = _errors(r, ref, c["keys"])
                print(f"  {integ:<20}{h:10.2e}{r['cpu']:10.3f}{r['wall']:10.3f}"
                      f"{r['newton_iterations'] / r['steps']:9.2f}" + "".join(f"{e[k]:22.3e}" for k in c["keys"]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("command", choices=("references", "convergence", "timings"))
    ap.add_argument("--case", nargs="+", choices=tuple(CASES), default=list(CASES))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--save", action="store_true", help="recompute the B5 references and store them")
    ap.add_argument("--newton", choices=("modified", "full"), default="modified",
                    help="Exudyn's Newton variant in the timed runs (default: its default, modified)")
    a = ap.parse_args(argv)
    if not available():
        raise SystemExit("exudyn is not installed: pip install '.[benchmark]'")
    print(f"Exudyn {_exu.__version__} ({module_variant()} module), one thread, EigenSparse")
    if a.command == "references":
        cmd_references(a.case, a.save)
    elif a.command == "convergence":
        cmd_convergence(a.case)
    else:
        cmd_timings(a.case, a.repeats, a.newton)


if __name__ == "__main__":
    main()
