"""SQ2D/SQ3D inertia on a rectangular section (I2 != I3), against rigid-body mechanics.

Every other dynamic SQ test uses a square section, on which the cross-section inertia rows
``rho I2`` and ``rho I3`` of the mass matrix (chapter Eq. 27) are interchangeable: these tests are
the ones that fail when they are swapped, or when the rotary inertia is dropped.
"""
import numpy as np
import pytest

from ancfdae import PointForce, RectangularSection, simulate
from ancfdae.models import SQ2D, SQ3D, Beam

SECTION = RectangularSection(0.4, 0.2)   # h = 0.4 along e_y (eta), b = 0.2 along e_z (zeta): I3 = 4 I2
L = 1.0                                   # short and thick, so that rotary inertia is 16 % of J_z


def rotary(section, axis):
    """Second moment entering the rotation about ``axis`` of the section: I3 about e_z, I2 about e_y."""
    return section.I3 if axis == "z" else section.I2


def rigid_inertia(material, axis):
    """Moment of inertia of the beam about its centre, ``rho (A L^3 / 12 + I L)`` (a rigid bar)."""
    return material.rho * (SECTION.A * L**3 / 12 + rotary(SECTION, axis) * L)


CASES = [(SQ2D, "z"), (SQ3D, "z"), (SQ3D, "y")]


@pytest.mark.parametrize("cls, axis", CASES)
def test_rigid_rotation_kinetic_energy(steel, cls, axis):
    # A rigid rotation lies in the span of the ANCF coordinates (linear in positions and slopes), so
    # 1/2 v^T M v must equal 1/2 J w^2 exactly (to round-off).
    el = cls(steel, SECTION)
    beam = Beam(el, 3, L, start=-0.5 * L * np.eye(el.dim)[0])         # centre at the origin
    w = np.zeros(3)
    w[2 if axis == "z" else 1] = 0.7
    Q = beam.nodal(beam.initial_state()[0]).reshape(beam.n_nodes, -1, el.dim)   # (node, vector, dim)
    Q3 = np.zeros(Q.shape[:2] + (3,))
    Q3[..., :el.dim] = Q
    V = np.cross(w, Q3)[..., :el.dim]                 # every node vector (position, slopes) turns with w
    v = V.reshape(-1)[beam.free]
    T = beam.energy(0.0, beam.initial_state()[0], v).kinetic
    assert T == pytest.approx(0.5 * rigid_inertia(steel, axis) * 0.7**2, rel=1e-12)


@pytest.mark.parametrize("cls, axis", CASES)
def test_free_beam_under_a_couple_turns_like_a_rigid_body(steel, cls, axis):
    # A free, stiff beam under two opposite end forces (a couple M = F L) turns by M t^2 / (2 J).
    # Swapped rho I2 / rho I3 rows make J 10-12 % wrong here; the flexible beam's own deviation from
    # the rigid body is below 1e-4 (measured 4.2e-5 about e_z, 8.3e-5 about e_y).
    el = cls(steel, SECTION)
    M, t_end = 1.2e4, 0.01
    force = np.zeros(el.dim)
    force[1 if axis == "z" else 2] = M / L
    beam = Beam(el, 2, L, loads=[PointForce(force, node=-1), PointForce(-force, node=0)])
    res = simulate(beam, (0.0, t_end), "lobatto3", h=t_end / 10)
    assert res.status == "success", res.message
    chord = beam.position(res.q[-1], L) - beam.position(res.q[-1], 0.0)
    angle = np.arctan2(chord[1 if axis == "z" else 2], chord[0])
    expected = M * t_end**2 / (2 * rigid_inertia(steel, axis))
    assert abs(angle) == pytest.approx(expected, rel=3e-4)
