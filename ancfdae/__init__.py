"""ancfdae: absolute nodal coordinate formulation beam elements and time integrators.

The chapter cited throughout is Gerstmayr, Humer, Gruber, Nachbagauer, "The
Absolute Nodal Coordinate Formulation" (Sects. 2-5, Eqs. 1-115).

Submodules: :mod:`ancfdae.models` (elements and the beam), :mod:`ancfdae.bodies` (rigid bodies),
:mod:`ancfdae.integrators`,
:mod:`ancfdae.export` (ParaView), :mod:`ancfdae.plot` (matplotlib pictures and animations).
"""
import logging

from .loads import DistributedLoad, Gravity, PointForce, PointMoment, constant, hat, pulse, ramp
from .materials import CircularSection, Material, RectangularSection, Section, cowper_shear_factor
from .problem import Energy, JacobianBlocks, Model
from .static import StaticResult, solve_static
from .simulate import METHODS, simulate
from .result import Result, ResultFileError
from .monitors import ConstraintMonitor, DirectorGeometry, EnergyMonitor, PointSensor, Probe
from .system import System
from . import joints
from .bodies import RigidBody

__version__ = "0.1.0"

# The library reports through logging.getLogger("ancfdae") and prints nothing; by default its messages
# go nowhere until the application configures logging.
logging.getLogger("ancfdae").addHandler(logging.NullHandler())

__all__ = [
    "Material", "Section", "RectangularSection", "CircularSection", "cowper_shear_factor",
    "PointForce", "PointMoment", "Gravity", "DistributedLoad", "constant", "ramp", "pulse", "hat",
    "Model", "JacobianBlocks", "Energy",
    "solve_static", "StaticResult",
    "simulate", "METHODS", "Result", "ResultFileError", "EnergyMonitor", "PointSensor", "Probe",
    "DirectorGeometry", "System", "joints", "ConstraintMonitor", "RigidBody",
]
