"""The multibody benchmarks B5-B7 (studies/_multibody_models.py) and the study `ancfdae study multibody`.

They need the joints and the System of the constraints work (ancfdae.joints): skipped where those are missing.
"""
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("ancfdae.joints")

from ancfdae import simulate  # noqa: E402
from ancfdae.studies import multibody  # noqa: E402
from ancfdae.studies._multibody_models import crank_angle, hub_angle, slider_crank, spatial_pendulum, spinup  # noqa: E402
from support.numerics import fd_gradient  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data" / "exudyn_b5_reference.npz"


@pytest.mark.parametrize("build", [spinup, slider_crank, lambda: spatial_pendulum("Cable3D", 2, E=5e7)],
                         ids=["B5", "B6", "B7"])
def test_benchmarks_start_on_their_constraints(build):
    # Catches: a joint placed at the wrong body point or initial velocities that violate the joints (B7's
    # slopes must turn with the payload's directors).
    b = build()
    s = b.system
    q, v = s.initial_state()
    assert np.abs(s.constraints(0.0, q)).max() < 1e-14
    assert np.abs(s.constraint_jacobian(0.0, q) @ v + s.constraint_rates(0.0, q, v)[0]).max() < 1e-13


@pytest.mark.parametrize("fn, w", [(lambda t: hub_angle(t, 4.0), 4.0), (crank_angle, 100.0)])
def test_drive_angles_and_their_derivatives(fn, w):
    # Catches: a rate or acceleration that is not the derivative of the angle (the constraint's g_t, g_tt).
    for t in (0.01, 0.1, 0.19, 3.0, 20.0):
        th, dth, ddth = fn(t)
        assert dth == pytest.approx(fd_gradient(lambda x: np.array([fn(x[0])[0]]), np.array([t]), 1e-6)[0, 0],
                                    rel=1e-7, abs=1e-9)
        assert ddth == pytest.approx(fd_gradient(lambda x: np.array([fn(x[0])[1]]), np.array([t]), 1e-6)[0, 0],
                                     rel=1e-6, abs=1e-6)
    assert fn(50.0)[1] == w


def test_b7_angular_momentum_is_that_of_the_rigid_rotation():
    # Catches: a wrong Euler tensor or initial director velocities of the payload, a wrong L_z formula.
    b = spatial_pendulum("Cable3D", 4, E=5e7, thickness=0.0 + 1e-9)
    q, v = b.system.initial_state()
    s30 = math.sin(math.radians(30.0))
    rod = 1000.0 * math.pi * 0.01 ** 2 * s30 ** 2 / 3                    # rho A sin^2 L^3 / 3
    disk = 0.5 ** 2 + 0.005 * (1 - s30 ** 2) + 0.0025 * s30 ** 2          # m x^2 + axial cos^2 + diametral sin^2
    Lz = b.outputs["angular_momentum_z"](np.zeros(1), q[None], v[None], None)[0]
    assert Lz == pytest.approx(2.0 * (rod + disk), rel=1e-9)
    assert Lz == pytest.approx(0.561109877560, rel=1e-9)                  # the Exudyn peer's B7 model


def test_b5_against_the_exudyn_reference_at_the_start_of_the_spin_up():
    # Catches: a hub torque of the wrong sign or arm, the deflection in the wrong frame, the wrong hub angle.
    ref = np.load(DATA)
    b = spinup("BE2D", 8, 4.0)
    res = simulate(b.system, (0.0, 2.5), "generalized-alpha", h=0.05, t_eval=[0.0, 2.5])
    assert res.success, res.message
    d = b.outputs["tip_deflection"](res.t, res.q, res.v, res.lam)[-1]
    tq = b.outputs["hub_torque"](res.t, res.q, res.v, res.lam)[-1]
    k = int(np.argmin(np.abs(ref["t"] - 2.5)))
    assert d == pytest.approx(ref["b5-4/deflection"][k], rel=5e-3)
    assert tq == pytest.approx(ref["b5-4/torque"][k], rel=5e-3)


def test_b7_model_conserves_the_vertical_angular_momentum_under_the_midpoint_rule():
    # Catches: a joint whose reaction has a moment about e_z (a pivot off the origin, a weld that is not
    # rotation-equivariant), a payload inertia not turning with its directors. The constrained midpoint rule
    # (support.constrained_midpoint) conserves L_z of a rotation-invariant model exactly.
    from support import constrained_midpoint as cm
    from ancfdae.studies._multibody_models import angular_momentum_z
    b = spatial_pendulum("Cable3D", 2, E=5e7, t_end=0.1)
    s = b.system
    t, Q, V, _ = cm.run(s, cm.Constraints(s), 0.1, 0.01)
    Lz = angular_momentum_z(s, Q, V)
    assert np.abs(Lz - Lz[0]).max() < 1e-12 * abs(Lz[0])
    assert np.abs([s.constraints(0.0, q) for q in Q]).max() < 1e-14


def test_b7_energy_momentum_keeps_energy_and_constraints():
    # Catches: a constraint force that does work (energy drift) or a weld/pivot row that drifts.
    b = spatial_pendulum("Cable3D", 2, E=5e7, t_end=0.1)
    res = simulate(b.system, (0.0, 0.1), "energy-momentum", h=0.01)
    assert res.success, res.message
    s = b.system
    E = b.outputs["energy"](res.t, res.q, res.v, res.lam)
    T = np.array([s.energy(t, q, v).kinetic for t, q, v in zip(res.t, res.q, res.v)])
    assert np.abs(E - E[0]).max() < 1e-10 * T.max()
    assert np.abs([s.constraints(t, q) for t, q in zip(res.t, res.q)]).max() < 1e-12


def test_quick_study_rows_and_orders(tmp_path):
    # Catches: a study whose errors do not fall with the step (wrong reference or outputs misaligned).
    # three steps: an order needs two agreeing local orders (studies/_orders.py)
    r = multibody.run(benchmarks=["B6"], integrators=["generalized-alpha"], quick=True, out=tmp_path, progress=False,
                      steps={"B6": (8e-4, 4e-4, 2e-4)})
    assert not r["errors"], r["errors"]
    rows = r["rows"]
    assert [row["h"] for row in rows] == sorted((row["h"] for row in rows), reverse=True)
    assert rows[-1]["error"] < rows[0]["error"]
    assert 1.5 < r["orders"][("B6", "generalized-alpha")] < 2.5
    # the coarsest step's Newton stops at its tolerance on the crank's start (full run: 3.7e-7 at h = 8e-4)
    assert all(row["drift_q"] < 1e-6 for row in rows) and rows[-1]["drift_q"] < 1e-8
    assert (tmp_path / "multibody.md").is_file()
    # Catches: a figure not written (or not both formats); B7's energy figure only with B7 in the run
    for stem in ("work_precision", "drift", "multipliers"):
        assert (tmp_path / f"{stem}.png").stat().st_size > 0 and (tmp_path / f"{stem}.svg").is_file()
    assert set(r["figures"]) == {"work_precision", "drift", "multipliers"}


def test_quick_study_runs_the_variable_step_method_at_its_tolerances(tmp_path):
    # Catches: a step h handed to IDA (simulate refuses it: every IDA case failed), rtols not applied.
    r = multibody.run(benchmarks=["B5"], integrators=["ida"], quick=True, out=tmp_path, progress=False)
    assert not r["errors"], r["errors"]
    assert [row["h"] for row in r["rows"]] == list(multibody.QUICK["rtols"]["B5"])
    assert all(row["status"] == "success" for row in r["rows"])
    assert r["rows"][-1]["error"] < r["rows"][0]["error"]


def test_b5_tip_deflection_converges_in_the_mesh_towards_the_exudyn_reference():
    # Catches: a clamp or deflection output that is only right on one mesh (an element-length or node-index
    # slip), a beam whose deflection does not converge (the geometric stiffening term missing on some
    # elements). The stored peer reference is 32 ObjectANCFCable2D elements, Richardson-extrapolated in h.
    ref = np.load(DATA)
    k = int(np.argmin(np.abs(ref["t"] - 5.0)))
    errs = []
    for n in (2, 4, 8):
        b = spinup("BE2D", n, 4.0)
        res = simulate(b.system, (0.0, 5.0), "generalized-alpha", h=0.01, t_eval=[0.0, 5.0])
        assert res.success, res.message
        errs.append(abs(b.outputs["tip_deflection"](res.t, res.q, res.v, res.lam)[-1] - ref["b5-4/deflection"][k]))
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 1e-4 * abs(ref["b5-4/deflection"][k])   # measured 1.8e-5 m of 0.3155 m (2: 4.0e-3, 4: 9.1e-5)


def test_full_study_outputs_lie_on_every_step_grid():
    # Catches: output times inside steps (n_out = 201 put B7's at 0.025 s, between the steps of 0.02 and
    # 0.01 s): there the stepper's interpolant is measured, not the method (energy-momentum's "energy error"
    # 6.9e-2 at h = 0.02 instead of 1e-14).
    full = multibody.FULL
    for bm in full["benchmarks"]:
        n_out = full["n_out"][bm] if isinstance(full["n_out"], dict) else full["n_out"]
        dt = full["t_end"][bm] / (n_out - 1)
        h_ref = min(full["steps"][bm]) / multibody.REFERENCE[bm][1]
        for h in list(full["steps"][bm]) + [h_ref, 2 * h_ref]:
            assert abs(dt / h - round(dt / h)) < 1e-9, (bm, h, dt)


@pytest.mark.parametrize("option", [{"n_out": {"B6": 1}}, {"n_out": {"B5": 11}}, {"n_out": 2.5},
                                    {"n_out": {"B6": 11, "B9": 11}}, {"steps": {"B6": (-1e-3,)}},
                                    {"t_end": {"B6": float("nan")}}],
                         ids=["n_out<2", "n_out-missing", "n_out-float", "n_out-unknown", "steps<0", "t_end-nan"])
def test_per_benchmark_options_are_checked_before_any_work(option, tmp_path):
    # Catches: a per-benchmark dict passed unchecked (the common check sees no numbers in a dict): n_out
    # {"B6": 1} ran one output time, a missing benchmark raised a bare KeyError inside the sweep.
    key = next(iter(option))
    with pytest.raises(multibody.OptionError, match=f"`{key}`"):
        multibody.run(benchmarks=["B6"], integrators=["newmark"], quick=True, out=tmp_path, progress=False, **option)


def test_b7_interval_mean_pivot_force_is_the_mean_of_the_multiplier():
    # Catches: a wrong lift vector or total mass in B7's momentum balance (a slope or director counted as a
    # translation: 1.319 kg instead of 1.314 kg), a sign or gravity slip. The output's mean over [0, 0.02] s
    # against the trapezoidal mean of the pivot multiplier at every step (h = 1e-4; measured 1.6e-6 relative).
    b = spatial_pendulum("Cable3D", 4, E=5e7, t_end=0.02)
    res = simulate(b.system, (0.0, 0.02), "lobatto3", h=1e-4, t_eval=np.linspace(0.0, 0.02, 201))
    assert res.success, res.message
    point = -res.lam[:, b.rows["pivot"]][:, 2]
    mean = b.outputs["pivot_force_mean_z"](res.t[[0, -1]], res.q[[0, -1]], res.v[[0, -1]], res.lam[[0, -1]])
    assert mean[0] == point[0]
    from scipy.integrate import trapezoid
    assert abs(mean[1] - trapezoid(point, res.t) / 0.02) < 1e-5 * np.abs(point).max()
