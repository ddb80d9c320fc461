"""ANCF beam element models and the beam that assembles them into a Model."""
from ._element import Element
from .beam import Beam
from .be2d import BE2D
from .be3d import BE3D
from .cable3d import Cable3D
from .sq2d import SQ2D
from .sq3d import SQ3D

__all__ = ["Element", "Beam", "BE2D", "BE3D", "Cable3D", "SQ2D", "SQ3D"]
