"""Shared fixtures and finite-difference helpers for the element tests."""
import numpy as np
import pytest

from ancfdae import Material, RectangularSection


@pytest.fixture
def steel():
    """B1 material (benchmarks.md): E = 2.07e11, nu = 0.3, rho = 7800."""
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
