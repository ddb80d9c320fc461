"""BE2D's compiled strain energy (be2d_energy_numba): equal to the NumPy reference, consistent with the compiled
force, and the beam's potential through the fused entry point equal to the summed element energies."""
import numpy as np
import pytest

from ancfdae import Gravity, Material, RectangularSection
from ancfdae.models import BE2D, Beam
from support.numerics import assert_forces_and_tangent_fd, fd_gradient, rel_err

STEEL, SECTION = Material(2.1e11, 0.3, 7800.0), RectangularSection(0.1)


def _beam(formulation, kernel="numba", curved=False, element=BE2D):
    el = element(STEEL, SECTION, formulation=formulation, kernel=kernel)
    if curved:   # a quarter arc: eps_ref and K_ref nonzero, both supports fixing coordinates
        th = np.linspace(0.0, 0.5 * np.pi, 6)
        return Beam(el, nodes=np.column_stack([np.cos(th), np.sin(th)]), supports={0: "clamp", -1: "pin"},
                    loads=[Gravity((0.0, -9.81))])
    return Beam(el, 5, 2.0, supports={0: "clamp"}, loads=[Gravity((0.0, -9.81))])


def _states(beam, seed=0):
    """Free coordinates: the reference and two random deformations (small, and large: |r'| far from 1)."""
    rng = np.random.default_rng(seed)
    q0 = beam.initial_state()[0]
    return [q0 + s * rng.standard_normal(beam.n_dof) for s in (0.0, 0.01, 0.2)]


CASES = [("structural", False), ("continuum", False), ("structural", True)]


@pytest.mark.parametrize("formulation, curved", CASES)
def test_compiled_energy_equals_numpy_energy(formulation, curved):
    # Catches a density written differently from the reference (a wrong factor, eps_ref / K_ref not
    # subtracted, the continuum's I4 term), a point of the wrong rule, or the fixed coordinates misread.
    beam = _beam(formulation, curved=curved)
    el = beam.element
    assert el.kernel_in_use == "numba"
    pairs = []
    for q in _states(beam):
        qe = beam._element_q(q)
        U1, P1 = el.strain_energy(beam.geom, qe), beam.potential(0.0, q)
        el.kernel = "numpy"
        U0, P0 = el.strain_energy(beam.geom, qe), beam.potential(0.0, q)
        el.kernel = "numba"
        pairs.append((U1, U0, P1, P0, beam.energy(0.0, q, 0 * q)))
    # relative to the largest energy over the states: the reference state's energies are round-off
    scale = max(np.abs(U0).max() for _, U0, _, _, _ in pairs)
    assert scale > 0
    for U1, U0, P1, P0, E in pairs:
        assert U1.shape == (beam.n_elements,)
        assert np.abs(U1 - U0).max() <= 1e-12 * scale
        assert abs(P1 - P0) <= 1e-12 * (beam.n_elements * scale + abs(E.potential))
        # the fused sum equals the compiled per-element energies (energy()) plus gravity's potential
        assert abs(P1 - (E.strain + E.potential)) <= 1e-12 * (beam.n_elements * scale + abs(E.potential))


@pytest.mark.parametrize("formulation, curved", CASES)
def test_compiled_force_is_the_gradient_of_the_compiled_energy(formulation, curved):
    # Catches an energy that is not the one the compiled force and tangent derive from (per element, and
    # through the beam: potential_gradient against finite differences of the fused potential).
    beam = _beam(formulation, curved=curved)
    q = _states(beam, seed=1)[1]
    assert_forces_and_tangent_fd(beam.element, beam.geom, beam._element_q(q))
    g, _ = beam.potential_gradient(0.0, q, tangent=False)
    h = 1e-7 * max(1.0, np.abs(q).max())
    assert rel_err(g, fd_gradient(lambda x: beam.potential(0.0, x), q, h)) < 1e-6


def test_subclass_with_its_own_energy_takes_its_energy():
    # Catches the fused entry point overriding an element subclass's own strain_energy in the potential.
    class Doubled(BE2D):
        def strain_energy(self, geom, q):
            return 2.0 * super().strain_energy(geom, q)

    beam, ref = _beam("structural", element=Doubled), _beam("structural")
    q = _states(beam)[2]
    grav = -float(ref._load_set.gravity @ (q - ref.q_ref[ref.free]))
    assert rel_err(beam.potential(0.0, q) - grav, 2.0 * (ref.potential(0.0, q) - grav)) < 1e-13


def test_numpy_kernel_offers_no_fused_energy():
    # Catches the reference path reaching the compiled energy (the numpy option must run NumPy alone).
    el = BE2D(STEEL, SECTION, kernel="numpy")
    assert getattr(el.kernels, "fused_energy", None) is None
    el.kernel = "auto"
    assert el.kernels.fused_energy is not None
