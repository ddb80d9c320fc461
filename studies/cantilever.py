"""Largely deforming cantilever: the chapter's Table 2 and Figs. 5-6 (benchmark B1, Sect. 5.1).

A cantilever of length 2 m, square section 0.1 m, E = 2.07e11, nu = 0.3, is
clamped at x = 0 and loaded at its tip by the dead force F = 3EI/L^2 in +e_y,
applied in 10 uniform load steps solved by full Newton (relative max-norm
tolerance 1e-8). For 1, 2, 4, ..., 64 elements of each element type the study
reports DOF, the tip error against chapter Eq. 113, CPU seconds and Newton
iterations beside the chapter's own values, and plots Fig. 5 (error against
elements and DOF) and Fig. 6 (CPU time against error).

Run: ``ancfdae study cantilever [--quick] [--out DIR]``.
"""
from __future__ import annotations

import time

import numpy as np

from ancfdae import Material, PointForce, RectangularSection, solve_static
from ancfdae import models

from ._common import Progress, markdown_table, output_dir

__all__ = ["run", "build", "ELEMENTS", "TABLE2", "REFERENCE"]

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
    """Solve B1 for one element type and mesh; CPU time is the median over ``repeats`` solves."""
    beam = build(name, n_elements, **element_options)
    cpu, wall = [], []
    for _ in range(repeats):
        c0, w0 = time.process_time(), time.perf_counter()
        res = solve_static(beam, load_steps=10, tol=1e-8)
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
    tip = beam.position(res.q, L)[:2] - np.array([L, 0.0])
    error = float(np.linalg.norm(tip - REFERENCE[ELEMENTS[name]]))
    return {"element": name, "n_elements": n_elements, "dof": int(beam.q_ref.size), "error": error,
            "tip": tip.tolist(), "cpu": float(np.median(cpu)), "wall": float(np.median(wall)),
            "iterations": res.iterations, "status": res.status, "message": res.message}


def _plots(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(dict.fromkeys(r["element"] for r in rows))
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for name in names:
        rs = [r for r in rows if r["element"] == name]
        axes[0].loglog([r["n_elements"] for r in rs], [r["error"] for r in rs], "o-", label=name)
        axes[1].loglog([r["dof"] for r in rs], [r["error"] for r in rs], "o-", label=name)
    n = np.array([4, 64])
    axes[0].loglog(n, 2e-3 * (n / 4.0) ** -4, "k--", label="order 4")
    axes[0].set(xlabel="number of elements", ylabel="tip error |u_ref - u_FE| (m)")
    axes[1].set(xlabel="degrees of freedom", ylabel="tip error (m)")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle("B1 largely deforming cantilever: convergence (chapter Fig. 5)")
    fig.tight_layout()
    fig.savefig(path / "fig5_convergence.png", dpi=120)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for name in names:
        rs = [r for r in rows if r["element"] == name]
        ax.loglog([r["error"] for r in rs], [r["cpu"] for r in rs], "o-", label=name)
    ax.set(xlabel="tip error (m)", ylabel="CPU time per 10-step solve (s)",
           title="B1: CPU time against error (chapter Fig. 6)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path / "fig6_performance.png", dpi=120)
    plt.close(fig)


def run(elements=None, n_elements=(1, 2, 4, 8, 16, 32, 64), quick: bool = False, repeats: int = 3,
        out=None, plots: bool = True, progress: bool = True) -> dict:
    """Run the study.

    Parameters
    ----------
    elements : sequence of str, optional
        Element types (default: every type available).
    n_elements : sequence of int
        Meshes; ``quick`` uses 1 ... 16.
    quick : bool
        Small meshes and one repeat: the test-suite mode.
    repeats : int
        Solves per case for the median CPU time.
    out : path, optional
        Output folder (default ``out/cantilever``); ``None`` with
        ``plots=False`` writes nothing.
    plots : bool
        Write the markdown table and the PNG figures.

    Returns
    -------
    dict
        ``rows`` (one dict per element type and mesh), ``orders`` (regressed
        convergence order per type), ``table`` (markdown) and ``path``.
    """
    names = list(elements) if elements is not None else available_elements()
    for name in names:
        if name not in available_elements():
            raise ValueError(f"`elements` must name types of {available_elements()}, got {name!r}.")
    meshes = [n for n in n_elements if n <= 16] if quick else list(n_elements)
    repeats = 1 if quick else repeats
    tick = Progress("cantilever", len(names) * len(meshes), progress)
    rows = []
    for name in names:
        for n in meshes:
            row = solve_case(name, n, repeats)
            rows.append(row)
            tick(f"{name} {n:3d} el: error {row['error']:.3e}, {row['iterations']} its, {row['cpu']:.3f} s")
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
    path = None
    if plots:
        path = output_dir("cantilever", out)
        (path / "table2.md").write_text("# B1 largely deforming cantilever (chapter Table 2)\n\n" + table)
        _plots(rows, path)
    return {"rows": rows, "orders": orders, "table": table, "path": path}


def main(argv=None):
    """Command-line entry: ``python -m ancfdae.studies.cantilever [--quick]``."""
    import argparse
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true")
    p.add_argument("--out", default=None)
    p.add_argument("--elements", nargs="*", default=None)
    args = p.parse_args(argv)
    res = run(elements=args.elements, quick=args.quick, out=args.out)
    print(res["table"])
    print(f"written to {res['path']}")


if __name__ == "__main__":
    main()
