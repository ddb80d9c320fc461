"""The thin (Bernoulli-Euler) ANCF beam elements of chapter Sect. 3: BE2D, Cable3D, BE3D, and BE3DSR (BE3D with transported interior frames)."""
from .be2d import BE2D
from .be3d import BE3D
from .be3dsr import BE3DSR
from .cable3d import Cable3D

__all__ = ["BE2D", "BE3D", "BE3DSR", "Cable3D"]
