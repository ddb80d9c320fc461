"""Free beam flying in plane: eps_T against elements, DOF and CPU time (B2, chapter Sect. 5.2, Figs. 8-9).

The B2 beam (benchmarks.md; :mod:`studies._flying`) is integrated by
Lobatto IIIA with 3 stages, h = 1e-3 s, modified Newton with the relative
max-norm tolerance 1e-8, over [0, 10] s, with 2 ... 64 elements of each type
and with 128 elements of each family (thin BE, shear-deformable SQ) as the
reference. The error measure is the integrated tip error of chapter Eq. 115,

    eps_T = ( int_0^T |u_ref^B - u^B|^2 dt )^(1/2),

sampled every 0.01 s (trapezoidal rule). BE3D and SQ3D move in the plane and
are compared with their family's reference (the planar twin with 128
elements): the study also reports how far their tip stays from the planar
twin's with the same mesh, a check that in-plane 3D elements reproduce the 2D
ones. Reported per run: DOF, eps_T, CPU seconds, Newton iterations, Jacobian
evaluations and factorisations, and the energy drift after the pulse.

Run: ``ancfdae study flying2d [--quick] [--out DIR] [--jobs N]``.
"""
from __future__ import annotations

import pickle

import numpy as np

from ._common import command_line, Progress, markdown_table, output_dir, run_cases
from ._flying import FAMILY, Case, T_PULSE, available, b2_beam, eps_T, regress_order, simulate_case, steady_drift

__all__ = ["run", "run_case", "ELEMENTS"]

#: element types of the study (those not in ancfdae.models are skipped)
ELEMENTS = ("BE2D", "SQ2D", "BE3D", "SQ3D")
#: the planar twin whose reference a 3D type moving in the plane is compared with
_TWIN = {"BE2D": "BE2D", "BE3D": "BE2D", "SQ2D": "SQ2D", "SQ3D": "SQ2D"}
# rough relative cost per DOF, to start the longest runs first in a pool
_COST = {"BE2D": 1.0, "SQ2D": 2.5, "BE3D": 4.0, "SQ3D": 6.0}


def run_case(case: dict) -> dict:
    """One B2 run: ``case = {element, n, t_end, h, dt_out}`` -> the record of :func:`simulate_case`."""
    beam = b2_beam(case["element"], case["n"])
    rec = simulate_case(beam, case["t_end"], h=case["h"], dt_out=case["dt_out"])
    rec.update(element=case["element"], n=case["n"], reference=case.get("reference", False))
    return rec


def _label(case):
    return f"{case['element']} {case['n']} el" + (" (reference)" if case.get("reference") else "")


def run(elements=None, n_elements=(2, 4, 8, 16, 32, 64), n_ref: int = 128, n_elements_3d=(2, 4, 8),
        t_end: float = 10.0, h: float = 1e-3, dt_out: float = 0.01, t_window: float = 4.0, quick: bool = False,
        out=None,
        jobs: int | None = None, executor=None, plots: bool = True, progress: bool = True) -> dict:
    """Run the study.

    Parameters
    ----------
    elements : sequence of str, optional
        Element types (default: those of :data:`ELEMENTS` available).
    n_elements : sequence of int
        Meshes of the planar types.
    n_ref : int
        Elements of the reference solution of each family (chapter: 128).
    n_elements_3d : sequence of int
        Meshes of the 3D types moving in the plane (their runs cost 4-10 x
        the planar ones; they are compared with the planar reference).
    t_end, h, dt_out : float
        Time span (chapter: 10 s), step (1e-3 s) and output interval.
    t_window : float
        eps_T is also reported over ``[0, t_window]`` (the pulse and 1.5 s
        of free flight), where the 128-element references are converged.
    quick : bool
        Test-suite mode: planar types, 2, 4, 8 elements against a 32-element
        reference, 1.5 s, h = 2e-3.
    out : path, optional
        Output folder (default ``out/flying2d``).
    jobs : int, optional
        Worker processes (``ancfdae study flying2d --jobs 2``).
    executor : concurrent.futures.Executor, optional
        E.g. a Dask ``Client().get_executor()``; overrides ``jobs``.
    plots : bool
        Write ``flying2d.md`` and the PNG figures.

    Returns
    -------
    dict
        ``rows`` (per run), ``orders`` (regressed order of eps_T against the
        number of elements, per type), ``references``, ``table``, ``path``.
    """
    names = available(elements if elements is not None else ELEMENTS)
    if elements is not None and len(names) != len(list(elements)):
        raise ValueError(f"`elements` must name types of {available(ELEMENTS)}, got {list(elements)}.")
    if quick:
        names = [n for n in names if n in ("BE2D", "SQ2D")] if elements is None else names
        n_elements, n_elements_3d, n_ref, t_end, h, t_window = (2, 4, 8), (2,), 32, 1.5, 2e-3, 1.0
    twins = sorted({_TWIN[n] for n in names})
    cases = []
    for name in twins:
        cases.append({"element": name, "n": n_ref, "reference": True})
    for name in names:
        meshes = n_elements if name in ("BE2D", "SQ2D") else n_elements_3d
        cases += [{"element": name, "n": n} for n in meshes if not (n == n_ref and name in twins)]
    cases = [Case(c, t_end=t_end, h=h, dt_out=dt_out, label=_label(c)) for c in cases]
    cases.sort(key=lambda c: -_COST[c["element"]] * c["n"])   # longest first: better balanced pools
    records = run_cases(run_case, cases, executor=executor, jobs=jobs,
                        progress=Progress("flying2d", len(cases), progress))
    path = output_dir("flying2d", out) if plots else None
    if path is not None:   # keep the histories: post-processing can be redone without the runs
        with open(path / "records.pkl", "wb") as f:
            pickle.dump(records, f)
    return analyze(records, names, n_ref, t_end, h, t_window, path)


def analyze(records, names, n_ref, t_end, h, t_window, path=None) -> dict:
    """Tables, orders and figures from the run records (``records.pkl`` of a finished study).

    eps_T is evaluated over the whole span ``[0, t_end]`` (the chapter's
    measure) and over ``[0, t_window]``; orders are regressed on the three
    finest meshes below the reference.
    """
    refs = {FAMILY[r["element"]]: r for r in records if r["reference"]}
    by_key = {(r["element"], r["n"]): r for r in records}
    rows = []
    for name in names:
        ref = refs[FAMILY[name]]
        for r in sorted((r for r in records if r["element"] == name and not r["reference"]), key=lambda r: r["n"]):
            row = _row(r, ref, t_end)
            m = r["t"] <= t_window + 1e-9
            row["eps_window"] = eps_T(r["t"][m], r["tip"][m], ref["t"], ref["tip"]) if m.sum() > 1 else float("nan")
            twin = by_key.get((_TWIN[name], r["n"]))
            if name != _TWIN[name] and twin is not None and twin["status"] == r["status"] == "success":
                row["twin_difference"] = float(np.max(np.abs(r["tip"][:, :2] - twin["tip"][:, :2])))
                row["max_abs_z"] = float(np.max(np.abs(r["tip"][:, 2])))
            rows.append(row)
    orders, orders_window = {}, {}
    for name in names:
        rs = sorted((r for r in rows if r["element"] == name and np.isfinite(r["eps_T"])), key=lambda r: r["n"])[-3:]
        if len(rs) >= 2:
            orders[name] = regress_order([r["n"] for r in rs], [r["eps_T"] for r in rs])
            orders_window[name] = regress_order([r["n"] for r in rs], [r["eps_window"] for r in rs])
    references = {fam: _row(r, None, t_end) for fam, r in refs.items()}
    table = _table(rows, references, orders, orders_window, n_ref, t_end, h, t_window)
    if path is not None:
        (path / "flying2d.md").write_text("# B2 free beam flying in plane (chapter Sect. 5.2)\n\n" + table)
        from ._flying_plots import plot_flying2d
        plot_flying2d(rows, refs, path, t_window)
    return {"rows": rows, "orders": orders, "orders_window": orders_window, "references": references,
            "table": table, "path": path}


def _row(r, ref, t_end):
    st = r["stats"]
    row = {"element": r["element"], "n": r["n"], "dof": r["dof"], "status": r["status"], "message": r["message"],
           "cpu": r["cpu"], "steps": st["steps"], "newton_iterations": st["newton_iterations"],
           "jacobian_evals": st["jacobian_evals"], "factorizations": st["factorizations"],
           "eps_T": float("nan"), "drift": float("nan")}
    row["t_reached"] = float(r["t"][-1])
    if ref is not None and r["t"].size > 1:
        row["eps_T"] = eps_T(r["t"], r["tip"], ref["t"], ref["tip"])
        row["eps_span"] = float(min(r["t"][-1], ref["t"][-1]))
    if r["energy"] is not None and t_end > T_PULSE:
        row["drift"] = steady_drift(r["t"], r["energy"]["balance"], T_PULSE)["max"]
        row["energy"] = float(r["energy"]["total"][-1])
    return row


def _table(rows, references, orders, orders_window, n_ref, t_end, h, t_window):
    headers = ["element", "#NEL", "#DOF", f"eps_T [0, {t_end:g} s]", f"eps_T [0, {t_window:g} s]", "CPU (s)",
               "Newton its", "its/step", "Jacobians", "LU", "energy drift after pulse (J)", "status"]

    def line(r, eps, epsw):
        its = r["newton_iterations"] / max(r["steps"], 1)
        status = r["status"] if r["status"] == "success" else f"failed at {r['t_reached']:.3f} s"
        return [r["element"], r["n"], r["dof"], eps, epsw, r["cpu"], r["newton_iterations"], f"{its:.2f}",
                r["jacobian_evals"], r["factorizations"], f"{r['drift']:.2e}", status]

    body = [line(r, f"{r['eps_T']:.3e}" + ("" if r.get("eps_span", t_end) >= t_end - 1e-9
                                            else f" (to {r['eps_span']:.2f} s)"), f"{r['eps_window']:.3e}")
            for r in rows]
    body += [line(r, "reference", "reference") for r in references.values()]
    text = (f"Lobatto IIIA (3 stages), h = {h:g} s, modified Newton tol 1e-8, T = {t_end:g} s; "
            f"reference: {n_ref} elements of each family. eps_T in m s^1/2 (chapter Eq. 115).\n\n")
    text += markdown_table(headers, body)
    text += (f"\nObserved order of eps_T in the number of elements (log-log fit, three finest meshes): "
             f"[0, {t_end:g} s] " + ", ".join(f"{k} {v:.2f}" for k, v in orders.items())
             + f"; [0, {t_window:g} s] " + ", ".join(f"{k} {v:.2f}" for k, v in orders_window.items()) + "\n")
    checks = [r for r in rows if "twin_difference" in r]
    if checks:
        text += "\n3D types in the plane against their planar twin with the same mesh (max tip difference, " \
                "max |z|): " + ", ".join(f"{r['element']} {r['n']} el {r['twin_difference']:.1e} m, "
                                          f"{r['max_abs_z']:.1e} m" for r in checks) + "\n"
    return text


def main(argv=None):
    """Command-line entry: ``python -m ancfdae.studies.flying2d [--quick] [--out DIR] [--jobs N]``."""
    command_line(run, __doc__, argv)


if __name__ == "__main__":
    main()
