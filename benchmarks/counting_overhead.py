"""Per-call cost of the steppers' counting proxy (``ancfdae.integrators._counting.CountingModel``).

``python -m benchmarks.counting_overhead [--elements 8] [--calls 2000] [--repeats 21]``

The residual and the Jacobian of a BE2D pendulum (``--elements`` elements, pinned, gravity), called
directly, through the proxy, and through a stepper method that counts and forwards (what the
fixed-step integrators did by hand before the proxy); and the same three around a model whose
residual returns a stored array, which isolates the forwarding cost from the kernel's. Process-CPU
medians over ``--repeats`` rounds of ``--calls`` calls each, the variants interleaved in one process.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import Gravity, Material, RectangularSection
from ancfdae.integrators._counting import CountingModel
from ancfdae.models import BE2D, Beam


class _HandCounted:
    """The former per-stepper wrapper: a method that counts and forwards."""

    def __init__(self, model):
        self.model, self.n = model, 0

    def residual(self, t, q, v, a):
        self.n += 1
        return self.model.residual(t, q, v, a)

    def jacobian(self, t, q, v, a):
        self.n += 1
        return self.model.jacobian(t, q, v, a)


class _Null:
    """A model whose residual and Jacobian cost nothing: what remains is the call itself."""

    def __init__(self, r):
        self.r = r

    def residual(self, t, q, v, a):
        return self.r

    jacobian = residual


def _per_call(fn, args, calls):
    t0 = time.process_time()
    for _ in range(calls):
        fn(*args)
    return (time.process_time() - t0) / calls


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--elements", type=int, default=8)
    p.add_argument("--calls", type=int, default=2000)
    p.add_argument("--repeats", type=int, default=21)
    a = p.parse_args(argv)
    beam = Beam(BE2D(Material(E=2.1e10, nu=0.3, rho=4000.0), RectangularSection(0.05)), a.elements, 1.0,
                supports={0: "pin"}, loads=[Gravity((0.0, -9.81))])
    q, v = beam.initial_state()
    q = q + 1e-3 * np.sin(np.arange(q.size))
    args = (0.1, q, v + 0.1, np.full(q.size, 0.2))
    null = _Null(np.zeros(q.size))
    null_variants = {"direct": null, "proxy": CountingModel(null), "hand-counted": _HandCounted(null)}
    beam_variants = {"direct": beam, "proxy": CountingModel(beam), "hand-counted": _HandCounted(beam)}
    for label, variants, what in (("no-op model", null_variants, "residual"),
                                  (f"{a.elements} BE2D elements, n_dof {q.size}", beam_variants, "residual"),
                                  (f"{a.elements} BE2D elements, n_dof {q.size}", beam_variants, "jacobian")):
        times = {k: [] for k in variants}
        for m in variants.values():                  # warm-up: compiled kernels, caches
            _per_call(getattr(m, what), args, 50)
        for _ in range(a.repeats):
            for k, m in variants.items():
                times[k].append(_per_call(getattr(m, what), args, a.calls))
        med = {k: float(np.median(v)) * 1e6 for k, v in times.items()}
        print(f"{what} ({label}): " + ", ".join(
            f"{k} {t:.3f} us" for k, t in med.items())
              + f"; proxy overhead {med['proxy'] - med['direct']:+.3f} us per call"
              f" ({med['proxy'] / med['direct'] - 1:+.1%}), hand-counted {med['hand-counted'] - med['direct']:+.3f} us")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
