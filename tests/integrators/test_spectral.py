"""Numerical dissipation of the Newmark family against its design values (through ``simulate`` only).

On the linear oscillator ``q'' + w^2 q = 0`` every one-step method of the family is a linear map of
its state (q, v, a), so the computed ``q_n`` obey a three-term recurrence whose characteristic
polynomial is that of the amplification matrix. At ``w h -> infinity`` (here ``w h = 1e4``) its roots
must be, by construction of the methods:

* generalized-alpha (Chung and Hulbert 1993): a triple root ``-rho_inf`` -- the property that defines
  ``alpha_m = (2 rho - 1)/(rho + 1)``, ``alpha_f = rho/(rho + 1)``;
* HHT (Hilber, Hughes and Taylor 1977): a double root ``-(1 - alpha)/(1 + alpha)`` (its spectral
  radius) and the spurious root ``-alpha/(1 - alpha)``;
* Newmark's trapezoidal rule: spectral radius 1 (no dissipation).

The order tests cannot see a wrong ``alpha_m`` (the flipped sign keeps order 2); these can.
"""
import numpy as np
import pytest
import scipy.sparse as sp

from ancfdae import simulate
from ancfdae.problem import Energy, JacobianBlocks


class Oscillator:
    """``q'' + w^2 q = 0``, one coordinate: the smallest Model of the contract."""

    n_dof = 1
    mass_is_constant = True

    def __init__(self, w):
        self.k = w * w

    def initial_state(self):
        return np.array([1.0]), np.array([0.0])

    def mass(self, q=None):
        return sp.csr_matrix([[1.0]])

    def residual(self, t, q, v, a):
        return a + self.k * q

    def jacobian(self, t, q, v, a):
        return JacobianBlocks(sp.csr_matrix([[self.k]]), sp.csr_matrix([[0.0]]), sp.csr_matrix([[1.0]]))

    def energy(self, t, q, v):
        return Energy(0.5 * float(v @ v), 0.5 * self.k * float(q @ q))

    def external_power(self, t, q, v):
        return 0.0


def characteristic_polynomial(method, wh=1e4, steps=14, **options):
    """Monic cubic ``z^3 + c2 z^2 + c1 z + c0`` fitted to the recurrence of the computed ``q_n``."""
    res = simulate(Oscillator(wh), (0.0, float(steps)), method, h=1.0, **options)
    assert res.status == "success", res.message
    q = res.q[:, 0]
    rows = np.array([q[i:i + 3][::-1] for i in range(q.size - 3)])
    scale = 1.0 / np.abs(rows).max(axis=1)                   # q_n decays like rho^n: balance the rows
    c = np.linalg.lstsq(rows * scale[:, None], q[3:] * scale, rcond=None)[0]
    return np.array([1.0, -c[0], -c[1], -c[2]])


@pytest.mark.parametrize("rho_inf", [0.3, 0.5, 0.8])
def test_generalized_alpha_has_a_triple_root_minus_rho_inf(rho_inf):
    # Catches alpha_m with the wrong sign (rho_inf = 0.8: roots -0.8, -0.13, -0.12; 0.3: unstable, 1.17),
    # and any other wrong (alpha_m, alpha_f, beta, gamma). Measured agreement ~1e-7.
    p = characteristic_polynomial("generalized-alpha", rho_inf=rho_inf)
    assert np.abs(p - np.poly([-rho_inf] * 3)).max() < 1e-4
    assert np.abs(np.roots(p)).max() == pytest.approx(rho_inf, rel=0.03)   # a triple root: ill-conditioned


@pytest.mark.parametrize("alpha", [0.1, 0.3])
def test_hht_spectral_radius(alpha):
    # Principal roots: the double root -(1 - alpha)/(1 + alpha) (HHT's spectral radius at infinity).
    # Spurious root: as w h -> infinity the residual M a + (1 - alpha) K q_{n+1} + alpha K q_n = 0 is
    # dominated by K, so q_{n+1} = -alpha/(1 - alpha) q_n. Catches a wrong alpha_f (e.g. alpha/2, which
    # keeps the spectral radius within 1 %), beta or gamma.
    rho = (1 - alpha) / (1 + alpha)
    p = characteristic_polynomial("hht", alpha=alpha)
    assert np.abs(p - np.poly([-rho, -rho, -alpha / (1 - alpha)])).max() < 1e-4
    assert np.abs(np.roots(p)).max() == pytest.approx(rho, rel=1e-2)        # a double root: ~1e-3


def test_trapezoidal_rule_does_not_dissipate():
    p = characteristic_polynomial("newmark")
    assert np.abs(np.roots(p)).max() == pytest.approx(1.0, rel=1e-3)
    p = characteristic_polynomial("generalized-alpha", rho_inf=1.0)
    assert np.abs(np.roots(p)).max() == pytest.approx(1.0, rel=1e-3)
