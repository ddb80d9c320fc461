"""B5 spin-up of a flexible beam (Simo & Vu-Quoc 1986) as an Exudyn peer model.

Model (benchmarks B5): ``n`` ObjectANCFCable2D elements (NodePoint2DSlope1: x, y, x', y') on
[0, L] along e_x, at rest; no gravity. Node 0 is clamped to a driven hub whose angle follows
:func:`hub_angle`. Two ways of writing the rheonomic clamp in Exudyn:

``clamp="hub"`` (the default; as Exudyn's example ANCFrotatingCable2D)
    a rigid hub ObjectRigidBody2D (NodeRigidBody2D x, y, phi; 1 kg, 1 kg m^2 -- its inertia only
    changes the driving constraint's multiplier, not the beam) held at the origin by
    ObjectConnectorCoordinate on x and y, its angle prescribed by an ObjectConnectorCoordinate on
    phi with ``offsetUserFunction`` theta(t) and ``offsetUserFunction_t`` theta'(t); node 0 welded
    to it by ObjectJointGeneric (MarkerBodyRigid of the hub, MarkerNodeRigid of node 0,
    ``constrainedAxes=[1,1,0,0,0,1]``): its position and the *direction* of its slope r' (the
    node's rotation is atan2(y', x')) follow the hub; the slope's length stays free, as in the B1
    clamp. The hub torque is the joint's ``TorqueLocal`` z: the moment the hub applies to the beam.
``clamp="slope_coordinates"``
    four ObjectConnectorCoordinate on node 0: x = y = 0, x' = cos theta, y' = sin theta
    (``offsetUserFunction`` and ``_t`` on the displacement x' - 1, y'). This also fixes |r'| = 1 at
    the clamp (over-constraining the axial strain there); kept to measure that difference. The hub
    torque is then x' Q_y' - y' Q_x' with Q the reactions on the slope coordinates.

ObjectJointGeneric's own ``offsetUserFunction`` would prescribe the angle without a hub body, but
Exudyn 1.13.6 raises "offsetUserFunction_t not implemented for velocity level constraints" with the
index-2 trapezoidal rule, so the hub body is the form both integrators run.
"""
from __future__ import annotations

import math

import numpy as np

from ancfdae._validate import choice, positive, positive_int

from ._exudyn_base import _exu, _ii, _require
from ._exudyn_constrained import NEWTON_ATOL, constrained_settings, history, solve_checked, timed_runs

__all__ = ["SPINUP", "hub_angle", "spinup"]

#: B5 data (benchmarks B5): beam length, EA, EI, rho A; spin-up time T_s and time span.
SPINUP = dict(L=10.0, EA=2.8e7, EI=1.4e4, rhoA=1.2, T_s=15.0, t_end=30.0)
_CLAMPS = {"hub", "slope_coordinates"}


def hub_angle(t, w_s, T_s=SPINUP["T_s"]):
    """Hub angle theta (rad), its rate and acceleration at time ``t`` (benchmarks B5).

    theta = (w_s / T_s) (t^2 / 2 + (T_s / 2 pi)^2 (cos(2 pi t / T_s) - 1)) for t <= T_s and
    w_s (t - T_s / 2) after: the rate rises smoothly from 0 to w_s, the acceleration
    (w_s / T_s)(1 - cos(2 pi t / T_s)) is continuous and zero at both ends of the spin-up.
    """
    if t <= T_s:
        c = 2.0 * math.pi / T_s
        return (w_s / T_s * (0.5 * t * t + (math.cos(c * t) - 1.0) / (c * c)),
                w_s / T_s * (t - math.sin(c * t) / c),
                w_s / T_s * (1.0 - math.cos(c * t)))
    return w_s * (t - 0.5 * T_s), w_s, 0.0


def _sensor(mbs, kind, number, ovt):
    item = _ii.SensorNode(nodeNumber=number) if kind == "node" else _ii.SensorObject(objectNumber=number)
    item.storeInternal, item.writeToFile, item.outputVariableType = True, False, ovt
    return mbs.AddSensor(item)


def _build(n, w_s, clamp):
    p = SPINUP
    OVT = _exu.OutputVariableType
    SC = _exu.SystemContainer()
    mbs = SC.AddSystem()
    le = p["L"] / n
    nodes = [mbs.AddNode(_ii.NodePoint2DSlope1(referenceCoordinates=[i * le, 0.0, 1.0, 0.0]))
             for i in range(n + 1)]
    for e in range(n):
        mbs.AddObject(_ii.ObjectANCFCable2D(nodeNumbers=[nodes[e], nodes[e + 1]], length=le,
                                            massPerLength=p["rhoA"], axialStiffness=p["EA"],
                                            bendingStiffness=p["EI"]))
    ground = mbs.AddMarker(_ii.MarkerNodeCoordinate(
        nodeNumber=mbs.AddNode(_ii.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0])), coordinate=0))

    def coordinate_constraint(node, coordinate, offset=None, offset_t=None):
        m = mbs.AddMarker(_ii.MarkerNodeCoordinate(nodeNumber=node, coordinate=coordinate))
        kw = {} if offset is None else dict(offsetUserFunction=offset, offsetUserFunction_t=offset_t)
        return mbs.AddObject(_ii.ObjectConnectorCoordinate(markerNumbers=[ground, m], **kw))

    sensors = {}
    if clamp == "hub":
        hub = mbs.AddNode(_ii.NodeRigidBody2D(referenceCoordinates=[0.0, 0.0, 0.0]))
        body = mbs.AddObject(_ii.ObjectRigidBody2D(nodeNumber=hub, mass=1.0, inertia=1.0))
        coordinate_constraint(hub, 0)
        coordinate_constraint(hub, 1)
        coordinate_constraint(hub, 2, lambda mbs, t, item, off: hub_angle(t, w_s)[0],
                              lambda mbs, t, item, off: hub_angle(t, w_s)[1])
        weld = mbs.AddObject(_ii.ObjectJointGeneric(
            markerNumbers=[mbs.AddMarker(_ii.MarkerBodyRigid(bodyNumber=body, localPosition=[0.0, 0.0, 0.0])),
                           mbs.AddMarker(_ii.MarkerNodeRigid(nodeNumber=nodes[0]))],
            constrainedAxes=[1, 1, 0, 0, 0, 1]))
        sensors["torque"] = _sensor(mbs, "object", weld, OVT.TorqueLocal)
    else:
        coordinate_constraint(nodes[0], 0)
        coordinate_constraint(nodes[0], 1)

        def slope_x(mbs, t, item, off):  # displacement of x' (reference 1)
            return math.cos(hub_angle(t, w_s)[0]) - 1.0

        def slope_x_t(mbs, t, item, off):
            th, th_t, _ = hub_angle(t, w_s)
            return -math.sin(th) * th_t

        def slope_y(mbs, t, item, off):
            return math.sin(hub_angle(t, w_s)[0])

        def slope_y_t(mbs, t, item, off):
            th, th_t, _ = hub_angle(t, w_s)
            return math.cos(th) * th_t

        slope = [coordinate_constraint(nodes[0], 2, slope_x, slope_x_t),
                 coordinate_constraint(nodes[0], 3, slope_y, slope_y_t)]
        sensors["slope_reaction"] = [_sensor(mbs, "object", c, OVT.Force) for c in slope]
    sensors["tip"] = _sensor(mbs, "node", nodes[-1], OVT.Position)
    sensors["root"] = _sensor(mbs, "node", nodes[0], OVT.Coordinates)
    mbs.Assemble()
    return SC, mbs, sensors


def _outputs(mbs, sensors, clamp, w_s):
    tip = history(mbs, sensors["tip"])
    root = history(mbs, sensors["root"])
    t = tip[:, 0]
    angle = np.array([hub_angle(ti, w_s) for ti in t])
    th, th_t = angle[:, 0], angle[:, 1]
    slope = root[:, 3:5] + np.array([1.0, 0.0])  # total r' of node 0 (reference slope (1, 0))
    if clamp == "hub":
        torque = history(mbs, sensors["torque"])[:, 3]
    else:  # moment of the slope reactions about e_z; Exudyn's multiplier is minus the reaction
        qx, qy = (-history(mbs, s)[:, 1] for s in sensors["slope_reaction"])
        torque = slope[:, 0] * qy - slope[:, 1] * qx
    power = torque * th_t
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    psi = np.arctan2(slope[:, 1], slope[:, 0])  # the root's actual direction (drifts at index 2)
    angle_error = np.angle(np.exp(1j * (psi - th)))
    rel = tip[:, 1:3] - root[:, 1:3]  # node 0's reference position is the origin
    return dict(t=t, theta=th, deflection=-tip[:, 1] * np.sin(th) + tip[:, 2] * np.cos(th),
                deflection_root=-rel[:, 0] * np.sin(psi) + rel[:, 1] * np.cos(psi),
                tip_x=tip[:, 1], tip_y=tip[:, 2], torque=torque, work=work,
                drift_position=float(np.max(np.hypot(root[:, 1], root[:, 2]))),
                drift_angle=float(np.max(np.abs(angle_error))),
                root_stretch=np.hypot(slope[:, 0], slope[:, 1]) - 1.0)


def spinup(n_elements, h, integrator="generalized_alpha", w_s=4.0, *, clamp="hub", t_end=None,
           output_period=0.01, rho_inf=0.9, modified_newton=True, newton_atol=NEWTON_ATOL,
           repeats=1, strict=True):
    """B5 spin-up with Exudyn (module docstring); timed solve, outputs sampled every ``output_period``.

    Parameters
    ----------
    n_elements : int
        ObjectANCFCable2D elements on the 10 m beam.
    h : float
        Constant step size (s).
    integrator : {'generalized_alpha', 'trapezoidal_index2'}
        Exudyn's index-3 generalized-alpha (spectral radius ``rho_inf``) or index-2 trapezoidal rule.
    w_s : float
        Final spin rate (rad/s): 4 (benchmark) or 10 (harder case).
    clamp : {'hub', 'slope_coordinates'}
        How the rheonomic clamp is written (module docstring).
    t_end : float, optional
        End time, default 30 s.
    output_period, rho_inf, modified_newton, newton_atol
        Sampling period (s); see :func:`~benchmarks._exudyn_constrained.constrained_settings`
        (Newton relative tolerance 1e-8 always).
    repeats : int
        Timed runs (fresh model each); median wall and CPU time.
    strict : bool
        Raise if a run fails (default); with ``False`` a single failed run is returned with
        ``ok=False``, its ``reason`` and the outputs up to ``t_reached``.

    Returns
    -------
    dict
        The keys of :func:`~benchmarks._exudyn_constrained.solve_checked` and: ``t`` (s);
        ``theta`` (rad); ``deflection``: the tip's transverse deflection in the hub frame,
        r_tip . (-sin theta, cos theta) (m, positive ahead of the rotation); ``deflection_root``:
        the same in the frame of the root's actual slope direction, (r_tip - r_0) . (-sin psi,
        cos psi) with psi = atan2(r'(0)); it differs from ``deflection`` by about L times the
        clamp's angle drift (index 2); ``tip_x``, ``tip_y`` (m, global); ``torque``: the hub
        torque on the beam about +e_z (N m); ``work``: the work of the prescribed rotation, the
        integral of torque theta' dt (J, trapezoidal rule on the samples); ``drift_position``
        max |r(0)| (m) and ``drift_angle`` max |atan2(r'(0)) - theta| (rad) over the samples: the
        clamp's constraint drift; ``root_stretch`` |r'(0)| - 1.
    """
    n = positive_int("n_elements", n_elements)
    h, w_s = positive("h", h), positive("w_s", w_s)
    t_end = SPINUP["t_end"] if t_end is None else positive("t_end", t_end)
    clamp = choice("clamp", clamp, _CLAMPS)
    repeats = positive_int("repeats", repeats)
    _require()

    def run():
        SC, mbs, sensors = _build(n, w_s, clamp)  # SC owns mbs: keep it alive while mbs is used
        out = solve_checked(mbs, constrained_settings(t_end, h, integrator, rho_inf=rho_inf,
                                                      modified_newton=modified_newton, newton_atol=newton_atol,
                                                      output_period=output_period))
        out.update(_outputs(mbs, sensors, clamp, w_s))
        return out

    if not strict and repeats == 1:
        return run()
    return timed_runs(run, repeats)
