"""Bodies other than beams: rigid bodies in natural coordinates (a point and its directors).

They live in the same vector space as ANCF's nodal positions and slopes, have constant mass matrices and
keep every joint at most quadratic in the coordinates (see :mod:`ancfdae.attachment`).
"""
from .rigid import RigidBody

__all__ = ["RigidBody"]
