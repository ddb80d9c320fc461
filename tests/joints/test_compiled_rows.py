"""The compiled constraint rows of a System against the NumPy reference (kernel="numpy"), value by value.

A System with ``kernel="auto"`` folds its rigid bodies' orthonormality rows and its joints' rows into one
compiled set (:mod:`ancfdae.joints.assembled_numba`); ``kernel="numpy"`` evaluates the bodies' rows body
by body and the joints' in NumPy. On the B5, B6 and B7 models at random states (off the constraints, so
every quadratic term counts) and at times inside the drives' ramps (``phi'`` and ``phi''`` non-zero) the two
must agree in ``g``, ``G``, ``G^T lam``, ``d(G^T lam)/dq``, ``(g_t, gamma)``, ``Z(v) + G_t``, the one-pass
``(g, G^T lam)``, the one-pass ``(g, G, g_t)`` of a GGL stage and the KKT matrix. Caught: a quadratic
entry dropped or halved in one kernel, a body's row folded with the wrong offset, sign or constant, a time
derivative taken from the wrong weight row, ``G_t v`` without its factor 2, rows reordered (labels and
values). Not caught here: a defect the two paths
share (a joint's wrong row): ``test_joint_derivatives.py`` checks the rows against finite differences.
The multipliers at output times (dense KKT solve for small systems) against the sparse solve.
"""
import numpy as np
import pytest
import scipy.sparse as sp

from ancfdae import System
from ancfdae.constrained import kkt_matrix
from ancfdae.joints.assembled import ConstraintSet
from ancfdae.joints.assembled_numba import CompiledConstraintSet
from ancfdae.joints.rows import Rows, TimedTerm
from ancfdae.studies import _multibody_models as mm

BUILD = {"b5": lambda: mm.spinup("BE2D", 3), "b6": lambda: mm.slider_crank("BE2D", 3),
         "b7": lambda: mm.spatial_pendulum("Cable3D", 2)}
TIMES = {"b5": 3.7, "b6": 0.137, "b7": 0.4}   # inside B5's spin-up and B6's crank ramp


def _pair(case):
    s = BUILD[case]().system
    return System(s.bodies, s.joints, kernel="numpy"), System(s.bodies, s.joints, kernel="auto")


def _close(x, y, scale=1.0):
    x = x.toarray() if sp.issparse(x) else np.asarray(x)
    y = y.toarray() if sp.issparse(y) else np.asarray(y)
    assert x.shape == y.shape
    tol = 1e-13 * max(scale, float(np.max(np.abs(x), initial=0.0)))
    assert np.max(np.abs(x - y), initial=0.0) <= tol


@pytest.mark.parametrize("case", ["b5", "b6", "b7"])
def test_compiled_rows_equal_reference(case):
    ref, fast = _pair(case)
    assert type(fast._joint_set) is CompiledConstraintSet and not fast._body_rows   # every row folded
    assert ref.constraint_labels == fast.constraint_labels
    rng = np.random.default_rng(7)
    q0, _ = ref.initial_state()
    t = TIMES[case]
    for _ in range(3):
        q = q0 + 0.05 * rng.standard_normal(q0.size)
        v, lam = rng.standard_normal(q0.size), rng.standard_normal(ref.n_constraints)
        _close(ref.constraints(t, q), fast.constraints(t, q))
        G = ref.constraint_jacobian(t, q)
        _close(G, fast.constraint_jacobian(t, q))
        _close(ref.constraint_force(t, q, lam), fast.constraint_force(t, q, lam))
        H = ref.constraint_force_jacobian(t, q, lam)
        _close(H, fast.constraint_force_jacobian(t, q, lam))
        for x, y in zip(ref.constraint_rates(t, q, v), fast.constraint_rates(t, q, v)):
            _close(x, y)
        _close(ref.constraint_velocity_jacobian(t, q, v), fast.constraint_velocity_jacobian(t, q, v))
        g1, f1 = fast.constraint_terms_at(t)(q, lam)
        _close(ref.constraints(t, q), g1)
        _close(ref.constraint_force(t, q, lam), f1)
        for x, y in zip(ref.constraint_position_terms_at(t)(q), fast.constraint_position_terms_at(t)(q)):
            _close(x, y)
        _close(fast.constraint_position_terms_at(t)(q)[2], ref.constraint_rates(t, q, v)[0])
        M = ref.mass(q)
        _close(kkt_matrix(M, G, H), kkt_matrix(fast.mass(q), fast.constraint_jacobian(t, q),
                                                fast.constraint_force_jacobian(t, q, lam)))


def _drive(t):
    return 0.3 * np.sin(2 * t), 0.6 * np.cos(2 * t), -1.2 * np.sin(2 * t)


def _ramp(t):
    return t ** 3, 3 * t ** 2, 6 * t


def test_compiled_set_equals_numpy_set_with_shared_timed_rows():
    """Two timed terms on one row, a timed constant, a quadratic row and a plain linear row: the compiled set
    against the NumPy one (a weight read from the wrong term or derivative, a timed constant dropped)."""
    n = 5
    rng = np.random.default_rng(3)
    rows = Rows(n)
    rows.add("lin", rng.standard_normal((1, n)), 0.7)
    A = rng.standard_normal((n, n))
    rows.add("quad", rng.standard_normal((1, n)), -0.2, A + A.T)
    k = rows.add("timed", sp.csr_matrix((1, n)), 0.1)
    rows.add_timed([k], TimedTerm(_drive, sp.csr_matrix(rng.standard_normal((1, n))), np.array([0.4])))
    rows.add_timed([k, 0], TimedTerm(_ramp, sp.csr_matrix(rng.standard_normal((2, n))), np.array([-1.0, 0.0])))
    ref, fast = ConstraintSet(rows), CompiledConstraintSet(rows)
    q, v, lam, t = rng.standard_normal(n), rng.standard_normal(n), rng.standard_normal(3), 0.9
    _close(ref.g(t, q), fast.g(t, q))
    _close(ref.G(t, q), fast.G(t, q))
    _close(ref.force(t, q, lam), fast.force(t, q, lam))
    _close(ref.H(lam), fast.H(lam))
    for x, y in zip(ref.rates(t, q, v), fast.rates(t, q, v)):
        _close(x, y)
    _close(ref.velocity_jacobian(t, q, v), fast.velocity_jacobian(t, q, v))
    g, G, g_t = fast.position_terms(t, q)
    _close(ref.g(t, q), g)
    _close(ref.G(t, q), G)
    _close(ref.rates(t, q, v)[0], g_t)


def test_kernel_argument_checked():
    s = BUILD["b5"]().system
    with pytest.raises(ValueError, match="`kernel` must be 'auto', 'numba' or 'numpy', got 'fast'"):
        System(s.bodies, s.joints, kernel="fast")


def test_constant_mass_is_formed_once_and_read_only():
    """The cached mass of a System equals its bodies' blocks and cannot be changed in place by a caller
    (a caller scaling it in place would change every later step)."""
    ref, fast = _pair("b6")
    M = fast.mass()
    assert fast.mass() is M
    blocks = sp.block_diag([b.mass() for b in fast.bodies]).toarray()
    assert np.array_equal(M.toarray(), blocks)
    with pytest.raises(ValueError):
        M.data[0] = 1.0


def test_dense_multipliers_equal_sparse(monkeypatch):
    """The multipliers at an output time by the dense KKT solve (small systems) equal SuperLU's on the sparse
    matrix, and the pair satisfies M a + r + G^T lam = 0, G a = gamma (a block placed transposed, G^T
    missing in the upper right, or the rows of gamma and -r swapped would fail)."""
    import ancfdae.constrained as con
    _, fast = _pair("b6")
    rng = np.random.default_rng(5)
    q0, _ = fast.initial_state()
    q, v, t = q0 + 0.02 * rng.standard_normal(q0.size), rng.standard_normal(q0.size), TIMES["b6"]
    assert q.size + fast.n_constraints <= con.DENSE_KKT_LIMIT
    a, lam = con.multipliers(fast, t, q, v)
    monkeypatch.setattr(con, "DENSE_KKT_LIMIT", 0)
    a_sp, lam_sp = con.multipliers(fast, t, q, v)
    _close(a, a_sp)
    _close(lam, lam_sp)
    G = fast.constraint_jacobian(t, q)
    r = fast.residual(t, q, v, np.zeros(q.size))
    _close(fast.mass() @ a + G.T @ lam, -r, scale=float(np.max(np.abs(r))))
    _close(G @ a, fast.constraint_rates(t, q, v)[1])


def test_dense_multipliers_singular_named():
    """A KKT matrix with a repeated constraint row is refused with the sparse path's message."""
    import ancfdae.constrained as con
    M = sp.identity(3, format="csr")
    G = sp.csr_matrix(np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]))
    with pytest.raises(np.linalg.LinAlgError, match="KKT matrix .* is singular"):
        con._solve_dense(M, G, np.ones(5), "multipliers at t = 0")
