"""Benchmark B1: wall time of the full 10-step static solve, ancfdae against Exudyn in the same process.

``python -m benchmarks.cantilever [--repeats 5] [--max-elements 1024]`` prints, per mesh, the median
wall time of ``solve_static`` (model built outside the timed part), the tip error against chapter
Eq. 113, Newton iterations, and -- when exudyn is importable (``pip install ".[benchmark]"``) --
Exudyn's ObjectANCFCable2D on the same problem (its ANCFcantileverTest setup, EigenSparse, one
thread) and the ratio ancfdae / Exudyn (< 1: ancfdae faster). ``--element SQ3D`` compares with
Exudyn's ObjectANCFBeam (shear deformable, linear: the nearest it has) and then prints the speed
ratio at equal tip error (the coarsest SQ3D mesh at least as accurate as each Exudyn mesh);
``--nodes 2`` runs the linear SQ3D, the same element as ObjectANCFBeam.

Exudyn is run first with a stopping rule equivalent to ours; where that cannot converge (its residual
round-off floor lies above the absolute tolerance beyond ~128 elements) with its own default relative
rule, and the table says which; "failed" means neither converged in 10 load steps.
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
         "SQ3D": peer.cantilever_beam3d}


def ours(name: str, n_elements: int, repeats: int, **options) -> dict:
    """Median wall time of the 10-step static solve of B1 with ancfdae."""
    beam = build(name, n_elements, **options)
    walls = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = solve_static(beam, load_steps=10, tol=1e-8)
        walls.append(time.perf_counter() - t0)
    tip = beam.position(res.q, 2.0)[:2] - [2.0, 0.0]
    fam = "SQ" if name.startswith("SQ") else "BE"
    return {"wall": float(np.median(walls)), "error": float(np.linalg.norm(tip - REFERENCE[fam])),
            "iterations": res.iterations, "status": res.status}


def exudyn(n_elements: int, repeats: int, runner=None) -> dict | None:
    """Exudyn on the same mesh: our stopping rule, else its own; None if it fails or is missing."""
    if not peer.available():
        return None
    runner = runner or peer.cantilever_be2d
    for criterion in ("ours", "exudyn"):
        try:
            r = runner(n_elements, repeats=repeats, criterion=criterion)
            r["criterion"] = criterion
            return r
        except RuntimeError:
            continue
    return {"failed": True}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--max-elements", type=int, default=1024)
    p.add_argument("--element", default="BE2D")
    p.add_argument("--nodes", type=int, default=None, help="SQ elements: 3 (quadratic, default) or 2 (linear)")
    p.add_argument("--kernel", default=None, choices=["auto", "numpy", "numba"], help="BE2D kernel option")
    args = p.parse_args(argv)
    options = {} if args.nodes is None else {"nodes": args.nodes}
    if args.kernel is not None:
        options["kernel"] = args.kernel
    rows = []
    meshes = [n for n in (1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024) if n <= args.max_elements]
    print(f"B1 static solve, {args.element}, median of {args.repeats} (wall seconds)")
    print(f"{'n_el':>5} {'ancfdae s':>10} {'error':>10} {'its':>4} | {'Exudyn s':>10} {'error':>10} {'its':>4} "
          f"{'rule':>7} | {'ratio':>6}")
    for n in meshes:
        a = ours(args.element, n, args.repeats, **options)
        e = exudyn(n, args.repeats, PEERS[args.element]) if args.element in PEERS else None
        rows.append((n, a, e))
        if e is None:
            ex = f"{'-':>10} {'-':>10} {'-':>4} {'-':>7} | {'-':>6}"
        elif e.get("failed"):
            ex = f"{'failed':>10} {'-':>10} {'-':>4} {'-':>7} | {'-':>6}"
        else:
            ex = (f"{e['wall_median']:10.4f} {e['error']:10.3e} {e['newton_iterations']:4d} {e['criterion']:>7} | "
                  f"{a['wall'] / e['wall_median']:6.2f}")
        print(f"{n:5d} {a['wall']:10.4f} {a['error']:10.3e} {a['iterations']:4d} | {ex}", flush=True)
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
        print(f"  Exudyn {n:4d} el {e['error']:.2e} {e['wall_median']:.4f} s | ours {m:4d} el {a['error']:.2e} "
              f"{a['wall']:.4f} s | ratio {a['wall'] / e['wall_median']:.3f}")


if __name__ == "__main__":
    main()
