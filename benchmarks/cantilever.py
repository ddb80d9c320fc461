"""Benchmark B1: wall time of the full 10-step static solve, ancfdae against Exudyn in the same process.

``python -m benchmarks.cantilever [--repeats 5] [--max-elements 1024]`` prints, per mesh, the median
wall time of ``solve_static`` (model built outside the timed part), the tip error against chapter
Eq. 113, Newton iterations, and -- when exudyn is importable (``pip install ".[benchmark]"``) --
Exudyn's ObjectANCFCable2D on the same problem (its ANCFcantileverTest setup, EigenSparse, one
thread) and the ratio ancfdae / Exudyn (< 1: ancfdae faster). ``--element SQ3D`` compares with
Exudyn's ObjectBeamGeometricallyExact (Simo-Reissner beam, its strongest 3D beam; ``--peer
SQ3D-ancfbeam``: its linear ObjectANCFBeam), ``--element SQ2D`` with ObjectBeamGeometricallyExact2D;
after the table, the speed ratio at equal tip error (the coarsest mesh of ours at least as accurate
as each Exudyn mesh) is printed; ``--nodes 2`` runs the linear SQ3D, the same element as
ObjectANCFBeam.

Exudyn is run with a stopping rule equivalent to ours ("ours"); where that cannot converge (its
residual round-off floor lies above the absolute tolerance beyond ~128 elements) with its own
relative rule at 1e-8 ("exudyn"), then looser (1e-7 ... 1e-4), and the table says which rule it met;
"failed" means none converged in 10 load steps. Ours always uses the chapter's rule (1e-8 relative
to the step's first residual). Both sides are timed alternately in this process (median of the
repeats); the ratio is taken in CPU (process) time, which a shared machine disturbs less than wall time.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import solve_static
from ancfdae.studies.cantilever import REFERENCE, build

from . import _exudyn_peer as peer


#: Exudyn's counterpart of each element type (runner(n, repeats, criterion)).
PEERS = {"BE2D": peer.cantilever_be2d,
         "SQ3D": peer.cantilever_ge3d,
         "SQ3D-ancfbeam": peer.cantilever_beam3d,
         "SQ2D": peer.cantilever_ge2d}


#: Exudyn's stopping rules, tried in this order until one converges (module docstring).
LADDER = ("ours", "exudyn", 1e-7, 1e-6, 1e-5, 1e-4)


def _ours_once(beam, name):
    c0, t0 = time.process_time(), time.perf_counter()
    res = solve_static(beam, load_steps=10, tol=1e-8, check_stability=False, max_strain=None)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    tip = beam.position(res.q, 2.0)[:2] - [2.0, 0.0]
    fam = "SQ" if name.startswith("SQ") else "BE"
    return {"wall": wall, "cpu": cpu, "error": float(np.linalg.norm(tip - REFERENCE[fam])),
            "iterations": res.iterations, "status": res.status}


def ours(name: str, n_elements: int, repeats: int, **options) -> dict:
    """Median wall and CPU time of the 10-step static solve of B1 with ancfdae (model built untimed)."""
    beam = build(name, n_elements, **options)
    runs = [_ours_once(beam, name) for _ in range(repeats)]
    return _median(runs)


def _median(runs):
    out = dict(runs[-1])
    out["wall"] = float(np.median([r["wall"] for r in runs]))
    out["cpu"] = float(np.median([r["cpu"] for r in runs]))
    return out


def exudyn_rule(n_elements: int, runner=None):
    """The first rule of ``LADDER`` under which Exudyn converges on this mesh, or None."""
    if not peer.available():
        return None
    runner = runner or peer.cantilever_be2d
    for criterion in LADDER:
        try:
            runner(n_elements, repeats=1, criterion=criterion)
            return criterion
        except RuntimeError:
            continue
    return None


def interleaved(name, n, repeats, runner, options):
    """Ours and Exudyn alternately, ``repeats`` times each, in this process: (ours, exudyn or None)."""
    beam = build(name, n, **options)
    _ours_once(beam, name)   # warm-up (JIT cache load, band map)
    rule = exudyn_rule(n, runner) if runner is not None else None
    a_runs, e_runs = [], []
    for _ in range(repeats):
        a_runs.append(_ours_once(beam, name))
        if rule is not None:
            e = runner(n, repeats=1, criterion=rule)
            e_runs.append({"wall": e["wall_median"], "cpu": e["cpu_median"], "error": e["error"],
                           "iterations": e["newton_iterations"], "rule": rule})
    e = _median(e_runs) if e_runs else ({"failed": True} if runner is not None and peer.available() else None)
    return _median(a_runs), e


def _rule_name(rule):
    return rule if isinstance(rule, str) else f"rel{rule:.0e}"


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--max-elements", type=int, default=1024)
    p.add_argument("--meshes", type=int, nargs="+", default=None, help="explicit element counts")
    p.add_argument("--element", default="BE2D")
    p.add_argument("--peer", default=None, choices=sorted(PEERS),
                   help="Exudyn element to compare with (default: the element's own entry: BE2D -> "
                        "ANCFCable2D, SQ3D -> BeamGeometricallyExact, SQ2D -> BeamGeometricallyExact2D; "
                        "SQ3D-ancfbeam -> ANCFBeam)")
    p.add_argument("--nodes", type=int, default=None, help="SQ elements: 3 (quadratic, default) or 2 (linear)")
    p.add_argument("--kernel", default=None, choices=["auto", "numpy", "numba"], help="element kernel option")
    args = p.parse_args(argv)
    options = {} if args.nodes is None else {"nodes": args.nodes}
    if args.kernel is not None:
        options["kernel"] = args.kernel
    rows = []
    meshes = args.meshes or [n for n in (1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024) if n <= args.max_elements]
    print(f"B1 static solve, {args.element}, ours and Exudyn interleaved, median of {args.repeats} "
          f"(seconds; cpu = process time; ratio = ours / Exudyn in CPU time, < 1: ours faster)")
    print(f"{'n_el':>5} {'ours wall':>10} {'cpu':>9} {'error':>10} {'its':>4} | {'Exudyn wall':>11} {'cpu':>9} "
          f"{'error':>10} {'its':>4} {'rule':>8} | {'ratio':>6}")
    for n in meshes:
        a, e = interleaved(args.element, n, args.repeats, PEERS.get(args.peer or args.element), options)
        rows.append((n, a, e))
        if e is None:
            ex = f"{'-':>11} {'-':>9} {'-':>10} {'-':>4} {'-':>8} | {'-':>6}"
        elif e.get("failed"):
            ex = f"{'failed':>11} {'-':>9} {'-':>10} {'-':>4} {'-':>8} | {'-':>6}"
        else:
            ex = (f"{e['wall']:11.4f} {e['cpu']:9.4f} {e['error']:10.3e} {e['iterations']:4d} "
                  f"{_rule_name(e['rule']):>8} | {a['cpu'] / e['cpu']:6.2f}")
        print(f"{n:5d} {a['wall']:10.4f} {a['cpu']:9.4f} {a['error']:10.3e} {a['iterations']:4d} | {ex}", flush=True)
    equal_error(rows)


def equal_error(rows):
    """Speed ratio at equal tip error: each Exudyn mesh against the coarsest of ours as accurate."""
    peers = [(n, e) for n, _, e in rows if e and not e.get("failed")]
    if not peers:
        return
    print("at equal tip error (ours: coarsest mesh with error <= Exudyn's)")
    for n, e in peers:
        better = [(m, a) for m, a, _ in rows if a["error"] <= e["error"]]
        if not better:
            print(f"  Exudyn {n:4d} el ({e['error']:.2e}): no mesh of ours is as accurate")
            continue
        m, a = better[0]
        print(f"  Exudyn {n:4d} el {e['error']:.2e} {e['cpu']:.4f} s | ours {m:4d} el {a['error']:.2e} "
              f"{a['cpu']:.4f} s | ratio {a['cpu'] / e['cpu']:.3f}")


if __name__ == "__main__":
    main()
