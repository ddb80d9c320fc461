"""Result file engines: write and read time, file size and bit-exactness, h5netcdf against netCDF4.

A typical long result: 10,000 outputs x 200 coordinates (q, v, a) with an energy
monitor. Runs the two engines interleaved, ``repeats`` times each, and prints
the medians. Usage: ``python benchmarks/result_io.py [n_out] [n_dof] [repeats]``.
"""
from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ancfdae import Result
from ancfdae import _resultfile


def make_result(n_out: int, n_dof: int) -> Result:
    """A result of random data (random bits exercise the exact round trip)."""
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 1.0, n_out)
    q, v, a = (rng.standard_normal((n_out, n_dof)) for _ in range(3))
    energy = {k: rng.standard_normal(n_out) for k in ("kinetic", "strain", "total")}
    return Result(t=t, q=q, v=v, a=a, monitors={"energy": energy}, stats={"steps": n_out}, method="lobatto3")


def read_with(path: Path, engine: str) -> Result:
    import xarray as xr
    with xr.open_dataset(path, engine=engine) as ds:
        ds.load()
        return Result(**_resultfile.from_dataset(ds, path))


def main(n_out: int = 10_000, n_dof: int = 200, repeats: int = 5) -> None:
    res = make_result(n_out, n_dof)
    times = {e: {"write": [], "read": []} for e in ("h5netcdf", "netcdf4")}
    sizes, exact = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeats):
            for engine in times:
                path = Path(tmp) / f"{engine}.nc"
                t0 = time.perf_counter()
                res.save(path, engine=engine)
                t1 = time.perf_counter()
                back = read_with(path, engine)
                t2 = time.perf_counter()
                times[engine]["write"].append(t1 - t0)
                times[engine]["read"].append(t2 - t1)
                sizes[engine] = path.stat().st_size
                exact[engine] = all(np.array_equal(getattr(back, n), getattr(res, n)) for n in "tqva")
                path.unlink()
    print(f"{n_out} outputs x {n_dof} coordinates, medians of {repeats} interleaved runs")
    for engine, tt in times.items():
        print(f"{engine:9s} write {np.median(tt['write']):.3f} s  read {np.median(tt['read']):.3f} s  "
              f"size {sizes[engine] / 1e6:.1f} MB  bit-exact {exact[engine]}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:]))
