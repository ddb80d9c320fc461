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
the multiplier outputs (hub torque, slider normal force, crank torque, B7's pivot force as its mean over each
output interval; each output relative
to the reference's largest value, the largest over the kind), the position drift ``max |g|`` and the
velocity drift ``max |G v + g_t|`` over the outputs, on B7 the energy error ``max |E - E0|`` relative to
the largest kinetic energy and the drift of the angular momentum about the vertical, the CPU time; per
integrator the observed orders of ``q`` and ``lambda`` from its asymptotic runs only
(:func:`ancfdae.studies._orders.asymptotic_order`). The cases run longest first (:data:`METHOD_COST`), so
that the workers of a parallel run finish together; the case itself is defined in
:mod:`ancfdae.studies._multibody_cases`.

Run: ``ancfdae study multibody [--quick] [--out DIR] [--jobs N]``.
"""
from __future__ import annotations

import math
import numbers
import sys

import numpy as np

from ._cli import Option, main as cli_main
from ._common import Case, OptionError, output_dir, run_cases, settings
from ._multibody_cases import (INVARIANTS, MODELS, MULTIPLIER_OUTPUTS, benchmark, fixed_step, outputs,
                               run_case)
from ._orders import ORDER_TOL, asymptotic_order
from ._tables import cell, errors_note, markdown_table

__all__ = ["run", "run_case", "summarize", "FULL", "QUICK", "CLI_OPTIONS", "constrained_methods"]

#: the reference method per benchmark and how much finer than the finest step it runs (its check: at twice
#: its step). Lobatto IIIA-3 where it runs the whole span: B7 16 times finer (3.125e-4 s), where its
#: interval-mean pivot force has converged to 9.1e-4 against the check (4 times finer: 6.2e-3; docs/studies.md,
#: "B7: the pivot force"); B6 2 times finer (bound 8.4e-7, the finest errors of Lobatto IIIA-3 and
#: energy-collocation: those runs then enter no order; 5e-5 s stopped at t = 0.11 s before the GGL floor
#: covered the constraint rows). On the 30-s B5 every method without numerical dissipation fails
#: (docs/studies.md, "B5: why the non-dissipative methods fail"), so B5's reference is generalized-alpha 8x finer.
REFERENCE = {"B5": ("generalized-alpha", 8), "B6": ("lobatto3", 2), "B7": ("lobatto3", 16)}
#: a run whose error is below FLOOR times the reference's error bound does not enter an order
FLOOR = 10.0
#: CPU per step relative to generalized-alpha, measured in the full run at e1b9706 (B6 and B7, finest
#: steps); IDA: one run per tolerance as 40 of generalized-alpha's finest runs. Only orders the cases
#: (longest first, so that two workers end together) and weighs the progress bar.
METHOD_COST = {"lobatto3": 2.0, "lobatto2": 1.5, "energy-momentum": 6.0, "energy-collocation": 25.0,
               "ida": 40.0}

#: IDA's tolerances per benchmark, chosen by measurement (docs/studies.md): one each, at an error comparable to
#: the fixed-step runs'. B5 none: at rtol 1e-3 IDA's error over the 30 s is 0.18 (generalized-alpha at
#: h = 0.025: 5e-3) for 226 s CPU, at 1e-4 0.039 for 895 s (to 10 s: 2125 steps of ~2 ms, 14 % error;
#: generalized-alpha 400 steps, 0.5 %). B6 1e-3: 6.3e-3 (the second-order methods at h = 2e-4: 6.5e-3 ...
#: 7.5e-3) for 145 s. B7 1e-3: 8.0e-5 for 52 s, 62046 steps (at 1e-2: 0.29 in 339 steps; IDA resolves the
#: rod's axial vibration once the tolerance is below its amplitude).
RTOLS = {"B5": (), "B6": (1e-3,), "B7": (1e-3,)}
FULL = dict(benchmarks=tuple(MODELS), integrators=None, steps={"B5": (0.1, 0.05, 0.025), "B6": (8e-4, 4e-4, 2e-4),
            "B7": (0.02, 0.01, 0.005)}, rtols=RTOLS, t_end={"B5": 30.0, "B6": 0.5, "B7": 5.0},
            refine=None, n_out={"B5": 301, "B6": 126, "B7": 251})
#: FULL's n_out puts every output time on the step grid of every step (B5 0.1 s, B6 4e-3 s, B7 0.02 s): a time
#: inside a step is the stepper's interpolant, whose error (and energy) is not the method's (with n_out = 201
#: B7 energy-momentum showed an "energy error" 6.9e-2 at h = 0.02, 1.8e-14 at 0.005, on the grid)
QUICK = dict(steps={"B5": (0.1, 0.05), "B6": (4e-4, 2e-4), "B7": (0.02, 0.01)},
             rtols={"B5": (1e-3, 1e-4), "B6": (1e-3, 1e-4), "B7": (1e-3, 1e-4)},
             t_end={"B5": 4.0, "B6": 0.06, "B7": 0.2}, refine=None, n_out=11)
CLI_OPTIONS = [
    Option("benchmarks", str, "benchmarks", nargs="+", choices=tuple(MODELS)),
    Option("integrators", str, "integrators (default: every method that handles constraints)", nargs="+"),
]


def constrained_methods() -> list[str]:
    """The registered methods that run constrained models (``handles_constraints``)."""
    from ancfdae.simulate import METHODS
    return [m for m, cls in METHODS.items() if getattr(cls, "handles_constraints", False)]


def _runs_at(method: str, h: float, methods, steps) -> bool:
    """Whether the sweep runs ``method`` at the step ``h``."""
    return method in methods and fixed_step(method) and any(np.isclose(h, x, rtol=1e-9) for x in steps)


def _rtols_of(rtols, bm) -> tuple:
    """IDA's tolerances on ``bm``: ``rtols`` per benchmark (a dict) or the same for all (a sequence)."""
    if isinstance(rtols, dict):
        return tuple(rtols.get(bm, ()))
    return tuple(rtols)


def _per_benchmark(value, bm):
    """``value[bm]`` for a per-benchmark option (a dict), else ``value``."""
    return value[bm] if isinstance(value, dict) else value


def _check_per_benchmark(o: dict) -> None:
    """``steps``, ``t_end`` and ``n_out`` for every benchmark of the run: the common option check
    (:func:`._common.settings`) sees no numbers inside a dict, so a dict is checked here, before any work.

    Raises
    ------
    OptionError
        Naming the option, the rule and the value.
    """
    def positive(x):
        return not isinstance(x, bool) and isinstance(x, numbers.Real) and math.isfinite(x) and x > 0

    def count(x):
        return not isinstance(x, bool) and isinstance(x, numbers.Integral) and x >= 2

    rules = {"steps": (lambda x: isinstance(x, (list, tuple)) and len(x) > 0 and all(positive(y) for y in x),
                       "a non-empty sequence of positive finite steps per benchmark"),
             "t_end": (positive, "a positive finite end time per benchmark"),
             "n_out": (count, "an integer >= 2 (output times, both ends included), for all or per benchmark")}
    for key, (ok, rule) in rules.items():
        value = o[key]
        per = value if isinstance(value, dict) else (None if key != "n_out" else {bm: value for bm in o["benchmarks"]})
        if per is None:
            raise OptionError(f"`{key}` must be a dict of {rule}, got {value!r}.")
        bad = [bm for bm in o["benchmarks"] if bm not in per or not ok(per[bm])] + [k for k in per if k not in MODELS]
        if bad:
            raise OptionError(f"`{key}` must be {rule} {list(o['benchmarks'])}; wrong or missing for {bad}: "
                              f"got {value!r}.")


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
        rows.append({k: r.get(k) for k in ("benchmark", "integrator", "h", "status", "t_fail", "cpu", "drift_q",
                                            "drift_v", "energy_error", "momentum_error")}
                    | {"error": e["q"], "error_lam": e["lam"]})
    orders, orders_lam, local = {}, {}, {}
    for bm in refs:
        for m in methods:
            mine = [r for r in rows if r["benchmark"] == bm and r["integrator"] == m]
            for key, kind, dest in (("error", "q", orders), ("error_lam", "lam", orders_lam)):
                p, loc = asymptotic_order([(r["h"], r[key]) for r in mine],
                                          float(np.nan_to_num(floors[bm][kind], nan=0.0)), FLOOR)
                local[(bm, m, kind)] = loc
                if p is not None:
                    dest[(bm, m)] = p
    return rows, orders, orders_lam, refs, floors, local


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
    rtols : dict or sequence of float
        The relative tolerances of the variable-step methods (IDA), in place of the steps: per benchmark
        (default :data:`RTOLS`, chosen by measurement) or one sequence for every benchmark.
    refine : int, optional
        The reference runs its method (:data:`REFERENCE`) at the finest step divided by ``refine`` (its check
        at twice that); default: the benchmark's own in :data:`REFERENCE`.
    n_out : int or dict
        Output times (equally spaced, both ends included), per benchmark or for all; keep them on the step
        grid of every step (see :data:`FULL`).
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
    bad = [x for bm in o["benchmarks"] for x in _rtols_of(o["rtols"], bm)
           if isinstance(x, bool) or not isinstance(x, (int, float)) or not (np.isfinite(x) and x > 0)]
    if bad:
        raise OptionError(f"`rtols` must be positive finite tolerances (per benchmark or for all), got {o['rtols']!r}.")
    _check_per_benchmark(o)
    path = output_dir("multibody", out, quick) if (plots or out is not None) else None
    cases, finest = [], {bm: min(o["steps"][bm]) for bm in o["benchmarks"]}
    for bm in o["benchmarks"]:
        base = {"benchmark": bm, "t_end": o["t_end"][bm], "n_out": _per_benchmark(o["n_out"], bm)}
        method, refine_bm = REFERENCE[bm]
        h_ref = finest[bm] / (o["refine"] or refine_bm)
        # the check is the reference method's own run at 2 h_ref when the sweep has it (refine = 2)
        roles = [(1, "main")] + ([] if _runs_at(method, 2 * h_ref, methods, o["steps"][bm]) else [(2, "check")])
        cases += [Case(dict(base, integrator=method, h=k * h_ref, reference=role),
                       label=f"{bm} reference ({role}) h={k * h_ref:g}") for k, role in roles]
        for m in methods:
            xs, name = (o["steps"][bm], "h") if fixed_step(m) else (_rtols_of(o["rtols"], bm), "rtol")
            cases += [Case(dict(base, integrator=m, h=x, reference=False), label=f"{bm} {m} {name}={x:g}")
                      for x in xs]

    def cost(c):
        """Relative CPU of a case: its steps times :data:`METHOD_COST` (IDA: as at the finest step)."""
        h = c["h"] if fixed_step(c["integrator"]) else finest[c["benchmark"]]
        return METHOD_COST.get(c["integrator"], 1.0) * c["t_end"] / h

    sweep = run_cases(run_case, cases, out=path, executor=executor, jobs=jobs, reduce=outputs, name="multibody",
                      progress=progress, cost=cost)
    records = sweep.finished()
    rows, orders, orders_lam, refs, floors, local = summarize(records, methods)
    table = _table(rows, orders, orders_lam, local, refs, floors, sweep.errors) + _linear_b5(refs)
    figures = {}
    if plots:
        from ._multibody_plots import plot_multibody
        figures = plot_multibody(records, rows, refs, methods, path)
        (path / "multibody.md").write_text("# Flexible multibody benchmarks B5-B7\n\n" + table)
    return {"rows": rows, "orders": orders, "orders_lam": orders_lam, "references": refs,
            "reference_errors": floors, "records": records, "errors": sweep.errors,
            "reused": sweep.reused, "figures": figures, "table": table, "path": path}


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


def _order_cell(orders, local, bm, m, kind) -> str:
    """The order where the runs are asymptotic, else the local orders in parentheses ("-": fewer than 2 runs)."""
    p = orders.get((bm, m))
    if p is not None:
        return f"{p:.2f}"
    loc = local.get((bm, m, kind)) or []
    return "(" + ", ".join(f"{x:.2f}" for x in loc) + ")" if loc else "-"


def _status_cell(row) -> str:
    """The run's status, with the time of the step that failed (where the run stopped)."""
    t_fail = row.get("t_fail")
    return f"{row['status']} at {t_fail:.4g} s" if row["status"] != "success" and t_fail is not None else row["status"]


def _table(rows, orders, orders_lam, local, refs, floors, errors) -> str:
    headers = ["benchmark", "integrator", "h (s) or rtol", "status", "error q", "order q", "error lambda",
               "order lambda", "max |g|", "max |G v + g_t|", "energy error (B7)", "L_z drift (B7)", "CPU (s)"]
    body = [[r["benchmark"], r["integrator"], f"{r['h']:g}", _status_cell(r), cell(r["error"], ".2e"),
             _order_cell(orders, local, r["benchmark"], r["integrator"], "q"), cell(r["error_lam"], ".2e"),
             _order_cell(orders_lam, local, r["benchmark"], r["integrator"], "lam"), cell(r["drift_q"], ".1e"),
             cell(r["drift_v"], ".1e"), cell(r["energy_error"], ".1e"), cell(r["momentum_error"], ".1e"),
             f"{r['cpu']:.1f}"] for r in rows]
    text = "References: " + ", ".join(
        f"{bm} {r['integrator']} at h = {r['h']:g} s (differs from the run at 2h by {cell(floors[bm]['q'], '.1e')} in q, "
        f"{cell(floors[bm]['lam'], '.1e')} in lambda)" for bm, r in refs.items()) + \
        ". Errors: largest over the position (q) or multiplier (lambda: hub torque, slider normal force, crank " \
        "torque; B7: the pivot force's mean over each output interval, from the momentum balance) outputs, " \
        "each relative to the reference's largest value. Order: only from " \
        f"asymptotic runs (studies/_orders.py): runs whose error exceeds {FLOOR:g} times the reference's " \
        "difference from its check, the finest chain of at least two successive local orders (log error " \
        f"ratio over log h ratio; IDA: over log rtol ratio) that agree within {ORDER_TOL:.0%}, fitted; " \
        "otherwise the local orders are given in parentheses.\n\n"
    return text + markdown_table(headers, body) + errors_note(errors)


if __name__ == "__main__":     # python -m ancfdae.studies.multibody: the same as `ancfdae study multibody`
    raise SystemExit(cli_main(sys.modules[__name__]))
