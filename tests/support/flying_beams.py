"""Small B2/B3 beams (revision 2: L = 1 m, a = 0.05 m, E = 1e5, nu = 0.3, rho = 2500; B2: pulse force
0.24 N and moment 0.24 N m at B; B3: hat moment (0.1, 0.05, 0.2) N m) and the energy and momenta of a
run's states: shared by the tests of the energy-conserving integrators."""
import numpy as np

from ancfdae import Material, PointForce, PointMoment, RectangularSection, hat, models, pulse

__all__ = ["MAT", "SEC", "b2", "b3", "total_energy", "momenta", "CASES"]

MAT = Material(E=1e5, nu=0.3, rho=2500.0)
SEC = RectangularSection(0.05)


def b2(name, n, T=2.5, force=True, **kw):
    el = getattr(models, name)(MAT, SEC, **kw)
    f = pulse(T)
    if el.dim == 2:
        loads = [PointMoment(0.24, node=0, time=f)] + ([PointForce((0.24, 0.0), node=0, time=f)] if force else [])
        return models.Beam(el, n, 1.0, start=(0.0, 0.0), direction=(0.6, 0.8), loads=loads)
    loads = [PointMoment((0.0, 0.0, 0.24), node=0, time=f)]
    return models.Beam(el, n, 1.0, start=(0.0, 0.0, 0.0), direction=(0.6, 0.8, 0.0), loads=loads)


def b3(name, n, t_load=3.0, **kw):
    el = getattr(models, name)(MAT, SEC, **kw)
    return models.Beam(el, n, 1.0, start=(0.0, 0.0, 0.0), direction=(0.6, 0.8, 0.0),
                       loads=[PointMoment((0.1, 0.05, 0.2), node=0, time=hat(t_load / 2))])


def total_energy(model, states, t_from):
    return np.array([model.energy(t, q, v).total for t, q, v in states if t >= t_from - 1e-12])


def momenta(model, states):
    """Linear momentum T^T M v and angular momentum (M v) . (A_k q) of every state (rows)."""
    T, A = model.symmetry_generators()
    M = model.mass(None)
    return (np.array([T.T @ (M @ v) for _, q, v in states]),
            np.array([[(M @ v) @ (Ak @ q) for Ak in A] for _, q, v in states]))


CASES = [("BE2D", 2, {}), ("BE2D", 2, {"formulation": "continuum"}), ("Cable3D", 2, {}),
         ("SQ2D", 2, {}), ("SQ2D", 2, {"formulation": "continuum"}), ("SQ2D", 2, {"formulation": "continuum-locking"}),
         ("SQ3D", 2, {}), ("SQ3D", 2, {"formulation": "continuum"})]
