"""Figures of the multibody study (B5-B7), drawn as the other studies draw theirs (:mod:`._flying_plots`).

Four figures, each written as PNG and SVG into the study's output folder: the work-precision of every
integrator per benchmark (errors of q and lambda against CPU time), the constraint drift over time (position
and velocity level, each method at its finest step), B7's energy error over time and the multipliers over
time beside the reference (B6 the slider's normal force, B5 the hub torque). A run that failed is drawn up
to its failure, so that the figure shows where it stopped.
"""
from __future__ import annotations

import numpy as np

from ._flying_plots import figure, save

__all__ = ["plot_multibody"]

_MARKERS = "os^v<>Dxp*"


def _style(methods, m) -> dict:
    k = list(methods).index(m)
    return dict(color=f"C{k % 10}", marker=_MARKERS[k % len(_MARKERS)], ms=5)


def _finest(records, bm, m):
    """The finest-step (smallest ``h`` or rtol) run of ``m`` on ``bm`` (not a reference), or None."""
    mine = [r for r in records if r["benchmark"] == bm and r["integrator"] == m and not r["reference"]]
    return min(mine, key=lambda r: r["h"]) if mine else None


def _work_precision(rows, methods, benchmarks):
    fig, axes = figure(2, len(benchmarks), figsize=(5.2 * len(benchmarks), 8.5), squeeze=False)
    for j, bm in enumerate(benchmarks):
        for m in methods:
            rs = [r for r in rows if r["benchmark"] == bm and r["integrator"] == m]
            for i, key in enumerate(("error", "error_lam")):
                ok = [r for r in rs if np.isfinite(r[key]) and r[key] > 0]
                if ok:
                    axes[i, j].loglog([r["cpu"] for r in ok], [r[key] for r in ok], label=m, **_style(methods, m))
        for i, what in enumerate(("positions q", "multipliers lambda")):
            axes[i, j].set(xlabel="CPU time (s)", ylabel=f"largest relative error, {what}",
                           title=f"{bm}: work-precision, {what}")
            axes[i, j].grid(True, which="both", alpha=0.3)
            axes[i, j].legend(fontsize=7)
    return fig


def _drift(records, methods, benchmarks):
    fig, axes = figure(2, len(benchmarks), figsize=(5.2 * len(benchmarks), 8.5), squeeze=False)
    for j, bm in enumerate(benchmarks):
        for m in methods:
            r = _finest(records, bm, m)
            if r is None or not len(r["t"]):
                continue
            for i, key in enumerate(("drift_q_t", "drift_v_t")):
                y = np.maximum(np.asarray(r[key], float), 1e-18)      # exact zeros at t = 0 on a log axis
                axes[i, j].semilogy(r["t"], y, lw=1.0, label=f"{m} ({r['h']:g})", color=_style(methods, m)["color"])
        for i, what in enumerate(("max |g|", "max |G v + g_t|")):
            axes[i, j].set(xlabel="t (s)", ylabel=what, title=f"{bm}: {what} at the outputs, finest step")
            axes[i, j].grid(True, which="both", alpha=0.3)
            axes[i, j].legend(fontsize=7)
    return fig


def _energy(records, methods):
    fig, axes = figure(1, 2, figsize=(11, 4.5), squeeze=False)
    for m in methods:
        r = _finest(records, "B7", m)
        if r is None or "energy_error_t" not in r or not len(r["t"]):
            continue
        e = np.abs(np.asarray(r["energy_error_t"], float))
        L = np.asarray(r["out"]["angular_momentum_z"], float)
        kw = dict(lw=1.0, label=f"{m} ({r['h']:g})", color=_style(methods, m)["color"])
        axes[0, 0].semilogy(r["t"], np.maximum(e, 1e-17), **kw)
        axes[0, 1].semilogy(r["t"], np.maximum(np.abs(L - L[0]) / abs(L[0]), 1e-17), **kw)
    axes[0, 0].set(xlabel="t (s)", ylabel="|E - E0| / max T", title="B7: energy error, finest step")
    axes[0, 1].set(xlabel="t (s)", ylabel="|L_z - L_z0| / |L_z0|", title="B7: vertical angular momentum")
    for ax in axes[0]:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    return fig


def _multipliers(records, refs, methods, benchmarks):
    shown = [(bm, key, label) for bm, key, label in (("B6", "slider_normal_force", "slider normal force (N)"),
                                                     ("B5", "hub_torque", "hub torque (N m)")) if bm in benchmarks]
    if not shown:
        return None
    fig, axes = figure(len(shown), 1, figsize=(11, 4.2 * len(shown)), squeeze=False)
    for i, (bm, key, label) in enumerate(shown):
        ax = axes[i, 0]
        if bm in refs:
            ref = refs[bm]
            ax.plot(ref["t"], ref["out"][key], "k-", lw=2.2, alpha=0.4,
                    label=f"reference: {ref['integrator']} {ref['h']:g}")
        for m in methods:
            r = _finest(records, bm, m)
            if r is None or not len(r["t"]):
                continue
            ax.plot(r["t"], r["out"][key], lw=0.9, label=f"{m} ({r['h']:g}, {r['status']})",
                    color=_style(methods, m)["color"])
        ax.set(xlabel="t (s)", ylabel=label, title=f"{bm}: {label} at the outputs, finest step of each method")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    return fig


def plot_multibody(records, rows, refs, methods, path) -> dict:
    """Draw and save the study's figures; ``{file stem: Figure}``.

    Parameters
    ----------
    records : list of dict
        The reduced records of every case (:func:`ancfdae.studies._multibody_cases.outputs`).
    rows : list of dict
        The study's rows (errors, CPU).
    refs : dict
        The reference record per benchmark.
    methods : sequence of str
    path : pathlib.Path
        The output folder.
    """
    benchmarks = list(dict.fromkeys(r["benchmark"] for r in rows))
    figs = {"work_precision": _work_precision(rows, methods, benchmarks),
            "drift": _drift(records, methods, benchmarks)}
    if "B7" in benchmarks:
        figs["b7_energy"] = _energy(records, methods)
    mult = _multipliers(records, refs, methods, benchmarks)
    if mult is not None:
        figs["multipliers"] = mult
    for stem, fig in figs.items():
        save(fig, path, stem)
    return figs
