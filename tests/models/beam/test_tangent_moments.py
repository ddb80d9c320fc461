"""Compiled point moments of BE2D and Cable3D (one pass over precomputed slope operators) equal the element's
NumPy ``moment_load``, force and derivative; and their derivative is the force's (finite differences).

Catches: a wrong slope operator (element length or load point mixed up between moments), a sign or
transposition error in ``[M]_x`` or in ``b a^T``, a 2D moment read from the wrong component, a
fixed coordinate leaking into the free vector or the CSR data, the time function not applied (or a
moment with scale zero added), and a subclass with its own ``moment_load`` bypassed by the compiled pass.
"""
import numpy as np
import pytest

from ancfdae import Material, PointForce, PointMoment, RectangularSection
from ancfdae.models import BE2D, Beam, Cable3D
from support.numerics import fd_gradient, rel_err

pytest.importorskip("numba")

MAT, SEC = Material(E=2.1e11, nu=0.3, rho=7850.0), RectangularSection(0.02)


def _loads(name):
    """Moments at the clamped node (its fixed coordinates must drop), inside an element, at the tip, one
    scaled by sin(t), one switched off by its time function."""
    if name == "BE2D":
        vecs = (1.5, -2.0, 3.0, 1.0)
    else:
        vecs = ((0.0, 1.0, 0.2), (-2.0, 0.5, 1.0), (1.0, 2.0, 3.0), (1.0, 1.0, 1.0))
    return [PointMoment(vecs[0], node=0), PointMoment(vecs[1], s=0.37, time=np.sin),
            PointMoment(vecs[2], node=-1), PointMoment(vecs[3], s=0.61, time=lambda t: 0.0),
            PointForce((0.0, -5.0) if name == "BE2D" else (0.0, -5.0, 1.0), node=-1)]


def _beam(name, cls=None, loads=None):
    cls = cls or {"BE2D": BE2D, "Cable3D": Cable3D}[name]
    return Beam(cls(MAT, SEC, kernel="numba"), n_elements=4, length=1.0, supports={0: "clamp"},
                loads=_loads(name) if loads is None else loads)


def _state(beam, seed=0):
    rng = np.random.default_rng(seed)
    return beam.initial_state()[0] + 0.05 * rng.standard_normal(beam.n_dof)


@pytest.mark.parametrize("name", ["BE2D", "Cable3D"])
def test_compiled_moments_equal_numpy_reference(name):
    beam = _beam(name)
    assert beam._load_set.stacked is not None
    qf = beam.expand(_state(beam))
    f1, k1 = beam._load_set.nonconservative(0.7, qf, beam.geom, True)
    f1_only, none = beam._load_set.nonconservative(0.7, qf, beam.geom, False)
    assert none is None and np.array_equal(f1, f1_only)       # the force does not depend on `tangent`
    beam.element.kernel = "numpy"                               # the per-moment moment_load path
    f0, k0 = beam._load_set.nonconservative(0.7, qf, beam.geom, True)
    assert rel_err(f1, f0) < 1e-14 and rel_err(k1, k0) < 1e-14
    assert np.abs(f0).max() > 0 and np.abs(k0).max() > 0


@pytest.mark.parametrize("name", ["BE2D", "Cable3D"])
def test_compiled_moment_derivative_is_the_force_derivative(name):
    beam = _beam(name)
    q = _state(beam, 1)
    t = 0.7
    f, K = beam.nonconservative_force(t, q, tangent=True)
    K_fd = fd_gradient(lambda x: beam.nonconservative_force(t, x, tangent=False)[0], q)
    assert np.abs(K.toarray()).max() > 0
    assert rel_err(K.toarray(), K_fd) < 1e-7


@pytest.mark.parametrize("name", ["BE2D", "Cable3D"])
def test_time_functions_scale_the_compiled_moments(name):
    beam = _beam(name)
    qf = beam.expand(_state(beam, 2))
    f_a, _ = beam._load_set.nonconservative(0.0, qf, beam.geom, False)     # sin(0) = 0: only two moments act
    f_b, _ = beam._load_set.nonconservative(np.pi / 2, qf, beam.geom, False)
    one = Beam(beam.element, n_elements=4, length=1.0, supports={0: "clamp"}, loads=[_loads(name)[1]])
    f_one, _ = one._load_set.nonconservative(np.pi / 2, qf, one.geom, False)
    assert rel_err(f_b - f_a, f_one) < 1e-12


def test_subclass_with_its_own_moment_takes_the_reference_path():
    class Doubled(BE2D):
        def moment_load(self, geom, q, s, moment, element, tangent=True):
            f, K = super().moment_load(geom, q, s, moment, element, tangent)
            return 2.0 * f, (None if K is None else 2.0 * K)

    moments = _loads("BE2D")[:4]
    beam, ref = _beam("BE2D", Doubled, moments), _beam("BE2D", loads=moments)
    assert beam._load_set.stacked is None
    qf = beam.expand(_state(beam))
    f2, _ = beam._load_set.nonconservative(0.7, qf, beam.geom, False)
    f1, _ = ref._load_set.nonconservative(0.7, qf, ref.geom, False)
    assert rel_err(f2, 2.0 * f1) < 1e-14
