"""Checks shared by SQ2D and SQ3D (chapter Sect. 4): derivatives, invariants, mass, moment loads, input."""
import numpy as np
import pytest

from ancfdae import CircularSection, RectangularSection
from ancfdae.models import SQ2D, SQ3D, Beam
from support.numerics import assert_forces_and_tangent_fd, fd_gradient, rel_err

FORMULATIONS = ["structural", "continuum", "continuum-locking"]


def rotation(dim, angle):
    """Rotation by ``angle`` about e_z (2D) or about the axis (1, 2, 3)/|.| (3D)."""
    if dim == 2:
        c, s = np.cos(angle), np.sin(angle)
        return np.array([[c, -s], [s, c]])
    k = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    Kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * Kx + (1 - np.cos(angle)) * Kx @ Kx


def deformed(beam, scale, seed):
    rng = np.random.default_rng(seed)
    return beam.q_ref[beam.edofs] + scale * rng.standard_normal(beam.edofs.shape)


@pytest.mark.parametrize("cls", [SQ2D, SQ3D])
@pytest.mark.parametrize("formulation", FORMULATIONS)
@pytest.mark.parametrize("nodes", [3, 2])
def test_forces_are_energy_gradient_and_tangent_is_exact(steel, cls, formulation, nodes):
    section = RectangularSection(0.1, 0.07) if nodes == 3 else CircularSection(0.08)
    el = cls(steel, section, formulation, nodes=nodes)
    beam = Beam(el, 2, 1.3, direction=np.ones(el.dim))          # oblique, to exercise the frames
    q = deformed(beam, 0.05, 1)
    assert_forces_and_tangent_fd(el, beam.geom, q)


@pytest.mark.parametrize("cls", [SQ2D, SQ3D])
@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_rigid_motion_has_zero_energy_and_force(steel, square, cls, formulation):
    el = cls(steel, square, formulation)
    beam = Beam(el, 3, 2.0, direction=np.ones(el.dim))
    n = beam.q_ref.size // el.dim
    R = rotation(el.dim, 1.1)                                   # a finite rotation
    moved = (beam.q_ref.reshape(n, el.dim) @ R.T).reshape(-1)
    moved[:: el.n_node_dof] += 0.7                              # translate all node positions in x
    q = moved[beam.edofs]
    f, _ = el.internal_forces(beam.geom, q, False)
    stiff = el.internal_forces(beam.geom, deformed(beam, 1e-3, 2), False)[0]
    assert np.abs(el.strain_energy(beam.geom, q)).max() < 1e-12 * steel.E
    assert np.abs(f).max() < 1e-9 * np.abs(stiff).max()


@pytest.mark.parametrize("cls", [SQ2D, SQ3D])
@pytest.mark.parametrize("nodes", [3, 2])
def test_mass_is_spd_with_total_mass_rho_A_L(steel, square, cls, nodes):
    el = cls(steel, square, nodes=nodes)
    beam = Beam(el, 4, 2.0, direction=np.ones(el.dim))
    M = beam.mass().toarray()
    assert np.allclose(M, M.T) and np.linalg.eigvalsh(M).min() > 0
    ex = np.zeros(beam.n_dof)
    ex[:: el.n_node_dof] = 1.0                                 # unit x-velocity of every position
    assert np.isclose(ex @ M @ ex, steel.rho * square.A * 2.0, rtol=1e-13)
    assert beam.q_ref.size == el.n_node_dof * (4 * (nodes - 1) + 1)   # Table 2 DOF counts


@pytest.mark.parametrize("cls", [SQ2D, SQ3D])
def test_moment_load_tangent_and_virtual_rotation(steel, square, cls):
    el = cls(steel, square)
    beam = Beam(el, 1, 1.0)
    q = deformed(beam, 0.1, 3)[0]
    M = np.array([0.3, -0.7, 1.1])
    f, dfdq = el.moment_load(beam.geom, q, 0.4, M, 0)
    assert rel_err(dfdq, fd_gradient(lambda x: el.moment_load(beam.geom, x, 0.4, M, 0, False)[0], q)) < 1e-7
    # A small rigid rotation of the element by t about e_z does the virtual work M_z t.
    t = 1e-7
    W = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])[:el.dim, :el.dim]
    dq = (q.reshape(-1, el.dim) @ W.T).reshape(-1)
    assert np.isclose(f @ dq, M[2], rtol=1e-12)


def test_per_instance_node_layout(steel, square):
    quad, lin = SQ3D(steel, square), SQ3D(steel, square, nodes=2)
    assert quad.n_nodes == 3 and lin.n_nodes == 2 and SQ3D.node_params == (-1.0, 1.0, 0.0)
    assert lin.n_edof == 18 and quad.n_edof == 27 and SQ2D(steel, square, nodes=2).n_edof == 8


@pytest.mark.parametrize("kwargs, match", [
    ({"formulation": "continuum-mechanics"}, "formulation"),
    ({"nodes": 4}, "nodes"),
    ({"quadrature": {"axal": 2}}, "quadrature"),
    ({"quadrature": {"shear": 0}}, "shear"),
    ({"quadrature": {"bending": ("radau", 2)}}, "bending"),
    ({"quadrature": {"cross_section": ("lobatto", 1)}}, "cross_section"),
    ({"formulation": "continuum", "quadrature": {"section": ("lobatto", 3)}}, "section"),
])
@pytest.mark.parametrize("cls", [SQ2D, SQ3D])
def test_bad_input_raises_clear_errors(steel, square, cls, kwargs, match):
    with pytest.raises(ValueError, match=match):
        cls(steel, square, **kwargs)


@pytest.mark.parametrize("cls", [SQ2D, SQ3D])
def test_bad_material_or_section(steel, square, cls):
    with pytest.raises(TypeError, match="material"):
        cls("steel", square)
    with pytest.raises(TypeError, match="section"):
        cls(steel, object())
    with pytest.raises(TypeError, match="section"):
        cls(steel, type("S", (), {"A": 1.0, "I2": 1.0, "I3": 1.0, "J": 1.0, "k_s": None, "k_t": 1.0})(),
            formulation="continuum")


def test_continuum_rejects_curved_reference(steel, square):
    nodes = np.array([[np.sin(t), 1 - np.cos(t)] for t in np.linspace(0, 1, 5)])
    with pytest.raises(ValueError, match="straight"):
        Beam(SQ2D(steel, square, "continuum"), nodes=nodes)
    Beam(SQ2D(steel, square), nodes=nodes)                     # the structural formulation takes it


def test_curved_reference_is_stress_free(steel, square):
    nodes = np.array([[np.sin(t), 1 - np.cos(t), 0.3 * t] for t in np.linspace(0, 1, 5)])
    el = SQ3D(steel, square)
    beam = Beam(el, nodes=nodes)
    f, _ = el.internal_forces(beam.geom, beam.q_ref[beam.edofs], False)
    assert np.abs(el.strain_energy(beam.geom, beam.q_ref[beam.edofs])).max() < 1e-20 * steel.E
    # round-off of forces of order E A (2e9 N here): a reference strain left in would give ~E A * 1e-3
    assert np.abs(f).max() < 1e-13 * steel.E * square.A
