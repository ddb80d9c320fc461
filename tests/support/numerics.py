"""Finite-difference helpers of the element and Jacobian tests."""
import numpy as np


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
