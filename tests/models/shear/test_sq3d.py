"""SQ3D (chapter Sect. 4): B1 in plane, Chrono's single-element data, spatial statics, Poisson locking."""
import numpy as np
import pytest

from ancfdae import Material, PointForce, PointMoment, RectangularSection, solve_static
from ancfdae.models import SQ2D, SQ3D, Beam
from test_sq2d import REF_SQ, TABLE2_SQ2D


def test_b1_in_plane_gives_sq2d_numbers(steel, square):
    F = 3 * steel.E * square.I3 / 2.0**2
    for n in (2, 8):
        b3 = Beam(SQ3D(steel, square), n, 2.0, supports={0: "clamp"}, loads=[PointForce((0, F, 0), node=-1)])
        b2 = Beam(SQ2D(steel, square), n, 2.0, supports={0: "clamp"}, loads=[PointForce((0, F), node=-1)])
        r3, r2 = solve_static(b3), solve_static(b2)
        tip3, tip2 = b3.position(r3.q, 2.0), b2.position(r2.q, 2.0)
        assert np.abs(tip3[:2] - tip2).max() < 1e-12 and abs(tip3[2]) < 1e-14
        assert np.linalg.norm(tip3[:2] - [2.0, 0.0] - REF_SQ) == pytest.approx(TABLE2_SQ2D[n], rel=1e-3)
        assert r3.iterations == r2.iterations


# Independent reference: the data of Project Chrono's unit tests for its 3-node ANCF beam (continuum,
# full integration): one element, L = 1, square 0.1, rho 7850, E 210e9, nu 0.3, node C moved 1e-3 in z.
CHRONO_FORCE = np.array([  # -dU/de per node A, B, C and vector r, r_eta, r_zeta
    [7538.46153846154, 0, 1830101.54409251], [0, -969.230769230769, 0], [-457516.339869281, 0, -2067.26998491704],
    [-7538.46153846154, 0, 1830101.54409251], [0, -969.230769230769, 0], [457516.339869281, 0, -2067.26998491704],
    [0, 0, -3660203.08818502], [0, -1292.30769230769, 0], [0, 0, -2756.35997988939]]).ravel()


@pytest.mark.parametrize("formulation", ["continuum", "continuum-locking"])
def test_chrono_single_element_force_and_mass(formulation):
    mat, sec = Material(E=210e9, nu=0.3, rho=7850.0), RectangularSection(0.1)
    el = SQ3D(mat, sec, formulation, quadrature={"axial": 3})       # Chrono integrates fully
    beam = Beam(el, 1, 1.0)
    q = beam.q_ref[beam.edofs].copy()
    q[0, 2 * 9 + 2] += 1e-3                                          # node C, z
    f, _ = el.internal_forces(beam.geom, q, False)
    assert np.abs(-f[0] - CHRONO_FORCE).max() < 1e-9 * np.abs(CHRONO_FORCE).max()
    M = el.mass_matrix(beam.geom)[0]
    m = np.array([[2 / 15, -1 / 30, 1 / 15], [-1 / 30, 2 / 15, 1 / 15], [1 / 15, 1 / 15, 8 / 15]])
    expect = np.kron(m, np.kron(np.diag([sec.A, sec.I3, sec.I2]), np.eye(3))) * mat.rho * 1.0
    assert np.abs(M - expect).max() < 1e-14 * M.max()
    assert M[0, 0] == pytest.approx(10.4666667) and M[3, 3] == pytest.approx(0.00872222, rel=1e-6)


def _tip(beam, res):
    return beam.nodal(res.q)[-1]


def test_small_load_spatial_statics(steel):
    """Bending about both axes with shear, axial and torsion (B4 linear statics, structural)."""
    sec = RectangularSection(0.1, 0.06)                       # h along eta, b along zeta
    L, P, T = 2.0, 1e2, 1e2
    E, G, A, ks = steel.E, steel.G, sec.A, sec.k_s(steel)
    def solve(load):
        beam = Beam(SQ3D(steel, sec), 4, L, supports={0: "clamp"}, loads=[load])
        return beam, solve_static(beam, 1)
    beam, res = solve(PointForce((0, P, 0), node=-1))
    assert beam.position(res.q, L)[1] == pytest.approx(P * L**3 / (3 * E * sec.I3) + P * L / (ks * G * A), rel=1e-6)
    beam, res = solve(PointForce((0, 0, P), node=-1))
    assert beam.position(res.q, L)[2] == pytest.approx(P * L**3 / (3 * E * sec.I2) + P * L / (ks * G * A), rel=1e-6)
    beam, res = solve(PointForce((P, 0, 0), node=-1))
    assert beam.position(res.q, L)[0] - L == pytest.approx(P * L / (E * A), rel=1e-6)
    beam, res = solve(PointMoment((T, 0, 0), node=-1))
    a2 = _tip(beam, res)[3:6]
    assert np.arctan2(a2[2], a2[1]) == pytest.approx(T * L / (G * sec.J * sec.k_t), rel=1e-6)


def test_large_tip_moments_about_both_bending_axes(steel, square):
    """A dead moment bends the beam into a circle: tip rotation M L / EI (Sect. 2.2, Eq. 7 frame)."""
    L, EI = 2.0, steel.E * square.I2
    M = 0.5 * EI / L
    beam = Beam(SQ3D(steel, square), 8, L, supports={0: "clamp"}, loads=[PointMoment((0, -M, 0), node=-1)])
    a3 = _tip(beam, solve_static(beam, 5))[6:9]               # x_zeta turns about -e_y
    assert np.arctan2(-a3[0], a3[2]) == pytest.approx(M * L / EI, rel=1e-6)


@pytest.mark.parametrize("formulation, ratio", [("continuum", 1.0),
                                                ("continuum-locking", 0.7 / (1.3 * 0.4)), ("structural", 1.0)])
def test_poisson_locking_in_pure_bending(steel, square, formulation, ratio):
    """One element bent to an arc: EI phi^2/(2L) with the remedy of Eq. 108, about 1.35 x without."""
    el = SQ3D(steel, square, formulation)
    beam = Beam(el, 1, 1.0)
    phi = 1e-3
    Q = beam.nodal(beam.initial_state()[0]).copy()
    for node, s in ((0, 0.0), (1, 0.5), (2, 1.0)):            # global nodes along the axis
        th = (s - 0.5) * phi
        Q[node, :6] = [0.5 + np.sin(th) / phi, (1 - np.cos(th)) / phi, 0, -np.sin(th), np.cos(th), 0]
    U = el.strain_energy(beam.geom, Q.reshape(-1)[beam.edofs])[0]
    assert U / (steel.E * square.I3 * phi**2 / 2) == pytest.approx(ratio, rel=1e-4)
