"""Free beam flying in plane: eps_T against elements, DOF and CPU time (B2, chapter Sect. 5.2, Figs. 8-9).

The B2 beam (revision 2: force 0.24 N and moment 0.24 N m, pulse of 2.5 s;
:mod:`studies._flying`) is integrated by Lobatto IIIA with 3 stages,
h = 1e-3 s, modified Newton with the relative max-norm tolerance 1e-8, over
[0, 10] s, with 2 ... 64 elements of each type and with 128 elements of each
family (thin BE, shear-deformable SQ) as the reference. The error measure is
the integrated tip error of chapter Eq. 115,

    eps_T = ( int_0^T |u_ref^B - u^B|^2 dt )^(1/2),

sampled every 0.01 s (trapezoidal rule); its order in the number of elements
is regressed on the three finest meshes below the reference. BE3D and SQ3D
move in the plane and are compared with their family's reference (the planar
twin with 128 elements); the study also reports how far their tip stays from
the planar twin's with the same mesh. Reported per run: DOF, eps_T, CPU
seconds, Newton iterations, Jacobian evaluations and factorisations, and the
energy drift after the pulse.

Run: ``ancfdae study flying2d [--quick] [--out DIR] [--jobs N] [--elements ...] [--n-elements ...]``.
"""
from __future__ import annotations

import sys

import numpy as np

from ._cli import Option, main as cli_main
from ._common import OptionError, output_dir, run_cases, settings
from ._tables import errors_note, markdown_table
from ._flying import FAMILY, Case, T_PULSE, available, b2_beam, eps_T, regress_order, simulate_case, steady_drift, \
    unpack

__all__ = ["run", "run_case", "analyze", "ELEMENTS", "FULL", "QUICK", "CLI_OPTIONS"]

#: element types of the study (those not in ancfdae.models are skipped)
ELEMENTS = ("BE2D", "SQ2D", "BE3D", "SQ3D")
#: the planar twin whose reference a 3D type moving in the plane is compared with
_TWIN = {"BE2D": "BE2D", "BE3D": "BE2D", "SQ2D": "SQ2D", "SQ3D": "SQ2D"}
# rough relative cost per element, to start the longest runs first in a pool
_COST = {"BE2D": 1.0, "SQ2D": 2.5, "BE3D": 4.0, "SQ3D": 6.0}

#: defaults of the full study (chapter Sect. 5.2: h = 1e-3 s, T = 10 s, reference 128 elements)
FULL = dict(elements=ELEMENTS, n_elements=(2, 4, 8, 16, 32, 64), n_ref=128, n_elements_3d=(2, 4, 8), t_end=10.0,
            h=1e-3, dt_out=0.01)
#: quick mode (the tests): BE2D, 4-16 elements against 32, still the whole [0, 10] s at h = 1e-3 (SQ2D costs
#: 10-20 x as much per run)
QUICK = dict(elements=("BE2D",), n_elements=(4, 8, 16), n_ref=32, n_elements_3d=(4,))
CLI_OPTIONS = [
    Option("elements", str, "element types", nargs="+"),
    Option("n_elements", int, "meshes of the planar types", nargs="+"),
    Option("n_elements_3d", int, "meshes of the 3D types moving in the plane", nargs="+"),
    Option("n_ref", int, "elements of each family's reference solution"),
    Option("t_end", float, "end time (s)"),
    Option("h", float, "time step (s)"),
]


def run_case(case: dict) -> dict:
    """One B2 run: ``case = {element, n, t_end, h, dt_out}`` -> the record of :func:`simulate_case`."""
    beam = b2_beam(case["element"], case["n"])
    rec = simulate_case(beam, case["t_end"], h=case["h"], dt_out=case["dt_out"])
    rec.update(element=case["element"], n=case["n"], reference=case.get("reference", False))
    return rec


def _label(case):
    return f"{case['element']} {case['n']} el" + (" (reference)" if case.get("reference") else "")


def run(elements=None, n_elements=None, n_ref=None, n_elements_3d=None, t_end=None, h=None, dt_out=None,
        quick: bool = False, out=None, jobs: int | None = None, executor=None, plots: bool = True,
        progress: bool = True) -> dict:
    """Run the study. Every option left None takes its value from :data:`FULL` (:data:`QUICK` with ``quick``).

    Parameters
    ----------
    elements : sequence of str
        Element types (of :data:`ELEMENTS` that ancfdae.models provides).
    n_elements : sequence of int
        Meshes of the planar types.
    n_ref : int
        Elements of the reference solution of each family (chapter: 128).
    n_elements_3d : sequence of int
        Meshes of the 3D types moving in the plane (their runs cost 4-10 x
        the planar ones; they are compared with the planar reference).
    t_end, h, dt_out : float
        Time span (chapter: 10 s), step (1e-3 s) and output interval.
    quick, out, jobs, executor, plots, progress
        The sweep options of every study (:mod:`ancfdae.studies._common`);
        ``quick``: BE2D, 4, 8, 16 elements against 32, over the whole
        [0, 10] s at h = 1e-3.

    Returns
    -------
    dict
        ``rows`` (per run), ``orders`` (regressed order of eps_T against the
        number of elements, per type) and ``references``, with the keys of
        every study.
    """
    o = settings(FULL, QUICK, quick, dict(elements=elements, n_elements=n_elements, n_ref=n_ref,
                                          n_elements_3d=n_elements_3d, t_end=t_end, h=h, dt_out=dt_out))
    names = available(o["elements"])
    if len(names) != len(list(o["elements"])) or not names:
        raise OptionError(f"`elements` must name types of {available(ELEMENTS)}, got {list(o['elements'])}.")
    path = output_dir("flying2d", out, quick) if (plots or out is not None) else None
    twins = sorted({_TWIN[n] for n in names})
    cases = [{"element": name, "n": o["n_ref"], "reference": True} for name in twins]
    for name in names:
        meshes = o["n_elements"] if name in ("BE2D", "SQ2D") else o["n_elements_3d"]
        cases += [{"element": name, "n": n} for n in meshes if not (n == o["n_ref"] and name in twins)]
    cases = [Case(c, t_end=o["t_end"], h=o["h"], dt_out=o["dt_out"], label=_label(c)) for c in cases]
    cases.sort(key=lambda c: -_COST[c["element"]] * c["n"])   # longest first: better balanced pools
    sweep = run_cases(run_case, cases, out=path, executor=executor, jobs=jobs, reduce=unpack, name="flying2d",
                      progress=progress, cost=lambda c: _COST[c["element"]] * (c["n"] + 16))
    res = analyze(sweep.finished(), names, o["n_ref"], o["t_end"], o["h"], path if plots else None, sweep.errors)
    res.update(errors=sweep.errors, reused=sweep.reused, path=path)
    return res


def analyze(records, names, n_ref, t_end, h, path=None, errors=None) -> dict:
    """Tables, orders and figures from the run records.

    eps_T is evaluated over the whole span ``[0, t_end]`` (the chapter's
    measure); orders are regressed on the three finest meshes below the
    reference.
    """
    refs = {FAMILY[r["element"]]: r for r in records if r["reference"]}
    by_key = {(r["element"], r["n"]): r for r in records}
    rows = []
    for name in names:
        ref = refs.get(FAMILY[name])
        for r in sorted((r for r in records if r["element"] == name and not r["reference"]), key=lambda r: r["n"]):
            row = _row(r, ref, t_end)
            twin = by_key.get((_TWIN[name], r["n"]))
            if name != _TWIN[name] and twin is not None and twin["status"] == r["status"] == "success":
                row["twin_difference"] = float(np.max(np.abs(r["tip"][:, :2] - twin["tip"][:, :2])))
                row["max_abs_z"] = float(np.max(np.abs(r["tip"][:, 2])))
            rows.append(row)
    orders, fits = {}, {}
    for name in names:
        rs = sorted((r for r in rows if r["element"] == name and np.isfinite(r["eps_T"])), key=lambda r: r["n"])[-3:]
        if len(rs) >= 2:
            orders[name] = regress_order([r["n"] for r in rs], [r["eps_T"] for r in rs])
            fits[name] = [r["n"] for r in rs]
    references = {fam: _row(r, None, t_end) for fam, r in refs.items()}
    table = _table(rows, references, orders, n_ref, t_end, h, errors or {})
    figures = {}
    if path is not None:
        (path / "flying2d.md").write_text("# B2 free beam flying in plane (chapter Sect. 5.2)\n\n" + table)
        from ._flying_plots import plot_flying2d
        figures = plot_flying2d(rows, refs, orders, fits, path)
    return {"rows": rows, "orders": orders, "fits": fits, "references": references, "table": table,
            "figures": figures}


def _row(r, ref, t_end):
    st = r["stats"]
    row = {"element": r["element"], "n": r["n"], "dof": r["dof"], "status": r["status"], "message": r["message"],
           "cpu": r["cpu"], "steps": st["steps"], "newton_iterations": st["newton_iterations"],
           "jacobian_evals": st["jacobian_evals"], "factorizations": st["factorizations"],
           "eps_T": float("nan"), "drift": float("nan"), "t_reached": float(r["t"][-1])}
    if ref is not None and r["t"].size > 1:
        row["eps_T"] = eps_T(r["t"], r["tip"], ref["t"], ref["tip"])
        row["eps_span"] = float(min(r["t"][-1], ref["t"][-1]))
    if r["energy"] is not None and t_end > T_PULSE:
        row["drift"] = steady_drift(r["t"], r["energy"]["balance"], T_PULSE)["max"]
        row["energy"] = float(r["energy"]["total"][-1])
    return row


def _table(rows, references, orders, n_ref, t_end, h, errors):
    headers = ["element", "#NEL", "#DOF", f"eps_T [0, {t_end:g} s]", "CPU (s)", "Newton its", "its/step",
               "Jacobians", "LU", "T+U after pulse (J)", "energy drift after pulse (J)", "status"]

    def line(r, eps):
        its = r["newton_iterations"] / max(r["steps"], 1)
        status = r["status"] if r["status"] == "success" else f"failed at {r['t_reached']:.3f} s"
        return [r["element"], r["n"], r["dof"], eps, r["cpu"], r["newton_iterations"], f"{its:.2f}",
                r["jacobian_evals"], r["factorizations"], f"{r.get('energy', float('nan')):.6g}",
                f"{r['drift']:.2e}", status]

    body = [line(r, f"{r['eps_T']:.3e}" + ("" if r.get("eps_span", t_end) >= t_end - 1e-9
                                            else f" (to {r['eps_span']:.2f} s)")) for r in rows]
    body += [line(r, "reference") for r in references.values()]
    text = (f"Lobatto IIIA (3 stages), h = {h:g} s, modified Newton tol 1e-8, T = {t_end:g} s; "
            f"reference: {n_ref} elements of each family. eps_T in m s^1/2 (chapter Eq. 115).\n\n")
    text += markdown_table(headers, body)
    text += (f"\nObserved order of eps_T over [0, {t_end:g} s] in the number of elements (log-log fit, three finest "
             "meshes): " + ", ".join(f"{k} {v:.2f}" for k, v in orders.items()) + "\n")
    checks = [r for r in rows if "twin_difference" in r]
    if checks:
        text += "\n3D types in the plane against their planar twin with the same mesh (max tip difference, " \
                "max |z|): " + ", ".join(f"{r['element']} {r['n']} el {r['twin_difference']:.1e} m, "
                                          f"{r['max_abs_z']:.1e} m" for r in checks) + "\n"
    return text + errors_note(errors)


if __name__ == "__main__":     # python -m ancfdae.studies.flying2d: the same as `ancfdae study flying2d`
    raise SystemExit(cli_main(sys.modules[__name__]))
