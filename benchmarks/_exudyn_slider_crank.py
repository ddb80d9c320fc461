"""B6 flexible slider-crank as an Exudyn peer model.

Model (benchmarks B6), planar, no gravity, all at rest at t = 0 with the crank along +e_x:

- crank: ObjectRigidBody2D (NodeRigidBody2D x, y, phi at its centre of mass, a uniform bar of
  length ``crank_length`` and mass ``crank_mass``: inertia m l^2 / 12), pinned to the ground at the
  origin by ObjectJointRevolute2D; its angle prescribed by ObjectConnectorCoordinate on phi with
  ``offsetUserFunction`` phi(t) and ``offsetUserFunction_t`` (:func:`crank_angle`);
- connecting rod: ``n`` ObjectANCFCable2D elements (NodePoint2DSlope1) on the straight line from the
  crank pin to the slider, circular section;
- slider: ObjectMassPoint2D (NodePoint2D), kept on the line y = 0 by ObjectConnectorCoordinate on its
  y (the prismatic joint of a point);
- pins: ObjectJointRevolute2D between the crank's end (MarkerBodyPosition) and the rod's node 0,
  and between the rod's last node and the slider (MarkerNodePosition): positions coincide, slopes
  free (as Exudyn's SliderCrank example joins its bodies).

The multipliers give the crank torque (the drive's reaction) and the slider's normal force.
"""
from __future__ import annotations

import math

import numpy as np

from ancfdae._validate import positive, positive_int

from ._exudyn_base import _exu, _ii, _require
from ._exudyn_constrained import NEWTON_ATOL, constrained_settings, history, solve_checked, timed_runs

__all__ = ["SLIDER_CRANK", "crank_angle", "slider_crank", "rod_properties"]

#: B6 revision 1 (benchmarks B6): crank length (m) and mass (kg); rod length (m), diameter (m), E
#: (N/m^2), rho (kg/m^3); slider mass (kg); final crank speed w_s (rad/s), ramp time T_r (s), end time (s).
SLIDER_CRANK = dict(crank_length=0.15, crank_mass=0.5, rod_length=0.3, d=0.01, E=2e9, rho=1200.0,
                    slider_mass=0.02, w_s=100.0, T_r=0.2, t_end=0.5)


def rod_properties(data=SLIDER_CRANK):
    """EA (N), EI (N m^2), rho A (kg/m), first pinned-pinned bending frequency (rad/s), Euler load (N)."""
    A = math.pi * data["d"] ** 2 / 4
    I = math.pi * data["d"] ** 4 / 64
    EA, EI, rhoA = data["E"] * A, data["E"] * I, data["rho"] * A
    L = data["rod_length"]
    return dict(EA=EA, EI=EI, rhoA=rhoA, omega1=math.pi**2 * math.sqrt(EI / (rhoA * L**4)),
                euler_load=math.pi**2 * EI / L**2)


def crank_angle(t, w_s, T_r):
    """Crank angle (rad) and rate (rad/s): rate w_s (1 - cos(pi t / T_r)) / 2 up to T_r, w_s after."""
    if t <= T_r:
        c = math.pi / T_r
        return 0.5 * w_s * (t - math.sin(c * t) / c), 0.5 * w_s * (1.0 - math.cos(c * t))
    return w_s * (t - 0.5 * T_r), w_s


def _sensor(mbs, kind, number, ovt):
    item = _ii.SensorNode(nodeNumber=number) if kind == "node" else _ii.SensorObject(objectNumber=number)
    item.storeInternal, item.writeToFile, item.outputVariableType = True, False, ovt
    return mbs.AddSensor(item)


def _build(n, data):
    OVT = _exu.OutputVariableType
    rod = rod_properties(data)
    lc, lr = data["crank_length"], data["rod_length"]
    w_s, T_r = data["w_s"], data["T_r"]
    SC = _exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(_ii.ObjectGround())
    ground_coordinate = mbs.AddMarker(_ii.MarkerNodeCoordinate(
        nodeNumber=mbs.AddNode(_ii.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0])), coordinate=0))

    crank_node = mbs.AddNode(_ii.NodeRigidBody2D(referenceCoordinates=[0.5 * lc, 0.0, 0.0]))
    crank = mbs.AddObject(_ii.ObjectRigidBody2D(nodeNumber=crank_node, mass=data["crank_mass"],
                                                inertia=data["crank_mass"] * lc**2 / 12))
    mbs.AddObject(_ii.ObjectJointRevolute2D(markerNumbers=[
        mbs.AddMarker(_ii.MarkerBodyPosition(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0])),
        mbs.AddMarker(_ii.MarkerBodyPosition(bodyNumber=crank, localPosition=[-0.5 * lc, 0.0, 0.0]))]))
    drive = mbs.AddObject(_ii.ObjectConnectorCoordinate(
        markerNumbers=[ground_coordinate, mbs.AddMarker(_ii.MarkerNodeCoordinate(nodeNumber=crank_node, coordinate=2))],
        offsetUserFunction=lambda mbs, t, item, off: crank_angle(t, w_s, T_r)[0],
        offsetUserFunction_t=lambda mbs, t, item, off: crank_angle(t, w_s, T_r)[1]))

    le = lr / n
    nodes = [mbs.AddNode(_ii.NodePoint2DSlope1(referenceCoordinates=[lc + i * le, 0.0, 1.0, 0.0]))
             for i in range(n + 1)]
    for e in range(n):
        mbs.AddObject(_ii.ObjectANCFCable2D(nodeNumbers=[nodes[e], nodes[e + 1]], length=le,
                                            massPerLength=rod["rhoA"], axialStiffness=rod["EA"],
                                            bendingStiffness=rod["EI"]))
    slider_node = mbs.AddNode(_ii.NodePoint2D(referenceCoordinates=[lc + lr, 0.0]))
    mbs.AddObject(_ii.ObjectMassPoint2D(nodeNumber=slider_node, mass=data["slider_mass"]))
    mbs.AddObject(_ii.ObjectJointRevolute2D(markerNumbers=[
        mbs.AddMarker(_ii.MarkerBodyPosition(bodyNumber=crank, localPosition=[0.5 * lc, 0.0, 0.0])),
        mbs.AddMarker(_ii.MarkerNodePosition(nodeNumber=nodes[0]))]))
    slider_pin = mbs.AddObject(_ii.ObjectJointRevolute2D(markerNumbers=[
        mbs.AddMarker(_ii.MarkerNodePosition(nodeNumber=nodes[-1])),
        mbs.AddMarker(_ii.MarkerNodePosition(nodeNumber=slider_node))]))
    guide = mbs.AddObject(_ii.ObjectConnectorCoordinate(markerNumbers=[
        ground_coordinate, mbs.AddMarker(_ii.MarkerNodeCoordinate(nodeNumber=slider_node, coordinate=1))]))

    sensors = dict(crank=_sensor(mbs, "node", crank_node, OVT.Coordinates),
                   slider=_sensor(mbs, "node", slider_node, OVT.Position),
                   rod_a=_sensor(mbs, "node", nodes[0], OVT.Position),
                   rod_b=_sensor(mbs, "node", nodes[-1], OVT.Position),
                   drive=_sensor(mbs, "object", drive, OVT.Force),
                   guide=_sensor(mbs, "object", guide, OVT.Force),
                   slider_pin=_sensor(mbs, "object", slider_pin, OVT.Force))
    if n % 2 == 0:
        sensors["rod_mid"] = _sensor(mbs, "node", nodes[n // 2], OVT.Position)
    mbs.Assemble()
    return SC, mbs, sensors


def _outputs(mbs, sensors, data):
    lc = data["crank_length"]
    h = {k: history(mbs, s) for k, s in sensors.items()}
    t = h["slider"][:, 0]
    phi_exact = np.array([crank_angle(ti, data["w_s"], data["T_r"])[0] for ti in t])
    phi = h["crank"][:, 3]
    centre = h["crank"][:, 1:3] + np.array([0.5 * lc, 0.0])  # Coordinates are displacements
    half = 0.5 * lc * np.column_stack([np.cos(phi), np.sin(phi)])
    crank_tip = centre + half
    a, b, s = h["rod_a"][:, 1:3], h["rod_b"][:, 1:3], h["slider"][:, 1:3]
    chord = b - a
    normal = np.column_stack([-chord[:, 1], chord[:, 0]]) / np.linalg.norm(chord, axis=1)[:, None]
    out = dict(t=t, slider_x=s[:, 0], slider_y=s[:, 1], crank_angle=phi,
               # Exudyn's multiplier of a coordinate constraint is minus the generalized reaction
               crank_torque=-h["drive"][:, 1], normal_force=-h["guide"][:, 1],
               rod_axial_force=np.einsum("ij,ij->i", h["slider_pin"][:, 1:3], chord) / np.linalg.norm(chord, axis=1),
               chord_length=np.linalg.norm(chord, axis=1),
               drift=dict(slider_y=float(np.max(np.abs(s[:, 1]))),
                          pivot=float(np.max(np.linalg.norm(centre - half, axis=1))),
                          crank_pin=float(np.max(np.linalg.norm(crank_tip - a, axis=1))),
                          slider_pin=float(np.max(np.linalg.norm(b - s, axis=1))),
                          crank_angle=float(np.max(np.abs(phi - phi_exact)))))
    if "rod_mid" in h:
        out["mid_deflection"] = np.einsum("ij,ij->i", h["rod_mid"][:, 1:3] - 0.5 * (a + b), normal)
    return out


def slider_crank(n_elements, h, integrator="generalized_alpha", *, data=SLIDER_CRANK, t_end=None,
                 output_period=1e-3, rho_inf=0.9, modified_newton=True, newton_atol=NEWTON_ATOL,
                 repeats=1, strict=True):
    """B6 flexible slider-crank with Exudyn (module docstring); timed solve, sampled outputs.

    Parameters
    ----------
    n_elements : int
        ObjectANCFCable2D elements of the rod (even, so that a node sits at its midpoint).
    h : float
        Constant step size (s).
    integrator : {'generalized_alpha', 'trapezoidal_index2'}
        Exudyn's index-3 generalized-alpha or index-2 trapezoidal rule.
    data : dict
        Benchmark data (default revision 1, :data:`SLIDER_CRANK`).
    t_end : float, optional
        End time, default ``data['t_end']``.
    output_period, rho_inf, modified_newton, newton_atol, repeats, strict
        As for :func:`benchmarks._exudyn_spinup.spinup`.

    Returns
    -------
    dict
        The keys of :func:`~benchmarks._exudyn_constrained.solve_checked` and: ``t`` (s);
        ``slider_x``, ``slider_y`` (m); ``crank_angle`` (rad); ``crank_torque``: the drive's torque
        on the crank about +e_z (N m); ``normal_force``: the guide's force on the slider along +e_y
        (N); ``rod_axial_force``: the slider pin's force along the rod's chord (N, negative when the
        rod is compressed); ``mid_deflection``: the rod midpoint's distance from the chord of its
        ends, positive to the left of the chord direction (m); ``chord_length`` (m); ``drift``: max
        over the samples of |slider y|, the gaps of the crank's pivot and of the two pins (m) and
        |phi - phi(t)| (rad).
    """
    n = positive_int("n_elements", n_elements)
    if n % 2:
        raise ValueError(f"`n_elements` must be even (a node at the rod's midpoint), got {n}.")
    h = positive("h", h)
    t_end = data["t_end"] if t_end is None else positive("t_end", t_end)
    repeats = positive_int("repeats", repeats)
    _require()

    def run():
        SC, mbs, sensors = _build(n, data)  # SC owns mbs: keep it alive while mbs is used
        out = solve_checked(mbs, constrained_settings(t_end, h, integrator, rho_inf=rho_inf,
                                                      modified_newton=modified_newton, newton_atol=newton_atol,
                                                      output_period=output_period))
        out.update(_outputs(mbs, sensors, data))
        return out

    if not strict and repeats == 1:
        return run()
    return timed_runs(run, repeats)
