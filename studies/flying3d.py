"""Free beam flying in space: energy of BE3D against SQ3D, failure times (B3, chapter Sect. 5.3, Figs. 11-12).

The B3 beam (benchmarks.md; :mod:`studies._flying`) is loaded at B by the
dead moment ``f(t) (0.4, 0.2, 0.8) N m`` with a hat ramp that ends at 3 s, and
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
energy (see ``ancfdae/models/_be3d_dynamics.py``).

Run: ``ancfdae study flying3d [--quick] [--out DIR] [--jobs N]``.
"""
from __future__ import annotations

import pickle

import numpy as np

from ._common import command_line, Progress, markdown_table, output_dir, run_cases
from ._flying import T_HAT, Case, available, b3_beam, simulate_case, steady_drift

__all__ = ["run", "run_case", "UpdateAudit"]


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
    """One B3 run: ``case = {element, n, t_end, h, dt_out, t_load[, director_update]}``."""
    opts = {"director_update": case["director_update"]} if case.get("director_update") else {}
    beam = b3_beam(case["element"], case["n"], t_load=case["t_load"], **opts)
    model = UpdateAudit(beam) if case["element"] == "BE3D" else beam
    rec = simulate_case(model, case["t_end"], h=case["h"], dt_out=case["dt_out"])
    rec.update(element=case["element"], n=case["n"], director_update=case.get("director_update") or "-",
               t_end=case["t_end"], t_load=case["t_load"], h=case["h"], long=bool(case.get("long")),
               label=case["label"])
    rec["t_end_reached"] = float(rec["t"][-1]) if rec["t"].size else 0.0
    if isinstance(model, UpdateAudit):
        jumps = np.array(model.jumps).reshape(-1, 2)
        rec["update_jumps"] = jumps
    return rec


def summarize(rec: dict) -> dict:
    """Key numbers of one run: failure and blow-up times, balance during and drift after the load."""
    t, en = rec["t"], rec["energy"]
    row = {k: rec[k] for k in ("element", "n", "director_update", "dof", "status", "message", "t_end_reached",
                               "t_end", "t_load", "h", "cpu")}
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
    if "update_jumps" in rec and rec["update_jumps"].size:
        tj, jj = rec["update_jumps"][:, 0], rec["update_jumps"][:, 1]
        load = tj <= t_load
        row["update_net_load"] = float(np.sum(jj[load]))
        row["update_net_free"] = float(np.sum(jj[~load]))
        row["update_max"] = float(np.max(np.abs(jj)))
    return row


def _cases(be_meshes, sq_meshes, variants, variant_mesh, long_run, t_end, t_end_sq, h, dt_out, t_load=T_HAT,
           sq_steps=None):
    cases = []
    for n in be_meshes:
        cases.append({"element": "BE3D", "n": n, "director_update": variants[0], "t_end": t_end, "h": h})
    for var in variants[1:]:
        cases.append({"element": "BE3D", "n": variant_mesh, "director_update": var, "t_end": t_end, "h": h})
    for n in sq_meshes:
        cases += [{"element": "SQ3D", "n": n, "t_end": t_end_sq, "h": hs} for hs in (sq_steps or (h,))]
    if long_run:
        cases.append({"element": "SQ3D", "n": long_run[0], "t_end": long_run[1], "h": h, "long": True})
    out = []
    for c in cases:
        label = f"{c['element']} {c['n']} el" + (f" ({c['director_update']})" if c.get("director_update") else "") \
            + f" h {c['h']:g} to {c['t_end']:g} s"
        out.append(Case(c, dt_out=dt_out, t_load=t_load, label=label))
    # SQ3D runs go to the end; BE3D runs usually stop early: start the long ones first.
    out.sort(key=lambda c: -(c["t_end"] * c["n"] / c["h"] * (3.0 if c["element"] == "SQ3D" else 0.3)))
    return out


def run(be_meshes=(8, 16, 32), sq_meshes=(32, 64, 128), variants=("projected", "post-rotated", "none"),
        variant_mesh: int = 8, long_run=(16, 50.0), t_end: float = 20.0, t_end_sq: float = 20.0, h: float = 1e-3,
        dt_out: float = 0.01, quick: bool = False, out=None, jobs: int | None = None, executor=None,
        plots: bool = True, progress: bool = True) -> dict:
    """Run the study.

    Parameters
    ----------
    be_meshes : sequence of int
        BE3D meshes (chapter: 8, 16, 32), run with ``variants[0]``.
    sq_meshes : sequence of int
        SQ3D meshes (chapter: 32, 64, 128).
    variants : sequence of str
        BE3D director updates (Sect. 3.6): the first is used on every mesh,
        the others on ``variant_mesh`` elements only.
    long_run : (int, float) or None
        ``(elements, t_end)`` of one long SQ3D run (chapter: to 50 s).
    t_end, t_end_sq : float
        End times of the BE3D and the SQ3D runs.
    h, dt_out : float
        Step and output interval.
    quick : bool
        Test-suite mode: the moment hat shortened to 1 s; BE3D 2 el (h = 2e-3)
        and SQ3D 2 el (h = 4e-3 and 2e-3) to 1.5 s.
    out, jobs, executor, plots, progress
        As in :func:`studies.flying2d.run`.

    Returns
    -------
    dict
        ``rows`` (summary per run), ``records`` (histories), ``table``, ``path``.
    """
    missing = [n for n in ("BE3D", "SQ3D") if n not in available(("BE3D", "SQ3D"))]
    t_load, sq_steps = T_HAT, None
    if quick:
        # The moment hat shortened to 1 s (same peak); SQ3D at two steps for the order of its energy error.
        be_meshes, sq_meshes, variants, long_run = (2,), (2,), variants[:1], None
        t_end, t_end_sq, h, dt_out, t_load, sq_steps = 1.5, 1.5, 2e-3, 0.02, 1.0, (4e-3, 2e-3)
    if "BE3D" in missing:
        be_meshes, variants = (), variants[:1]
    if "SQ3D" in missing:
        sq_meshes, long_run = (), None
    cases = _cases(be_meshes, sq_meshes, variants, variant_mesh, long_run, t_end, t_end_sq, h, dt_out, t_load,
                   sq_steps)
    if not cases:
        raise RuntimeError("flying3d needs BE3D or SQ3D in ancfdae.models; neither is available.")
    records = run_cases(run_case, cases, executor=executor, jobs=jobs,
                        progress=Progress("flying3d", len(cases), progress))
    order = {"BE3D": 0, "SQ3D": 1}
    records.sort(key=lambda r: (order[r["element"]], r["director_update"] != variants[0], r["t_end"], r["n"],
                                -r["h"]))
    path = output_dir("flying3d", out) if plots else None
    if path is not None:   # keep the histories: post-processing can be redone without the runs
        with open(path / "records.pkl", "wb") as f:
            pickle.dump(records, f)
    rows = [summarize(r) for r in records]
    table = _table(rows, h, missing)
    if plots:
        (path / "flying3d.md").write_text("# B3 free beam flying in space (chapter Sect. 5.3)\n\n" + table)
        from ._flying_plots import plot_flying3d
        plot_flying3d(records, path)
    return {"rows": rows, "records": records, "table": table, "path": path}


def _fmt(x, spec=".3g"):
    return "-" if x is None or (isinstance(x, float) and not np.isfinite(x)) else format(x, spec)


def _table(rows, h, missing):
    headers = ["element", "#NEL", "director update", "h (s)", "run to (s)", "fails at (s)", "blow-up flagged (s)",
               "balance off by 1 % at (s)", "T+U at load end (J)", "balance at load end (J)", "drift after load (J)",
               "drift rate (J/s)", "update jumps, load / free (J)", "CPU (s)"]
    body = []
    for r in rows:
        jumps = "-" if "update_net_load" not in r else f"{r['update_net_load']:.2e} / {r['update_net_free']:.2e}"
        body.append([r["element"], r["n"], r["director_update"], f"{r['h']:g}", f"{r['t_end']:g}",
                     _fmt(r["t_fail"], ".3f") if r["status"] != "success" else "-",
                     _fmt(r["t_blow_up"], ".2f"), _fmt(r["t_drift_1pc"], ".2f"),
                     _fmt(r["energy_at_load_end"], ".4g"), _fmt(r["balance_at_load_end"], ".2e"),
                     _fmt(r["drift_max"], ".2e"), _fmt(r["drift_rate"], ".2e"), jumps, f"{r['cpu']:.0f}"])
    t_load = rows[0]["t_load"] if rows else T_HAT
    text = f"Lobatto IIIA (3 stages), modified Newton tol 1e-8; the moment ends at {t_load:g} s.\n\n"
    text += markdown_table(headers, body)
    if missing:
        text += f"\nNot available in ancfdae.models: {', '.join(missing)}.\n"
    return text


def main(argv=None):
    """Command-line entry: ``python -m ancfdae.studies.flying3d [--quick] [--out DIR] [--jobs N]``."""
    command_line(run, __doc__, argv)


if __name__ == "__main__":
    main()
