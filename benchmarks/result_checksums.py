"""Cost of the result-file checksums: save/load with them against the same file without, interleaved.

Usage: ``python benchmarks/result_checksums.py [n_out] [n_dof] [repeats]``. "plain" writes the dataset
without Fletcher-32 and reads it with xarray + ``from_dataset`` (no verification: the format-2 path);
"checked" is :meth:`Result.save` / :meth:`Result.load`. Prints medians, the ratio and the file sizes.
"""
from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ancfdae import Result
from ancfdae import _resultfile

sys.path.insert(0, str(Path(__file__).resolve().parent))
from result_io import make_result  # noqa: E402


def plain_write(res, path):
    _resultfile.to_dataset(res._fields()).to_netcdf(path, engine="netcdf4", format="NETCDF4")


def plain_read(path):
    import xarray as xr
    with xr.open_dataset(path, engine="netcdf4") as ds:
        ds.load()
        return Result(**_resultfile.from_dataset(ds, path))


def main(n_out=10_000, n_dof=200, repeats=5):
    res = make_result(n_out, n_dof)
    t = {k: [] for k in ("plain write", "checked write", "plain read", "checked read")}
    with tempfile.TemporaryDirectory() as tmp:
        a, b = Path(tmp) / "plain.nc", Path(tmp) / "checked.nc"
        for _ in range(repeats):
            for name, fn in (("plain write", lambda: plain_write(res, a)), ("checked write", lambda: res.save(b)),
                             ("plain read", lambda: plain_read(a)), ("checked read", lambda: Result.load(b))):
                t0 = time.perf_counter()
                fn()
                t[name].append(time.perf_counter() - t0)
        assert np.array_equal(Result.load(b).q, res.q) and np.array_equal(plain_read(a).q, res.q)
        sizes = a.stat().st_size, b.stat().st_size
    med = {k: float(np.median(v)) for k, v in t.items()}
    print(f"{n_out} outputs x {n_dof} coordinates, medians of {repeats} interleaved runs")
    for op in ("write", "read"):
        print(f"  {op}: plain {med['plain ' + op]:.4f} s, checked {med['checked ' + op]:.4f} s, "
              f"ratio {med['checked ' + op] / med['plain ' + op]:.2f}")
    print(f"  size: plain {sizes[0]} B, checked {sizes[1]} B (ratio {sizes[1] / sizes[0]:.3f})")


if __name__ == "__main__":
    main(*(int(x) for x in sys.argv[1:4]))
