"""BE2D kernel option: the compiled (numba) kernel equals the NumPy reference; option validation."""
import numpy as np
import pytest

from ancfdae import Material, RectangularSection
from ancfdae.models import BE2D, Beam


def _states(formulation, kernel, n_el=5, seed=0):
    el = BE2D(Material(2.1e11, 0.3, 7800.0), RectangularSection(0.1), formulation=formulation, kernel=kernel)
    beam = Beam(el, n_el, 2.0, supports={0: "clamp"})
    rng = np.random.default_rng(seed)
    q0 = beam.initial_state()[0]
    return el, beam, [beam.expand(q0 + s * rng.standard_normal(beam.n_dof))[beam.edofs] for s in (0.0, 0.01, 0.1)]


@pytest.mark.parametrize("formulation", ["structural", "continuum"])
def test_numba_kernel_equals_numpy_kernel(formulation):
    el, beam, states = _states(formulation, "numba")
    assert el.kernel_in_use == "numba"
    pairs = []
    for qe in states:
        f1, K1 = el.internal_forces(beam.geom, qe, True)
        f1n, none = el.internal_forces(beam.geom, qe, False)
        el.kernel = "numpy"
        f0, K0 = el.internal_forces(beam.geom, qe, True)
        el.kernel = "numba"
        assert none is None and np.array_equal(f1, f1n)
        pairs.append((f1, K1, f0, K0))
    # relative to the largest entry over all the states: the reference state has f = 0, its entries are
    # round-off of the bending densities, which two correct summation orders need not share
    scale_f = max(np.abs(f0).max() for _, _, f0, _ in pairs)
    scale_K = max(np.abs(K0).max() for _, _, _, K0 in pairs)
    for f1, K1, f0, K0 in pairs:
        assert np.abs(f1 - f0).max() <= 1e-12 * scale_f
        assert np.abs(K1 - K0).max() <= 1e-12 * scale_K
    assert scale_f > 0


def test_auto_kernel_is_the_compiled_one_and_the_option_selects_once():
    # Catches "auto" falling back to NumPy (numba is a dependency: there is nothing to fall back from), and a
    # kernel object that is not rebuilt when the option changes on a built element.
    el = BE2D(Material(2.1e11, 0.3, 7800.0), RectangularSection(0.1))
    assert el.kernel == "auto" and el.kernel_in_use == "numba" and "kernel='auto'" in repr(el)
    compiled = el.kernels
    el.kernel = "numpy"
    assert el.kernel_in_use == "numpy" and el.kernels is not compiled and el.fused_kernel({}) is None


def test_unknown_kernel_is_rejected():
    with pytest.raises(ValueError, match="kernel"):
        BE2D(Material(2.1e11, 0.3, 7800.0), RectangularSection(0.1), kernel="fortran")


@pytest.mark.parametrize("kernel", ["numpy", "numba"])
def test_residual_stages_equal_per_stage_residuals(kernel):
    from ancfdae import Gravity, PointForce, PointMoment
    beam = Beam(BE2D(Material(2.1e11, 0.3, 7800.0), RectangularSection(0.1), kernel=kernel), 5, 2.0,
                supports={0: "clamp"}, loads=[PointForce((1e5, 2e5), s=1.3, time=lambda t: 1.0 + t),
                                              PointMoment(3e5, node=-1), Gravity((0.0, -9.81))])
    rng = np.random.default_rng(4)
    n = beam.n_dof
    ts = np.array([0.1, 0.7, 0.9])
    Q = beam.initial_state()[0][:, None] + 0.01 * rng.standard_normal((n, 3))
    V, A = rng.standard_normal((n, 3)), rng.standard_normal((n, 3))
    R = beam.residual_stages(ts, Q, V, A)
    R0 = np.column_stack([beam.residual(ts[i], Q[:, i], V[:, i], A[:, i]) for i in range(3)])
    assert R.shape == (n, 3)
    assert np.abs(R - R0).max() <= 1e-14 * np.abs(R0).max()


def test_hermite_per_distinct_length_equals_per_element():
    # Catches: a wrong gather of the per-length values (an element given another element's functions).
    from ancfdae.models.shapes import hermite
    rng = np.random.default_rng(5)
    L = rng.choice([0.01, 0.02, 0.3], size=300)
    s = np.linspace(-0.95, 0.95, 8)
    many = hermite(s, L)
    for e in (0, 1, 77, 299):
        one = hermite(s, L[e:e + 1])
        assert all(np.array_equal(many[k][e], one[k][0]) for k in range(3))


def test_compiled_beam_stores_no_hessians_and_the_reference_makes_them():
    # Catches: the per-element Hessians built with every mesh again (n_el x 2 n_pts x 64 numbers), or
    # the NumPy reference reading arrays that are no longer prepared.
    el, beam, states = _states("structural", "numba")
    el.internal_forces(beam.geom, states[1], True)
    assert "_reference" not in beam.geom and "d2" not in beam.geom
    el.kernel = "numpy"
    f, K = el.internal_forces(beam.geom, states[1], True)
    assert beam.geom["_reference"][2].shape == (beam.n_elements, 2 * beam.geom["w"].shape[1], 64)
    el.kernel = "numba"
    f1, K1 = el.internal_forces(beam.geom, states[1], True)
    assert np.abs(K1 - K).max() <= 1e-12 * np.abs(K).max()
