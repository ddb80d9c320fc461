"""The constrained toy models' own derivatives against finite differences (a wrong toy would make every
stepper test against it meaningless)."""
import numpy as np
import pytest

from support.numerics import fd_gradient, rel_err
from support.toy_constrained import double_pendulum, hanging_link, hub, kkt

PROBLEMS = {"pendulum": double_pendulum, "link": hanging_link, "hub": hub}


def _state(model, seed=0):
    rng = np.random.default_rng(seed)
    q0, _ = model.initial_state()
    return 0.37, q0 + 0.05 * rng.standard_normal(q0.size), rng.standard_normal(q0.size), \
        rng.standard_normal(model.n_constraints)


@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_forces_and_blocks_against_fd(name):
    """Forces = gradient of the strain + gravity energy (undamped); K, D against FD of the residual."""
    model = PROBLEMS[name]()
    t, q, v, lam = _state(model)
    a = np.zeros_like(q)
    blk = model.jacobian(t, q, v, a)
    assert rel_err(blk.K.toarray(), fd_gradient(lambda x: model.residual(t, x, v, a), q)) < 1e-7
    assert rel_err(blk.D.toarray(), fd_gradient(lambda x: model.residual(t, q, x, a), v)) < 1e-7
    und = PROBLEMS[name](damping=(0.0, 0.0))
    grad = fd_gradient(lambda x: und.energy(t, x, 0 * v).strain + und.energy(t, x, 0 * v).potential, q)
    assert rel_err(und.residual(t, q, 0 * v, a), grad) < 1e-7


@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_constraint_derivatives_against_fd(name):
    """G = dg/dq, d(G^T lam)/dq, d(G v + g_t)/dq, g_t = dg/dt and gamma = -d2g/dt2 - ... along a path
    (the gamma check catches a wrong G_t or g_tt together)."""
    model = PROBLEMS[name]()
    t, q, v, lam = _state(model)
    G = model.constraint_jacobian(t, q).toarray()
    assert rel_err(G, fd_gradient(lambda x: model.constraints(t, x), q)) < 1e-8
    H = model.constraint_force_jacobian(t, q, lam).toarray()
    if np.abs(H).max() > 0:
        assert rel_err(H, fd_gradient(lambda x: model.constraint_jacobian(t, x).T @ lam, q)) < 1e-8
    W = model.constraint_velocity_jacobian(t, q, v).toarray()
    gv = lambda x: model.constraint_jacobian(t, x) @ v + model.constraint_rates(t, x, v)[0]   # noqa: E731
    Wfd = fd_gradient(gv, q)
    assert np.abs(W - Wfd).max() <= 1e-8 * max(1.0, np.abs(Wfd).max())
    g_t, gamma = model.constraint_rates(t, q, v)
    assert np.allclose(g_t + G @ v, fd_gradient(lambda s: model.constraints(s[0], q + (s[0] - t) * v),
                                                np.array([t]))[:, 0], atol=1e-8)
    a = np.random.default_rng(1).standard_normal(q.size)
    path = lambda s: model.constraints(s, q + (s - t) * v + 0.5 * (s - t) ** 2 * a)   # noqa: E731
    h = 1e-4
    d2 = (path(t + h) - 2 * path(t) + path(t - h)) / h ** 2
    assert np.allclose(d2, G @ a - gamma, atol=1e-5 * max(1.0, np.abs(d2).max()))


def test_kkt_start_satisfies_acceleration_constraint():
    model = hanging_link()
    q0, v0 = model.initial_state()
    a, lam = kkt(model, 0.0, q0, v0)
    assert np.abs(model.residual(0.0, q0, v0, a) + model.constraint_jacobian(0.0, q0).T @ lam).max() < 1e-12
    assert np.abs(model.constraint_jacobian(0.0, q0) @ a - model.constraint_rates(0.0, q0, v0)[1]).max() < 1e-12
