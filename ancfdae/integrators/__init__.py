"""Interchangeable time integrators; each consumes only the Model contract.

Fixed step: :class:`LobattoIIIA` (:class:`Lobatto3`, :class:`Lobatto2`), :class:`Newmark`,
:class:`HHTAlpha`, :class:`GeneralizedAlpha`, :class:`EnergyMomentum` (discrete-gradient midpoint
rule: energy and momenta kept exactly, constant-mass models), :class:`EnergyCollocation` (HBVM(k, 2):
order 4 with the energy kept exactly, constant-mass models); variable step: :class:`IDA` (SUNDIALS,
scikit-sundae imported lazily). Each is a stepper run by the one driver (:func:`integrate`, behind
:func:`ancfdae.simulate` and :meth:`Integrator.run`). Subclass :class:`Integrator` (any stepper),
:class:`FixedStepIntegrator` (one ``_step_impl`` on the uniform grid) or :class:`NewtonStepper`
(and a Newton solve per step) for a method of your own.
"""
from ancfdae.integrators._checks import RunInterrupted
from ancfdae.integrators._newton_records import NewtonOptions
from ancfdae.integrators.driver import integrate
from ancfdae.integrators.energy_collocation import EnergyCollocation
from ancfdae.integrators.energy_momentum import EnergyMomentum
from ancfdae.integrators.fixed_step import FixedStepIntegrator
from ancfdae.integrators.ida import IDA
from ancfdae.integrators.integrator import Integrator
from ancfdae.integrators.lobatto import LOBATTO_IIIA_2, LOBATTO_IIIA_3, ButcherTableau, Lobatto2, Lobatto3, LobattoIIIA
from ancfdae.integrators.newmark import GeneralizedAlpha, HHTAlpha, Newmark
from ancfdae.integrators.newton_stepper import NewtonStepper
from ancfdae.integrators.protocol import Quadrature, StepOutcome

__all__ = ["Integrator", "FixedStepIntegrator", "NewtonStepper", "StepOutcome", "Quadrature", "NewtonOptions",
           "LobattoIIIA", "Lobatto3", "Lobatto2", "ButcherTableau", "LOBATTO_IIIA_2", "LOBATTO_IIIA_3", "Newmark",
           "HHTAlpha", "GeneralizedAlpha", "EnergyMomentum", "EnergyCollocation", "IDA", "integrate",
           "RunInterrupted"]
