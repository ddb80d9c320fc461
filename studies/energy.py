"""Energy drift in long free motion: every element x integrator pair (chapter Sect. 5.3).

The planar elements fly as in B2 (force and moment pulse, ends at 2.5 s), the
spatial ones as in B3 (moment hat, ends at 3 s), both as the project defines them;
after the load the motion is free and the total energy ``T + U`` of the exact
solution is constant. Each element type is integrated by Lobatto IIIA (3 and
2 stages, modified Newton), Newmark (beta 1/4, gamma 1/2), HHT (alpha 0.05),
generalized-alpha (rho_inf 0.8), IDA (BDF, max order 5), energy-momentum and the
energy-preserving collocation (order 4) -- the last two on the constant-mass elements -- and the study
records the balance ``E(t) = T + U - W_ext`` against time, the drift after the
load (largest ``|E - E(t_load)|``, fitted rate dE/dt, relative to the energy
at the end of the load), the time the energy monitor flags a blow-up (drift
above 10 % of the energy scale; the run is stopped there) and the time a
run fails (Newton divergence).

Run: ``ancfdae study energy [--quick] [--out DIR] [--jobs N]``.
"""
from __future__ import annotations

import os
import sys

import numpy as np

from ancfdae.simulate import METHODS

from ._cli import Option, main as cli_main
from ._common import Case, OptionError, output_dir, run_cases, settings
from ._tables import cell, errors_note, markdown_table
from ._flying import T_HAT, T_PULSE, available, b2_beam, b3_beam, simulate_case, steady_drift, unpack

__all__ = ["run", "run_case", "INTEGRATORS", "FULL", "QUICK", "CLI_OPTIONS"]

#: label -> (simulate method, options)
INTEGRATORS = {
    "lobatto3": ("lobatto3", {}),
    "lobatto2": ("lobatto2", {}),
    "newmark": ("newmark", {}),
    "hht": ("hht", {"alpha": 0.05}),
    "generalized-alpha": ("generalized-alpha", {"rho_inf": 0.8}),
    "ida": ("ida", {"rtol": 1e-6, "max_steps": 400_000}),
}
if "energy-momentum" in METHODS:
    INTEGRATORS["energy-momentum"] = ("energy-momentum", {})
if "energy-collocation" in METHODS:
    INTEGRATORS["energy-collocation"] = ("energy-collocation", {})
#: element -> (problem, elements)
ELEMENTS = {"BE2D": ("B2", 4), "SQ2D": ("B2", 4), "BE3D": ("B3", 4), "SQ3D": ("B3", 4)}

#: defaults of the full study
FULL = dict(elements=tuple(ELEMENTS), integrators=tuple(INTEGRATORS), n=None, t_end_b2=10.0, t_end_b3=6.0, h=2e-3,
            dt_out=0.02)
#: quick mode (the tests): BE2D, 2 elements, 4 s, h = 4e-3
QUICK = dict(elements=("BE2D",), n=2, t_end_b2=4.0, t_end_b3=4.0, h=4e-3)
CLI_OPTIONS = [
    Option("elements", str, "element types (planar: B2, spatial: B3)", nargs="+", choices=tuple(ELEMENTS)),
    Option("integrators", str, "integrators", nargs="+", choices=tuple(INTEGRATORS)),
    Option("n", int, "elements per beam (default of each type: 4)"),
    Option("t_end_b2", float, "end time of the planar runs (s)"),
    Option("t_end_b3", float, "end time of the spatial runs (s)"),
    Option("h", float, "time step of the fixed-step methods (s)"),
]


def run_case(case: dict) -> dict:
    """One run: ``case = {element, n, problem, integrator, h, t_end, dt_out}``."""
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    build = b2_beam if case["problem"] == "B2" else b3_beam
    beam = build(case["element"], case["n"])
    method, opts = INTEGRATORS[case["integrator"]]
    h = None if method == "ida" else case["h"]
    rec = simulate_case(beam, case["t_end"], method=method, h=h, dt_out=case["dt_out"], stop_on_blowup=True, **opts)
    rec.update({k: case[k] for k in ("element", "n", "problem", "integrator", "h", "t_end", "label")})
    return rec


def summarize(rec: dict) -> dict:
    """Drift after the load, blow-up and failure times of one run."""
    t_load = T_PULSE if rec["problem"] == "B2" else T_HAT
    t, en = rec["t"], rec["energy"]
    k = np.searchsorted(t, t_load - 1e-9)
    e_load = float(en["total"][k]) if k < t.size else float("nan")
    d = steady_drift(t, en["balance"], t_load)
    blown = en["t_blow_up"] is not None
    return {"element": rec["element"], "n": rec["n"], "problem": rec["problem"], "integrator": rec["integrator"],
            "h": rec["h"], "t_end": rec["t_end"], "t_reached": float(t[-1]) if t.size else 0.0,
            "status": rec["status"], "failed": rec["status"] != "success" and not blown,
            "t_fail": rec["t_fail"], "t_blow_up": en["t_blow_up"], "energy": e_load,
            "drift": d["max"], "rate": d["rate"], "final": d["final"],
            "relative": d["max"] / abs(e_load) if np.isfinite(e_load) and e_load else float("nan"),
            "cpu": rec["cpu"], "steps": rec["stats"].get("steps", 0), "message": rec["message"],
            "max_order": rec["stats"].get("max_order") or rec.get("options", {}).get("max_order")}


def run(elements=None, integrators=None, n: int | None = None, t_end_b2=None, t_end_b3=None, h=None, dt_out=None,
        quick: bool = False, out=None, jobs: int | None = None, executor=None, plots: bool = True,
        progress: bool = True) -> dict:
    """Run the study. Every option left None takes its value from :data:`FULL` (:data:`QUICK` with ``quick``).

    Parameters
    ----------
    elements : sequence of str, optional
        Element types (default: all of BE2D, SQ2D, BE3D, SQ3D available);
        planar ones fly as in B2, spatial ones as in B3.
    integrators : sequence of str
        Keys of :data:`INTEGRATORS`. IDA is not paired with BE3D: the
        director update after every step restarts IDA (its BDF history is
        lost), which made one 6 s run take over 35 min.
    n : int, optional
        Elements per beam (default 4).
    t_end_b2, t_end_b3 : float
        End times of the planar and the spatial runs.
    h, dt_out : float
        Step of the fixed-step methods and output interval.
    quick, out, jobs, executor, plots, progress
        The sweep options of every study (:mod:`ancfdae.studies._common`);
        ``quick``: BE2D, 2 elements, 4 s, h = 4e-3.

    Returns
    -------
    dict
        ``rows`` (summary per run) and ``records`` (histories), with the
        keys of every study.
    """
    o = settings(FULL, QUICK, quick, dict(elements=elements, integrators=integrators, n=n, t_end_b2=t_end_b2,
                                          t_end_b3=t_end_b3, h=h, dt_out=dt_out))
    names = available(o["elements"])
    if len(names) != len(list(o["elements"])) or not names:
        raise OptionError(f"`elements` must name types of {available(ELEMENTS)}, got {list(o['elements'])}.")
    unknown = [i for i in o["integrators"] if i not in INTEGRATORS]
    if unknown:
        raise OptionError(f"`integrators` must be keys of {list(INTEGRATORS)}, got {unknown}.")
    path = output_dir("energy", out, quick) if (plots or out is not None) else None
    cases = []
    for name in names:
        problem, n_default = ELEMENTS[name]
        for integ in o["integrators"]:
            if name == "BE3D" and integ == "ida":
                continue   # the director update restarts IDA after every step (BDF history lost): hours
            if name == "BE3D" and integ == "energy-collocation":
                continue   # needs a constant mass matrix; BE3D's rotary inertia depends on the slopes
            c = {"element": name, "n": o["n"] or n_default, "problem": problem, "integrator": integ, "h": o["h"],
                 "t_end": o["t_end_b2"] if problem == "B2" else o["t_end_b3"], "dt_out": o["dt_out"]}
            cost = c["t_end"] * c["n"] * (1 if name == "BE2D" else 3 if name in ("SQ2D", "BE3D") else 10)
            cases.append(Case(c, label=f"{name} {c['n']} el ({problem}) {integ}", cost=cost))
    cases.sort(key=lambda c: -c["cost"])
    sweep = run_cases(run_case, cases, out=path, executor=executor, jobs=jobs, reduce=unpack, name="energy",
                      progress=progress, cost=lambda c: c["cost"])
    records = sweep.finished()
    key = {k: i for i, k in enumerate(INTEGRATORS)}
    records.sort(key=lambda r: (list(ELEMENTS).index(r["element"]), key[r["integrator"]]))
    rows = [summarize(r) for r in records]
    table = _table(rows, o["h"], sweep.errors)
    figures = {}
    if plots:
        (path / "energy.md").write_text("# Energy drift in free flight\n\n" + table)
        figures = _plot(records, path)
    return {"rows": rows, "records": records, "errors": sweep.errors, "reused": sweep.reused, "figures": figures,
            "table": table, "path": path}


def _table(rows, h, errors):
    headers = ["element", "problem", "integrator", "run to (s)", "reached (s)", "fails at (s)", "blow-up at (s)",
               "T+U at load end (J)", "max drift after load (J)", "relative", "rate (J/s)", "CPU (s)"]
    body = [[r["element"] + f" {r['n']} el", r["problem"], r["integrator"], f"{r['t_end']:g}",
             f"{r['t_reached']:.2f}", cell(r["t_fail"], ".2f") if r["failed"] else "-", cell(r["t_blow_up"], ".2f"),
             cell(r["energy"], ".4g"), cell(r["drift"], ".2e"), cell(r["relative"], ".1e"), cell(r["rate"], ".1e"),
             f"{r['cpu']:.1f}"] for r in rows]
    ida = sorted({r["max_order"] for r in rows if r["integrator"] == "ida" and r["max_order"] is not None})
    text = (f"Fixed-step methods: h = {h:g} s, modified Newton tol 1e-8; IDA: rtol 1e-6"
            + (f", max order {', '.join(map(str, ida))}" if ida else "") + ", at most 400 000 steps. "
            "Planar elements: B2 (load ends at 2.5 s); spatial: B3 (load ends at 3 s).\n\n")
    text += markdown_table(headers, body)
    return text + errors_note(errors)


def _plot(records, path) -> dict:
    from ._flying_plots import figure, save
    names = list(dict.fromkeys(r["element"] for r in records))
    cols = min(2, len(names))
    rows_ = (len(names) + cols - 1) // cols
    fig, axes = figure(rows_, cols, figsize=(6.5 * cols, 3.8 * rows_), squeeze=False)
    for ax, name in zip(axes.ravel(), names):
        for k, r in enumerate(rec for rec in records if rec["element"] == name):
            t_load = T_PULSE if r["problem"] == "B2" else T_HAT
            m = r["t"] >= t_load - 1e-9
            if m.sum() < 2:
                continue
            bal = r["energy"]["balance"][m]
            # Newmark (1/4, 1/2) and Lobatto IIIA-2 are the same scheme: styles keep coinciding curves visible
            ax.semilogy(r["t"][m], np.abs(bal - bal[0]) + 1e-14, color=f"C{k}", lw=2.0 - 0.25 * k,
                        ls=("-", "--", ":", "-.")[k % 4], label=r["integrator"])
        ax.set(xlabel="t (s)", ylabel="|E(t) - E(t_load)| (J)", title=f"{name}: energy drift after the load")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    for ax in axes.ravel()[len(names):]:
        ax.set_visible(False)
    save(fig, path, "energy_drift")
    return {"energy_drift": fig}


if __name__ == "__main__":     # python -m ancfdae.studies.energy: the same as `ancfdae study energy`
    raise SystemExit(cli_main(sys.modules[__name__]))
