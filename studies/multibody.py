"""Flexible multibody benchmarks B5-B7 with every integrator that handles constraints.

B5 spin-up of a flexible beam (Simo & Vu-Quoc 1986), B6 flexible slider-crank and B7 flexible spatial pendulum
with a spinning rigid payload (:mod:`ancfdae.studies._multibody_models`), each run by every registered
integrator that declares ``handles_constraints`` at a sequence of steps. The reference of each model is
Lobatto IIIA-3 (order 4 in the positions) at a step ``refine`` times finer than the finest (B5, where it
fails: generalized-alpha 8 times finer; :data:`REFERENCE`), checked against a second run of the same
method at twice its step: their difference bounds the reference's own error (the
table gives it), and a run whose error is within :data:`FLOOR` times that bound does not enter an order
(a reference of a second-order method, as generalized-alpha at h/2 was, is as coarse as the runs of the
fourth-order methods, whose orders then meant nothing). Per run: the errors of the position outputs and of
the multiplier outputs (hub torque, slider normal force, crank torque, pivot force; each output relative
to the reference's largest value, the largest over the kind), the position drift ``max |g|`` and the
velocity drift ``max |G v + g_t|`` over the outputs, on B7 the energy error ``max |E - E0|`` relative to
the largest kinetic energy and the drift of the angular momentum about the vertical, the CPU time; per
integrator the observed orders of ``q`` and ``lambda`` (least-squares slopes of log error against log step).

Run: ``ancfdae study multibody [--quick] [--out DIR] [--jobs N]``.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

from ancfdae.simulate import METHODS

from ._cli import Option, main as cli_main
from ._common import Case, OptionError, output_dir, run_cases, settings
from ._multibody_models import BUILDERS
from ._tables import cell, errors_note, markdown_table

__all__ = ["run", "run_case", "summarize", "FULL", "QUICK", "CLI_OPTIONS", "constrained_methods"]

#: benchmark -> (element, elements, builder options)
MODELS = {"B5": ("BE2D", 8, {"w_s": 4.0}), "B6": ("BE2D", 8, {}), "B7": ("Cable3D", 4, {"E": 5.0e7})}
#: the outputs that are multipliers (reactions); the others but the invariants are positions
MULTIPLIER_OUTPUTS = ("hub_torque", "slider_normal_force", "crank_torque", "pivot_force_z")
INVARIANTS = ("energy", "angular_momentum_z")
#: the reference method per benchmark and how much finer than the finest step it runs (its check: at twice
#: its step). Lobatto IIIA-3 where it runs the whole span; on the 30-s B5 every method without numerical
#: dissipation fails (Lobatto IIIA-3 at h = 0.0125 at 9.7 s, Lobatto IIIA-2 and Newmark at 9.6-12.6 s:
#: Newton diverges), so B5's reference is generalized-alpha 8 times finer than the finest step.
REFERENCE = {"B5": ("generalized-alpha", 8), "B6": ("lobatto3", 2), "B7": ("lobatto3", 2)}
#: a run whose error is below FLOOR times the reference's error bound does not enter an order
FLOOR = 10.0
#: options per method (beyond h)
OPTIONS = {"hht": {"alpha": 0.05}, "generalized-alpha": {"rho_inf": 0.8}}

FULL = dict(benchmarks=tuple(MODELS), integrators=None, steps={"B5": (0.1, 0.05, 0.025), "B6": (8e-4, 4e-4, 2e-4),
            "B7": (0.02, 0.01, 0.005)}, rtols=(1e-3, 1e-4), t_end={"B5": 30.0, "B6": 0.5, "B7": 5.0},
            refine=None, n_out=51)
QUICK = dict(steps={"B5": (0.1, 0.05), "B6": (4e-4, 2e-4), "B7": (0.02, 0.01)}, rtols=(1e-3, 1e-4),
             t_end={"B5": 4.0, "B6": 0.06, "B7": 0.2}, refine=None, n_out=11)
CLI_OPTIONS = [
    Option("benchmarks", str, "benchmarks", nargs="+", choices=tuple(MODELS)),
    Option("integrators", str, "integrators (default: every method that handles constraints)", nargs="+"),
]


def constrained_methods() -> list[str]:
    """The registered methods that run constrained models (``handles_constraints``)."""
    return [m for m, cls in METHODS.items() if getattr(cls, "handles_constraints", False)]


def _fixed_step(method: str) -> bool:
    """Whether ``method`` takes a step ``h`` (else it is variable-step and runs at the tolerances ``rtols``)."""
    return bool(getattr(METHODS[method], "fixed_step", True))


def _runs_at(method: str, h: float, methods, steps) -> bool:
    """Whether the sweep runs ``method`` at the step ``h``."""
    return method in methods and _fixed_step(method) and any(np.isclose(h, x, rtol=1e-9) for x in steps)


def _benchmark(name: str, t_end: float):
    element, n, opts = MODELS[name]
    opts = dict(opts, t_end=t_end) if name == "B7" else opts
    return BUILDERS[name](element, n, **opts)


def run_case(case: dict) -> dict:
    """One run: ``case = {benchmark, integrator, h, t_end, n_out}``; ``h`` is ``rtol`` for a variable-step method."""
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from ancfdae import simulate
    b = _benchmark(case["benchmark"], case["t_end"])
    t_eval = np.linspace(0.0, case["t_end"], case["n_out"])
    t0 = time.process_time()
    step = {"h": case["h"]} if _fixed_step(case["integrator"]) else {"rtol": case["h"]}
    res = simulate(b.system, (0.0, case["t_end"]), case["integrator"], t_eval=t_eval, **step,
                   **OPTIONS.get(case["integrator"], {}))
    return {"result": res, "cpu": time.process_time() - t0, **case}


def outputs(record: dict) -> dict:
    """The benchmark's outputs, the constraint drift and (B7) the invariants of a stored run."""
    res = record["result"]
    b = _benchmark(record["benchmark"], record["t_end"])
    s = b.system
    out = {k: np.asarray(f(res.t, res.q, res.v, res.lam)) for k, f in b.outputs.items()}
    g = np.array([s.constraints(t, q) for t, q in zip(res.t, res.q)])
    gv = np.array([s.constraint_jacobian(t, q) @ v + s.constraint_rates(t, q, v)[0]
                   for t, q, v in zip(res.t, res.q, res.v)])
    rec = {k: v for k, v in record.items() if k != "result"}
    rec.update(t=res.t, out=out, status=res.status, message=res.message,
               drift_q=float(np.abs(g).max()) if g.size else float("nan"),
               drift_v=float(np.abs(gv).max()) if gv.size else float("nan"))
    if "energy" in out and res.t.size:
        T = np.array([s.energy(t, q, v).kinetic for t, q, v in zip(res.t, res.q, res.v)])
        rec["energy_error"] = float(np.abs(out["energy"] - out["energy"][0]).max() / T.max())
        L = out["angular_momentum_z"]
        rec["momentum_error"] = float(np.abs(L - L[0]).max() / abs(L[0]))
    return rec


def _errors(rec, ref) -> dict:
    """``{"q": ..., "lam": ...}``: the largest error of the position and of the multiplier outputs against
    the reference, each output relative to the reference's largest value (NaN when a run stopped early)."""
    out = {}
    for kind in ("q", "lam"):
        keys = [k for k in ref["out"] if k not in INVARIANTS and (k in MULTIPLIER_OUTPUTS) == (kind == "lam")]
        if rec["t"].size != ref["t"].size or not keys:
            out[kind] = float("nan")
            continue
        out[kind] = float(max(np.abs(rec["out"][k] - ref["out"][k]).max() / max(np.abs(ref["out"][k]).max(), 1e-300)
                              for k in keys))
    return out


def _order(points, floor) -> float | None:
    """Least-squares slope of log error against log step over the points above ``FLOOR * floor``."""
    pts = [(h, e) for h, e in points if np.isfinite(e) and e > FLOOR * floor]
    if len(pts) < 2:
        return None
    h, e = np.log(np.array(pts)).T
    return float(np.polyfit(h, e, 1)[0])


def summarize(records: list[dict], methods) -> tuple:
    """Rows, orders of q and lambda, references and the references' error bounds of finished records
    (those :func:`outputs` made; also from the stored cases of an interrupted run)."""
    refs = {r["benchmark"]: r for r in records if r["reference"] == "main"}
    checks = {r["benchmark"]: r for r in records if r["reference"] == "check" or (
        not r["reference"] and r["benchmark"] in refs and r["integrator"] == refs[r["benchmark"]]["integrator"]
        and np.isclose(r["h"], 2 * refs[r["benchmark"]]["h"], rtol=1e-9))}
    # the reference's error bound per kind: its difference from the check (NaN without the check)
    floors = {bm: _errors(checks[bm], ref) if bm in checks else {"q": float("nan"), "lam": float("nan")}
              for bm, ref in refs.items()}
    rows = []
    for r in records:
        if r["reference"] or r["benchmark"] not in refs:
            continue
        e = _errors(r, refs[r["benchmark"]])
        rows.append({k: r.get(k) for k in ("benchmark", "integrator", "h", "status", "cpu", "drift_q", "drift_v",
                                            "energy_error", "momentum_error")} | {"error": e["q"], "error_lam": e["lam"]})
    orders, orders_lam = {}, {}
    for bm in refs:
        for m in methods:
            mine = [r for r in rows if r["benchmark"] == bm and r["integrator"] == m]
            for key, kind, dest in (("error", "q", orders), ("error_lam", "lam", orders_lam)):
                p = _order([(r["h"], r[key]) for r in mine], np.nan_to_num(floors[bm][kind], nan=0.0))
                if p is not None:
                    dest[(bm, m)] = p
    return rows, orders, orders_lam, refs, floors


def run(benchmarks=None, integrators=None, steps=None, rtols=None, t_end=None, refine=None, n_out=None,
        quick: bool = False, out=None, jobs: int | None = None, executor=None, plots: bool = True,
        progress: bool = True) -> dict:
    """Run the study. Options left None take :data:`FULL` (:data:`QUICK` with ``quick``).

    Parameters
    ----------
    benchmarks : sequence of str
        Of ``B5``, ``B6``, ``B7``.
    integrators : sequence of str, optional
        Default: :func:`constrained_methods`.
    steps, t_end : dict
        Steps and end time per benchmark.
    rtols : sequence of float
        The relative tolerances of the variable-step methods (IDA), in place of the steps (IDA costs
        about 10 times generalized-alpha's CPU per decade of rtol on B6: 6 s at 1e-4, 72 s at 1e-5 for the
        quick 0.05 s; hence 1e-3 and 1e-4).
    refine : int, optional
        The reference runs its method (:data:`REFERENCE`) at the finest step divided by ``refine`` (its check
        at twice that); default: the benchmark's own in :data:`REFERENCE`.
    n_out : int
        Output times (equally spaced, both ends included).
    quick, out, jobs, executor, plots, progress
        The sweep options of every study (:mod:`ancfdae.studies._common`).

    Returns
    -------
    dict
        ``rows`` (one per run: errors of q and lambda, drifts, invariants, CPU), ``orders`` and
        ``orders_lam`` (per benchmark and integrator, q and lambda), ``reference_errors`` (per benchmark and
        kind: the reference's difference from its check) and the keys of every study.
    """
    o = settings(FULL, QUICK, quick, dict(benchmarks=benchmarks, integrators=integrators, steps=steps,
                                          rtols=rtols, t_end=t_end, refine=refine, n_out=n_out))
    methods = list(o["integrators"] or constrained_methods())
    unknown = [m for m in methods if m not in constrained_methods()]
    if unknown or not methods:
        raise OptionError(f"`integrators` must name methods that handle constraints {constrained_methods()}, "
                          f"got {methods}.")
    path = output_dir("multibody", out, quick) if (plots or out is not None) else None
    cases = []
    for bm in o["benchmarks"]:
        base = {"benchmark": bm, "t_end": o["t_end"][bm], "n_out": o["n_out"]}
        method, refine_bm = REFERENCE[bm]
        h_ref = min(o["steps"][bm]) / (o["refine"] or refine_bm)
        # the check is the reference method's own run at 2 h_ref when the sweep has it (refine = 2)
        roles = [(1, "main")] + ([] if _runs_at(method, 2 * h_ref, methods, o["steps"][bm]) else [(2, "check")])
        cases += [Case(dict(base, integrator=method, h=k * h_ref, reference=role),
                       label=f"{bm} reference ({role}) h={k * h_ref:g}", cost=4 * base["t_end"] / (k * h_ref))
                  for k, role in roles]
        for m in methods:
            xs, name = (o["steps"][bm], "h") if _fixed_step(m) else (o["rtols"], "rtol")
            cases += [Case(dict(base, integrator=m, h=x, reference=False), label=f"{bm} {m} {name}={x:g}",
                           cost=base["t_end"] / (x if name == "h" else h_ref)) for x in xs]
    sweep = run_cases(run_case, cases, out=path, executor=executor, jobs=jobs, reduce=outputs, name="multibody",
                      progress=progress, cost=lambda c: c["cost"])
    records = sweep.finished()
    rows, orders, orders_lam, refs, floors = summarize(records, methods)
    table = _table(rows, orders, orders_lam, refs, floors, sweep.errors) + _linear_b5(refs)
    if plots:
        (path / "multibody.md").write_text("# Flexible multibody benchmarks B5-B7\n\n" + table)
    return {"rows": rows, "orders": orders, "orders_lam": orders_lam, "references": refs,
            "reference_errors": floors, "records": records, "errors": sweep.errors,
            "reused": sweep.reused, "figures": {}, "table": table, "path": path}


def _linear_b5(refs) -> str:
    """B5 beside the conventional linear beam (:mod:`._linear_beam`, no geometric stiffening)."""
    if "B5" not in refs:
        return ""
    from ._linear_beam import first_bending_frequency, linear_spinup
    ref = refs["B5"]
    w_lin, w = np.abs(linear_spinup(ref["t"])), np.abs(ref["out"]["tip_deflection"])
    return (f"\n\nB5 against the linear beam (small-strain stiffness in the hub frame, no geometric stiffening; "
            f"first bending frequency {first_bending_frequency():.3f} rad/s, below the hub's final 4 rad/s): "
            f"largest |tip deflection| over [0, {ref['t'][-1]:g}] s {w_lin.max():.3g} m (at "
            f"{ref['t'][int(np.argmax(w_lin))]:g} s), the ANCF reference's {w.max():.3g} m.\n")


def _table(rows, orders, orders_lam, refs, floors, errors) -> str:
    headers = ["benchmark", "integrator", "h (s) or rtol", "status", "error q", "order q", "error lambda",
               "order lambda", "max |g|", "max |G v + g_t|", "energy error (B7)", "L_z drift (B7)", "CPU (s)"]
    body = [[r["benchmark"], r["integrator"], f"{r['h']:g}", r["status"], cell(r["error"], ".2e"),
             cell(orders.get((r["benchmark"], r["integrator"])), ".2f"), cell(r["error_lam"], ".2e"),
             cell(orders_lam.get((r["benchmark"], r["integrator"])), ".2f"), cell(r["drift_q"], ".1e"),
             cell(r["drift_v"], ".1e"), cell(r["energy_error"], ".1e"), cell(r["momentum_error"], ".1e"),
             f"{r['cpu']:.1f}"] for r in rows]
    text = "References: " + ", ".join(
        f"{bm} {r['integrator']} at h = {r['h']:g} s (differs from the run at 2h by {cell(floors[bm]['q'], '.1e')} in q, "
        f"{cell(floors[bm]['lam'], '.1e')} in lambda)" for bm, r in refs.items()) + \
        ". Errors: largest over the position (q) or multiplier (lambda: hub torque, slider normal force, crank " \
        "torque, pivot force) outputs, each relative to the reference's largest value; order: slope of log " \
        f"error against log h (IDA: against log rtol) over the runs whose error exceeds {FLOOR:g} times the " \
        "reference's difference from its check.\n\n"
    return text + markdown_table(headers, body) + errors_note(errors)


if __name__ == "__main__":     # python -m ancfdae.studies.multibody: the same as `ancfdae study multibody`
    raise SystemExit(cli_main(sys.modules[__name__]))
