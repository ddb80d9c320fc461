"""Cost of building a mesh: CPU time and peak memory of ``Beam(element, n_elements)`` (issue 22: aim, 10^6
elements in seconds).

``python -m benchmarks.mesh_build [--elements BE2D SQ3D] [--sizes 10000 100000] [--repeats 3]``

Each measurement runs in a fresh Python process (peak memory is per process), after a 2-element beam has
warmed the imports and numba caches; a clamped straight steel beam of 1 m, square section 0.1 m. Prints the
CPU-time median and the largest peak resident memory of the repeats.
"""
from __future__ import annotations

import argparse
import statistics
import subprocess
import sys

_CHILD = """
import resource, time
from ancfdae import Material, RectangularSection
from ancfdae.models import Beam, {name}
el = {name}(Material(2.1e11, 0.3, 7800.0), RectangularSection(0.1))
Beam(el, 2, 1.0, supports={{0: "clamp"}})
c = time.process_time()
Beam(el, n_elements={n}, length=1.0, supports={{0: "clamp"}})
print(time.process_time() - c, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6)
"""


def measure(name: str, n: int) -> tuple[float, float]:
    """(CPU seconds, peak resident GB) of building an ``n``-element beam of element ``name``, fresh process."""
    out = subprocess.run([sys.executable, "-c", _CHILD.format(name=name, n=n)], capture_output=True, text=True,
                         check=True).stdout.split()
    return float(out[0]), float(out[1])


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--elements", nargs="+", default=["BE2D", "SQ3D"], choices=["BE2D", "Cable3D", "SQ2D", "SQ3D"])
    p.add_argument("--sizes", nargs="+", type=int, default=[10_000, 100_000])
    p.add_argument("--repeats", type=int, default=3)
    a = p.parse_args(argv)
    for name in a.elements:
        for n in a.sizes:
            runs = [measure(name, n) for _ in range(a.repeats)]
            cpu = statistics.median(r[0] for r in runs)
            print(f"{name:8s} {n:>9d} el: {cpu:8.2f} s CPU (median of {a.repeats}), "
                  f"peak {max(r[1] for r in runs):.2f} GB", flush=True)


if __name__ == "__main__":
    main()
