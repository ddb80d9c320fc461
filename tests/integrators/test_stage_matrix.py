"""StageMatrix: the eigenbasis solve of an implicit Runge-Kutta Newton matrix equals the real interleaved solve.

Catches: a transposed tableau (A instead of A^T), the wrong conjugate pairing, a dropped imaginary
part, the interleaving order (node-major, stage-minor) confused with stage-major.
"""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ancfdae import Gravity, Material, RectangularSection
from ancfdae.integrators._linsolve import StageMatrix, factorize
from ancfdae.models import BE2D, Beam

LOBATTO3 = np.array([[1 / 3, -1 / 24], [2 / 3, 1 / 6]])          # implicit part of Lobatto IIIA-3
RADAU_LIKE = np.array([[0.5, 0.0], [0.25, 0.25]])              # real, distinct eigenvalues


def _interleaved(blocks, h, a):
    m = a.shape[0]
    a2 = a @ a
    out = None
    for i in range(m):
        for k in range(m):
            B = h * h * a2[i, k] * blocks.K + h * a[i, k] * blocks.D + (blocks.M if i == k else 0 * blocks.M)
            E = sp.csr_matrix(([1.0], ([i], [k])), shape=(m, m))
            term = sp.kron(B, E, format="csr")
            out = term if out is None else out + term
    return out.tocsc()


@pytest.mark.parametrize("a", [LOBATTO3, RADAU_LIKE])
@pytest.mark.parametrize("h", [1e-4, 1e-2])
def test_eigenbasis_solve_equals_interleaved_solve(a, h):
    beam = Beam(BE2D(Material(2.1e10, 0.3, 4000.0), RectangularSection(0.05)), 6, 1.0,
                supports={0: ("x", "y")}, loads=[Gravity((0.0, -9.81))])
    rng = np.random.default_rng(1)
    n = beam.n_dof
    q = beam.initial_state()[0] + 0.01 * rng.standard_normal(n)
    blocks = beam.jacobian(0.0, q, rng.standard_normal(n), rng.standard_normal(n))
    # a non-zero D block, so that the h*lam*D term is exercised
    blocks = type(blocks)(blocks.K, beam._asm.csr(0.01 * np.abs(blocks.K.data)), blocks.M, same_pattern=True)
    r = rng.standard_normal(n * a.shape[0])
    x_ref = spla.spsolve(_interleaved(blocks, h, a), r)
    x = factorize(StageMatrix(blocks, h, a)).solve(r)
    assert x.dtype == float
    assert np.abs(x - x_ref).max() <= 1e-12 * np.abs(x_ref).max()   # round-off (measured 3e-15 - 9e-15)


def test_stage_matrix_needs_shared_pattern():
    K = sp.csr_matrix(np.eye(3))
    blk = type("B", (), {"K": K, "D": K, "M": K, "same_pattern": False})()
    with pytest.raises(ValueError, match="same_pattern"):
        StageMatrix(blk, 0.1, LOBATTO3)


def test_lobatto3_modified_newton_in_eigenbasis_gives_the_full_newton_steps():
    # Catches: the stage matrix wired with the wrong tableau part or step, which converges
    # slowly or to nothing; equal steps to the Newton tolerance with the exact per-stage Jacobian.
    from ancfdae import simulate
    beam = Beam(BE2D(Material(2.1e10, 0.3, 4000.0), RectangularSection(0.05)), 4, 1.0,
                supports={0: ("x", "y")}, loads=[Gravity((0.0, -9.81))])
    runs = [simulate(beam, (0.0, 0.02), "lobatto3", h=1e-3, newton={"tol": 1e-12, "jacobian": j})
            for j in ("modified", "full")]
    assert all(r.status == "success" for r in runs)
    assert np.abs(runs[0].q[-1] - runs[1].q[-1]).max() <= 1e-10 * np.abs(runs[1].q[-1]).max()


def test_lobatto3_falls_back_to_the_per_stage_matrix_when_the_eigenbasis_newton_fails(monkeypatch):
    # Catches: a step that fails with the one-state eigenbasis matrix although the exact per-stage
    # matrix converges (the fallback must run before the step is declared failed).
    from ancfdae import simulate
    from ancfdae.integrators import _linsolve

    class Useless(_linsolve.StageMatrix):   # a stage matrix whose corrections are 0: never converges
        def factorize(self):
            return type("Z", (), {"solve": staticmethod(lambda r: 0.0 * r)})()

    monkeypatch.setattr("ancfdae.integrators.lobatto.StageMatrix", Useless)
    beam = Beam(BE2D(Material(2.1e10, 0.3, 4000.0), RectangularSection(0.05)), 4, 1.0,
                supports={0: ("x", "y")}, loads=[Gravity((0.0, -9.81))])
    res = simulate(beam, (0.0, 0.005), "lobatto3", h=1e-3, newton={"tol": 1e-10, "max_iter": 8})
    assert res.status == "success"
