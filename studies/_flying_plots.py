"""Figures of the studies, drawn on ``matplotlib.figure.Figure`` objects (no pyplot state, no backend switch).

Every plotting function returns ``{file stem: Figure}``; :func:`save` writes
each as PNG (dpi 100) and SVG beside it. Conventions that keep overlapping
series readable: a planar type is drawn with filled small markers and a solid
line, its 3D twin with larger open markers and a dashed line, so both stay
visible when they coincide; a fitted-order guide is a thin dotted line over
the meshes of the fit, labelled with the fitted value.
"""
from __future__ import annotations

import numpy as np

__all__ = ["figure", "save", "style", "order_guide", "plot_flying2d", "plot_flying3d"]

_COLOR = {"BE2D": "C0", "SQ2D": "C1", "BE3D": "C0", "SQ3D": "C1", "Cable3D": "C2", "BE3DSR": "C3"}


def figure(nrows: int = 1, ncols: int = 1, **kw):
    """A new ``Figure`` and its axes (``Figure.subplots`` arguments)."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=kw.pop("figsize", None), layout="constrained")
    return fig, fig.subplots(nrows, ncols, **kw)


def save(fig, path, stem: str) -> None:
    """Write ``fig`` as ``path/stem.png`` and ``path/stem.svg``."""
    fig.savefig(path / f"{stem}.png", dpi=100)
    fig.savefig(path / f"{stem}.svg")


def style(name: str) -> dict:
    """Line style of an element type: 2D filled and solid, 3D open, larger and dashed (visible on top)."""
    planar = name.endswith("2D")
    marker = "o" if planar else {"Cable3D": "D"}.get(name, "s")
    return dict(color=_COLOR.get(name), ls="-" if planar else "--", marker=marker,
                ms=5 if planar else 10 if marker == "s" else 6, mfc=None if planar else "none", mew=1.5,
                lw=1.2 if planar else 1.0)


def order_guide(ax, x, y_fit_points, order: float, color, label_prefix: str = "") -> None:
    """A dotted line ``C x^-order`` through the geometric mean of the fitted points, labelled with the order."""
    x = np.asarray(x, float)
    y = np.asarray(y_fit_points, float)
    c = np.exp(np.mean(np.log(y) + order * np.log(x)))
    xs = np.array([x.min() / 1.2, x.max() * 1.2])
    ax.loglog(xs, 0.5 * c * xs ** -order, ":", color=color, lw=1.0,
              label=f"{label_prefix}fitted order {order:.2f} (x 0.5)")


def plot_flying2d(rows, refs, orders, fits, path) -> dict:
    """Fig. 8 (eps_T against elements and DOF), Fig. 9 (CPU against eps_T), tip path and energy."""
    names = list(dict.fromkeys(r["element"] for r in rows))
    ok = [r for r in rows if np.isfinite(r["eps_T"]) and r["eps_T"] > 0]
    t_end = max((float(r["t"][-1]) for r in refs.values()), default=float("nan"))
    figs = {}
    fig, axes = figure(1, 2, figsize=(11, 4.6))
    for name in names:
        rs = [r for r in ok if r["element"] == name]
        if not rs:
            continue
        axes[0].loglog([r["n"] for r in rs], [r["eps_T"] for r in rs], label=name, **style(name))
        axes[1].loglog([r["dof"] for r in rs], [r["eps_T"] for r in rs], label=name, **style(name))
        if name in orders and name.endswith("2D"):
            fit = [r for r in rs if r["n"] in fits[name]]
            order_guide(axes[0], [r["n"] for r in fit], [r["eps_T"] for r in fit], orders[name], _COLOR.get(name),
                        f"{name} ")
    meshes = sorted({r["n"] for r in ok})
    if meshes:
        axes[0].set_xticks(meshes, [str(m) for m in meshes])
        axes[0].set_xticks([], minor=True)
    axes[0].set(xlabel="number of elements", ylabel=f"eps_T over [0, {t_end:g} s] (Eq. 115, m s^1/2)")
    axes[1].set(xlabel="degrees of freedom", ylabel="eps_T (Eq. 115, m s^1/2)")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7, loc="lower left")
    axes[1].legend(fontsize=7, loc="lower left")
    fig.suptitle("B2 beam flying in plane: integrated tip error against the 128-element reference (chapter Fig. 8)"
                 if refs and next(iter(refs.values()))["n"] == 128 else
                 "B2 beam flying in plane: integrated tip error (chapter Fig. 8)")
    figs["fig8_convergence"] = fig

    fig, ax = figure(figsize=(6, 4.4))
    for name in names:
        rs = [r for r in ok if r["element"] == name]
        if rs:
            ax.loglog([r["eps_T"] for r in rs], [r["cpu"] for r in rs], label=name, **style(name))
    ax.set(xlabel="eps_T (Eq. 115, m s^1/2)", ylabel=f"CPU time of the {t_end:g} s run (s)",
           title="B2: CPU time against error (chapter Fig. 9)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    figs["fig9_performance"] = fig

    fig, axes = figure(1, 2, figsize=(11, 4.2))
    for fam, r in refs.items():
        axes[0].plot(r["tip"][:, 0], r["tip"][:, 1], lw=1, label=f"{r['element']} {r['n']} el")
        if r["energy"] is not None:
            axes[1].plot(r["t"], r["energy"]["total"], lw=1, label=f"T + U, {r['element']}")
            axes[1].plot(r["t"], r["energy"]["work"], "--", lw=1, label=f"work of the loads, {r['element']}")
    axes[0].set(xlabel="x_B (m)", ylabel="y_B (m)", title="path of the tip B (references)")
    axes[0].set_aspect("equal", adjustable="datalim")
    axes[1].set(xlabel="t (s)", ylabel="energy (J)", title="energy (references)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    figs["b2_tip_energy"] = fig
    for stem, f in figs.items():
        save(f, path, stem)
    return figs


def _label3d(r):
    thin = r["element"] in ("BE3D", "BE3DSR")
    lab = f"{r['element']} {r['n']} el" + (f" ({r['director_update']})" if thin else "")
    lab += f", below {r['update_below']:g}" if thin and r.get("update_below") else ""
    lab += f", {r['method']}" if r.get("method", "lobatto3") != "lobatto3" else ""
    lab += f", h {r['h']:g}"
    return lab + ("" if r["status"] == "success" else f", fails {r['t_end_reached']:.2f} s")


def plot_flying3d(records, path, chapter_failures=None) -> dict:
    """Fig. 11 (T + U, balance error), Fig. 12 (displacement of B), the long SQ3D run.

    ``chapter_failures`` (``{elements: t}``) marks the chapter's BE3D failure
    times on the energy plot.
    """
    figs = {}
    main = [r for r in records if not r.get("long")]
    fig, axes = figure(1, 2, figsize=(13, 4.8))
    be_colors = {}
    n_sq = 0
    for k, r in enumerate(main):
        if r["element"] == "SQ3D":
            # the SQ3D meshes coincide at this scale: thinner, differently dashed lines keep each visible
            kw = dict(ls=("-", "--", ":", "-.")[n_sq % 4], lw=max(2.6 - 0.8 * n_sq, 0.8))
            n_sq += 1
        else:
            kw = dict(ls="--", lw=1)
        line, = axes[0].plot(r["t"], r["energy"]["kinetic"] + r["energy"]["strain"], label=_label3d(r), **kw)
        axes[1].semilogy(r["t"], np.abs(r["energy"]["balance"]) + 1e-16, color=line.get_color(), label=_label3d(r),
                         **kw)
        if r["element"] in ("BE3D", "BE3DSR") and r["status"] != "success":
            axes[0].plot([r["t_end_reached"]], [r["energy"]["kinetic"][-1] + r["energy"]["strain"][-1]], "x",
                         color=line.get_color(), ms=9, mew=2)
        if r["element"] == "BE3D":
            be_colors.setdefault(r["n"], line.get_color())
    for n, t in (chapter_failures or {}).items():
        axes[0].axvline(t, color=be_colors.get(n, "0.5"), ls=":", lw=1.2,
                        label=f"chapter: BE3D {n} el fails at {t:g} s")
    ymax = max((np.nanmax(r["energy"]["kinetic"] + r["energy"]["strain"]) for r in main if r["element"] == "SQ3D"),
               default=None)
    if ymax:
        axes[0].set_ylim(0, 1.6 * ymax)
    axes[0].set(xlabel="t (s)", ylabel="T + U (J)", title="B3: total energy (chapter Fig. 11); x: run fails")
    axes[1].set(xlabel="t (s)", ylabel="|T + U - W_ext| (J)", title="energy balance error")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=6.5, loc="lower right")
    axes[1].legend(fontsize=6.5, loc="lower right")
    figs["fig11_energy"] = fig

    long = [r for r in records if r.get("long")]
    if long:
        fig, ax = figure(figsize=(7, 3.8))
        for r in long:
            ax.semilogy(r["t"], np.abs(r["energy"]["balance"]) + 1e-16, lw=1, label=f"SQ3D {r['n']} el, h {r['h']:g}")
        ax.set(xlabel="t (s)", ylabel="|T + U - W_ext| (J)", title="B3, SQ3D: energy balance error, long run")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        figs["sq3d_long_energy"] = fig

    kinds = list(dict.fromkeys(r["element"] for r in main))
    if kinds:
        fig, axes = figure(3, len(kinds), figsize=(5.5 * len(kinds), 7.5), sharex=True, squeeze=False)
        for j, kind in enumerate(kinds):
            variant = next((r["director_update"] for r in main if r["element"] == kind), None)
            sel = [r for r in main if r["element"] == kind and r["director_update"] == variant]
            for k, r in enumerate(sel):
                u = r["tip"] - r["tip"][:1]
                for i in range(3):
                    # finer meshes drawn thinner on top: coinciding curves stay visible
                    axes[i, j].plot(r["t"], u[:, i], lw=2.2 - 0.6 * k, ls=("-", "--", ":", "-.")[k % 4],
                                    label=_label3d(r))
            axes[0, j].set_title(f"{kind}: displacement of B (chapter Fig. 12)")
            for i, c in enumerate("xyz"):
                axes[i, j].set_ylabel(f"u_{c} (m)")
                axes[i, j].grid(True, alpha=0.3)
            axes[0, j].legend(fontsize=7)
            axes[2, j].set_xlabel("t (s)")
        figs["fig12_displacement"] = fig
    mech = [r for r in main if "directors" in r["monitors"] and r["monitors"].get("director_update")]
    if mech:
        figs["mechanism"] = _mechanism(mech)
    for stem, f in figs.items():
        save(f, path, stem)
    return figs


def _mechanism(records):
    """The director update's share of the balance, and the director geometry, per BE3D/BE3DSR run."""
    fig, axes = figure(3, 1, figsize=(9, 9), sharex=True)
    for k, r in enumerate(records):
        cum = np.asarray(r["monitors"]["director_update"]["cumulative"])
        step = r["energy"]["balance"] - cum
        kw = dict(ls=("-", "--", ":", "-.")[k % 4], lw=1.2)
        line, = axes[0].plot(r["t"], cum, label=_label3d(r) + ": update part", **kw)
        axes[0].plot(r["t"], step, color=line.get_color(), lw=0.8, alpha=0.6)
        geo = r["monitors"]["directors"]
        axes[1].plot(r["t"], geo["max_angle"], color=line.get_color(), label=_label3d(r), **kw)
        axes[2].plot(r["t"], geo["min_projection"], color=line.get_color(), **kw)
    axes[0].set(ylabel="balance parts (J)", title="B3: update part (the jumps of T + U at the director updates; "
                "thin: the step part)", ylim=(-3, 3))
    axes[1].set(ylabel="max angle (deg)", title="largest angle between an element's nodal directors")
    axes[2].set(ylabel="min |d - (d.e1) e1|", xlabel="t (s)", ylim=(0, 1.05),
                title="smallest interior projection of Eq. 99 (0: frame undefined)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=6.5)
    axes[1].legend(fontsize=6.5)
    return fig
