"""Shared fixtures (B1 material and section). Helpers live in the ``support`` package (tests/support)."""
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
