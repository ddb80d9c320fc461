"""The shear- and cross-section-deformable ANCF beam elements of chapter Sect. 4: SQ2D, SQ3D."""
from .sq2d import SQ2D
from .sq3d import SQ3D

__all__ = ["SQ2D", "SQ3D"]
