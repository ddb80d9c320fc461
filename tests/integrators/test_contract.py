"""One contract, every integrator: run over the test models of toy_models.py."""
import numpy as np
import pytest

from ancfdae import EnergyMonitor, PointSensor, Probe, simulate
from ancfdae.integrators._hermite import hermite5
from ancfdae.integrators import IDA, GeneralizedAlpha, LobattoIIIA, Newmark, NewtonOptions
from support.toy_models import DoublePendulum, NaNAfter, SpringChain

# (method, options): every integrator of the registry, with the step it needs
CASES = [
    ("lobatto3", {"h": 0.01}),
    ("lobatto2", {"h": 0.01}),
    ("newmark", {"h": 0.01}),
    ("hht", {"h": 0.01, "alpha": 0.1}),
    ("generalized-alpha", {"h": 0.01, "rho_inf": 0.6}),
    ("ida", {"rtol": 1e-7}),
]
IDS = [c[0] for c in CASES]
MODELS = {"chain": lambda: SpringChain(3, force=(2.0, 1.0), T=0.5),
          "pendulum": lambda: DoublePendulum(torque=1.0, T=0.5)}
EXACT_A = {"lobatto3", "lobatto2", "newmark", "ida"}  # methods whose `a` solves r(t, q, v, a) = 0


@pytest.mark.parametrize("model_name", list(MODELS))
@pytest.mark.parametrize("method, opts", CASES, ids=IDS)
def test_contract(method, opts, model_name):
    model = MODELS[model_name]()
    t_eval = np.linspace(0.0, 1.0, 11)
    mons = [EnergyMonitor(), Probe("q0", lambda t, q, v, a: q[:1])]
    if model_name == "chain":
        mons.append(PointSensor(s=3.0))
    res = simulate(model, (0.0, 1.0), method=method, t_eval=t_eval, monitors=mons, **opts)
    assert res.success and res.status == "success", res.message
    assert res.t_fail is None
    n = model.n_dof
    np.testing.assert_allclose(res.t, t_eval, rtol=0, atol=1e-12)
    assert res.q.shape == res.v.shape == res.a.shape == (11, n)
    q0, v0 = model.initial_state()
    np.testing.assert_array_equal(res.q[0], q0)
    np.testing.assert_array_equal(res.v[0], v0)
    # consistent initial acceleration: r(t0, q0, v0, a0) = 0
    r0 = model.residual(0.0, q0, v0, res.a[0])
    assert np.max(np.abs(r0)) < 1e-12 * max(1.0, np.max(np.abs(model.residual(0.0, q0, v0, 0 * q0))))
    if method in EXACT_A:  # every output satisfies the equations of motion
        scale = np.max(np.abs(model.mass(q0) @ res.a[1]))
        # IDA's Newton stops at 0.33 of its error weights: its residuals are not much smaller
        tol = 1e-3 if method == "ida" else 1e-5
        for k in range(res.t.size):
            assert np.max(np.abs(model.residual(res.t[k], res.q[k], res.v[k], res.a[k]))) < tol * scale
    # monitors logged once per output time
    for name, log in res.monitors.items():
        for key, val in log.items():
            if isinstance(val, np.ndarray) and val.ndim >= 1 and key != "s":
                assert val.shape[0] == res.t.size, (name, key)
    np.testing.assert_allclose(res.monitors["q0"]["value"][:, 0], res.q[:, 0])
    if model_name == "chain":
        np.testing.assert_allclose(res.monitors["point@3"]["position"], res.q[:, -2:], atol=1e-12)
        np.testing.assert_allclose(res.monitors["point@3"]["velocity"], res.v[:, -2:], atol=1e-12)
    # the model's step_event ran after every accepted step, in order
    acc = np.array(model.accepted)
    assert acc.size == res.stats["steps"] and np.all(np.diff(acc) > 0) and abs(acc[-1] - 1.0) < 1e-12
    for key in ("steps", "newton_iterations", "residual_evals", "jacobian_evals", "factorizations"):
        assert isinstance(res.stats[key], int) and res.stats[key] >= 0
    assert res.stats["factorizations"] <= res.stats["newton_iterations"]


@pytest.mark.parametrize("method, opts", CASES, ids=IDS)
def test_all_solutions_agree(method, opts):
    """Every integrator approximates the same motion (reference: Lobatto IIIA-3, small step)."""
    ref = simulate(DoublePendulum(torque=1.0, T=0.5), (0, 1), "lobatto3", h=1e-3, t_eval=[0.5, 1.0])
    assert ref.success, ref.message
    res = simulate(DoublePendulum(torque=1.0, T=0.5), (0, 1), method, t_eval=[0.5, 1.0], **opts)
    assert res.success, res.message
    assert res.t.size == 2
    np.testing.assert_allclose(res.q, ref.q, atol=2e-2)


@pytest.mark.parametrize("method, opts", CASES, ids=IDS)
def test_default_output_every_step(method, opts):
    res = simulate(SpringChain(2), (0.0, 0.1), method=method, **opts)
    assert res.success
    assert res.t[0] == 0.0 and abs(res.t[-1] - 0.1) < 1e-14
    assert res.t.size == res.stats["steps"] + 1 and np.all(np.diff(res.t) > 0)


def test_hermite5_is_exact_for_quintics():
    rng = np.random.default_rng(3)
    c = rng.standard_normal((6, 3))
    p = np.polynomial.polynomial
    y = lambda t: (p.polyval(t, c), p.polyval(t, p.polyder(c)), p.polyval(t, p.polyder(c, 2)))
    for t in (0.31, 0.5, 0.77):
        for got, want in zip(hermite5(0.3, y(0.3), 0.8, y(0.8), t), y(t)):
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("method", ["lobatto3", "lobatto2", "newmark", "generalized-alpha", "ida"])
def test_off_grid_output_is_interpolated(method):
    """Off-grid outputs are as accurate as the on-grid ones around them."""
    opts = {"rtol": 1e-6} if method == "ida" else {"h": 0.01}
    ref = simulate(DoublePendulum(), (0, 0.2), "lobatto3", h=1e-3, t_eval=[0.1, 0.105, 0.11])
    assert ref.success, ref.message
    res = simulate(DoublePendulum(), (0, 0.2), method, t_eval=[0.1, 0.105, 0.11], **opts)
    assert res.success, res.message
    err = np.abs(res.q - ref.q).max(axis=1)
    assert err[1] <= 2 * max(err[0], err[2]) + 1e-9
    if method != "ida":  # on-grid outputs are the step values themselves
        grid = simulate(DoublePendulum(), (0, 0.2), method, t_eval=[0.1, 0.11], **opts)
        assert grid.success, grid.message
        np.testing.assert_array_equal(res.q[[0, 2]], grid.q)


def test_last_step_shortened_to_reach_tf():
    res = simulate(SpringChain(2), (0.0, 0.105), "lobatto3", h=0.01)
    assert res.success and abs(res.t[-1] - 0.105) < 1e-15 and res.stats["steps"] == 11


@pytest.mark.parametrize("method, opts", CASES, ids=IDS)
def test_failure_returns_partial_result(method, opts):
    res = simulate(NaNAfter(SpringChain(2), 0.3), (0.0, 1.0), method, t_eval=np.linspace(0, 1, 21), **opts)
    assert not res.success and res.status == "failed"
    assert res.t_fail is not None and 0.2 <= res.t_fail <= 0.3 + 1e-12
    assert f"{res.t_fail:.4g}"[:3] in res.message or "t = 0.2" in res.message or "0.29" in res.message
    assert res.t.size >= 5 and res.t[-1] <= res.t_fail + 1e-12  # earlier output intact
    assert np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.v))
    ok = simulate(SpringChain(2), (0.0, 1.0), method, t_eval=np.linspace(0, 1, 21), **opts)
    assert ok.success, ok.message
    np.testing.assert_allclose(res.q, ok.q[:res.t.size], rtol=0, atol=1e-12)


@pytest.mark.parametrize("cls", [LobattoIIIA, Newmark, GeneralizedAlpha])
def test_unconverged_step_is_never_accepted(cls):
    """max_iter=1 with a tight tolerance: the first step fails and the state stays at t0."""
    model = DoublePendulum()
    integ = cls(model, 0.05, newton=NewtonOptions(max_iter=1, tol=1e-14, residual_atol=0.0, jacobian="full"))
    res = integ.run((0.0, 1.0))
    assert res.status == "failed" and res.t_fail == 0.0 and "failed" in res.message
    assert res.t.size == 1 and model.accepted == []
    assert integ.t == 0.0 and integ.n_steps == 0
    out = integ.step()      # the protocol: a failed step reports, the state stays
    assert not out.ok and "Newton" in out.message and integ.t == 0.0


def test_step_by_step_api():
    """The stepper protocol driven by hand: initialize, step, accept."""
    model = SpringChain(2)
    integ = LobattoIIIA(model, 0.01)
    q0, v0 = model.initial_state()
    integ.initialize(model, 0.0, q0, v0, np.linalg.solve(model.mass(q0).toarray(), -model.residual(0, q0, v0, 0 * q0)),
                     1.0)
    for _ in range(5):
        out = integ.step()
        assert out.ok and out.t > integ.t
        integ.accept(out)
    assert abs(integ.t - 0.05) < 1e-15 and integ.stats["steps"] == 5
    res = simulate(SpringChain(2), (0, 0.05), "lobatto3", h=0.01)
    assert res.success, res.message
    np.testing.assert_allclose(integ.q, res.q[-1], atol=1e-14)


def test_hook_can_stop_the_run():
    res = simulate(SpringChain(2), (0, 1), "newmark", h=0.01, hooks=[lambda t, q, v, a: t >= 0.25 - 1e-12])
    assert res.success and "hook" in res.message and abs(res.t[-1] - 0.25) < 1e-12


def test_energy_blowup_stop():
    """A monitor may end the run: an energy 'blow-up' (tiny threshold) -> failed with reason."""
    res = simulate(SpringChain(2, force=(5.0, 5.0), T=0.5), (0, 1), "newmark", h=0.01,
                   monitors=[EnergyMonitor(blowup=1e-12, stop_on_blowup=True)])
    assert res.status == "failed" and "blow-up" in res.message
    assert res.monitors["energy"]["blow_up"]


@pytest.mark.parametrize("kwargs, match", [
    ({"method": "rk4", "h": 0.1}, "method"),
    ({"method": "lobatto3"}, "h"),
    ({"method": "lobatto3", "h": -0.1}, "h"),
    ({"method": "lobatto3", "h": 0.1, "t_eval": [0.5, 2.0]}, "t_eval"),
    ({"method": "lobatto3", "h": 0.1, "t_eval": [0.5, 0.2]}, "t_eval"),
    ({"method": "lobatto3", "h": 0.1, "stages": 4}, "unknown option"),
    ({"method": "lobatto3", "h": 0.1, "newton": {"tol": 2.0}}, "tol"),
    ({"method": "lobatto3", "h": 0.1, "predictor": "linear"}, "predictor"),
    ({"method": "newmark", "h": 0.1, "beta": 0.7}, "beta"),
    ({"method": "hht", "h": 0.1, "alpha": 0.5}, "alpha"),
    ({"method": "generalized-alpha", "h": 0.1, "rho_inf": 1.5}, "rho_inf"),
    ({"method": "ida", "h": 0.1}, "max_step"),
    ({"method": "ida", "rtol": -1.0}, "rtol"),
    ({"method": "ida", "atol": [1.0, 2.0, 3.0]}, "atol"),
    ({"method": "ida", "max_order": 7}, "max_order"),
])
def test_bad_options_raise_clear_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        simulate(SpringChain(2), (0.0, 1.0), **kwargs)


def test_bad_t_span_and_model():
    with pytest.raises(ValueError, match="t_span"):
        simulate(SpringChain(2), (1.0, 0.0), "newmark", h=0.1)
    with pytest.raises(TypeError, match="Model contract"):
        simulate(object(), (0.0, 1.0), "newmark", h=0.1)
    with pytest.raises(ValueError, match="stages"):
        LobattoIIIA(SpringChain(2), 0.1, stages=5)
    with pytest.raises(TypeError, match="monitors"):
        simulate(SpringChain(2), (0.0, 1.0), "newmark", h=0.1, monitors=[object()])


def test_ida_is_usable_directly():
    res = IDA(DoublePendulum(), rtol=1e-6).run((0, 0.5), t_eval=[0.25, 0.5])
    assert res.success and res.t.tolist() == [0.25, 0.5] and res.stats["max_order"] == 5
    res = IDA(SpringChain(2, damping=0.5), rtol=1e-6, max_order=2).run((0, 0.5))
    assert res.success and res.stats["max_order"] == 2 and res.options["max_order"] == 2
