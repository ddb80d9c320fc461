"""The ``kernel`` option of the elements: compiled (numba, the default) or the NumPy reference."""
from __future__ import annotations

import importlib.util

from .._validate import choice

__all__ = ["KERNELS", "KernelOption", "numba_available", "resolve_kernel"]

KERNELS = ("auto", "numpy", "numba")


def numba_available() -> bool:
    """True when numba can be imported (a core dependency; absent only in a broken install)."""
    return importlib.util.find_spec("numba") is not None


def resolve_kernel(kernel: str) -> str:
    """The implementation behind a ``kernel`` option: "numpy" or "numba".

    ``"auto"`` is the compiled kernel when numba is importable, else the NumPy
    reference; ``"numba"`` without numba raises ImportError.
    """
    kernel = choice("kernel", kernel, KERNELS)
    if kernel == "auto":
        return "numba" if numba_available() else "numpy"
    if kernel == "numba" and not numba_available():
        raise ImportError("`kernel` 'numba' needs numba (a dependency of ancfdae), which is not importable; "
                          "reinstall ancfdae or use kernel='auto' or 'numpy'.")
    return kernel


class KernelOption:
    """The ``kernel`` attribute of an element (a mixin): setting it checks the option and resolves the
    implementation once, so the kernels read ``self._impl`` ("numpy" or "numba")."""

    @property
    def kernel(self) -> str:
        """The ``kernel`` option as given ("auto", "numpy" or "numba")."""
        return self._kernel

    @kernel.setter
    def kernel(self, value: str) -> None:
        self._impl = resolve_kernel(value)
        self._kernel = value

    @property
    def kernel_in_use(self) -> str:
        """The implementation that runs: "numpy" or "numba"."""
        return self._impl
