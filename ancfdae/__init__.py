"""ancfdae: absolute nodal coordinate formulation beam elements and time integrators.

The chapter cited throughout is Gerstmayr, Humer, Gruber, Nachbagauer, "The
Absolute Nodal Coordinate Formulation" (Sects. 2-5, Eqs. 1-115).
"""
from .loads import DistributedLoad, Gravity, PointForce, PointMoment, constant, hat, pulse, ramp
from .materials import CircularSection, Material, RectangularSection, cowper_shear_factor
from .problem import Energy, JacobianBlocks, Model
from .static import StaticResult, solve_static
from .simulate import METHODS, simulate
from .result import Result, ResultFileError
from .monitors import EnergyMonitor, PointSensor, Probe

__version__ = "0.1.0"

__all__ = [
    "Material", "RectangularSection", "CircularSection", "cowper_shear_factor",
    "PointForce", "PointMoment", "Gravity", "DistributedLoad", "constant", "ramp", "pulse", "hat",
    "Model", "JacobianBlocks", "Energy",
    "solve_static", "StaticResult",
    "simulate", "METHODS", "Result", "ResultFileError", "EnergyMonitor", "PointSensor", "Probe",
]
