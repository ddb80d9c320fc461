"""B7 flexible spatial pendulum with a spinning payload as an Exudyn peer model (Cable3D).

Model (benchmarks B7), gravity 9.81 m/s^2 along -e_z:

- rod: ``n`` ObjectANCFCable elements (NodePointSlope1: r, r'; no torsion) on the straight line from
  the origin, tilted 30 degrees from -e_z towards +e_x; its top node on ObjectJointSpherical to the
  ground at the origin (MarkerNodePosition);
- payload: rigid disk ObjectRigidBody on NodeRigidBodyEP (Euler parameters; Exudyn adds their
  normalisation constraint), body z axis along the rod, inertia diag(m r^2/4, m r^2/4, m r^2/2);
  its centre on ObjectJointSpherical to the rod's last node, and its axis kept along the rod's
  slope by ObjectConnectorCoordinateVector with Python constraint and Jacobian user functions:
  t_x . r' = 0 and t_y . r' = 0 (t_x, t_y: the disk's body x and y axes in global coordinates).
  A Cable3D carries no torsion, so this weld has 5 equations: the disk spins freely about its
  axis. Exudyn's NodePointSlope1 provides no rotation (Jacobian), so ObjectJointGeneric cannot weld it.
- initial state: the whole assembly turns rigidly about e_z at ``spin`` rad/s (v = w e_z x r, slope
  rates w e_z x r', disk angular velocity w e_z).

The energy (kinetic, gravity, strain with Exudyn's measures eps = |r'| - 1 and K = r' x r'' / |r'|^2
on its Gauss rules 9 and 5) and the angular momentum about e_z are evaluated from the sampled
states after the run.

The start is not in axial equilibrium (the rod is unstretched under the disk's weight), so it
excites the axial mode of the rod carrying the disk (about sqrt(EA / (m L)) = 1250 rad/s with the
revision-1 data): the disk's distance from the pivot oscillates by about 1.5e-5 m, which steps
above about 6e-5 s do not resolve. Payload positions of different steps or integrators therefore
agree only to that level, while energy and angular momentum converge at order 2.
"""
from __future__ import annotations

import math

import numpy as np

from ancfdae._validate import positive, positive_int
from ancfdae._quadrature import gauss_for_order
from ancfdae.models.shapes import hermite

from ._exudyn_base import _exu, _ii, _require

if _exu is not None:  # Exudyn's own conversions, so that its conventions hold
    from exudyn import rigidBodyUtilities as _rbu
from ._exudyn_constrained import NEWTON_ATOL, constrained_settings, history, solve_checked, timed_runs

__all__ = ["PENDULUM3D", "spatial_pendulum"]

#: B7 revision 1 (benchmarks B7): rod length (m), diameter (m), E (N/m^2), rho (kg/m^3); disk mass
#: (kg) and radius (m); tilt of the rod from -e_z (rad); spin about e_z (rad/s); gravity; end time (s).
PENDULUM3D = dict(L=1.0, d=0.02, E=5e9, rho=1000.0, disk_mass=1.0, disk_radius=0.1,
                  tilt=math.radians(30.0), spin=2.0, g=9.81, t_end=5.0)


def _sensor(mbs, number, ovt):
    return mbs.AddSensor(_ii.SensorNode(nodeNumber=number, storeInternal=True, writeToFile=False,
                                        outputVariableType=ovt))


def _axes_and_derivatives(p):
    """Body x and y axes of Euler parameters p = (e0, e1, e2, e3) and their derivatives (4, 3)."""
    e0, e1, e2, e3 = p
    tx = np.array([e0 * e0 + e1 * e1 - e2 * e2 - e3 * e3, 2 * (e1 * e2 + e0 * e3), 2 * (e1 * e3 - e0 * e2)])
    ty = np.array([2 * (e1 * e2 - e0 * e3), e0 * e0 - e1 * e1 + e2 * e2 - e3 * e3, 2 * (e2 * e3 + e0 * e1)])
    dtx = 2 * np.array([[e0, e3, -e2], [e1, e2, e3], [-e2, e1, -e0], [-e3, e0, e1]])
    dty = 2 * np.array([[-e3, e0, e1], [e2, -e1, e0], [e1, e2, e3], [-e0, -e3, e2]])
    return tx, ty, dtx, dty


def _axis_jacobian(q):
    """Jacobian (2, 13) of (t_x . r', t_y . r') w.r.t. [r, r' of the rod node, position, p of the disk]."""
    slope, p = np.asarray(q[3:6]), np.asarray(q[9:13])
    tx, ty, dtx, dty = _axes_and_derivatives(p)
    jac = np.zeros((2, 13))
    jac[0, 3:6], jac[1, 3:6] = tx, ty
    jac[0, 9:13], jac[1, 9:13] = dtx @ slope, dty @ slope
    return jac


def _axis_constraint(mbs, t, item, q, q_t, velocity_level):
    if velocity_level:  # scleronomic: c_t = J q_t
        return list(_axis_jacobian(q) @ np.asarray(q_t))
    tx, ty, _, _ = _axes_and_derivatives(np.asarray(q[9:13]))
    slope = np.asarray(q[3:6])
    return [float(tx @ slope), float(ty @ slope)]


def _axis_constraint_jacobian(mbs, t, item, q, q_t, velocity_level):
    return _axis_jacobian(q)


def _build(n, data):
    OVT = _exu.OutputVariableType
    L, w = data["L"], data["spin"]
    A, I = math.pi * data["d"] ** 2 / 4, math.pi * data["d"] ** 4 / 64
    rod = dict(rhoA=data["rho"] * A, EA=data["E"] * A, EI=data["E"] * I)
    u = np.array([math.sin(data["tilt"]), 0.0, -math.cos(data["tilt"])])  # rod direction
    spin = np.array([0.0, 0.0, w])
    SC = _exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(_ii.ObjectGround())
    le = L / n
    nodes = []
    for i in range(n + 1):
        r = i * le * u
        rates = list(np.cross(spin, r)) + list(np.cross(spin, u))  # rigid rotation about e_z
        nodes.append(mbs.AddNode(_ii.NodePointSlope1(referenceCoordinates=list(r) + list(u), initialVelocities=rates)))
    gravity = [0.0, 0.0, -data["g"]]
    for e in range(n):
        cable = mbs.AddObject(_ii.ObjectANCFCable(nodeNumbers=[nodes[e], nodes[e + 1]], length=le,
                                                  massPerLength=rod["rhoA"], axialStiffness=rod["EA"],
                                                  bendingStiffness=rod["EI"]))
        mbs.AddLoad(_ii.LoadMassProportional(markerNumber=mbs.AddMarker(_ii.MarkerBodyMass(bodyNumber=cable)),
                                             loadVector=gravity))
    mbs.AddObject(_ii.ObjectJointSpherical(markerNumbers=[
        mbs.AddMarker(_ii.MarkerBodyPosition(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0])),
        mbs.AddMarker(_ii.MarkerNodePosition(nodeNumber=nodes[0]))]))

    m, rd = data["disk_mass"], data["disk_radius"]
    ez = u
    ex = np.cross([0.0, 1.0, 0.0], ez)
    R0 = np.column_stack([ex, np.cross(ez, ex), ez])  # body axes: z along the rod
    p0 = np.asarray(_rbu.RotationMatrix2EulerParameters(R0))
    p0_t = np.asarray(_rbu.AngularVelocity2EulerParameters_t(spin, p0))  # of the global angular velocity
    centre = L * u
    disk_node = mbs.AddNode(_ii.NodeRigidBodyEP(referenceCoordinates=list(centre) + list(p0),
                                                initialVelocities=list(np.cross(spin, centre)) + list(p0_t)))
    disk = mbs.AddObject(_ii.ObjectRigidBody(nodeNumber=disk_node, mass=m,
                                             inertia=[m * rd**2 / 4, m * rd**2 / 4, m * rd**2 / 2, 0, 0, 0]))
    mbs.AddLoad(_ii.LoadMassProportional(markerNumber=mbs.AddMarker(_ii.MarkerBodyMass(bodyNumber=disk)),
                                         loadVector=gravity))
    mbs.AddObject(_ii.ObjectJointSpherical(markerNumbers=[
        mbs.AddMarker(_ii.MarkerBodyPosition(bodyNumber=disk, localPosition=[0.0, 0.0, 0.0])),
        mbs.AddMarker(_ii.MarkerNodePosition(nodeNumber=nodes[-1]))]))
    mbs.AddObject(_ii.ObjectConnectorCoordinateVector(
        markerNumbers=[mbs.AddMarker(_ii.MarkerNodeCoordinates(nodeNumber=nodes[-1])),
                       mbs.AddMarker(_ii.MarkerNodeCoordinates(nodeNumber=disk_node))],
        scalingMarker0=np.zeros((2, 13)), constraintUserFunction=_axis_constraint,
        jacobianUserFunction=_axis_constraint_jacobian))
    sensors = dict(q=[_sensor(mbs, nd, OVT.Coordinates) for nd in nodes],
                   v=[_sensor(mbs, nd, OVT.Coordinates_t) for nd in nodes],
                   disk_r=_sensor(mbs, disk_node, OVT.Position), disk_v=_sensor(mbs, disk_node, OVT.Velocity),
                   disk_R=_sensor(mbs, disk_node, OVT.RotationMatrix),
                   disk_w=_sensor(mbs, disk_node, OVT.AngularVelocity))
    mbs.Assemble()
    ref = np.array([list(i * le * u) + list(u) for i in range(n + 1)])
    return SC, mbs, sensors, dict(rod, le=le, ref=ref)


def _rod_energy_momentum(q, v, le, rhoA, EA, EI, g):
    """Kinetic, strain and gravity energy and angular momentum about e_z of the Cable3D chain.

    ``q``, ``v``: (n_nodes, 6) total coordinates (r, r') and their rates of one sample.
    """
    n_el = q.shape[0] - 1
    L = np.full(n_el, le)
    qe = np.stack([q[:-1, 0:3], q[:-1, 3:6], q[1:, 0:3], q[1:, 3:6]], axis=1)
    ve = np.stack([v[:-1, 0:3], v[:-1, 3:6], v[1:, 0:3], v[1:, 3:6]], axis=1)
    s9, w9 = gauss_for_order(9)
    d1 = np.einsum("eps,esc->epc", hermite(s9, L)[1], qe)
    eps = np.linalg.norm(d1, axis=-1) - 1.0
    s5, w5 = gauss_for_order(5)
    _, N1, N2 = hermite(s5, L)
    a, b = np.einsum("eps,esc->epc", N1, qe), np.einsum("eps,esc->epc", N2, qe)
    K = np.cross(a, b) / np.sum(a * a, axis=-1)[..., None]
    strain = 0.5 * le / 2 * (EA * np.sum(w9 * eps**2) + EI * np.sum(w5[None, :, None] * K**2))
    s7, w7 = gauss_for_order(7)
    N = hermite(s7, L)[0]
    r, rdot = np.einsum("eps,esc->epc", N, qe), np.einsum("eps,esc->epc", N, ve)
    kinetic = 0.5 * rhoA * le / 2 * np.sum(w7[None, :, None] * rdot**2)
    gravity = rhoA * g * le / 2 * np.sum(w7[None, :] * r[..., 2])
    momentum = rhoA * le / 2 * np.sum(w7[None, :] * np.cross(r, rdot)[..., 2])
    return kinetic, strain, gravity, momentum


def _outputs(mbs, sensors, rod, data):
    qs = np.stack([history(mbs, s)[:, 1:] for s in sensors["q"]], axis=1) + rod["ref"][None]
    vs = np.stack([history(mbs, s)[:, 1:] for s in sensors["v"]], axis=1)
    t = history(mbs, sensors["disk_r"])[:, 0]
    rc, vc = history(mbs, sensors["disk_r"])[:, 1:], history(mbs, sensors["disk_v"])[:, 1:]
    R = history(mbs, sensors["disk_R"])[:, 1:].reshape(-1, 3, 3)
    w = history(mbs, sensors["disk_w"])[:, 1:]
    m, rd, g = data["disk_mass"], data["disk_radius"], data["g"]
    J = np.diag([m * rd**2 / 4, m * rd**2 / 4, m * rd**2 / 2])
    Jw = np.einsum("kij,jl,kml,km->ki", R, J, R, w)  # R J R^T w
    parts = np.array([_rod_energy_momentum(qs[k], vs[k], rod["le"], rod["rhoA"], rod["EA"], rod["EI"], g)
                      for k in range(len(t))])
    kinetic = parts[:, 0] + 0.5 * m * np.sum(vc**2, axis=1) + 0.5 * np.einsum("ki,ki->k", w, Jw)
    energy = kinetic + parts[:, 1] + parts[:, 2] + m * g * rc[:, 2]
    momentum_z = parts[:, 3] + m * np.cross(rc, vc)[:, 2] + Jw[:, 2]
    axis_error = np.abs(np.einsum("ki,ki->k", R[:, :, 0], qs[:, -1, 3:6])) + np.abs(
        np.einsum("ki,ki->k", R[:, :, 1], qs[:, -1, 3:6]))
    return dict(t=t, payload=rc, energy=energy, strain_energy=parts[:, 1], momentum_z=momentum_z,
                energy_drift=float(np.max(np.abs(energy - energy[0])) / abs(energy[0])),
                momentum_drift=float(np.max(np.abs(momentum_z - momentum_z[0])) / abs(momentum_z[0])),
                drift=dict(pivot=float(np.max(np.linalg.norm(qs[:, 0, 0:3], axis=1))),
                           payload_pin=float(np.max(np.linalg.norm(qs[:, -1, 0:3] - rc, axis=1))),
                           payload_axis=float(np.max(axis_error))))


def spatial_pendulum(n_elements, h, integrator="generalized_alpha", *, data=PENDULUM3D, t_end=None,
                     output_period=0.01, rho_inf=0.9, modified_newton=True, newton_atol=NEWTON_ATOL,
                     repeats=1, strict=True):
    """B7 with Exudyn (module docstring): timed solve; energy and angular momentum from the samples.

    Parameters are those of :func:`benchmarks._exudyn_slider_crank.slider_crank`.

    Returns
    -------
    dict
        The keys of :func:`~benchmarks._exudyn_constrained.solve_checked` and: ``t`` (s);
        ``payload`` (samples, 3): the disk centre (m); ``energy``: kinetic + gravity + strain (J,
        zero gravity level at z = 0); ``strain_energy`` (J); ``momentum_z``: angular momentum about
        e_z through the pivot (kg m^2/s); ``energy_drift`` and ``momentum_drift``: their max
        deviation from the initial value, relative to it; ``drift``: max over the samples of the
        pivot's and the payload pin's gap (m) and of |t_x . r'| + |t_y . r'| (the weld's axis).
    """
    n = positive_int("n_elements", n_elements)
    h = positive("h", h)
    t_end = data["t_end"] if t_end is None else positive("t_end", t_end)
    repeats = positive_int("repeats", repeats)
    _require()

    def run():
        SC, mbs, sensors, rod = _build(n, data)  # SC owns mbs: keep it alive while mbs is used
        out = solve_checked(mbs, constrained_settings(t_end, h, integrator, rho_inf=rho_inf,
                                                      modified_newton=modified_newton, newton_atol=newton_atol,
                                                      output_period=output_period))
        out.update(_outputs(mbs, sensors, rod, data))
        return out

    if not strict and repeats == 1:
        return run()
    return timed_runs(run, repeats)
