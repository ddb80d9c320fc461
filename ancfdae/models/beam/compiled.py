"""The beam's Newton iterations as one compiled call, for the Newmark-family integrators.

A beam whose element's compiled kernel offers an iterations entry point (``Kernel.alpha_iterations``,
contract in :mod:`.iteration_numba`; BE2D), whose mass is constant and whose loads need no
configuration (gravity, dead point and line loads: no point moments) has the residual
``r(t, q, v, a) = f(q) + M a - lambda f_ext(t)``, with ``f_ext`` a fixed vector within a step.
:class:`CompiledResidual` hands the entry point and its arrays to the integrator
(:mod:`ancfdae.integrators._alpha_iteration`), which then runs the modified-Newton iterations --
substitution, update, weighted state, fused kernel, ``+ M a - lambda f_ext``, norms -- in one compiled
call until a decision is due. The same compiled pieces on the same arrays as :meth:`Beam.residual`
and the Python iteration; inlined into one function, LLVM may round the residual differently (measured:
1.5e-16 of its largest entry).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["CompiledResidual", "compiled_residual"]


@dataclass(frozen=True)
class CompiledResidual:
    """The pieces of a beam's compiled Newton iteration (module docstring).

    Attributes
    ----------
    iterations : numba dispatcher
        The element's entry point (contract in :mod:`ancfdae.models.beam.iteration_numba`).
    arrays : tuple
        ``(q_fixed, gather, vec_slot, mat_slot, m_data, indptr, indices)``: the fused kernel's arrays
        after ``q`` and the CSR mass for products (its own pattern, without stored zeros).
    element_args : tuple
        The element's own arguments, last in the call.
    external : callable
        ``external(t) -> f_ext`` (free vector): gravity plus the dead loads at ``t``.
    load_factor : float
        ``lambda``.
    steps : numba dispatcher or None
        The element's whole-steps entry point (contract in :mod:`ancfdae.integrators._alpha_steps_numba`), if any.
    gravity : ndarray (n_dof,)
        Gravity's free force vector.
    dead : ndarray (m, n_dof)
        The dead loads' free force vectors, ``dead_times`` their time functions (in the loads' order).
    index3_steps : numba dispatcher or None
        The element's entry point of whole index-3 steps of a System holding the beam (contract in
        :mod:`ancfdae.integrators._index3_steps_numba`), if any.
    multipliers : numba dispatcher or None
        The element's entry point of a System's reactions at an output time
        (:func:`ancfdae.integrators._index3_steps_numba.system_multipliers`), if any.
    """

    iterations: Callable
    arrays: tuple
    element_args: tuple
    external: Callable
    load_factor: float
    steps: Callable | None = None
    gravity: np.ndarray | None = None
    dead: np.ndarray | None = None
    dead_times: tuple = ()
    index3_steps: Callable | None = None
    multipliers: Callable | None = None


# the beam is named, not imported: beam.py imports this module
def compiled_residual(beam: "ancfdae.models.Beam") -> CompiledResidual | None:
    """The beam's compiled Newton iterations, or None when it has none (see the module docstring)."""
    if not beam.mass_is_constant or beam._load_set.moments or not beam.element.kernel_twins:
        return None
    offer = getattr(beam.element.kernels, "alpha_iterations", None)
    if offer is None:
        return None
    fn, element_args = offer(beam.geom)
    asm, loads = beam._asm, beam._load_set

    def external(t):
        return np.ascontiguousarray(loads.external(t, None, beam.geom, False)[0], dtype=float)

    m = beam._M_csr   # the mass without its stored zeros (Assembler.product_csr)
    arrays = (beam._q_fixed, beam._gather, asm._vec_all, asm._slot_all, m.data, m.indptr, m.indices)
    steps = getattr(beam.element.kernels, "alpha_steps", None)
    index3 = getattr(beam.element.kernels, "index3_steps", None)
    reactions = getattr(beam.element.kernels, "multipliers", None)
    dead = np.array([vec for _, vec in loads.dead], dtype=float).reshape(len(loads.dead), loads.n_dof)
    return CompiledResidual(fn, arrays, tuple(element_args), external, float(beam.load_factor),
                            steps(beam.geom)[0] if steps is not None else None,
                            np.ascontiguousarray(loads.gravity, dtype=float), np.ascontiguousarray(dead),
                            tuple(time for time, _ in loads.dead),
                            index3(beam.geom)[0] if index3 is not None else None,
                            reactions(beam.geom)[0] if reactions is not None else None)
