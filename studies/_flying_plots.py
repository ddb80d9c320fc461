"""Figures of the flying-beam studies (PNG, small: dpi 100)."""
from __future__ import annotations

import numpy as np

__all__ = ["figure", "plot_flying2d", "plot_flying3d"]

_STYLE = {"BE2D": "C0", "SQ2D": "C1", "BE3D": "C2", "SQ3D": "C3"}


def figure(*args, **kw):
    """A matplotlib figure with the Agg backend (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt.subplots(*args, **kw)


def save(fig, path, name):
    import matplotlib.pyplot as plt
    fig.tight_layout()
    fig.savefig(path / name, dpi=100)
    plt.close(fig)


def plot_flying2d(rows, refs, path, t_window=None):
    """Fig. 8 (eps_T against elements and DOF), Fig. 9 (CPU against eps_T), tip path and energy."""
    names = list(dict.fromkeys(r["element"] for r in rows))
    ok = [r for r in rows if np.isfinite(r["eps_T"]) and r["eps_T"] > 0]
    t_end = max(float(r["t"][-1]) for r in refs.values())
    fig, axes = figure(1, 2, figsize=(10, 4.2))
    for name in names:
        rs = [r for r in ok if r["element"] == name]
        mk = "o" if name.endswith("2D") else "s"
        for key, ls, lab in (("eps_T", "-", f"{name}, [0, T]"), ("eps_window", ":", f"{name}, [0, {t_window:g} s]")):
            if key == "eps_window" and t_window is None:
                continue
            axes[0].loglog([r["n"] for r in rs], [r[key] for r in rs], ls, marker=mk, color=_STYLE.get(name),
                           mfc="none" if name.endswith("3D") else None, label=lab)
            axes[1].loglog([r["dof"] for r in rs], [r[key] for r in rs], ls, marker=mk, color=_STYLE.get(name),
                           mfc="none" if name.endswith("3D") else None, label=lab)
    if ok:
        n = np.array([8.0, max(r["n"] for r in ok)])
        e8 = min(r.get("eps_window", r["eps_T"]) for r in ok if r["n"] == 8) if any(r["n"] == 8 for r in ok) else 1e-3
        axes[0].loglog(n, e8 * 0.3 * (n / 8) ** -4, "k--", lw=0.8, label="order 4")
    meshes = sorted({r["n"] for r in ok})
    axes[0].set_xticks(meshes, [str(m) for m in meshes])
    axes[0].set_xticks([], minor=True)
    axes[0].set(xlabel="number of elements", ylabel="eps_T (Eq. 115)")
    axes[1].set(xlabel="degrees of freedom", ylabel="eps_T (Eq. 115)")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("B2 beam flying in plane: integrated tip error (chapter Fig. 8)")
    save(fig, path, "fig8_convergence.png")

    fig, ax = figure(figsize=(5.5, 4))
    key = "eps_T" if t_window is None else "eps_window"
    for name in names:
        rs = [r for r in ok if r["element"] == name]
        ax.loglog([r[key] for r in rs], [r["cpu"] for r in rs], "o-", color=_STYLE.get(name), label=name)
    span = "[0, T]" if t_window is None else f"[0, {t_window:g} s]"
    ax.set(xlabel=f"eps_T over {span} (Eq. 115)", ylabel=f"CPU time of the {t_end:g} s run (s)",
           title="B2: CPU time against error (chapter Fig. 9)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    save(fig, path, "fig9_performance.png")

    fig, axes = figure(1, 2, figsize=(10, 4))
    for fam, r in refs.items():
        axes[0].plot(r["tip"][:, 0], r["tip"][:, 1], label=f"{r['element']} {r['n']} el")
        if r["energy"] is not None:
            axes[1].plot(r["t"], r["energy"]["total"], label=f"T + U, {r['element']}")
            axes[1].plot(r["t"], r["energy"]["work"], "--", label=f"work of the loads, {r['element']}")
    axes[0].set(xlabel="x_B (m)", ylabel="y_B (m)", title="path of the tip B (reference)")
    axes[0].set_aspect("equal", adjustable="datalim")
    axes[1].set(xlabel="t (s)", ylabel="energy (J)", title="energy (reference)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    save(fig, path, "b2_tip_energy.png")


def plot_flying3d(records, path):
    """Fig. 11 (total energy and balance error against time), Fig. 12 (displacement of B), long runs."""
    main = [r for r in records if not r.get("long")]
    fig, axes = figure(1, 2, figsize=(12, 4.4))
    for r in main:
        ls = "-" if r["element"] == "SQ3D" else "--"
        lab = f"{r['element']} {r['n']} el" + (f" ({r['director_update']})" if r["element"] == "BE3D" else "") \
            + f", h {r['h']:g}" + ("" if r["status"] == "success" else f", fails {r['t_end_reached']:.2f} s")
        axes[0].plot(r["t"], r["energy"]["kinetic"] + r["energy"]["strain"], ls, lw=1, label=lab)
        axes[1].semilogy(r["t"], np.abs(r["energy"]["balance"]) + 1e-16, ls, lw=1, label=lab)
    ymax = max((np.nanmax(r["energy"]["kinetic"] + r["energy"]["strain"]) for r in main if r["element"] == "SQ3D"),
               default=None)
    if ymax:
        axes[0].set_ylim(0, 1.6 * ymax)
    axes[0].set(xlabel="t (s)", ylabel="T + U (J)", title="B3: total energy (chapter Fig. 11)")
    axes[1].set(xlabel="t (s)", ylabel="|T + U - W_ext| (J)", title="energy balance error")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    save(fig, path, "fig11_energy.png")

    long = [r for r in records if r.get("long")]
    if long:
        fig, ax = figure(figsize=(7, 3.8))
        for r in long:
            ax.semilogy(r["t"], np.abs(r["energy"]["balance"]) + 1e-16, lw=1, label=f"SQ3D {r['n']} el, h {r['h']:g}")
        ax.set(xlabel="t (s)", ylabel="|T + U - W_ext| (J)", title="B3, SQ3D: energy balance error, long run")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        save(fig, path, "sq3d_long_energy.png")

    kinds = list(dict.fromkeys(r["element"] for r in main))
    fig, axes = figure(3, len(kinds), figsize=(5 * len(kinds), 7), sharex=True, squeeze=False)
    for j, kind in enumerate(kinds):
        variant = next((r["director_update"] for r in main if r["element"] == kind), None)
        for r in (r for r in main if r["element"] == kind and r["director_update"] == variant):
            u = r["tip"] - r["tip"][:1]
            for i in range(3):
                axes[i, j].plot(r["t"], u[:, i], lw=1, label=f"{r['n']} el, h {r['h']:g}")
        axes[0, j].set_title(f"{kind}: displacement of B (chapter Fig. 12)")
        for i, c in enumerate("xyz"):
            axes[i, j].set_ylabel(f"u_{c} (m)")
            axes[i, j].grid(True, alpha=0.3)
        axes[0, j].legend(fontsize=8)
        axes[2, j].set_xlabel("t (s)")
    save(fig, path, "fig12_displacement.png")
