"""The test models satisfy the contract with exact Jacobians (else the integrator tests mean nothing)."""
import numpy as np
import pytest

from ancfdae.problem import Model
from support.toy_models import DoublePendulum, SpringChain


def _models():
    return [SpringChain(n_masses=4, force=(3.0, 1.0), damping=0.3), DoublePendulum(torque=2.0)]


@pytest.mark.parametrize("model", _models(), ids=["chain", "pendulum"])
def test_jacobian_matches_finite_differences(model):
    assert isinstance(model, Model)
    rng = np.random.default_rng(0)
    q0, _ = model.initial_state()
    q = q0 + 0.1 * rng.standard_normal(model.n_dof)
    v, a = rng.standard_normal(model.n_dof), rng.standard_normal(model.n_dof)
    t, eps = 0.3, 1e-6
    J = model.jacobian(t, q, v, a)
    for blk, arg in ((J.K, 0), (J.D, 1), (J.M, 2)):
        fd = np.zeros((model.n_dof, model.n_dof))
        for j in range(model.n_dof):
            e = np.zeros(model.n_dof)
            e[j] = eps
            args_p, args_m = [q, v, a], [q, v, a]
            args_p[arg] = args_p[arg] + e
            args_m[arg] = args_m[arg] - e
            fd[:, j] = (model.residual(t, *args_p) - model.residual(t, *args_m)) / (2 * eps)
        np.testing.assert_allclose(blk.toarray(), fd, atol=1e-6 * max(1, np.abs(fd).max()))
    for blk in (J.D, J.M):
        np.testing.assert_array_equal(blk.indices, J.K.indices)


@pytest.mark.parametrize("model", _models(), ids=["chain", "pendulum"])
def test_forces_derive_from_energy(model):
    """r(t, q, 0, 0) + f_ext,nc = dU/dq + dV/dq (conservative parts derive from the energies)."""
    rng = np.random.default_rng(1)
    q0, _ = model.initial_state()
    q = q0 + 0.1 * rng.standard_normal(model.n_dof)
    z = np.zeros(model.n_dof)
    t = 5.0  # after the pulse: no non-conservative load
    eps = 1e-6
    grad = np.array([(model.energy(t, q + eps * e, z).total - model.energy(t, q - eps * e, z).total) / (2 * eps)
                     for e in np.eye(model.n_dof)])
    np.testing.assert_allclose(model.residual(t, q, z, z), grad, rtol=1e-6, atol=1e-6)
