"""Largely deforming cantilever: the chapter's Table 2 and Figs. 5-6 (benchmark B1, Sect. 5.1).

A cantilever of length 2 m, square section 0.1 m, E = 2.07e11, nu = 0.3, is
clamped at x = 0 and loaded at its tip by the dead force F = 3EI/L^2 in +e_y,
applied in 10 uniform load steps solved by full Newton (relative max-norm
tolerance 1e-8). For 1, 2, 4, ..., 64 elements of each element type the study
reports DOF, the tip error against chapter Eq. 113, CPU seconds and Newton
iterations beside the chapter's own values, and plots Fig. 5 (error against
elements and DOF) and Fig. 6 (CPU time against error).

Run: ``ancfdae study cantilever [--quick] [--out DIR] [--elements ...] [--n-elements ...]``.
"""
from __future__ import annotations

import sys
import time

import numpy as np

from ancfdae import Material, PointForce, RectangularSection, solve_static
from ancfdae import models

from ancfdae.result import Result

from ._cli import Option, main as cli_main
from ._common import Case, OptionError, output_dir, run_cases, settings
from ._tables import errors_note, markdown_table

__all__ = ["run", "run_case", "build", "solve_case", "ELEMENTS", "TABLE2", "REFERENCE", "FULL", "QUICK",
           "CLI_OPTIONS"]

L = 2.0
MATERIAL = Material(E=2.07e11, nu=0.3, rho=7800.0)
SECTION = RectangularSection(0.1)
FORCE = 3.0 * MATERIAL.E * SECTION.I3 / L**2          # 1.29375e6 N

#: Chapter Eq. 113: tip displacement of the thin (BE) and shear-deformable (SQ) beams.
REFERENCE = {"BE": np.array([-0.50853730436, 1.20723985455]),
             "SQ": np.array([-0.50946471774, 1.20882282955])}

#: Element types of the study: name -> reference family (Eq. 113). Types whose
#: class is not (yet) in ancfdae.models are skipped.
ELEMENTS = {"BE2D": "BE", "SQ2D": "SQ", "BE3D": "BE", "SQ3D": "SQ", "Cable3D": "BE"}

#: Chapter Table 2: elements -> (DOF, tip error [m], CPU [s] on HOTINT 2013, Newton iterations).
TABLE2 = {
    "SQ2D": {1: (12, 1.098e-1, 0.109, 51), 2: (20, 1.516e-2, 0.187, 49), 4: (36, 1.327e-3, 0.297, 49),
             8: (68, 9.159e-5, 0.531, 49), 16: (132, 5.874e-6, 0.952, 49), 32: (260, 3.695e-7, 1.731, 49),
             64: (516, 2.312e-8, 3.244, 50)},
    "BE2D": {1: (8, 2.585e-1, 0.094, 49), 2: (12, 3.755e-2, 0.156, 49), 4: (20, 2.035e-3, 0.265, 49),
             8: (36, 5.060e-5, 0.655, 49), 16: (68, 1.202e-6, 0.827, 49), 32: (132, 3.876e-8, 1.716, 49),
             64: (260, 1.820e-9, 3.136, 49)},
    "SQ3D": {1: (27, 1.098e-1, 1.482, 54), 2: (45, 1.516e-2, 2.324, 55), 4: (81, 1.327e-3, 4.586, 55),
             8: (153, 9.159e-5, 8.471, 55), 16: (297, 5.874e-6, 16.41, 55), 32: (585, 3.695e-7, 32.6, 55),
             64: (1161, 2.312e-8, 70.86, 55)},
    "BE3D": {1: (14, 2.585e-1, 0.905, 49), 2: (21, 3.755e-2, 1.404, 49), 4: (35, 2.035e-3, 2.652, 49),
             8: (63, 5.060e-5, 4.695, 49), 16: (119, 1.202e-6, 9.002, 49), 32: (231, 3.876e-8, 17.94, 49),
             64: (455, 1.820e-9, 35.47, 49)},
}


#: defaults of the full study (chapter Table 2: 1 ... 64 elements); None: every available type
FULL = dict(elements=None, n_elements=(1, 2, 4, 8, 16, 32, 64), repeats=3)
#: quick mode (the tests)
QUICK = dict(n_elements=(1, 2, 4, 8, 16), repeats=1)
CLI_OPTIONS = [
    Option("elements", str, "element types (none given: every available type)", nargs="+"),
    Option("n_elements", int, "meshes", nargs="+"),
    Option("repeats", int, "solves per case for the median CPU time"),
]


def available_elements() -> list[str]:
    """Element types of the study that ancfdae.models provides."""
    return [name for name in ELEMENTS if hasattr(models, name)]


def build(name: str, n_elements: int, **element_options):
    """The B1 cantilever with ``n_elements`` elements of type ``name`` (a Beam)."""
    if name not in ELEMENTS or not hasattr(models, name):
        raise ValueError(f"`elements` must name types of {available_elements()}, got {name!r}.")
    element = getattr(models, name)(MATERIAL, SECTION, **element_options)
    if element.dim == 2:
        start, direction, force = (0.0, 0.0), (1.0, 0.0), (0.0, FORCE)
    else:
        start, direction, force = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, FORCE, 0.0)
    return models.Beam(element, n_elements, L, start=start, direction=direction,
                       supports={0: "clamp"}, loads=[PointForce(force, node=-1)])


def solve_case(name: str, n_elements: int, repeats: int = 1, **element_options) -> dict:
    """Solve B1 for one element type and mesh; CPU time: the median of ``repeats`` solves after an untimed one."""
    beam = build(name, n_elements, **element_options)
    cpu, wall = [], []
    # untimed: compiled kernels and caches warm; it also judges the solution (stability, plausibility)
    judged = solve_static(beam, load_steps=10, tol=1e-8)
    for _ in range(repeats):       # the timed solves are the chapter's Newton solve only
        c0, w0 = time.process_time(), time.perf_counter()
        res = solve_static(beam, load_steps=10, tol=1e-8, check_stability=False, max_strain=None)
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
    tip = beam.position(res.q, L)[:2] - np.array([L, 0.0])
    error = float(np.linalg.norm(tip - REFERENCE[ELEMENTS[name]]))
    return {"element": name, "n_elements": n_elements, "dof": int(beam.q_ref.size), "error": error,
            "tip": tip.tolist(), "cpu": float(np.median(cpu)), "wall": float(np.median(wall)),
            "iterations": res.iterations, "status": res.status, "message": res.message,
            "stable": judged.stable, "warnings": list(judged.warnings),
            "load_steps": [{"q": s["q"]} for s in res.steps], "load_factors": [s["load_factor"] for s in res.steps]}


def _plots(rows, orders, path) -> dict:
    """Figs. 5 and 6 with the chapter's Table 2 values beside ours; returns ``{file stem: Figure}``."""
    from ._flying_plots import figure, order_guide, save, style

    names = list(dict.fromkeys(r["element"] for r in rows))
    chapter_kw = dict(ls="none", marker="x", ms=7, mew=1.2)
    fig, axes = figure(1, 2, figsize=(12, 4.6))
    for name in names:
        rs = [r for r in rows if r["element"] == name]
        axes[0].loglog([r["n_elements"] for r in rs], [r["error"] for r in rs], label=name, **style(name))
        axes[1].loglog([r["dof"] for r in rs], [r["error"] for r in rs], label=name, **style(name))
        ch = TABLE2.get(name)
        if ch and name.endswith("2D"):        # the chapter's 3D errors equal its 2D ones: drawn once
            meshes = sorted(ch)
            twin = name.replace("2D", "3D")
            lab = f"chapter Table 2, {name}" + (f" (= {twin})" if twin in TABLE2 else "")
            axes[0].loglog(meshes, [ch[m][1] for m in meshes], color=style(name)["color"], label=lab, **chapter_kw)
        if ch:
            meshes = sorted(ch)
            axes[1].loglog([ch[m][0] for m in meshes], [ch[m][1] for m in meshes], color=style(name)["color"],
                           label=f"chapter Table 2, {name}", **dict(chapter_kw, marker="x" if name.endswith("2D")
                                                                   else "+"))
        if name in orders and name.endswith("2D"):
            fit = [r for r in rs if r["n_elements"] >= 4]
            order_guide(axes[0], [r["n_elements"] for r in fit], [r["error"] for r in fit], orders[name],
                        style(name)["color"], f"{name} ")
    axes[0].set(xlabel="number of elements", ylabel="tip error |u_ref - u_FE| (m)")
    axes[1].set(xlabel="degrees of freedom", ylabel="tip error (m)")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="lower left")
    fig.suptitle("B1 largely deforming cantilever: convergence (chapter Fig. 5); 3D types open markers, "
                 "chapter values x / +")
    figs = {"fig5_convergence": fig}

    fig, ax = figure(figsize=(8.5, 4.6))
    for name in names:
        rs = [r for r in rows if r["element"] == name]
        ax.loglog([r["error"] for r in rs], [r["cpu"] for r in rs], label=f"{name} (ancfdae)", **style(name))
        ch = TABLE2.get(name)
        if ch:
            meshes = sorted(ch)
            ax.loglog([ch[m][1] for m in meshes], [ch[m][2] for m in meshes], color=style(name)["color"],
                      ls=":", lw=0.8, marker="x" if name.endswith("2D") else "+", ms=7,
                      label=f"{name} (chapter, HOTINT, 2013 hardware)")
    ax.set(xlabel="tip error (m)", ylabel="CPU time per 10-step solve (s)",
           title="B1: CPU time against error (chapter Fig. 6)")
    ax.grid(True, which="both", alpha=0.3)
    fig.legend(loc="outside right upper", fontsize=7)      # beside the axes: it covers no point
    figs["fig6_performance"] = fig
    for stem, f in figs.items():
        save(f, path, stem)
    return figs


def run_case(case: dict) -> dict:
    """One B1 solve (``case = {element, n, repeats}``) as a record for the runner.

    The stored :class:`ancfdae.Result` holds the load path: ``t`` is the load
    factor of each of the 10 steps and ``q`` the converged coordinates there.
    """
    row = solve_case(case["element"], case["n"], case["repeats"])
    q = np.array([s["q"] for s in row.pop("load_steps")])
    lam = np.array(row.pop("load_factors"), dtype=float)
    zeros = np.zeros_like(q)
    result = Result(t=lam, q=q, v=zeros, a=zeros, status=row["status"],
                    message=row["message"], stats={"newton_iterations": row["iterations"]}, method="static-newton",
                    options={"load_steps": 10, "tol": 1e-8})
    return dict(row, result=result)


def run(elements=None, n_elements=None, repeats=None, quick: bool = False, out=None, plots: bool = True,
        progress: bool = True) -> dict:
    """Run the study. Every option left None takes its value from :data:`FULL` (:data:`QUICK` with ``quick``).

    Parameters
    ----------
    elements : sequence of str
        Element types (default: every type available).
    n_elements : sequence of int
        Meshes (chapter: 1 ... 64; quick: 1 ... 16).
    repeats : int
        Solves per case for the median CPU time (quick: 1).
    quick, out, plots, progress
        The sweep options of every study (:mod:`ancfdae.studies._common`);
        ``quick``: small meshes and one repeat. The cases run serially (no
        ``jobs``): their CPU times are the study's result.

    Returns
    -------
    dict
        ``rows`` (one dict per element type and mesh), ``orders`` (regressed
        convergence order per type), with the keys of every study.
    """
    o = settings(FULL, QUICK, quick, dict(elements=elements, n_elements=n_elements, repeats=repeats))
    names = list(o["elements"]) if o["elements"] else available_elements()
    for name in names:
        if name not in available_elements():
            raise OptionError(f"`elements` must name types of {available_elements()}, got {name!r}.")
    path = output_dir("cantilever", out, quick) if (plots or out is not None) else None
    cases = [Case(element=name, n=n, repeats=o["repeats"], label=f"{name} {n} el")
             for name in names for n in o["n_elements"]]
    # serial: the CPU times are the study's result and must not share the machine with a sweep
    sweep = run_cases(run_case, cases, out=path, name="cantilever", progress=progress,
                      reduce=lambda r: {k: v for k, v in r.items() if k != "result"})
    rows = sweep.finished()
    orders = {}
    for name in names:
        rs = [r for r in rows if r["element"] == name and r["n_elements"] >= 4]
        if len(rs) >= 2:
            orders[name] = float(-np.polyfit(np.log([r["n_elements"] for r in rs]),
                                             np.log([r["error"] for r in rs]), 1)[0])
    headers = ["element", "#NEL", "#DOF", "error (m)", "chapter error", "CPU (s)", "chapter CPU (s)",
               "#its", "chapter #its"]
    table_rows = []
    for r in rows:
        ch = TABLE2.get(r["element"], {}).get(r["n_elements"], (None, None, None, None))
        table_rows.append([r["element"], r["n_elements"], r["dof"], f"{r['error']:.3e}",
                           "-" if ch[1] is None else f"{ch[1]:.3e}", r["cpu"],
                           "-" if ch[2] is None else ch[2], r["iterations"], "-" if ch[3] is None else ch[3]])
    table = markdown_table(headers, table_rows)
    table += "\nConvergence order (log-log fit, 4 elements and up): " + ", ".join(
        f"{k} {v:.2f}" for k, v in orders.items()) + "\n"
    table += errors_note(sweep.errors)
    figures = {}
    if plots:
        (path / "table2.md").write_text("# B1 largely deforming cantilever (chapter Table 2)\n\n" + table)
        figures = _plots(rows, orders, path)
    return {"rows": rows, "orders": orders, "errors": sweep.errors, "reused": sweep.reused, "figures": figures,
            "table": table, "path": path}


if __name__ == "__main__":     # python -m ancfdae.studies.cantilever: the same as `ancfdae study cantilever`
    raise SystemExit(cli_main(sys.modules[__name__]))
