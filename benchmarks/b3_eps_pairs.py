"""eps_T of B's displacement in space between any two stored B3 runs (chapter Eq. 115, as ``flying3d``).

``python -m benchmarks.b3_eps_pairs RUN.nc REF.nc [RUN.nc REF.nc ...] [--window 10]`` loads each pair of
``Result`` files (e.g. the cases of ``ancfdae study flying3d --out DIR``: ``DIR/cases/*.nc``) and prints
``eps_T`` of the first's point B (monitor ``tip``) against the second's over ``[0, window]`` s, or up to where
either run ends. ``flying3d`` compares every run with its finest SQ3D run only; this compares, e.g., two
thin-element runs with each other, to tell a mesh error from a difference of the beam models.
"""
from __future__ import annotations

import argparse

import numpy as np

from ancfdae import Result
from ancfdae.studies.flying3d import eps_T3


def _record(path: str) -> dict:
    res = Result.load(path)
    return {"t": res.t, "tip": np.asarray(res.monitors["tip"]["position"]).reshape(res.t.size, -1),
            "label": f"{res.model.get('element', {}).get('type', '?')} ({res.status}, to {res.t[-1]:.3f} s)"}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("files", nargs="+")
    p.add_argument("--window", type=float, default=10.0)
    a = p.parse_args()
    if len(a.files) % 2:
        raise SystemExit(f"files: pairs of RUN REF expected, got {len(a.files)} files.")
    for run, ref in zip(a.files[::2], a.files[1::2]):
        r, s = _record(run), _record(ref)
        eps, end = eps_T3(r, s, a.window)
        print(f"eps_T {eps:.3e} m over [0, {end:g}] s: {run} [{r['label']}] against {ref} [{s['label']}]")


if __name__ == "__main__":
    main()
