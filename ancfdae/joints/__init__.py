"""Joints between bodies (and the ground) of an :class:`ancfdae.System`, planar and spatial as they apply.

A side is ``"ground"`` or ``(body, where)``: a beam is held at a node (``(beam, 3)``, negative from the end)
or at the axis point of arc length ``s`` (``(beam, 0.25)`` or ``(beam, {"s": 0.25})``), see
:meth:`ancfdae.models.Beam.attachment`. Every joint is at most quadratic in the coordinates
(:mod:`ancfdae.joints.rows`).

=============  =================================================================  ==========
joint          rows                                                               dimension
=============  =================================================================  ==========
Spherical      points coincide (planar: a pin)                                    2D, 3D
Revolute       points coincide, an axis of ``a`` normal to two vectors of ``b``   3D
Rigid          points coincide, frame vectors keep their initial relation (weld)  2D, 3D
Prismatic      a point stays on a line                                            2D, 3D
Distance       two points keep their distance                                     2D, 3D
Prescribed     a point follows ``p(t)``; planar: a slope follows an angle         2D, 3D
=============  =================================================================  ==========
"""
from ancfdae.joints.base import GROUND, Joint
from ancfdae.joints.frames import Revolute, Rigid
from ancfdae.joints.points import Distance, Prismatic, Spherical
from ancfdae.joints.prescribed import Prescribed

__all__ = ["Joint", "GROUND", "Spherical", "Revolute", "Rigid", "Prismatic", "Distance", "Prescribed"]
