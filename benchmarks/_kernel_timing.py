"""Timing an element's NumPy and compiled kernels interleaved in one process (shared by the kernel benchmarks)."""
from __future__ import annotations

import time

import numpy as np

KERNELS = ("numpy", "numba")


def time_calls(fn, calls: int) -> float:
    """Process time per call of ``fn`` over ``calls`` calls (s)."""
    t0 = time.process_time()
    for _ in range(calls):
        fn()
    return (time.process_time() - t0) / calls


def interleaved_medians(element, fns: dict, calls: int, repeats: int) -> dict:
    """``{kernel: {name: median seconds per call}}``: every function of ``fns`` under each of :data:`KERNELS`,
    alternated ``repeats`` times (the kernel switched on ``element``, compiled and warmed up outside the timed
    loop), the element left on ``"auto"``."""
    samples = {k: {m: [] for m in fns} for k in KERNELS}
    for kernel in KERNELS:
        element.kernel = kernel
        for fn in fns.values():
            fn()
    for _ in range(repeats):
        for kernel in KERNELS:
            element.kernel = kernel
            for m, fn in fns.items():
                samples[kernel][m].append(time_calls(fn, calls))
    element.kernel = "auto"
    return {k: {m: float(np.median(s)) for m, s in d.items()} for k, d in samples.items()}
