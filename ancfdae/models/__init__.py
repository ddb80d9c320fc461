"""ANCF beam element models and the beam that assembles them into a Model."""
from ._element import Element
from .beam import Beam
from .be2d import BE2D

__all__ = ["Element", "Beam", "BE2D"]
