"""Lobatto IIIA's linearized predictor (``predictor="linearized"``) and the retry from it.

On a linear model (constant M, D, K and a load linear in t) the stage equations linearized at the
step's start are the stage equations, so the predicted stage accelerations are the solution: Newton
has nothing left to do. Catches a wrong sign or a missing term of the linearization (the load at the
stage times, the damping D (V - v_n), the stage offsets c_i h v_n), and a wrong stage layout of the
right-hand side (not interleaved). The SQ3D run catches the loss of the retry: the 16-element
free-flying beam of ``benchmarks.sq3d_dynamics`` failed at t = 0.008 s with h = 1e-3 before it.
"""
import numpy as np
import pytest
import scipy.sparse as sp

from ancfdae import Material, RectangularSection, simulate
from ancfdae.integrators.lobatto import LobattoIIIA
from ancfdae.models import SQ3D, Beam
from ancfdae.problem import Energy, JacobianBlocks


class LinearChain:
    """``M a + D v + K q = f(t)``: three coupled masses with frequencies 1 ... 1e4 rad/s, load linear in t."""

    mass_is_constant = True
    n_dof = 3

    def __init__(self):
        self.M = sp.csr_matrix(np.diag([1.0, 2.0, 0.5]))
        self.K = sp.csr_matrix(np.array([[1.0, -0.5, 0.0], [-0.5, 1e6, -1e3], [0.0, -1e3, 5e7]]))
        self.D = sp.csr_matrix(0.01 * self.K.toarray() + 0.1 * np.eye(3))

    def initial_state(self):
        return np.array([0.1, -0.02, 1e-4]), np.array([1.0, 0.5, -2.0])

    def mass(self, q=None):
        return self.M

    def _f(self, t):
        return np.array([1.0, -3.0, 2.0]) * (1.0 + 40.0 * t)

    def residual(self, t, q, v, a):
        return self.M @ a + self.D @ v + self.K @ q - self._f(t)

    def jacobian(self, t, q, v, a):
        return JacobianBlocks(self.K, self.D, self.M, same_pattern=False)

    def energy(self, t, q, v):
        return Energy(0.5 * float(v @ (self.M @ v)), 0.5 * float(q @ (self.K @ q)))

    def external_power(self, t, q, v):
        return float(self._f(t) @ v)


def _same_pattern(model):
    """The chain's blocks on one CSR pattern (the eigenbasis stage matrix needs it)."""
    full = sp.csr_matrix(np.ones((3, 3)))
    for name in ("M", "K", "D"):
        m = getattr(model, name).toarray()
        setattr(model, name, sp.csr_matrix((m[full.nonzero()], full.indices, full.indptr), shape=(3, 3)))
    model.jacobian = lambda t, q, v, a: JacobianBlocks(model.K, model.D, model.M, same_pattern=True)
    return model


def _initial_residuals(predictor):
    """max|r| of every step's stage residual at the predictor's guess (the Newton solve's first residual)."""
    model = _same_pattern(LinearChain())
    stepper = LobattoIIIA(model, 1e-2, 3, predictor=predictor, newton={"tol": 1e-10})
    seen, solve = [], stepper.newton.solve

    def recording_solve(residual, jacobian, x0, **kw):
        seen.append(float(np.abs(residual(np.asarray(x0))).max()))
        return solve(residual, jacobian, x0, **kw)

    stepper.newton.solve = recording_solve
    res = simulate(model, (0.0, 0.05), stepper)
    assert res.status == "success", res.message
    return np.array(seen)


def test_linearized_guess_solves_a_linear_model():
    lin, const = _initial_residuals("linearized"), _initial_residuals("constant")
    assert lin.size == const.size == 5
    # measured: 1e-6 ... 1e-5 (round-off of forces K q ~ 1e4) against 1.5e10 from a_n
    assert lin.max() <= 1e-12 * const.min()


def test_lobatto3_takes_h_1e_3_on_free_flying_sq3d():
    beam = Beam(SQ3D(Material(E=2.1e10, nu=0.3, rho=4000.0), RectangularSection(0.05)), n_elements=16,
                length=1.0, initial_velocity=lambda p: np.column_stack(
                    [0.0 * p[:, 0], 2.0 * np.sin(np.pi * p[:, 0]), np.sin(2.0 * np.pi * p[:, 0])]))
    res = simulate(beam, (0.0, 0.02), "lobatto3", h=1e-3, newton={"tol": 1e-6})
    assert res.status == "success", res.message
    assert res.t[-1] == pytest.approx(0.02)
