"""Free beam flying in space: energy of BE3D against SQ3D, failure times (B3, chapter Sect. 5.3, Figs. 11-12).

The B3 beam (revision 2; :mod:`studies._flying`) is loaded at B by the
dead moment ``f(t) (0.1, 0.05, 0.2) N m`` with a hat ramp that ends at 3 s, and
integrated by Lobatto IIIA (3 stages, h = 1e-3 s, modified Newton, tol 1e-8)
with BE3D (thin, torsion angle + director, Sects. 3.5-3.6) and SQ3D
(shear- and cross-section deformable, Sect. 4). Per run the study records the
energy balance ``E = T + U - W_ext`` (constant for the exact solution of an
energy-conserving semi-discretisation), the time at which the run fails
(Newton divergence), the time at which the energy monitor flags a blow-up
(drift above 10 % of the energy scale), the drift and its rate after the load
ends, and the displacement of B.

For BE3D it also audits the director update (Sect. 3.6) that runs after
every step: the model is wrapped so that ``T + U`` is evaluated just before
and just after each update; the sum of these jumps is energy that the update
itself puts into or takes out of the discrete system -- between updates
BE3D's semi-discrete equations derive from one Lagrangian and conserve
energy (see ``ancfdae/models/thin/be3d_directors.py``). Divided by the number of
updates it is the energy injected per director update; the balance minus
the jumps is the step part, the integrator's own error (round-off-small since
the driver restarts with a consistent acceleration). The ``"energy-momentum"``
integrator keeps BE3D's energy between updates exactly (its variable-mass
form), so with it the jumps are the whole balance error. Per BE3D/BE3DSR run
the monitor :class:`ancfdae.DirectorGeometry` logs the largest angle between
an element's nodal directors and the smallest interior projection of Eq. 99:
the projected update lets the directors of an element drift apart until the
interpolated director degenerates inside it, and the energy explodes then.
The mechanism runs (``variant_mesh``): BE3D at h/2 (``be_steps``; updating
every step drains O(h), the chapter's configuration), updating only below a
sine of 0.5 (``update_below``), and BE3DSR (``sr_meshes``), whose interior
frames are transported from the nodal frames so that no update changes its
energy. ``eps_T`` (Eq. 115) of B's displacement in space is taken against the
finest SQ3D run over [0, 10] s (the data of the chapter's Fig. 12).
SQ3D's mass matrix is constant, so one SQ3D mesh is also run with the
energy-momentum method (option ``em_run``: elements and step; full 16
elements, h = 5e-3 s; quick 2 elements, h = 4e-3 s) with that integrator's
own Newton tolerance (round-off): its balance after the load is exact to
round-off where Lobatto IIIA's is off by its truncation error. (At h = 1e-2 s
the 16-element run's Newton iteration diverged at 5.7 s.)

The chapter's BE3D runs failed after 8, 9 and 12 s (8, 16, 32 elements); the
table and Fig. 11 show them beside ours.

Run: ``ancfdae study flying3d [--quick] [--out DIR] [--jobs N] [--be-meshes ...] [--methods ...]
[--em-run N H]``.
"""
from __future__ import annotations

import sys

import numpy as np

from ancfdae.monitors import DirectorGeometry
from ancfdae.simulate import METHODS

from ._cli import Option, main as cli_main
from ._common import Case, OptionError, output_dir, run_cases, settings
from ._tables import cell, errors_note, markdown_table
from ._flying import T_HAT, available, b3_beam, simulate_case, steady_drift, unpack

__all__ = ["run", "run_case", "summarize", "UpdateAudit", "FULL", "QUICK", "CLI_OPTIONS", "CHAPTER_FAILURES"]

#: Chapter Sect. 5.3: BE3D runs failed to converge after 8, 9 and 12 s with 8, 16 and 32 elements.
CHAPTER_FAILURES = {8: 8.0, 16: 9.0, 32: 12.0}

#: BE3D integrators: Lobatto IIIA (the chapter's); ``methods`` adds others (e.g. the energy-momentum method,
#: which isolates the director update's share exactly) on the variant mesh.
_BE_METHODS = ("lobatto3",)

#: the element types with nodal directors and a director update (audited, their director geometry logged)
THIN = ("BE3D", "BE3DSR")

#: defaults of the full study (chapter: BE3D 8, 16, 32; SQ3D 32, 64, 128; SQ3D 16 to 50 s); the mechanism:
#: BE3D on ``variant_mesh`` at h/2 and updating only below a sine of 0.5; BE3DSR, which does not blow up
FULL = dict(be_meshes=(8, 16, 32), sq_meshes=(32, 64, 128), variants=("projected", "post-rotated", "none"),
            variant_mesh=8, methods=_BE_METHODS, long_run=(16, 50.0), t_end=20.0, t_end_sq=20.0, h=1e-3,
            dt_out=0.01, t_load=T_HAT, sq_steps=None, em_run=(16, 5e-3), be_steps=(5e-4,), update_below=(0.5,),
            sr_meshes=(8, 16), eps_window=10.0)
#: quick mode (the tests): the hat shortened to 1 s; BE3D, BE3DSR and SQ3D with 2 elements to 1.5 s
QUICK = dict(be_meshes=(2,), sq_meshes=(2,), variants=("projected",), methods=("lobatto3",), long_run=(),
             t_end=1.5, t_end_sq=1.5, h=2e-3, dt_out=0.02, t_load=1.0, sq_steps=(4e-3, 2e-3),
             em_run=(2, 4e-3), be_steps=(), update_below=(), sr_meshes=(2,), eps_window=1.5)
CLI_OPTIONS = [
    Option("be_meshes", int, "BE3D meshes", nargs="+"),
    Option("sq_meshes", int, "SQ3D meshes", nargs="+"),
    Option("variants", str, "BE3D director updates (the first on every mesh, the others on --variant-mesh)",
           nargs="+", choices=("projected", "post-rotated", "none")),
    Option("variant_mesh", int, "BE3D mesh of the other director updates"),
    Option("methods", str, "BE3D integrators (the first on every mesh, the others on --variant-mesh)", nargs="+",
           choices=tuple(sorted(METHODS))),
    Option("long_run", float, "elements and end time of one long SQ3D run (none: give 0 0)", nargs=2),
    Option("em_run", float, "elements and step of one SQ3D energy-momentum run to --t-end-sq (none: give 0 0)",
           nargs=2),
    Option("t_end", float, "end time of the BE3D runs (s)"),
    Option("t_end_sq", float, "end time of the SQ3D runs (s)"),
    Option("h", float, "time step (s)"),
    Option("be_steps", float, "further steps of the projected BE3D run on --variant-mesh (none: give 0)", nargs="+"),
    Option("update_below", float, "projected BE3D runs on --variant-mesh updating only when a director's sine "
           "falls below these (none: give 0)", nargs="+"),
    Option("sr_meshes", int, "BE3DSR meshes (none: give 0)", nargs="+"),
    Option("eps_window", float, "eps_T of B's displacement against the finest SQ3D run over [0, this] s"),
]


class UpdateAudit:
    """A model proxy that measures the energy change made by BE3D's director update (a model event).

    Every attribute is the wrapped beam's; it declares the beam's capabilities (so the fast paths
    and the event state are forwarded deliberately) and wraps ``step_event`` to record
    ``(T + U)(after) - (T + U)(before)`` per update; ``bind`` returns a proxy of the bound beam
    that records into the same list.
    """

    def __init__(self, beam, jumps=None):
        self._beam = beam
        self.jumps = [] if jumps is None else jumps       # (t, jump)
        self.capabilities = beam.capabilities

    def __getattr__(self, name):
        return getattr(self._beam, name)

    def bind(self, state):
        return UpdateAudit(self._beam.bind(state), self.jumps)

    def step_event(self, t, q, v):
        ev = self._beam.step_event(t, q, v)
        if ev is not None:
            q2, v2, state = ev
            e0 = self._beam.energy(t, q, v)
            e1 = self._beam.bind(state).energy(t, q2, v2)
            self.jumps.append((float(t), (e1.kinetic + e1.strain) - (e0.kinetic + e0.strain)))
        return ev


def run_case(case: dict) -> dict:
    """One B3 run: ``case = {element, n, t_end, h, dt_out, t_load[, director_update, update_below, method]}``.

    For BE3D and BE3DSR the energy jumps at the director updates are kept in
    the Result's monitor ``director_update``: ``cumulative`` (their running sum
    at the output times), ``count`` and ``max_abs``; the monitor ``directors``
    (:class:`ancfdae.DirectorGeometry`) logs the director geometry.
    """
    opts = {"director_update": case["director_update"]} if case.get("director_update") else {}
    if "update_below" in case:
        opts["update_below"] = case["update_below"]
    beam = b3_beam(case["element"], case["n"], t_load=case["t_load"], **opts)
    thin = case["element"] in THIN
    model = UpdateAudit(beam) if thin else beam
    rec = simulate_case(model, case["t_end"], method=case.get("method", "lobatto3"), h=case["h"],
                        dt_out=case["dt_out"], monitors=(DirectorGeometry(),) if thin else ())
    if isinstance(model, UpdateAudit):
        res = rec["result"]
        jumps = np.array(model.jumps).reshape(-1, 2)
        upto = np.searchsorted(jumps[:, 0], res.t + 1e-12, side="right")     # updates at or before each output
        cumulative = np.concatenate([[0.0], np.cumsum(jumps[:, 1])])[upto]
        res.monitors["director_update"] = {"cumulative": cumulative, "count": int(jumps.shape[0]),
                                           "max_abs": float(np.max(np.abs(jumps[:, 1]))) if jumps.size else 0.0}
    rec.update(element=case["element"], n=case["n"], director_update=case.get("director_update") or "-",
               method=case.get("method", "lobatto3"), t_end=case["t_end"], t_load=case["t_load"], h=case["h"],
               long=bool(case.get("long")), label=case["label"],
               update_below=getattr(beam.element, "update_below", None) if thin else None)
    return rec


def _unpack(record):
    rec = unpack(record)
    rec["t_end_reached"] = float(rec["t"][-1]) if rec["t"].size else 0.0
    return rec


def summarize(rec: dict) -> dict:
    """Key numbers of one run: failure and blow-up times, balance during and drift after the load."""
    t, en = rec["t"], rec["energy"]
    row = {k: rec.get(k) for k in ("element", "n", "director_update", "method", "dof", "status", "message",
                                   "t_end_reached", "t_end", "t_load", "h", "cpu", "update_below", "label")}
    chapter = rec["element"] == "BE3D" and rec["h"] == FULL["h"] and rec.get("update_below") is None
    row["chapter_fails"] = CHAPTER_FAILURES.get(rec["n"]) if chapter else None
    t_load = rec["t_load"]
    row["t_fail"] = rec["t_fail"]
    row["t_blow_up"] = en["t_blow_up"]
    bal = en["balance"]
    k3 = np.searchsorted(t, t_load - 1e-9)
    row["energy_at_load_end"] = float(en["total"][k3]) if k3 < t.size else float("nan")
    row["balance_at_load_end"] = float(bal[k3]) if k3 < t.size else float("nan")
    d = steady_drift(t, bal, t_load)
    row["drift_max"], row["drift_rate"] = d["max"], d["rate"]
    # first time the balance has moved by 1 % of the energy put in by the load
    scale = row["energy_at_load_end"] if np.isfinite(row["energy_at_load_end"]) else float(np.nanmax(en["total"]))
    off = np.flatnonzero(~(np.abs(bal) <= 0.01 * abs(scale)))
    row["t_drift_1pc"] = float(t[off[0]]) if off.size else None
    audit = rec["monitors"].get("director_update")
    if audit is not None and audit["count"]:
        cum, t_ = np.asarray(audit["cumulative"]), t
        k = min(k3, t_.size - 1)
        row["update_net_load"] = float(cum[k])
        row["update_net_free"] = float(cum[-1] - cum[k])
        row["update_max"] = float(audit["max_abs"])
        row["update_mean"] = float(cum[-1] / audit["count"])
        row["update_count"] = int(audit["count"])
        # the balance split: the update part (the jumps) and the step part (everything else: the integrator)
        row["step_part_load"] = float(bal[k] - cum[k])
        row["step_part_free"] = float((bal[-1] - bal[k]) - (cum[-1] - cum[k]))
    geo = rec["monitors"].get("directors")
    if geo is not None and len(geo["max_angle"]):
        row["max_angle"] = float(np.max(geo["max_angle"]))
        row["min_projection"] = float(np.min(geo["min_projection"]))
    return row


def eps_T3(rec: dict, ref: dict, window: float) -> tuple[float, float]:
    """Integrated error (chapter Eq. 115) of B's displacement in space against ``ref`` over ``[0, window]``,
    or up to where either run ends; returns ``(eps_T, end of the interval)``."""
    t, t_ref = rec["t"], ref["t"]
    end = min(window, float(t[-1]), float(t_ref[-1]))
    keep = t <= end + 1e-9
    idx = np.searchsorted(t_ref, t[keep] - 1e-9)
    if keep.sum() < 2 or np.any(np.abs(t_ref[idx] - t[keep]) > 1e-9):
        return float("nan"), end
    e2 = np.sum((rec["tip"][keep] - ref["tip"][idx]) ** 2, axis=1)
    return float(np.sqrt(np.sum(0.5 * (e2[1:] + e2[:-1]) * np.diff(t[keep])))), end


def _cases(o):
    cases = []
    be = available(("BE3D",)) and o["be_meshes"]
    methods = list(o["methods"]) or ["lobatto3"]
    for n in (o["be_meshes"] if be else ()):
        cases.append({"element": "BE3D", "n": n, "director_update": o["variants"][0], "method": methods[0],
                      "t_end": o["t_end"], "h": o["h"]})
    for var in (o["variants"][1:] if be else ()):
        cases.append({"element": "BE3D", "n": o["variant_mesh"], "director_update": var, "method": methods[0],
                      "t_end": o["t_end"], "h": o["h"]})
    for m in (methods[1:] if be else ()):
        cases.append({"element": "BE3D", "n": o["variant_mesh"], "director_update": o["variants"][0], "method": m,
                      "t_end": o["t_end"], "h": o["h"]})
    mech = {"element": "BE3D", "n": o["variant_mesh"], "director_update": o["variants"][0], "method": methods[0],
            "t_end": o["t_end"]}
    cases += [dict(mech, h=float(h)) for h in (o["be_steps"] if be else ()) if h]
    cases += [dict(mech, h=o["h"], update_below=float(b)) for b in (o["update_below"] if be else ()) if b]
    cases += [{"element": "BE3DSR", "n": n, "director_update": o["variants"][0], "method": methods[0],
               "t_end": o["t_end"], "h": o["h"]} for n in (o["sr_meshes"] if available(("BE3DSR",)) else ()) if n]
    if available(("SQ3D",)):
        for n in o["sq_meshes"]:
            cases += [{"element": "SQ3D", "n": n, "t_end": o["t_end_sq"], "h": hs}
                      for hs in (o["sq_steps"] or (o["h"],))]
        if o["long_run"] and o["long_run"][0]:
            cases.append({"element": "SQ3D", "n": int(o["long_run"][0]), "t_end": float(o["long_run"][1]),
                          "h": o["h"], "long": True})
        if o["em_run"] and o["em_run"][0] and "energy-momentum" in METHODS:
            cases.append({"element": "SQ3D", "n": int(o["em_run"][0]), "t_end": o["t_end_sq"],
                          "h": float(o["em_run"][1]), "method": "energy-momentum"})
    out = []
    for c in cases:
        label = f"{c['element']} {c['n']} el" + (f" ({c['director_update']})" if c.get("director_update") else "") \
            + (f" below {c['update_below']:g}" if "update_below" in c else "") \
            + (f" {c['method']}" if c.get("method", "lobatto3") != "lobatto3" else "") \
            + f" h {c['h']:g} to {c['t_end']:g} s" + (" long" if c.get("long") else "")
        out.append(Case(c, dt_out=o["dt_out"], t_load=o["t_load"], label=label))
    out.sort(key=lambda c: -_cost(c))      # the long ones first: better balanced pools
    return out


def _cost(case):
    # relative CPU cost; SQ3D runs go to the end, BE3D runs usually stop early
    return case["t_end"] * case["n"] / case["h"] * {"SQ3D": 3.0, "BE3DSR": 6.0}.get(case["element"], 0.3)


def run(be_meshes=None, sq_meshes=None, variants=None, variant_mesh=None, methods=None, long_run=None, t_end=None,
        t_end_sq=None, h=None, em_run=None, dt_out=None, be_steps=None, update_below=None, sr_meshes=None,
        eps_window=None, quick: bool = False, out=None, jobs: int | None = None, executor=None,
        plots: bool = True, progress: bool = True) -> dict:
    """Run the study. Every option left None takes its value from :data:`FULL` (:data:`QUICK` with ``quick``).

    Parameters
    ----------
    be_meshes : sequence of int
        BE3D meshes (chapter: 8, 16, 32), run with ``variants[0]`` and ``methods[0]``.
    sq_meshes : sequence of int
        SQ3D meshes (chapter: 32, 64, 128).
    variants : sequence of str
        BE3D director updates (Sect. 3.6): the first is used on every mesh,
        the others on ``variant_mesh`` elements only.
    variant_mesh : int
    methods : sequence of str
        BE3D integrators: the first on every mesh, the others (default: the
        energy-momentum method where available) on ``variant_mesh`` elements.
    long_run : (int, float) or ()
        ``(elements, t_end)`` of one long SQ3D run (chapter: to 50 s).
    em_run : (int, float) or ()
        ``(elements, h)`` of one SQ3D run to ``t_end_sq`` with the
        energy-momentum method (its own round-off Newton tolerance); skipped
        when its first entry is 0 or the method is not available.
    t_end, t_end_sq : float
        End times of the BE3D and the SQ3D runs.
    h, dt_out : float
        Step and output interval.
    be_steps : sequence of float
        Further steps of the ``variants[0]`` BE3D run on ``variant_mesh`` elements (the update's energy is
        O(h^2) per update, so updating every step drains O(h) overall: halving h halves it).
    update_below : sequence of float
        ``variants[0]`` BE3D runs on ``variant_mesh`` elements that update only when a director's sine
        falls below the value (rare updates).
    sr_meshes : sequence of int
        BE3DSR meshes (its default ``update_below=0.5``); its updates keep T and U.
    eps_window : float
        ``eps_T`` of every run's displacement of B in space against the finest
        SQ3D run over ``[0, eps_window]`` s (or up to the failure).
    quick, out, jobs, executor, plots, progress
        The sweep options of every study (:mod:`ancfdae.studies._common`);
        ``quick``: the moment hat shortened to 1 s; BE3D 2 el (h = 2e-3)
        and SQ3D 2 el (h = 4e-3 and 2e-3; energy-momentum h = 4e-3) to 1.5 s.

    Returns
    -------
    dict
        ``rows`` (summary per run) and ``records`` (histories), with the
        keys of every study.
    """
    o = settings(FULL, QUICK, quick, dict(be_meshes=be_meshes, sq_meshes=sq_meshes, variants=variants,
                                          variant_mesh=variant_mesh, methods=methods, long_run=long_run, t_end=t_end,
                                          t_end_sq=t_end_sq, h=h, dt_out=dt_out, em_run=em_run, be_steps=be_steps,
                                          update_below=update_below, sr_meshes=sr_meshes, eps_window=eps_window),
                 zero_allowed=("long_run", "em_run", "be_steps", "update_below", "sr_meshes"))
    unknown = [m for m in o["methods"] if m not in METHODS]
    if unknown:
        raise OptionError(f"`methods` must be keys of {sorted(METHODS)}, got {unknown}.")
    missing = [n for n in ("BE3D", "BE3DSR", "SQ3D") if n not in available(("BE3D", "BE3DSR", "SQ3D"))]
    cases = _cases(o)
    if not cases:
        raise OptionError("flying3d has no case to run: no BE3D/SQ3D meshes, or neither type in ancfdae.models.")
    path = output_dir("flying3d", out, quick) if (plots or out is not None) else None
    sweep = run_cases(run_case, cases, out=path, executor=executor, jobs=jobs, reduce=_unpack, name="flying3d",
                      progress=progress, cost=_cost)
    records = sweep.finished()
    order = {"BE3D": 0, "BE3DSR": 1, "SQ3D": 2}
    records.sort(key=lambda r: (order[r["element"]], r["director_update"] != o["variants"][0],
                                r["method"] != (list(o["methods"]) or ["lobatto3"])[0], r.get("update_below") or 0,
                                r["t_end"], r["n"], -r["h"]))
    rows = [summarize(r) for r in records]
    refs = [r for r in records if r["element"] == "SQ3D" and not r["long"] and r["method"] == "lobatto3"]
    ref = max(refs, key=lambda r: (r["n"], -r["h"])) if refs else None
    for row, r in zip(rows, records):
        row["eps_T"], row["eps_T_to"] = eps_T3(r, ref, o["eps_window"]) if ref is not None else (None, None)
        row["eps_T_reference"] = ref["label"] if ref is not None else None
    table = _table(rows, missing, sweep.errors)
    figures = {}
    if plots:
        (path / "flying3d.md").write_text("# B3 free beam flying in space (chapter Sect. 5.3)\n\n" + table)
        from ._flying_plots import plot_flying3d
        figures = plot_flying3d(records, path, {n: t for n, t in CHAPTER_FAILURES.items() if n in o["be_meshes"]})
    return {"rows": rows, "records": records, "errors": sweep.errors, "reused": sweep.reused, "figures": figures,
            "table": table, "path": path}


def _table(rows, missing, errors):
    headers = ["element", "#NEL", "director update", "integrator", "h (s)", "run to (s)", "fails at (s)",
               "chapter: fails at (s)", "blow-up flagged (s)", "balance off by 1 % at (s)", "T+U at load end (J)",
               "balance at load end (J)", "drift after load (J)", "drift rate (J/s)",
               "update jumps, load / free (J)", "step part, load / free (J)", "per update: mean / max (J)",
               "max director angle (deg)", "min projection (Eq. 99)", "eps_T of B (m)", "eps_T over (s)", "CPU (s)"]
    body = []
    for r in rows:
        jumps = per = steps = "-"
        if "update_net_load" in r:
            jumps = f"{r['update_net_load']:.2e} / {r['update_net_free']:.2e}"
            steps = f"{r['step_part_load']:.2e} / {r['step_part_free']:.2e}"
            per = f"{r['update_mean']:.1e} / {r['update_max']:.1e}"
        update = r["director_update"] + (f", below {r['update_below']:g}" if r.get("update_below") else "")
        body.append([r["element"], r["n"], update, r["method"], f"{r['h']:g}", f"{r['t_end']:g}",
                     cell(r["t_fail"], ".3f") if r["status"] != "success" else "-",
                     cell(r["chapter_fails"], "g"), cell(r["t_blow_up"], ".2f"), cell(r["t_drift_1pc"], ".2f"),
                     cell(r["energy_at_load_end"], ".4g"), cell(r["balance_at_load_end"], ".2e"),
                     cell(r["drift_max"], ".2e"), cell(r["drift_rate"], ".2e"), jumps, steps, per,
                     cell(r.get("max_angle"), ".1f"), cell(r.get("min_projection"), ".3f"),
                     cell(r.get("eps_T"), ".3e"), cell(r.get("eps_T_to"), "g"), f"{r['cpu']:.0f}"])
    t_load = rows[0]["t_load"] if rows else T_HAT
    ref = next((r["eps_T_reference"] for r in rows if r.get("eps_T_reference")), None)
    text = (f"Modified Newton tol 1e-8 (energy-momentum: its own, round-off); the moment ends at {t_load:g} s. "
            "Chapter: Lobatto IIIA, h = 1e-3 s. Balance = update part (the jumps of T + U at the director "
            "updates) + step part (the integrator's). "
            + (f"eps_T (Eq. 115, B's displacement in space) against {ref}. " if ref else "") + "\n\n")
    text += markdown_table(headers, body)
    if missing:
        text += f"\nNot available in ancfdae.models: {', '.join(missing)}.\n"
    return text + errors_note(errors)


if __name__ == "__main__":     # python -m ancfdae.studies.flying3d: the same as `ancfdae study flying3d`
    raise SystemExit(cli_main(sys.modules[__name__]))
