"""Energy balance E = T + U + V - W_ext under every integrator.

Toy: the spring chain of toy_models with a pulse force (W_ext != 0 while it acts).
B2 (benchmarks.md): free BE2D beam in the plane, 4 elements, force and moment pulse for 2.5 s,
then free motion; E must stay constant after 2.5 s up to the integrator's accuracy.
"""
import functools

import numpy as np
import pytest

from ancfdae import EnergyMonitor, Material, PointForce, PointMoment, PointSensor, RectangularSection, simulate
from ancfdae.loads import pulse
from ancfdae.models import BE2D, Beam
from support.toy_models import SpringChain

T_LOAD, T_END = 2.5, 3.5
T_EVAL = np.linspace(0.0, T_END, 71)


def b2_beam(n_elements=4):
    """The B2 beam (revision 2): L = 1, a = 0.05, E = 1e5, nu = 0.3, rho = 2500, r(s) = s (0.6, 0.8); 0.24 N, N m."""
    el = BE2D(Material(E=1e5, nu=0.3, rho=2500.0), RectangularSection(0.05))
    return Beam(el, n_elements=n_elements, length=1.0, direction=(0.6, 0.8),
                loads=[PointForce((0.24, 0.0), node=0, time=pulse(T_LOAD)),
                       PointMoment(0.24, node=0, time=pulse(T_LOAD))])


@functools.lru_cache(maxsize=None)
def b2_run(method, key, **kw):
    kw = {k: (dict(v) if isinstance(v, tuple) else v) for k, v in kw.items()}
    opts = {"rtol": key} if method == "ida" else {"h": key}
    return simulate(b2_beam(), (0.0, T_END), method, t_eval=T_EVAL, monitors=[EnergyMonitor(), PointSensor(s=0.0)],
                    **opts, **kw)


def free_drift(res):
    """max |E(t) - E(2.5)| for t >= 2.5 (no load: E must be constant)."""
    E, t = res.monitors["energy"]["balance"], res.t
    after = E[t >= T_LOAD - 1e-12]
    return float(np.max(np.abs(after - after[0])))


def _order(d_coarse, d_fine):
    return np.log2(d_coarse / d_fine)


@pytest.mark.parametrize("method, declared", [("lobatto3", 4), ("lobatto2", 2), ("newmark", 2)])
def test_b2_balance_kept_to_the_order(method, declared):
    coarse, fine = b2_run(method, 0.01), b2_run(method, 0.005)
    assert coarse.success and fine.success
    p = _order(free_drift(coarse), free_drift(fine))
    assert p > declared - 0.5, (method, free_drift(coarse), free_drift(fine), p)
    assert free_drift(fine) < 0.02 * fine.monitors["energy"]["scale"]
    assert not fine.monitors["energy"]["blow_up"]


def test_b2_generalized_alpha_dissipates():
    """Generalized-alpha with rho_inf = 0 loses energy in free flight; the trapezoidal rule does not.

    B2 (revision 2) is gentle: over 1 s the loss hides in the balance's oscillation, so the mean
    of the balance over [8, 10] s is compared with its mean over [2.5, 4.5] s. Measured (h = 5e-3):
    generalized-alpha -4.1e-4 J, Newmark +8e-6 J.
    """
    t_end, t_eval = 10.0, np.linspace(0.0, 10.0, 201)
    runs = {m: simulate(b2_beam(), (0.0, t_end), m, h=0.005, t_eval=t_eval, monitors=[EnergyMonitor()], **kw)
            for m, kw in (("generalized-alpha", {"rho_inf": 0.0}), ("newmark", {}))}
    change = {}
    for m, r in runs.items():
        E, t = r.monitors["energy"]["balance"], r.t
        change[m] = E[t >= 8.0].mean() - E[(t >= T_LOAD) & (t < 4.5)].mean()
    assert change["generalized-alpha"] < -20 * abs(change["newmark"]), change


def test_b2_ida_drift_shrinks_with_rtol():
    """IDA's energy drift after the pulse falls with rtol (catches a tolerance not passed to SUNDIALS).

    Measured (BDF order <= 5, B2 revision 2, 4 BE2D): 5.4e-6 J at rtol 1e-3, 5.3e-8 J at 1e-6; in
    between the drift is at its noise level (3.3e-7 at 1e-4, 5.0e-7 at 1e-5), so the decades are wide.
    """
    d = [free_drift(b2_run("ida", r)) for r in (1e-3, 1e-6)]
    assert d[1] < 0.1 * d[0], d


def test_b2_integrators_agree_on_tip_trajectory():
    """Point B's trajectory: Lobatto IIIA-3, Newmark, generalized-alpha, IDA agree to their accuracy."""
    ref = b2_run("lobatto3", 0.005).monitors["point@0"]["position"]
    scale = np.max(np.abs(ref - ref[0]))
    # measured: lobatto3 (h 0.01) 2.5e-3, IDA (rtol 1e-5) 4e-4, newmark 2.8e-2, gen.-alpha 2.7e-2 of the motion
    for method, key, tol in [("lobatto3", 0.01, 5e-3), ("ida", 1e-5, 5e-3), ("newmark", 0.005, 5e-2),
                             ("generalized-alpha", 0.005, 5e-2)]:
        kw = {"rho_inf": 0.5} if method == "generalized-alpha" else {}
        pos = b2_run(method, key, **kw).monitors["point@0"]["position"]
        assert np.max(np.abs(pos - ref)) < tol * scale, (method, np.max(np.abs(pos - ref)) / scale)


def test_modified_newton_matches_full_newton_with_far_fewer_factorizations():
    mod, full = b2_run("lobatto3", 0.005), b2_run("lobatto3", 0.005, newton=(("jacobian", "full"),))
    assert mod.success and full.success
    np.testing.assert_allclose(mod.q, full.q, rtol=0, atol=1e-6 * np.max(np.abs(full.q)))
    assert mod.stats["factorizations"] * 10 < full.stats["factorizations"]
    assert full.stats["factorizations"] == full.stats["newton_iterations"]


def _chain_drift(method, h):
    res = simulate(SpringChain(3, force=(4.0, 2.0), T=0.5), (0, 1.5), method, h=h, monitors=[EnergyMonitor()])
    assert res.success, res.message
    return res.monitors["energy"]["max_abs_drift"]


@pytest.mark.parametrize("method, declared", [("lobatto3", 4), ("newmark", 2)])
def test_balance_includes_work_of_loads(method, declared):
    """With the work W_ext of the pulse force, E is conserved to the order also while it acts."""
    d1, d2 = _chain_drift(method, 0.02), _chain_drift(method, 0.01)
    assert _order(d1, d2) > declared - 0.5, (d1, d2)
    res = simulate(SpringChain(3, force=(4.0, 2.0), T=0.5), (0, 1.5), method, h=0.01, monitors=[EnergyMonitor()])
    assert res.success, res.message
    log = res.monitors["energy"]
    assert np.max(np.abs(log["work"])) > 20 * log["max_abs_drift"]  # the loads did real work


def test_energy_monitor_log_and_checks():
    res = simulate(SpringChain(2), (0, 0.1), "newmark", h=0.01, t_eval=[0.0, 0.05, 0.1],
                   monitors=[EnergyMonitor(name="E")])
    assert res.success, res.message
    log = res.monitors["E"]
    for key in ("kinetic", "strain", "potential", "work", "total", "balance", "drift"):
        assert log[key].shape == (3,)
    np.testing.assert_allclose(log["total"], log["kinetic"] + log["strain"] + log["potential"])
    np.testing.assert_allclose(log["balance"], log["total"] - log["work"])
    assert log["drift"][0] == 0.0 and not log["blow_up"] and log["t_blow_up"] is None
    with pytest.raises(ValueError, match="blowup"):
        EnergyMonitor(blowup=0.0)
    with pytest.raises(ValueError, match="stop_on_blowup"):
        EnergyMonitor(stop_on_blowup="yes")
    with pytest.raises(ValueError, match="exactly one"):
        PointSensor()


def test_point_sensor_equals_model_position_at_every_output():
    """PointSensor builds the beam's point operator once: its positions and velocities must still be the
    model's ``position`` at every output (catches an operator built at the wrong arc length, for the
    wrong beam, or a velocity taken without the fixed coordinates' offset), on a clamped beam (fixed
    coordinates enter r(s) through the reference)."""
    beam = Beam(BE2D(Material(E=1e5, nu=0.3, rho=2500.0), RectangularSection(0.05)), n_elements=3, length=1.0,
                supports={0: "clamp"}, loads=[PointForce((0.0, -0.5), node=-1)])
    s = 0.7
    res = simulate(beam, (0.0, 0.05), "generalized-alpha", h=5e-3, t_eval=np.linspace(0.0, 0.05, 6),
                   monitors=[PointSensor(s=s)])
    log = res.monitors[f"point@{s:g}"]
    for k in range(res.t.size):
        np.testing.assert_allclose(log["position"][k], beam.position(res.q[k], s), rtol=0, atol=1e-15)
        np.testing.assert_allclose(log["velocity"][k], beam.position(res.q[k] + res.v[k], s)
                                   - beam.position(res.q[k], s), rtol=0, atol=1e-15)
    assert np.ptp(log["position"][:, 1]) > 1e-4   # the point moved: equality is not of constants
