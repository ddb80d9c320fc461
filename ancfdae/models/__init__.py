"""ANCF beam element models and the beam that assembles them into a Model."""
from .beam import Beam
from .element import Element
from .shear import SQ2D, SQ3D
from .thin import BE2D, BE3D, BE3DSR, Cable3D

__all__ = ["Element", "Beam", "BE2D", "BE3D", "BE3DSR", "Cable3D", "SQ2D", "SQ3D"]
