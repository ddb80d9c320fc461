"""Integrators compared on B2: work-precision, Newton work per step, energy drift.

The B2 beam (the project's definition; a small mesh of BE2D) and a stiffer variant
(Young's modulus x 100: its axial and bending frequencies x 10) are integrated
over [0, T] by Lobatto IIIA with 3 and 2 stages (modified and full Newton),
Newmark (beta 1/4, gamma 1/2), HHT (alpha 0.05), generalized-alpha
(rho_inf 0.8), energy-momentum and the energy-preserving collocation
(order 4; Newton to round-off, its own default) over a range of step sizes, by Lobatto IIIA (3 stages) over a
range of Newton tolerances, and by IDA (BDF, max order 5)
over a range of relative tolerances. The error of a run is the integrated tip
error of chapter Eq. 115 against a fine reference (Lobatto IIIA, 3 stages,
h = 1.25e-4 s, full Newton, tol 1e-10; T = 4 s, so the pulse -- 2.5 s -- and
1.5 s of free flight), sampled every 0.01 s. Steps divide 2.5 s, so the
load's kink in f'' at the end of the pulse falls on a step boundary.

Reported per run: eps_T, CPU seconds, steps, Newton iterations and LU
factorisations per step, the largest energy-balance error ``max |E - E(0)|``
over the run (the work of the loads integrated along, see EnergyMonitor) and
the drift after the pulse; per method the observed order (log-log fit of
eps_T against h).

IDA runs set ``OMP_NUM_THREADS=1`` (measured: with a busy second core the bundled OpenMP threads made IDA's solvers several times slower); set it in the shell
before the study starts to be sure it takes effect.

Run: ``ancfdae study integrators [--quick] [--out DIR] [--jobs N]``.
"""
from __future__ import annotations

import os
import sys

import numpy as np

from ancfdae.simulate import METHODS as _AVAILABLE

from ._cli import Option, main as cli_main
from ._common import Case, OptionError, output_dir, run_cases, settings
from ._tables import errors_note, markdown_table
from ._flying import T_PULSE, b2_beam, eps_T, regress_order, simulate_case, steady_drift, unpack

__all__ = ["run", "run_case", "METHODS", "FULL", "QUICK", "CLI_OPTIONS"]

#: label -> (simulate method, integrator options, Newton options)
METHODS = {
    "lobatto3": ("lobatto3", {}, {"jacobian": "modified"}),
    "lobatto3-full": ("lobatto3", {}, {"jacobian": "full"}),
    "lobatto2": ("lobatto2", {}, {"jacobian": "modified"}),
    "lobatto2-full": ("lobatto2", {}, {"jacobian": "full"}),
    "newmark": ("newmark", {}, {"jacobian": "modified"}),
    "hht": ("hht", {"alpha": 0.05}, {"jacobian": "modified"}),
    "generalized-alpha": ("generalized-alpha", {"rho_inf": 0.8}, {"jacobian": "modified"}),
}
if "energy-momentum" in _AVAILABLE:
    METHODS["energy-momentum"] = ("energy-momentum", {}, {"jacobian": "modified"})
if "energy-collocation" in _AVAILABLE:   # its own Newton default (round-off: the energy is exact)
    METHODS["energy-collocation"] = ("energy-collocation", {}, None)
MODELS = {"B2": 1.0, "B2-stiff": 100.0}
STEPS = (1e-2, 5e-3, 2.5e-3, 1.25e-3, 6.25e-4)
RTOLS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
#: Newton tolerances of the Lobatto-3 sweep at the middle step (modified Newton; 1e-12 with full Newton)
NEWTON_TOLS = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)

#: defaults of the full study
FULL = dict(models=tuple(MODELS), element="BE2D", n=4, t_end=4.0, dt_out=0.01, steps=STEPS, rtols=RTOLS,
            newton_tols=NEWTON_TOLS, methods=tuple(METHODS), h_ref=1.25e-4)
#: quick mode (the tests): B2 only, 2 elements, 1 s, three steps, two IDA tolerances, no Newton-tolerance sweep
QUICK = dict(models=("B2",), n=2, t_end=1.0, h_ref=6.25e-4, steps=(1e-2, 5e-3, 2.5e-3), rtols=(1e-5, 1e-7),
             newton_tols=())
CLI_OPTIONS = [
    Option("models", str, "problems: B2 and its variant with E x 100", nargs="+", choices=tuple(MODELS)),
    Option("element", str, "element type"),
    Option("n", int, "number of elements"),
    Option("t_end", float, "end time (s)"),
    Option("methods", str, "fixed-step methods", nargs="+", choices=tuple(METHODS)),
    Option("steps", float, "step sizes of the fixed-step methods (s)", nargs="+"),
    Option("rtols", float, "relative tolerances of IDA (none: give 0)", nargs="+"),
    Option("newton_tols", float, "Newton tolerances of the Lobatto-3 sweep (none: give 0)", nargs="+"),
]


def run_case(case: dict) -> dict:
    """One run: ``case = {model, n, method, h | rtol, newton_tol, t_end, dt_out, reference}``."""
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    beam = b2_beam(case["element"], case["n"], E_scale=MODELS[case["model"]])
    if case["method"] == "ida":
        rec = simulate_case(beam, case["t_end"], method="ida", h=None, dt_out=case["dt_out"], rtol=case["rtol"])
    else:
        method, opts, newton = METHODS[case["method"]]
        if newton is not None:
            newton = dict(newton, tol=case.get("newton_tol", 1e-8))
        rec = simulate_case(beam, case["t_end"], method=method, h=case["h"], dt_out=case["dt_out"], newton=newton,
                            **opts)
    rec.update({k: case.get(k) for k in ("model", "method", "h", "rtol", "newton_tol", "reference", "label",
                                         "tol_sweep")})
    return rec


def _cases(models, element, n, t_end, dt_out, steps, rtols, newton_tols, methods, h_ref):
    cases = []
    for model in models:
        base = {"model": model, "element": element, "n": n, "t_end": t_end, "dt_out": dt_out}
        cases.append(dict(base, method="lobatto3-full", h=h_ref, newton_tol=1e-10, reference=True))
        for m in methods:
            cases += [dict(base, method=m, h=h) for h in steps]
        newton_tols = [t for t in newton_tols if t > 0]
        if newton_tols:
            h_mid = steps[len(steps) // 2]
            # modified Newton down to 1e-10; 1e-12 with full Newton (to rule out the Newton error)
            cases += [dict(base, method="lobatto3" if tol >= 1e-10 else "lobatto3-full", h=h_mid, newton_tol=tol,
                           tol_sweep=True) for tol in newton_tols if tol != 1e-8]
        cases += [dict(base, method="ida", rtol=r) for r in rtols if r > 0]
    out = []
    for c in cases:
        what = f"rtol {c['rtol']:g}" if c["method"] == "ida" else f"h {c['h']:g}"
        if c.get("tol_sweep"):
            what += f", Newton tol {c['newton_tol']:g}"
        cost = 1.0 / c["h"] if c["method"] != "ida" else 1.0 / c["rtol"] ** 0.3
        out.append(Case(c, label=f"{c['model']} {c['method']} {what}" + (" (reference)" if c.get("reference") else ""),
                        cost=cost))
    out.sort(key=lambda c: -c["cost"])
    return out


def run(models=None, element=None, n=None, t_end=None, dt_out=None, steps=None, rtols=None, newton_tols=None,
        methods=None, h_ref=None, quick: bool = False, out=None, jobs: int | None = None, executor=None,
        plots: bool = True, progress: bool = True) -> dict:
    """Run the study. Every option left None takes its value from :data:`FULL` (:data:`QUICK` with ``quick``).

    Parameters
    ----------
    models : sequence of {"B2", "B2-stiff"}
        The B2 beam and its variant with E x 100.
    element, n : str, int
        Element type and mesh (default 4 BE2D elements).
    t_end, dt_out : float
        Time span and output interval of the tip and energy logs.
    steps, rtols, newton_tols : sequences of float
        Step sizes of the fixed-step methods, IDA relative tolerances and
        Newton tolerances of the Lobatto-3 tolerance sweep (at the middle step).
    methods : sequence of str
        Keys of :data:`METHODS`.
    h_ref : float
        Step of the reference run.
    quick, out, jobs, executor, plots, progress
        The sweep options of every study (:mod:`ancfdae.studies._common`);
        ``quick``: B2 only, 2 elements, 1 s, three steps, two IDA
        tolerances, no Newton-tolerance sweep.

    Returns
    -------
    dict
        ``rows`` (one per run), ``orders`` (``{model: {method: order}}``, all
        steps) and ``orders_fine`` (the three finest steps), with the keys of
        every study.
    """
    o = settings(FULL, QUICK, quick, dict(models=models, element=element, n=n, t_end=t_end, dt_out=dt_out,
                                          steps=steps, rtols=rtols, newton_tols=newton_tols, methods=methods,
                                          h_ref=h_ref),
                 zero_allowed=("rtols", "newton_tols"))
    unknown = [m for m in o["methods"] if m not in METHODS]
    if unknown:
        raise OptionError(f"`methods` must be keys of {list(METHODS)}, got {unknown}.")
    unknown = [m for m in o["models"] if m not in MODELS]
    if unknown:
        raise OptionError(f"`models` must be keys of {list(MODELS)}, got {unknown}.")
    path = output_dir("integrators", out, quick) if (plots or out is not None) else None
    cases = _cases(o["models"], o["element"], o["n"], o["t_end"], o["dt_out"], o["steps"], o["rtols"],
                   o["newton_tols"], o["methods"], o["h_ref"])
    sweep = run_cases(run_case, cases, out=path, executor=executor, jobs=jobs, reduce=unpack, name="integrators",
                      progress=progress, cost=lambda c: c["cost"])
    records = sweep.finished()
    t_end = o["t_end"]
    refs = {r["model"]: r for r in records if r["reference"]}
    rows = []
    for r in records:
        if r["reference"] or r["model"] not in refs:
            continue
        ref = refs[r["model"]]
        st = r["stats"]
        steps_ = max(st.get("steps", 0), 1)
        bal = r["energy"]["balance"]
        row = {"model": r["model"], "method": r["method"], "h": r["h"], "rtol": r["rtol"],
               "newton_tol": r["newton_tol"] or (1e-8 if r["method"] != "ida" else None), "status": r["status"],
               "cpu": r["cpu"], "steps": st.get("steps", 0), "its_per_step": st.get("newton_iterations", 0) / steps_,
               "lu_per_step": st.get("factorizations", 0) / steps_, "factorizations": st.get("factorizations", 0),
               "eps_T": eps_T(r["t"], r["tip"], ref["t"], ref["tip"]) if r["status"] == "success" else float("nan"),
               "energy_error": float(np.nanmax(np.abs(bal - bal[0]))) if bal.size else float("nan"),
               "drift": steady_drift(r["t"], bal, T_PULSE)["max"] if t_end > T_PULSE else float("nan"),
               "tol_sweep": bool(r.get("tol_sweep")),
               "max_order": r["stats"].get("max_order") or r.get("options", {}).get("max_order")}
        rows.append(row)
    rows.sort(key=lambda r: (r["model"], list(METHODS).index(r["method"]) if r["method"] in METHODS else 99,
                             r["tol_sweep"], -(r["h"] or 0), -(r["rtol"] or 0), -(r["newton_tol"] or 0)))
    orders, orders_fine = {}, {}
    for model in dict.fromkeys(r["model"] for r in rows):
        orders[model], orders_fine[model] = {}, {}
        for m in o["methods"]:
            rs = sorted((r for r in rows if r["model"] == model and r["method"] == m and not r["tol_sweep"]
                         and np.isfinite(r["eps_T"]) and r["eps_T"] > 0), key=lambda r: -r["h"])
            if len(rs) >= 2:
                orders[model][m] = -regress_order([r["h"] for r in rs], [r["eps_T"] for r in rs])
            if len(rs) >= 3:
                orders_fine[model][m] = -regress_order([r["h"] for r in rs[-3:]], [r["eps_T"] for r in rs[-3:]])
    table = _table(rows, orders, orders_fine, refs, t_end, sweep.errors)
    figures = {}
    if plots:
        (path / "integrators.md").write_text("# Integrators on B2: work-precision\n\n" + table)
        figures = _plot(rows, orders, path)
    return {"rows": rows, "orders": orders, "orders_fine": orders_fine, "errors": sweep.errors,
            "reused": sweep.reused, "figures": figures, "table": table, "path": path}


def _table(rows, orders, orders_fine, refs, t_end, errors):
    headers = ["model", "method", "h (s) / rtol", "Newton tol", "eps_T", "CPU (s)", "steps", "its/step", "LU/step",
               "LU total", "max energy error (J)", "drift after pulse (J)", "status"]
    body = []
    for r in rows:
        step = f"rtol {r['rtol']:g}" if r["method"] == "ida" else f"{r['h']:g}"
        body.append([r["model"], r["method"], step, "-" if r["newton_tol"] is None else f"{r['newton_tol']:g}",
                     f"{r['eps_T']:.3e}", r["cpu"], r["steps"], f"{r['its_per_step']:.2f}",
                     f"{r['lu_per_step']:.3f}", r["factorizations"], f"{r['energy_error']:.2e}", f"{r['drift']:.2e}",
                     r["status"]])
    ref = next(iter(refs.values()), None)
    ida = sorted({r["max_order"] for r in rows if r["method"] == "ida" and r["max_order"] is not None})
    text = ""
    if ref is not None:
        text = (f"B2 with {ref['dof']} DOF, T = {t_end:g} s; reference: Lobatto IIIA 3 stages, h = "
                f"{ref['h']:g} s, full Newton tol 1e-10. eps_T: chapter Eq. 115 against the reference. "
                "Lobatto with modified Newton unless '-full'; Newton tolerance 1e-12 with full Newton"
                + (f"; IDA max order {', '.join(map(str, ida))}" if ida else "") + ".\n\n")
    text += markdown_table(headers, body)
    text += "\nObserved order in h (log-log fit of eps_T, all steps): " + "; ".join(
        f"{model}: " + ", ".join(f"{m} {p:.2f}" for m, p in o.items()) for model, o in orders.items()) + "\n"
    text += "\nObserved order in h (three finest steps): " + "; ".join(
        f"{model}: " + ", ".join(f"{m} {p:.2f}" for m, p in o.items()) for model, o in orders_fine.items()) + "\n"
    return text + errors_note(errors)


def _plot(rows, orders, path) -> dict:
    """Work-precision (eps_T against CPU time, the headline) above eps_T against h, one column per model."""
    from ._flying_plots import figure, save
    models = list(dict.fromkeys(r["model"] for r in rows))
    fig, axes = figure(2, len(models), figsize=(6.5 * len(models), 9), squeeze=False)
    methods = list(METHODS) + ["ida"]
    for j, model in enumerate(models):
        for k, m in enumerate(methods):
            rs = [r for r in rows if r["model"] == model and r["method"] == m and not r["tol_sweep"]
                  and np.isfinite(r["eps_T"]) and r["eps_T"] > 0]
            if not rs:
                continue
            kw = dict(ls="--" if m.endswith("-full") else "-", marker="os^v<>Dxp"[k % 9], color=f"C{k}",
                      mfc="none" if m.endswith("-full") else None, ms=8 if m.endswith("-full") else 5)
            axes[0, j].loglog([r["cpu"] for r in rs], [r["eps_T"] for r in rs], label=m, **kw)
            if m != "ida":
                p = orders.get(model, {}).get(m)
                axes[1, j].loglog([r["h"] for r in rs], [r["eps_T"] for r in rs],
                                  label=m + ("" if p is None else f" (fitted order {p:.2f})"), **kw)
        sweep = [r for r in rows if r["model"] == model and r["tol_sweep"] and np.isfinite(r["eps_T"])]
        if sweep:
            axes[0, j].loglog([r["cpu"] for r in sweep], [r["eps_T"] for r in sweep], "k*", ms=9,
                              label="lobatto3 at one h, Newton tol 1e-4 ... 1e-12")
        axes[0, j].set(xlabel="CPU time (s)", ylabel="eps_T against the reference (m s^1/2)",
                       title=f"{model}: work-precision")
        axes[1, j].set(xlabel="step h (s)", ylabel="eps_T against the reference (m s^1/2)",
                       title=f"{model}: error at equal step")
        for ax in axes[:, j]:
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
    save(fig, path, "work_precision")
    return {"work_precision": fig}


if __name__ == "__main__":     # python -m ancfdae.studies.integrators: the same as `ancfdae study integrators`
    raise SystemExit(cli_main(sys.modules[__name__]))
