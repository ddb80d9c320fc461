"""Monitors: energy balance and point sensors, logged at the output times.

Every integrator drives a monitor through four calls:

``start(model, t0, q0, v0, a0)``
    once, before the first step;
``advance(t, q, v, a, nodes=None)``
    after every accepted step (on IDA: every internal step), with the
    step's quadrature when the integrator has one, an
    :class:`ancfdae.integrators.protocol.Quadrature` ``(t, q, v, w)`` (node
    times, coordinates and velocities as rows, weights that sum to the step
    size), for integrals over the step;
``sample(t, q, v, a)``
    at every output time (``t`` lies in the last advanced step);
``rebind(model)`` (optional)
    after a model event (BE3D's director update) with the model bound to
    the new event state, so that later evaluations use it;
``log()``
    the arrays (one entry per output time) and scalars stored in
    ``Result.monitors[name]``.

``stop_reason()`` returns a string when the monitor asks the run to end.
"""
from ancfdae.monitors.base import Monitor
from ancfdae.monitors.constraints import ConstraintMonitor
from ancfdae.monitors.directors import DirectorGeometry
from ancfdae.monitors.energy import EnergyMonitor
from ancfdae.monitors.sensors import PointSensor, Probe

__all__ = ["Monitor", "EnergyMonitor", "PointSensor", "Probe", "ConstraintMonitor", "DirectorGeometry"]
