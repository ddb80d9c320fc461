"""Cable3D and BE3D: the compiled (numba) kernels equal the NumPy reference; their blocks match finite differences.

Equality is checked to 1e-12 relative, each output normalised by its own largest entry over the states
(energy, forces, tangent, inertia force, and each inertia derivative block K, D, M separately, so that an
error confined to one block, e.g. a factor 1.1 on the rotary-inertia derivative, cannot hide behind a larger
block). BE3D uses I2 != I3 and random nodal directors, so every term of the curvature and spin formulas is
active; the states are random perturbations of growing size, including the (force-free) reference state.
"""
import numpy as np
import pytest

from ancfdae import Material, RectangularSection
from ancfdae.models import BE3D, Beam, Cable3D
from support.numerics import fd_gradient, rel_err

FLAT = RectangularSection(0.1, 0.05)    # I3 = 4 I2
STEEL = Material(2.07e11, 0.3, 7800.0)
SCALES = (0.0, 0.01, 0.1, 0.3)


def _beam(kind, n_el=4, seed=0):
    """A cantilever of ``kind`` on a skew axis; BE3D gets random nodal directors (not along the axis)."""
    el = Cable3D(STEEL, RectangularSection(0.1)) if kind == "Cable3D" else BE3D(STEEL, FLAT)
    beam = Beam(el, n_el, 2.0, supports={0: "clamp"}, direction=(0.6, 0.8, 0.0))
    if kind == "BE3D":
        rng = np.random.default_rng(seed + 100)
        D = beam.geom["directors"]
        beam = beam.bind({"directors": D + 0.4 * rng.standard_normal(D.shape)})
    return el, beam


def _states(beam, seed=0):
    rng = np.random.default_rng(seed)
    q0 = beam.initial_state()[0]
    shape = beam.edofs.shape
    for s in SCALES:
        yield (beam.expand(q0 + s * rng.standard_normal(beam.n_dof))[beam.edofs],
               rng.standard_normal(shape), rng.standard_normal(shape))


def _both(el, fun):
    """``fun()`` with the compiled kernel, then with the NumPy reference."""
    el.kernel = "numba"
    out1 = fun()
    el.kernel = "numpy"
    out0 = fun()
    el.kernel = "numba"
    return out1, out0


def _assert_equal_by_block(pairs, names):
    """max|compiled - reference| <= 1e-12 max|reference|, per named output over all states."""
    for i, name in enumerate(names):
        got = np.array([p[0][i] for p in pairs])
        ref = np.array([p[1][i] for p in pairs])
        scale = np.abs(ref).max()
        assert scale > 0, name
        assert np.abs(got - ref).max() <= 1e-12 * scale, (name, np.abs(got - ref).max() / scale)


@pytest.mark.parametrize("kind", ["Cable3D", "BE3D"])
def test_compiled_forces_tangent_energy_equal_reference(kind):
    """Catches any formula or index slip of the compiled elastic kernels (and a stale residual-only path)."""
    el, beam = _beam(kind)
    assert el.kernel == "auto" and el.kernel_in_use == "numba"
    g = beam.geom
    pairs = []
    for qe, _, _ in _states(beam):
        pairs.append(_both(el, lambda: (el.strain_energy(g, qe), *el.internal_forces(g, qe, True))))
        f_only, none = el.internal_forces(g, qe, False)
        assert none is None and np.array_equal(f_only, pairs[-1][0][1])
    _assert_equal_by_block(pairs, ["energy", "forces", "tangent"])


def test_compiled_be3d_inertia_equals_reference_block_by_block():
    """Rotary inertia force, K = df/dq, D = df/dv, M = df/da and the kinetic energy, each to 1e-12 of itself."""
    el, beam = _beam("BE3D")
    g = beam.geom
    pairs = []
    for qe, ve, ae in _states(beam, seed=1):
        ve, ae = 5.0 * ve, 50.0 * ae
        pairs.append(_both(el, lambda: (*el.inertia(g, qe, ve, ae, True), el.kinetic_energy_extra(g, qe, ve))))
        f_only = el.inertia(g, qe, ve, ae, False)
        assert f_only[1:] == (None, None, None) and np.array_equal(f_only[0], pairs[-1][0][0])
    _assert_equal_by_block(pairs, ["force", "K", "D", "M", "kinetic energy"])


def test_compiled_be3d_reads_the_directors_it_is_given():
    """Directors are an input, not cached state: changing them changes the compiled result like the reference's."""
    el, beam = _beam("BE3D")
    qe, ve, ae = next(_states(beam, seed=2))
    g = beam.geom
    before = el.internal_forces(g, qe)[0], el.inertia(g, qe, ve, ae)[0]
    g["directors"] = g["directors"] + np.random.default_rng(3).standard_normal(g["directors"].shape) * 0.2
    pairs = [_both(el, lambda: (el.internal_forces(g, qe)[0], el.inertia(g, qe, ve, ae)[0]))]
    _assert_equal_by_block(pairs, ["forces", "inertia force"])
    assert rel_err(before[1], pairs[0][0][1]) > 1e-3


@pytest.mark.parametrize("kind", ["Cable3D", "BE3D"])
def test_compiled_forces_and_tangent_match_finite_differences(kind):
    """Forces = dU/dq and tangent = df/dq of the compiled kernel itself (not only equal to the reference)."""
    el, beam = _beam(kind, n_el=2)
    g = beam.geom
    *_, (qe, _, _) = _states(beam, seed=4)
    f, K = el.internal_forces(g, qe)
    x0 = qe.ravel()
    U = lambda x: el.strain_energy(g, x.reshape(qe.shape)).sum()
    F = lambda x: el.internal_forces(g, x.reshape(qe.shape), False)[0].ravel()
    assert rel_err(f.ravel(), fd_gradient(U, x0, h=1e-6)) < 1e-6
    Kfd = fd_gradient(F, x0, h=1e-7)
    Kfull = np.zeros_like(Kfd)
    n = qe.shape[1]
    for e in range(qe.shape[0]):
        Kfull[e * n:(e + 1) * n, e * n:(e + 1) * n] = K[e]
    assert rel_err(Kfull, Kfd) < 1e-6


def test_compiled_be3d_inertia_blocks_match_finite_differences():
    """K, D, M of the compiled rotary inertia against differences of its force, each block on its own scale."""
    el, beam = _beam("BE3D", n_el=2)
    g = beam.geom
    *_, (qe, ve, ae) = _states(beam, seed=5)
    f, Kq, Dv, Ma = el.inertia(g, qe, ve, ae)
    shape = qe.shape

    def blockdiag(B):
        n = shape[1]
        out = np.zeros((B.shape[0] * n, B.shape[0] * n))
        for e in range(B.shape[0]):
            out[e * n:(e + 1) * n, e * n:(e + 1) * n] = B[e]
        return out

    force = lambda x, y, z: el.inertia(g, x.reshape(shape), y.reshape(shape), z.reshape(shape), False)[0].ravel()
    q, v, a = qe.ravel(), ve.ravel(), ae.ravel()
    assert rel_err(blockdiag(Kq), fd_gradient(lambda x: force(x, v, a), q, h=1e-6)) < 1e-6
    # quadratic in v and linear in a: central differences with h = 1 are exact up to rounding
    assert rel_err(blockdiag(Dv), fd_gradient(lambda x: force(q, x, a), v, h=1.0)) < 1e-10
    assert rel_err(blockdiag(Ma), fd_gradient(lambda x: force(q, v, x), a, h=1.0)) < 1e-10
    T = lambda y: el.kinetic_energy_extra(g, qe, y.reshape(shape)).sum()
    assert T(v) == pytest.approx(0.5 * np.einsum("ei,eij,ej", ve, Ma, ve), rel=1e-13)


@pytest.mark.parametrize("kind", ["Cable3D", "BE3D"])
def test_beam_residual_and_jacobian_equal_across_kernels(kind):
    """The whole model with either kernel: same residual and Jacobian blocks (wrapper and assembly glue)."""
    el, beam = _beam(kind, n_el=3)
    rng = np.random.default_rng(7)
    q = beam.initial_state()[0] + 0.05 * rng.standard_normal(beam.n_dof)
    v, a = rng.standard_normal((2, beam.n_dof))
    (r1, J1), (r0, J0) = _both(el, lambda: (beam.residual(0.0, q, v, a), beam.jacobian(0.0, q, v, a)))
    assert rel_err(r1, r0) < 1e-12
    for blk in ("K", "D", "M"):
        B1, B0 = getattr(J1, blk).toarray(), getattr(J0, blk).toarray()
        if not B0.any():    # Cable3D: no velocity-dependent forces
            assert not B1.any(), blk
            continue
        assert rel_err(B1, B0) < 1e-12, blk


@pytest.mark.parametrize("cls", [Cable3D, BE3D])
def test_kernel_option_is_validated(cls):
    section = RectangularSection(0.1)
    with pytest.raises(ValueError, match="kernel"):
        cls(STEEL, section, kernel="fortran")
    el = cls(STEEL, section, kernel="numpy")
    assert el.kernel_in_use == "numpy" and "kernel='numpy'" in repr(el)


def test_compiled_be3d_moment_load_equals_reference_and_finite_differences():
    """The dead-moment force and its q-derivative: compiled == reference, and df/dq by differences."""
    el, beam = _beam("BE3D", n_el=3)
    g = beam.geom
    M = np.array([2e3, -1e3, 5e2])
    pairs = []
    for qe, _, _ in _states(beam, seed=8):
        for e, s in ((0, -1.0), (1, 0.37), (2, 1.0)):
            pairs.append(_both(el, lambda: el.moment_load(g, qe[e], s, M, e, True)))
            f_only, none = el.moment_load(g, qe[e], s, M, e, False)
            assert none is None and np.array_equal(f_only, pairs[-1][0][0])
    _assert_equal_by_block(pairs, ["force", "tangent"])
    qe = next(_states(beam, seed=9))[0][1] + 0.05
    _, K = el.moment_load(g, qe, 0.37, M, 1, True)
    assert rel_err(K, fd_gradient(lambda x: el.moment_load(g, x, 0.37, M, 1, False)[0], qe, h=1e-6)) < 1e-6


def test_compiled_be3d_mass_bilinear_equals_reference_block_by_block():
    """The energy-momentum method's ``B = 1/2 u^T M_rot(q) w``, dB/dq and d2B/dq2: compiled == reference, each
    to 1e-12 of itself, at every ``order`` (0, 1, 2 run different branches); ``B(q, v, v)`` is the kinetic energy.

    Catches an index slip in the compiled ``C = Ba^T G Ba`` or ``Hc`` (e.g. the director or the torsion rows
    swapped), a missing point or element, or a lower-order branch that differs. A formula error shared by both
    would pass here; the finite-difference test of the beam's forms (tests/integrators) holds that.
    """
    el, beam = _beam("BE3D")
    g = beam.geom
    pairs = []
    for qe, ue, we in _states(beam, seed=6):
        pairs.append(_both(el, lambda: el.mass_bilinear(g, qe, ue, we, 2)))
        for order in (0, 1):
            lower = _both(el, lambda: el.mass_bilinear(g, qe, ue, we, order))
            assert len(lower[0]) == len(lower[1]) == order + 1
            for got, ref in zip(lower[0], pairs[-1][0]):
                assert np.array_equal(got, ref)
        T = el.kinetic_energy_extra(g, qe, ue)
        assert rel_err(el.mass_bilinear(g, qe, ue, ue, 0)[0], T) < 1e-13
    _assert_equal_by_block(pairs, ["B", "dB/dq", "d2B/dq2"])
