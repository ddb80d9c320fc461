"""The Exudyn peer models of the multibody benchmarks obey their joints and do the right work.

Skipped where exudyn is not installed. Each test runs coarse, short models (a few seconds in all).
"""
import pathlib
import sys

import numpy as np
import pytest

pytest.importorskip("exudyn", reason="exudyn is not installed (pip install '.[benchmark]')")
# benchmarks/ is a folder of the repository, not part of the installed package: reach it from the
# checkout (appended, so an installed ancfdae keeps precedence over the source tree).
sys.path.append(str(pathlib.Path(__file__).resolve().parents[2]))
from benchmarks import _exudyn_slider_crank as crank  # noqa: E402
from benchmarks import _exudyn_spinup as spin  # noqa: E402


def _rigid_slider_crank_energy(phi, w, data):
    """Kinetic energy of the slider-crank with a rigid rod (uniform bar) at crank angle phi, rate w."""
    r, l = data["crank_length"], data["rod_length"]
    root = np.sqrt(l**2 - (r * np.sin(phi)) ** 2)
    vb = (-r * np.sin(phi) - r**2 * np.sin(phi) * np.cos(phi) / root) * w  # slider velocity
    va2, va_vb = (r * w) ** 2, -r * np.sin(phi) * w * vb  # crank pin speed^2, v_A . v_B
    m_rod = data["rho"] * np.pi * data["d"] ** 2 / 4 * l
    return (0.5 * data["crank_mass"] * r**2 / 3 * w**2 + m_rod / 6 * (va2 + va_vb + vb**2)
            + 0.5 * data["slider_mass"] * vb**2)


def test_slider_crank_with_a_stiff_rod_moves_and_works_as_the_rigid_mechanism():
    # Catches: a misplaced crank or slider marker (kinematics), a wrong sign or component of the
    # crank torque, a wrong crank inertia (the work the drive does must equal the rigid mechanism's
    # kinetic energy: crank 26 % of it at 0.15 s), a guide on the wrong coordinate.
    data = dict(crank.SLIDER_CRANK, E=2e11, t_end=0.15)  # 100x stiffer rod: nearly rigid
    r = crank.slider_crank(2, 1e-4, data=data, output_period=1e-4)
    assert r["ok"] and r["t"][-1] == pytest.approx(0.15)
    phi = r["crank_angle"]
    rc, l = data["crank_length"], data["rod_length"]
    rigid_x = rc * np.cos(phi) + np.sqrt(l**2 - (rc * np.sin(phi)) ** 2)
    assert np.max(np.abs(r["slider_x"] - rigid_x)) < 2e-6  # measured 6.2e-7 m (axial strain)
    w = np.array([crank.crank_angle(t, data["w_s"], data["T_r"])[1] for t in r["t"]])
    kinetic = _rigid_slider_crank_energy(phi, w, data)
    power = r["crank_torque"] * w
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(r["t"]))])
    assert np.max(np.abs(work - kinetic)) < 1e-3 * kinetic.max()  # measured 6.1e-5
    # index 3: the slider stays on its line and the joints close to round-off
    d = r["drift"]
    assert d["slider_y"] < 1e-12 and d["pivot"] < 1e-12 and d["crank_pin"] < 1e-12
    assert d["slider_pin"] < 1e-12 and d["crank_angle"] < 1e-12


def test_flexible_slider_crank_rod_bends_by_its_inertia_and_stays_far_from_buckling():
    # Catches a rod built with wrong section data (EI, rho A): revision 1's rod bends 2.5 % of its
    # length by its own transverse inertia in the first revolution (7.5e-3 m by 0.16 s), while
    # compressed far below its Euler load (107.7 N; measured 18.5 N); the index-2 trapezoidal rule
    # keeps the linear constraints (guide, slider pin) exact.
    props = crank.rod_properties()
    assert props["omega1"] == pytest.approx(353.93, abs=0.01)
    assert props["euler_load"] == pytest.approx(107.66, abs=0.01)
    data = dict(crank.SLIDER_CRANK, t_end=0.16)
    r = crank.slider_crank(4, 1e-4, "trapezoidal_index2", data=data)
    assert r["ok"]
    assert 6e-3 < np.max(np.abs(r["mid_deflection"])) < 9e-3
    assert -0.5 * props["euler_load"] < r["rod_axial_force"].min() < 0.0
    assert r["drift"]["slider_y"] < 1e-12 and r["drift"]["slider_pin"] < 1e-12


def test_spinup_hub_angle_is_followed_and_the_torque_does_the_work_of_the_spin_up():
    # Catches: a clamp that does not follow theta(t) (angle or position drift at index 3), a torque
    # of the wrong sign or read from the driving constraint (it would include the hub's own
    # inertia: 8 J of 3200 J, 2.5e-3), a wrong rho A. The work of the hub torque up to T_s equals
    # the kinetic energy of the (nearly rigid) beam, rho A L^3 w_s^2 / 6 = 3200 J; measured 3.4e-4
    # above it (centrifugal stretch, elastic vibration, the integrator's dissipation).
    r = spin.spinup(4, 2.5e-3, w_s=4.0, t_end=15.0)
    assert r["ok"] and r["t"][-1] == pytest.approx(15.0)
    assert r["drift_angle"] < 1e-10 and r["drift_position"] < 1e-12
    p = spin.SPINUP
    rigid = p["rhoA"] * p["L"] ** 3 * 4.0**2 / 6
    assert r["work"][-1] == pytest.approx(rigid, rel=1e-3)
    assert np.all(np.abs(r["deflection"]) < 0.45)  # geometric stiffening keeps it bounded (0.400 m)
    theta = np.array([spin.hub_angle(t, 4.0)[0] for t in r["t"]])
    assert np.max(np.abs(r["theta"] - theta)) == 0.0


def test_slope_coordinate_clamp_fixes_the_slope_length_the_hub_weld_leaves_it_free():
    # Catches a weld that over-constrains the clamp: the hub weld fixes position and slope
    # direction only, so the centrifugal tension N = rho A w^2 L^2 / 2 stretches the root
    # (|r'| - 1 = N / EA); prescribing x', y' as coordinates pins |r'| = 1.
    p = spin.SPINUP
    weld = spin.spinup(4, 1e-2, clamp="hub", w_s=4.0, t_end=15.0)
    coords = spin.spinup(4, 1e-2, clamp="slope_coordinates", w_s=4.0, t_end=15.0)
    assert np.max(np.abs(coords["root_stretch"])) < 1e-12
    centrifugal = p["rhoA"] * 4.0**2 * p["L"] ** 2 / 2 / p["EA"]  # 3.4286e-5 at w_s = 4 rad/s
    assert weld["root_stretch"][-1] == pytest.approx(centrifugal, rel=0.01)  # measured 3.4305e-5


def test_spatial_pendulum_starts_in_rigid_rotation_and_keeps_its_invariants():
    # Catches: wrong initial velocities or Euler-parameter rates (the initial angular momentum and
    # energy have a closed form for the rigid rotation about e_z), a disk inertia in the wrong body
    # axes, gravity missing on a body (energy not conserved), a wrong Jacobian of the axis weld
    # (Newton failure or drift of the weld at index 3).
    from benchmarks import _exudyn_spatial_pendulum as pend

    p = pend.PENDULUM3D
    r = pend.spatial_pendulum(2, 1e-3, t_end=1.0)
    assert r["ok"] and r["t"][-1] == pytest.approx(1.0)
    s, c = np.sin(p["tilt"]), np.cos(p["tilt"])
    rhoA = p["rho"] * np.pi * p["d"] ** 2 / 4
    m, rd, L, w = p["disk_mass"], p["disk_radius"], p["L"], p["spin"]
    inertia_z = rhoA * L**3 * s**2 / 3 + m * (L * s) ** 2 + m * rd**2 / 2 * c**2 + m * rd**2 / 4 * s**2
    energy0 = 0.5 * inertia_z * w**2 - p["g"] * (rhoA * L * L * c / 2 + m * L * c)
    assert r["momentum_z"][0] == pytest.approx(inertia_z * w, rel=1e-12)
    assert r["energy"][0] == pytest.approx(energy0, rel=1e-12)
    # conservative: generalized-alpha (rho_inf 0.9) keeps both to its accuracy (measured 1.7e-6, 5.5e-6)
    assert r["energy_drift"] < 1e-5 and r["momentum_drift"] < 1e-5
    d = r["drift"]
    assert d["pivot"] < 1e-12 and d["payload_pin"] < 1e-12 and d["payload_axis"] < 1e-10
    # the payload swings inward from its start on the 0.5 m circle (2 rad/s is below the conical rate)
    assert np.min(np.hypot(r["payload"][:, 0], r["payload"][:, 1])) < 0.35
