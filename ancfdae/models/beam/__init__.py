"""The beam: a mesh of elements with supports and loads, assembled into a Model."""
from .beam import Beam

__all__ = ["Beam"]
