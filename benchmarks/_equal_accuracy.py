"""Cost at equal accuracy, ours against Exudyn's: the interleaved timing rounds and the ratio tables.

Shared by :mod:`benchmarks.work_precision` (the flexible pendulum) and :mod:`benchmarks.sq3d_dynamics`
(a free-flying 3D beam). A configuration is ``(side, method, x)``: side ``"ours"`` or ``"exudyn"``,
the method's name and its step (or IDA's rtol). A run is a dict with at least ``ok``, ``message``,
``cpu`` (process time of the solve, s), ``t`` and ``tip`` (the tip's history, rows per output time).

Every configuration runs once per round, ``repeats`` rounds (interleaved, so that both codes see the
same machine load); the cost of a configuration is the median CPU time of its rounds, its error that
of its last run. "Cheapest run at least as accurate" is a step function of the sampled steps: it
favours neither side systematically but is coarse, so :func:`summary` also gives the ratio with our
cost interpolated (log-log, between the two runs of one method that bracket the level).
"""
from __future__ import annotations

import numpy as np

__all__ = ["interleaved", "tip_error", "table", "summary", "per_method"]


def interleaved(configs, run, repeats: int) -> dict:
    """Run every configuration once per round, ``repeats`` rounds.

    Parameters
    ----------
    configs : list of (str, str, float)
        ``(side, method, x)``.
    run : callable
        ``run(side, method, x) -> dict`` (a run, see the module docstring); a
        RuntimeError counts as a failed run.
    repeats : int

    Returns
    -------
    dict
        ``{config: [runs]}`` of the configurations that never failed; a
        failure is printed at once and its configuration not run again.
    """
    runs, failed = {c: [] for c in configs}, set()
    for _ in range(repeats):
        for c in configs:
            if c in failed:
                continue
            try:
                r = run(*c)
            except RuntimeError as exc:
                r = dict(ok=False, message=str(exc))
            if not r["ok"]:
                failed.add(c)
                print(f"  {c[0]} {c[1]} {c[2]:g}: failed ({r['message']})", flush=True)
                continue
            runs[c].append(r)
    return {c: rs for c, rs in runs.items() if c not in failed and rs}


def tip_error(run: dict, t_ref: np.ndarray, tip_ref: np.ndarray) -> float:
    """Largest distance, over the reference's output times, of the run's tip (interpolated) to the reference's."""
    tip = np.column_stack([np.interp(t_ref, run["t"], run["tip"][:, k]) for k in range(tip_ref.shape[1])])
    return float(np.max(np.linalg.norm(tip - tip_ref, axis=1)))


def table(runs: dict, error, x_name: str = "h", columns=()) -> list:
    """Print one line per configuration and return the rows ``(config, median CPU s, error m)``.

    Parameters
    ----------
    runs : dict
        As returned by :func:`interleaved`.
    error : callable
        ``error(config, run) -> float`` of the configuration's last run.
    x_name : str
        Header of the step column.
    columns : sequence of (str, int, str, str)
        Further columns ``(header, width, format spec, key of the last run)``.

    Returns
    -------
    list of tuple
    """
    print(f"{'side':<7}{'method':<19}{x_name:>10}{'CPU s':>9}{'error m':>10}"
          + "".join(f"{head:>{width}}" for head, width, _, _ in columns))
    rows = []
    for c, rs in runs.items():
        cpu = float(np.median([r["cpu"] for r in rs]))
        err = error(c, rs[-1])
        rows.append((c, cpu, err))
        print(f"{c[0]:<7}{c[1]:<19}{c[2]:>10.1e}{cpu:9.3f}{err:10.2e}"
              + "".join(f"{rs[-1][key]:{width}{spec}}" for _, width, spec, key in columns), flush=True)
    return rows


def summary(rows) -> None:
    """At each Exudyn accuracy level: the cheapest run of each side at least as accurate."""
    ex = [r for r in rows if r[0][0] == "exudyn"]
    us = [r for r in rows if r[0][0] == "ours"]
    if not ex:
        return
    print("at equal accuracy (each Exudyn error level; cheapest run of each side with error <= it):")
    for level in sorted({r[2] for r in ex}, reverse=True):
        e_best = min((r for r in ex if r[2] <= level), key=lambda r: r[1])
        o = [r for r in us if r[2] <= level]
        if not o:
            print(f"  {level:9.2e} m: Exudyn {e_best[0][1]} h={e_best[0][2]:g} {e_best[1]:.3f} s | "
                  f"no run of ours this accurate")
            continue
        o_best = min(o, key=lambda r: r[1])
        interp = _interpolated_cost(us, level)
        print(f"  {level:9.2e} m: Exudyn {e_best[0][1]} h={e_best[0][2]:g} {e_best[1]:.3f} s | ours "
              f"{o_best[0][1]} {o_best[0][2]:g} {o_best[1]:.3f} s (error {o_best[2]:.1e}) | ratio "
              f"{o_best[1] / e_best[1]:.2f}" + (f" (log-log interpolated: {interp / e_best[1]:.2f})"
                                                  if interp is not None else ""), flush=True)


def per_method(rows) -> None:
    """For each run of ours: the cheapest Exudyn run (either integrator) at least as accurate, and the ratio."""
    ex = [r for r in rows if r[0][0] == "exudyn"]
    if not ex:
        return
    print("per method of ours (each run against Exudyn's cheapest run with error <= it):")
    for (side, m, x), cpu, err in rows:
        if side != "ours":
            continue
        e = [r for r in ex if r[2] <= err]
        if not e:
            print(f"  {m:<19}{x:9.1e} {cpu:.3f} s error {err:.1e} | no Exudyn run this accurate")
            continue
        b = min(e, key=lambda r: r[1])
        print(f"  {m:<19}{x:9.1e} {cpu:.3f} s error {err:.1e} | Exudyn {b[0][1]} h={b[0][2]:g} {b[1]:.3f} s "
              f"(error {b[2]:.1e}) | ratio {cpu / b[1]:.2f}", flush=True)


def _interpolated_cost(runs, level):
    """Cheapest cost of ours at error ``level``, interpolating each method's log(cost) over log(error)
    between its sampled runs (None if no method's runs bracket the level)."""
    best = None
    for method in {r[0][1] for r in runs}:
        pts = sorted((r[2], r[1]) for r in runs if r[0][1] == method)
        for (e0, c0), (e1, c1) in zip(pts, pts[1:]):
            if e0 <= level <= e1 and e1 > e0:
                w = np.log(level / e0) / np.log(e1 / e0)
                c = float(np.exp((1 - w) * np.log(c0) + w * np.log(c1)))
                best = c if best is None else min(best, c)
    return best
