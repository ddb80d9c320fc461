"""Separate shear factors k2 != k3 and the torsion factor of SQ3D/SQ2D sections (chapter Eq. 42).

The section of Nachbagauer et al. (2013): rectangle 0.2 (eta) x 0.4 (zeta), k1 = 0.5768 (torsion),
k2 = 0.8331, k3 = 0.7961. Reference values are independent closed forms, not the paper's tables (which
were not available): the small-load cantilever under tip forces along eta and zeta,
``P L^3 / (3 E I) + P L / (k G A)`` -- exact for the Timoshenko beam that the structural formulation
reduces to at small loads -- which separates k2 and k3; a tip torque, ``T L / (G J k1)``; and the
2013 tip-moment example, a dead moment bending the cantilever into a circle of radius EI/M about either
bending axis (exact in the structural formulation; independent of the shear factors, so it checks that
the example runs with k2 != k3 through the public API and that I2/I3 are not swapped).
"""
import importlib.util
from dataclasses import dataclass

import numpy as np
import pytest

from ancfdae import CircularSection, Material, PointForce, PointMoment, RectangularSection, Section, solve_static
from ancfdae.models import SQ2D, SQ3D, Beam

K1, K2, K3 = 0.5768, 0.8331, 0.7961
SECTION = RectangularSection(0.2, 0.4, shear_factors=(K2, K3), torsion_factor=K1)


@pytest.fixture
def mat():
    return Material(E=2.07e11, nu=0.3, rho=7800.0)


def _cantilever(element, L, load, n=4):
    beam = Beam(element, n, L, supports={0: "clamp"}, loads=[load])
    res = solve_static(beam, 1)
    assert res.success
    return beam, res


@pytest.mark.parametrize("kernel", ["numpy", pytest.param("numba", marks=pytest.mark.skipif(
    importlib.util.find_spec("numba") is None, reason="numba not installed"))])
def test_tip_forces_separate_k2_and_k3(mat, kernel):
    """Catches k2 and k3 swapped or one factor used for both (the shear part is ~13 % of the deflection)."""
    L, P = 1.0, 1e3
    E, G, A = mat.E, mat.G, SECTION.A
    wy = P * L**3 / (3 * E * SECTION.I3) + P * L / (K2 * G * A)
    wz = P * L**3 / (3 * E * SECTION.I2) + P * L / (K3 * G * A)
    beam, res = _cantilever(SQ3D(mat, SECTION, kernel=kernel), L, PointForce((0, P, 0), node=-1))
    assert beam.position(res.q, L)[1] == pytest.approx(wy, rel=1e-6)
    beam, res = _cantilever(SQ3D(mat, SECTION, kernel=kernel), L, PointForce((0, 0, P), node=-1))
    assert beam.position(res.q, L)[2] == pytest.approx(wz, rel=1e-6)
    # the factors matter at this tolerance: swapping them moves the deflection by far more than 1e-6
    assert abs(P * L / G / A * (1 / K2 - 1 / K3)) > 1e-3 * wy


def test_tip_torque_uses_the_torsion_factor(mat):
    """Catches the torsion factor ignored (Saint-Venant 0.5488 would be used) or applied to J twice."""
    L, T = 1.0, 1e3
    beam, res = _cantilever(SQ3D(mat, SECTION), L, PointMoment((T, 0, 0), node=-1))
    a2 = beam.nodal(res.q)[-1][3:6]
    assert np.arctan2(a2[2], a2[1]) == pytest.approx(T * L / (mat.G * SECTION.J * K1), rel=1e-6)


@pytest.mark.parametrize("axis", [1, 2])
def test_2013_tip_moment_bends_into_a_circle(mat, axis):
    """Large dead tip moments about e_y and e_z (tip rotation pi/2): circle of radius EI/M, tip at (R, R)."""
    L = 2.0
    EI = mat.E * (SECTION.I2 if axis == 1 else SECTION.I3)
    M = 0.5 * np.pi * EI / L
    moment = np.zeros(3)
    moment[axis] = -M if axis == 1 else M          # both bend the tip towards +z (axis 1) or +y (axis 2)
    beam = Beam(SQ3D(mat, SECTION), 16, L, supports={0: "clamp"}, loads=[PointMoment(moment, node=-1)])
    res = solve_static(beam, 8)
    assert res.success
    R = EI / M
    tip = beam.position(res.q, L)
    side = 2 if axis == 1 else 1
    # quadratic elements on 16 segments of a quarter circle: position error ~ 1e-6 of R
    assert tip[0] == pytest.approx(R, rel=1e-4) and tip[side] == pytest.approx(R, rel=1e-4)
    assert abs(tip[3 - side]) < 1e-10


def test_sq2d_uses_k2(mat):
    """The planar element's transverse shear is along eta: k2, not k3."""
    L, P = 1.0, 1e3
    beam, res = _cantilever(SQ2D(mat, SECTION), L, PointForce((0, P), node=-1))
    w = P * L**3 / (3 * mat.E * SECTION.I3) + P * L / (K2 * mat.G * SECTION.A)
    assert beam.position(res.q, L)[1] == pytest.approx(w, rel=1e-6)


@pytest.mark.parametrize("formulation", ["continuum", "continuum-locking"])
def test_continuum_shear_uses_k2_and_k3(mat, formulation):
    """Catches the continuum law's gamma_12 / gamma_13 factors swapped: compare with the swapped section."""
    L, P = 1.0, 1e3
    swapped = RectangularSection(0.2, 0.4, shear_factors=(K3, K2))
    tips = {}
    for name, sec in (("ok", SECTION), ("swapped", swapped)):
        for d in (1, 2):
            load = np.zeros(3)
            load[d] = P
            beam, res = _cantilever(SQ3D(mat, sec, formulation), L, PointForce(load, node=-1), n=8)
            tips[name, d] = beam.position(res.q, L)[d]
    for d, k in ((1, K2), (2, K3)):
        I = SECTION.I3 if d == 1 else SECTION.I2
        # shear compliance difference between the two sections, from the closed form
        expect = P * L / (mat.G * SECTION.A) * (1 / k - 1 / (K3 if k == K2 else K2))
        assert tips["ok", d] - tips["swapped", d] == pytest.approx(expect, rel=1e-3)
        if formulation == "continuum":
            # with the Poisson remedy of Eq. 108 the small-load continuum cantilever is Timoshenko's
            # (without it, Poisson locking makes it ~25 % stiffer, hence only the difference above)
            assert tips["ok", d] == pytest.approx(P * L**3 / (3 * mat.E * I) + P * L / (k * mat.G * SECTION.A),
                                                  rel=1e-6)


@pytest.mark.parametrize("formulation", ["continuum", "continuum-locking"])
def test_continuum_torsional_stiffness_is_shear_of_a_plane_section(mat, formulation):
    """Continuum SQ3D twists with G (k2 I2 + k3 I3) (k_s G J_polar), 28 % above Saint-Venant on 0.1 x 0.06.

    The clamp (cross-section slopes fixed) stiffens a boundary layer: the twist of a 1 m beam is 1.4 %
    short of the uniform-twist value, 0.1 % at 10 m. The rigidity is therefore measured from the twist
    difference of a 2 m and a 4 m cantilever, which that end effect cancels from.
    """
    def rigidity(sec):
        T, phi = 10.0, {}
        for n, L in ((8, 2.0), (16, 4.0)):
            beam, res = _cantilever(SQ3D(mat, sec, formulation), L, PointMoment((T, 0, 0), node=-1), n=n)
            a2 = beam.nodal(res.q)[-1][3:6]
            phi[L] = np.arctan2(a2[2], a2[1])
        return T * 2.0 / (phi[4.0] - phi[2.0])

    sec = RectangularSection(0.1, 0.06)
    GJ = rigidity(sec)
    assert GJ == pytest.approx(mat.G * sec.k_s(mat) * sec.J, rel=1e-5)
    assert GJ / (mat.G * sec.J * sec.k_t) == pytest.approx(1.282, abs=2e-3)
    # k2 pairs with I2 = int zeta^2 (gamma_12 = -zeta phi'), k3 with I3; the torsion factor does not enter
    sec = RectangularSection(0.1, 0.06, shear_factors=(0.9, 0.6), torsion_factor=0.3)
    assert rigidity(sec) == pytest.approx(mat.G * (0.9 * sec.I2 + 0.6 * sec.I3), rel=1e-5)


def test_shear_factor_input_is_checked(mat):
    with pytest.raises(ValueError, match="shear_factors"):
        RectangularSection(0.1, shear_factors=(0.8,))
    with pytest.raises(ValueError, match=r"shear_factors\[1\]"):
        RectangularSection(0.1, shear_factors=(0.8, -1.0))
    with pytest.raises(ValueError, match="not both"):
        RectangularSection(0.1, shear_factor=0.8, shear_factors=(0.8, 0.7))
    with pytest.raises(ValueError, match="shear_factors"):
        CircularSection(0.1, shear_factors="ab")
    with pytest.raises(ValueError, match="shear_factors_of"):
        SECTION.k_s(mat)
    assert SECTION.shear_factors_of(mat) == (K2, K3)
    assert RectangularSection(0.1, shear_factors=(0.7, 0.7)).k_s(mat) == 0.7
    assert RectangularSection(0.1).shear_factors_of(mat) == (RectangularSection(0.1).k_s(mat),) * 2


@dataclass(frozen=True)
class _Tube(Section):
    """A thin-walled tube of mean diameter d and wall t: a user's own shape on the Section base."""

    d: float
    t: float
    shear_factor: float | None = None
    torsion_factor: float | None = None
    shear_factors: tuple | None = None

    def _check_dimensions(self):
        object.__setattr__(self, "d", float(self.d))

    A = property(lambda self: np.pi * self.d * self.t)
    I2 = I3 = property(lambda self: np.pi * self.d**3 * self.t / 8)
    I4 = property(lambda self: 3 * np.pi * self.d**5 * self.t / 128)

    def _default_shear_factor(self, nu):
        return 0.5

    def _default_torsion_factor(self):
        return 1.0


def test_a_new_shape_gets_the_factor_rules_of_every_section(mat):
    """Catches a shape that skips the shared checks or defaults (each shape would re-implement them), and
    a shape that forgets a moment (it cannot be made, instead of failing inside an element)."""
    tube = _Tube(0.1, 0.002)
    assert tube.J == 2 * tube.I2 and tube.k_t == 1.0 and tube.shear_factors_of(mat) == (0.5, 0.5)
    assert _Tube(0.1, 0.002, shear_factors=(0.6, 0.4), torsion_factor=0.9).shear_factors_of(mat) == (0.6, 0.4)
    with pytest.raises(ValueError, match="not both"):
        _Tube(0.1, 0.002, shear_factor=0.5, shear_factors=(0.6, 0.4))
    with pytest.raises(ValueError, match="`torsion_factor` must be a positive"):
        _Tube(0.1, 0.002, torsion_factor=0.0)

    @dataclass(frozen=True)
    class NoI4(Section):
        shear_factor: float | None = None
        torsion_factor: float | None = None
        shear_factors: tuple | None = None
        A = I2 = I3 = property(lambda self: 1.0)
        _check_dimensions = _default_torsion_factor = lambda self: None
        _default_shear_factor = lambda self, nu: 1.0

    with pytest.raises(TypeError, match="I4"):
        NoI4()
