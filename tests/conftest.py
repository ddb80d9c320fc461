"""Shared fixtures and finite-difference helpers for the element tests."""
from contextlib import contextmanager
from pathlib import Path
from unittest import mock

import numpy as np
import pytest

from ancfdae import Material, RectangularSection


@pytest.fixture
def steel():
    """B1 material: E = 2.07e11, nu = 0.3 (chapter Sect. 5.1), rho = 7800 (steel; statics do not use it)."""
    return Material(E=2.07e11, nu=0.3, rho=7800.0)


@pytest.fixture
def square():
    """B1 section: square of side 0.1 m."""
    return RectangularSection(0.1)


def fd_gradient(fun, x, h=1e-6):
    """Central finite differences of a scalar or vector function (columns = d/dx_j)."""
    cols = [(np.asarray(fun(x + h * e)) - np.asarray(fun(x - h * e))) / (2 * h) for e in np.eye(x.size)]
    return np.array(cols).T


def rel_err(a, b):
    """max|a - b| / max|b|."""
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / np.max(np.abs(b)))


def assert_forces_and_tangent_fd(el, geom, q):
    """Per element of ``q`` (n_el, n_edof): the force against finite differences of the element energy,
    the tangent against finite differences of the force (1e-7), and the tangent symmetric (1e-12)."""
    f, K = el.internal_forces(geom, q)
    for e in range(len(q)):
        def energy(x, e=e):
            qq = q.copy()
            qq[e] = x
            return el.strain_energy(geom, qq)[e]

        def force(x, e=e):
            qq = q.copy()
            qq[e] = x
            return el.internal_forces(geom, qq, False)[0][e]
        assert rel_err(f[e], fd_gradient(energy, q[e])) < 1e-7
        assert rel_err(K[e], fd_gradient(force, q[e])) < 1e-7
    assert np.abs(K - np.swapaxes(K, 1, 2)).max() < 1e-12 * np.abs(K).max()


@contextmanager
def saved_figures():
    """Record every matplotlib Figure saved inside the block, by file name.

    The studies save and close their figures without returning them; the recorded Figure objects keep
    their axes and lines, so a test can check what a figure shows (labels, series, data ranges) instead
    of the size of its PNG file.
    """
    from matplotlib.figure import Figure
    figures = {}
    original = Figure.savefig

    def record(self, fname, *args, **kwargs):
        figures[Path(fname).name] = self
        return original(self, fname, *args, **kwargs)

    with mock.patch.object(Figure, "savefig", record):
        yield figures


def visible_axes(fig):
    """The figure's visible axes (hidden spare panels of a grid left out)."""
    return [ax for ax in fig.axes if ax.get_visible()]


def series(ax):
    """``{label: (x, y)}`` of the data lines of an axes (legend-less helper lines keep ``_child`` labels)."""
    return {ln.get_label(): (np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float))
            for ln in ax.get_lines()}


def check_panel(ax, min_lines=1):
    """A panel shows something: both axis labels, and lines of finite data with at least two points."""
    assert ax.get_xlabel() and ax.get_ylabel(), "axis labels missing"
    lines = [(x, y) for x, y in series(ax).values() if x.size >= 2]
    assert len(lines) >= min_lines, f"{len(lines)} lines with data, expected >= {min_lines}"
    for x, y in lines:
        assert np.all(np.isfinite(x)) and np.any(np.isfinite(y))
