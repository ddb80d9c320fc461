"""Compiled affine state updates of the fixed-step integrators against their NumPy expressions."""
import numpy as np

from ancfdae.integrators._affine import affine2, affine3, newmark_predict, stage_constants, stage_states


def test_newmark_updates_are_bit_for_bit_numpy():
    # Catches a coefficient or operand swapped in the fused kernels (e.g. 1 - af for af, gamma for
    # beta), and a reordered or fused (FMA) evaluation that would change the integrators' results.
    rng = np.random.default_rng(3)
    q, v, a, x = (rng.standard_normal(37) * 10.0 ** rng.uniform(-8, 8, 37) for _ in range(4))
    h, b, g, am, af = 1.3e-3, 0.3025, 0.6, -0.2, 0.15
    q_pred = q + h * v + (h * h * (0.5 - b)) * a
    v_pred = v + (h * (1.0 - g)) * a
    expect = (q_pred, v_pred, q + (1 - af) * (q_pred - q), v + (1 - af) * (v_pred - v), am * a)
    for got, ref in zip(newmark_predict(q, v, a, h, b, g, am, af), expect):
        assert np.array_equal(got, ref)
    cq, cv, ca = 0.7 * h * h, 0.6 * h, 1.2
    for got, ref in zip(affine3(q, v, a, cq, cv, ca, x), (q + cq * x, v + cv * x, a + ca * x)):
        assert np.array_equal(got, ref)
    for got, ref in zip(affine2(q, v, cq, cv, x), (q + cq * x, v + cv * x)):
        assert np.array_equal(got, ref)
    out = affine3(q, v, a, cq, cv, ca, x)
    assert all(o is not p for o in out for p in (q, v, a, x))   # fresh arrays: a model may keep them


def test_stage_states_match_numpy_to_roundoff():
    # Catches CQ/CV swapped or transposed, or X read in the wrong (column-major) order.
    rng = np.random.default_rng(4)
    n, m = 23, 2
    Q0, V0 = rng.standard_normal((n, m)), rng.standard_normal((n, m))
    CQ, CV = rng.standard_normal((m, m)).T, rng.standard_normal((m, m)).T   # transposed views, as Lobatto's
    x = rng.standard_normal(n * m)
    Q, V, X = stage_states(Q0, V0, CQ, CV, x)
    Xr = x.reshape(n, m)
    assert np.array_equal(X, Xr)
    np.testing.assert_allclose(Q, Q0 + Xr @ CQ, rtol=0, atol=4 * np.finfo(float).eps * 10)
    np.testing.assert_allclose(V, V0 + Xr @ CV, rtol=0, atol=4 * np.finfo(float).eps * 10)


def test_stage_constants_are_bit_for_bit_numpy():
    # Catches the stage coefficients applied to the wrong vector (c to a, a_first to v) or per row.
    rng = np.random.default_rng(5)
    q, v, a = (rng.standard_normal(19) for _ in range(3))
    ca, cc, ca2 = (rng.standard_normal(2) for _ in range(3))
    Q0, V0 = stage_constants(q, v, a, ca, cc, ca2)
    assert np.array_equal(V0, v[:, None] + ca * a[:, None])
    assert np.array_equal(Q0, q[:, None] + cc * v[:, None] + ca2 * a[:, None])
