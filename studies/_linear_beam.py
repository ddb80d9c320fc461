"""B5 with the conventional linear beam: why the spin-up benchmark needs geometric stiffening.

The "linear" floating-frame model of a beam on a rotating hub (the one Kane, Ryan & Banerjee, J. Guid.
Control Dyn. 10:139, 1987, showed to fail) describes the transverse deflection ``w(x, t)`` in the hub frame
with the small-strain stiffness about the undeformed beam and the frame's inertia forces, and nothing else::

    rho A (w_tt + theta_tt x - theta_t^2 w) + EI w_xxxx = 0,     w(0) = w_x(0) = 0

The centrifugal tension ``int_x^L rho A theta_t^2 s ds`` that stiffens the spinning beam is a product of the
axial and transverse motion and is dropped: the spin only *softens* it, and once ``theta_t`` exceeds the
first bending frequency ``omega_1 = 1.875^2 sqrt(EI / (rho A L^4))`` (3.80 rad/s for B5, whose hub reaches
4 rad/s) the deflection grows exponentially, while the ANCF beam (geometrically exact) stays bounded.

Discretised by cubic Hermite elements (exact stiffness and consistent mass of Euler-Bernoulli) and reduced
to its lowest bending modes, in which ``eta'' + (Omega^2 - theta_t^2) eta = -theta_tt Phi^T f`` is integrated
by an explicit Runge-Kutta method (the modes are not stiff).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sla
from scipy.integrate import solve_ivp

from ._multibody_models import SPINUP, hub_angle

__all__ = ["first_bending_frequency", "linear_spinup"]


def first_bending_frequency(EI: float = SPINUP["EI"], rhoA: float = SPINUP["rhoA"], L: float = SPINUP["L"]) -> float:
    """``omega_1 = (1.8751)^2 sqrt(EI / (rho A L^4))`` of the clamped-free beam (rad/s)."""
    return 1.875104068711961 ** 2 * math.sqrt(EI / (rhoA * L ** 4))


def _matrices(n_el: int, EI: float, rhoA: float, L: float):
    """Stiffness, consistent mass and the load vector ``f_i = int rho A x N_i dx`` (clamped node dropped)."""
    le = L / n_el
    k = EI / le ** 3 * np.array([[12, 6 * le, -12, 6 * le], [6 * le, 4 * le ** 2, -6 * le, 2 * le ** 2],
                                 [-12, -6 * le, 12, -6 * le], [6 * le, 2 * le ** 2, -6 * le, 4 * le ** 2]])
    m = rhoA * le / 420 * np.array([[156, 22 * le, 54, -13 * le], [22 * le, 4 * le ** 2, 13 * le, -3 * le ** 2],
                                    [54, 13 * le, 156, -22 * le], [-13 * le, -3 * le ** 2, -22 * le, 4 * le ** 2]])
    n = 2 * (n_el + 1)
    K, M, f = np.zeros((n, n)), np.zeros((n, n)), np.zeros(n)
    xg, wg = np.polynomial.legendre.leggauss(3)
    for e in range(n_el):
        s = slice(2 * e, 2 * e + 4)
        K[s, s] += k
        M[s, s] += m
        for xi, w in zip(xg, wg):              # int rho A x N dx, exact for the cubic shape times x
            z = (xi + 1) / 2
            N = np.array([1 - 3 * z * z + 2 * z ** 3, le * (z - 2 * z * z + z ** 3), 3 * z * z - 2 * z ** 3,
                          le * (z ** 3 - z * z)])
            f[s] += rhoA * (e + z) * le * N * w * le / 2
    return K[2:, 2:], M[2:, 2:], f[2:]


def linear_spinup(t_eval, w_s: float = 4.0, n_el: int = 8, n_modes: int = 4, rtol: float = 1e-9) -> np.ndarray:
    """Tip deflection of the linear beam model of B5 (module docstring) at ``t_eval``.

    Parameters
    ----------
    t_eval : array_like
        Increasing output times from 0.
    w_s : float
        The hub's final rate (rad/s), reached at ``T_s`` of :data:`SPINUP`.
    n_el, n_modes : int
        Hermite elements and retained bending modes.
    rtol : float
        Of the Runge-Kutta integration (DOP853; ``atol = rtol * 1e-3`` m).

    Returns
    -------
    ndarray
        ``w(L, t)`` in the hub frame (m), the ANCF benchmark's ``tip_deflection``.
    """
    t_eval = np.asarray(t_eval, dtype=float)
    K, M, f = _matrices(n_el, SPINUP["EI"], SPINUP["rhoA"], SPINUP["L"])
    Om2, Phi = sla.eigh(K, M, subset_by_index=[0, n_modes - 1])      # mass-normalised modes
    g, tip = Phi.T @ f, Phi[-2]

    def rhs(t, y):
        _, w, dw = hub_angle(t, w_s, SPINUP["T_s"])
        eta, deta = y[:n_modes], y[n_modes:]
        return np.concatenate([deta, -(Om2 - w * w) * eta - dw * g])

    sol = solve_ivp(rhs, (0.0, float(t_eval[-1])), np.zeros(2 * n_modes), method="DOP853", t_eval=t_eval,
                    rtol=rtol, atol=rtol * 1e-3)
    if not sol.success:
        raise RuntimeError(f"linear B5 model: {sol.message}")
    return tip @ sol.y[:n_modes]
