"""Interchangeable time integrators; each consumes only the Model contract.

Fixed step: :class:`LobattoIIIA` (2 or 3 stages), :class:`Newmark`, :class:`HHTAlpha`,
:class:`GeneralizedAlpha`, :class:`EnergyMomentum` (discrete-gradient midpoint rule: energy and
momenta kept exactly, constant-mass models); variable step: :class:`IDA` (SUNDIALS, scikit-sundae imported lazily).
Each is a stepper of the :class:`~ancfdae.integrators.protocol.Integrator` protocol, run by the
one driver (:func:`ancfdae.integrators.driver.integrate`, behind :func:`ancfdae.simulate` and
``Integrator.run``).
"""
from ancfdae.integrators._base import FixedStepIntegrator
from ancfdae.integrators._newton import NewtonOptions, NewtonOutcome, NewtonSolver, NewtonStats
from ancfdae.integrators.driver import integrate
from ancfdae.integrators.energy_momentum import EnergyMomentum
from ancfdae.integrators.ida import IDA
from ancfdae.integrators.protocol import Integrator, Quadrature, StepOutcome
from ancfdae.integrators.lobatto import LOBATTO_IIIA_2, LOBATTO_IIIA_3, ButcherTableau, LobattoIIIA
from ancfdae.integrators.newmark import GeneralizedAlpha, HHTAlpha, Newmark

__all__ = ["NewtonOptions", "NewtonOutcome", "NewtonSolver", "NewtonStats", "FixedStepIntegrator",
           "LobattoIIIA", "ButcherTableau", "LOBATTO_IIIA_2", "LOBATTO_IIIA_3", "Newmark", "HHTAlpha",
           "GeneralizedAlpha", "EnergyMomentum", "IDA", "Integrator", "StepOutcome", "Quadrature", "integrate"]
