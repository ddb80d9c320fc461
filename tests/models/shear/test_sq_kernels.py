"""SQ2D/SQ3D kernel option: the compiled (numba) kernels equal the NumPy reference; their tangent is exact.

Rectangular section with I2 != I3 and k2 != k3 so that a swapped index, a swapped
shear factor or a transposed block in the compiled code changes the numbers.
"""
import numpy as np
import pytest

from ancfdae import RectangularSection
from ancfdae.models import SQ2D, SQ3D, Beam
from support.numerics import assert_forces_and_tangent_fd, rel_err

pytest.importorskip("numba")

FORMULATIONS = ["structural", "continuum", "continuum-locking"]
SECTION = RectangularSection(0.1, 0.06, shear_factors=(0.83, 0.71))


def _beam_and_states(steel, cls, formulation, nodes, quadrature=None, n_states=3):
    el = cls(steel, SECTION, formulation, nodes=nodes, quadrature=quadrature, kernel="numpy")
    # Oblique axis: every frame component is non-trivial.
    beam = Beam(el, 3, 1.3, direction=np.arange(1, el.dim + 1, dtype=float))
    rng = np.random.default_rng(7)
    qs = [beam.q_ref[beam.edofs] + scale * rng.standard_normal(beam.edofs.shape)
          for scale in (1e-3, 0.05, 0.2)[:n_states]]
    return el, beam, qs


def _both(el, geom, q, tangent=True):
    out = []
    for kernel in ("numpy", "numba"):
        el.kernel = kernel
        f, K = el.internal_forces(geom, q, tangent)
        out.append((el.strain_energy(geom, q), f, K))
    return out


@pytest.mark.parametrize("cls", [SQ2D, SQ3D])
@pytest.mark.parametrize("formulation", FORMULATIONS)
@pytest.mark.parametrize("nodes", [3, 2])
def test_numba_kernel_equals_numpy_kernel(steel, cls, formulation, nodes):
    """Catches any compiled term that differs from the reference: energy, force, tangent, forces-only path."""
    el, beam, qs = _beam_and_states(steel, cls, formulation, nodes)
    for q in qs:
        (W0, f0, K0), (W1, f1, K1) = _both(el, beam.geom, q)
        assert el.kernel_in_use == "numba"
        assert rel_err(W1, W0) < 1e-12
        assert rel_err(f1, f0) < 1e-12
        assert rel_err(K1, K0) < 1e-12
        (_, f2, K2), (_, f3, K3) = _both(el, beam.geom, q, tangent=False)
        assert K2 is None and K3 is None and rel_err(f3, f0) < 1e-12


@pytest.mark.parametrize("cls", [SQ2D, SQ3D])
def test_numba_kernel_with_one_rule_for_all_terms(steel, cls):
    """All structural strains at the same points (frame and cross-section terms in one point group)."""
    quad = {"axial": 3, "shear": 3, "bending": 3, "cross_section": 3}
    el, beam, qs = _beam_and_states(steel, cls, "structural", 3, quadrature=quad, n_states=2)
    for q in qs:
        (W0, f0, K0), (W1, f1, K1) = _both(el, beam.geom, q)
        assert rel_err(W1, W0) < 1e-12 and rel_err(f1, f0) < 1e-12 and rel_err(K1, K0) < 1e-12
        (_, f2, _), (_, f3, _) = _both(el, beam.geom, q, tangent=False)     # the force-only pass (SQ3D: its own)
        assert rel_err(f3, f0) < 1e-12


@pytest.mark.parametrize("nodes", [3, 2])
def test_sq3d_cross_section_points_off_the_nodes(steel, nodes):
    """Cross-section terms at 2 Gauss points, the frame terms at 3: every shape function is nonzero at the
    cross-section-only points. Catches a compiled SQ3D scatter that assumes ``N = delta`` there (the default
    end-point rule) or that drops the derivative blocks of a frame point."""
    quad = {"axial": 3, "shear": 3, "bending": 3, "cross_section": 2}
    el, beam, qs = _beam_and_states(steel, SQ3D, "structural", nodes, quadrature=quad, n_states=2)
    for q in qs:
        (W0, f0, K0), (W1, f1, K1) = _both(el, beam.geom, q)
        assert rel_err(W1, W0) < 1e-12 and rel_err(f1, f0) < 1e-12 and rel_err(K1, K0) < 1e-12
        (_, f2, _), (_, f3, _) = _both(el, beam.geom, q, tangent=False)     # the force-only pass
        assert rel_err(f3, f0) < 1e-12


@pytest.mark.parametrize("cls", [SQ2D, SQ3D])
@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_numba_forces_are_energy_gradient_and_tangent_is_exact(steel, cls, formulation):
    """The compiled force against finite differences of the compiled energy, its tangent against FD of its force."""
    el, beam, qs = _beam_and_states(steel, cls, formulation, 3, n_states=2)
    el.kernel = "numba"
    q = qs[1]
    assert_forces_and_tangent_fd(el, beam.geom, q)


def test_kernel_option(steel):
    """Default is the compiled kernel; a bad name is a ValueError naming `kernel`."""
    assert SQ3D(steel, SECTION).kernel_in_use == "numba"
    assert SQ2D(steel, SECTION, kernel="numpy").kernel_in_use == "numpy"
    with pytest.raises(ValueError, match="kernel"):
        SQ3D(steel, SECTION, kernel="fortran")


@pytest.mark.parametrize("cls", [SQ2D, SQ3D])
@pytest.mark.parametrize("nodes", [3, 2])
def test_numba_moment_load_equals_numpy(steel, cls, nodes):
    """The compiled dead-moment load (force and derivative) against the NumPy reference, off-node point."""
    el, beam, qs = _beam_and_states(steel, cls, "structural", nodes)
    M = np.array([0.3, -0.7, 1.1])
    for q in qs:
        for s in (-1.0, 0.37):
            out = []
            for kernel in ("numpy", "numba"):
                el.kernel = kernel
                f, K = el.moment_load(beam.geom, q[1], s, M, 1)
                f2, K2 = el.moment_load(beam.geom, q[1], s, M, 1, tangent=False)
                assert K2 is None and np.array_equal(f, f2)
                out.append((f, K))
            (f0, K0), (f1, K1) = out
            assert rel_err(f1, f0) < 1e-12 and rel_err(K1, K0) < 1e-12


@pytest.mark.parametrize("dim", [2, 3])
def test_local_variables_in_chunks_equal_the_whole_mesh_product(dim):
    # The reference geometry's local variables are formed a chunk of elements at a time (no B for the
    # whole mesh); catches a chunk boundary that drops or repeats elements, or a different sum order.
    from ancfdae.models.shear.points import local_map, local_variables, rule, shapes
    lengths = np.random.default_rng(1).uniform(0.5, 1.5, 7)
    N, dN = shapes(3, rule("gauss", 3)[0], lengths)
    q = np.random.default_rng(2).standard_normal((7, 3 * dim * dim))
    whole = np.einsum("epvi,ei->epv", local_map(N, dN, dim), q)
    for chunk in (1, 3, 7, 100):
        assert np.array_equal(local_variables(N, dN, q, dim, chunk=chunk), whole)
