"""Which silent stages, energy correction and energy defect an energy-collocation run gets.

:class:`ancfdae.integrators.energy_collocation.EnergyCollocation` resolves its three coupled options here:
``energy_correction`` ("velocity" unless the model has constraints, which a change of ``v1`` alone would
break), ``energy_defect`` (the rule's ``sum V.R`` where the ``k``-point rule integrates the potential's power
exactly, else the model's own potential) and the number ``k`` of silent stages (the potential's degree for a
polynomial potential; by measurement otherwise).
"""
from __future__ import annotations

import numpy as np

from ancfdae import _validate as validate
from ancfdae.problem import Model, capabilities

__all__ = ["hbvm_options", "SMOOTH_SILENT_STAGES", "CORRECTED_SILENT_STAGES", "ENERGY_CORRECTIONS",
           "ENERGY_DEFECTS"]

#: Silent stages for a potential that is not a polynomial (chosen by measurement, see docs/energy_momentum.md:
#: one element, 1000 steps of 10 ms, energy drift SQ3D structural 3.6e-11 / 6.6e-14 / 3.8e-14 at k = 4 / 5 / 6,
#: SQ2D structural 2.0e-13 / 3.1e-14 / 3.0e-14, BE2D 8.4e-14 / 3.9e-14 / 4.3e-14; B3 8 SQ3D, h = 5 ms: 8.5e-14
#: at k = 5, 9.0e-14 at k = 6).
SMOOTH_SILENT_STAGES = 5
#: Silent stages for a non-polynomial potential with ``energy_defect="potential"``: k then sets the accuracy alone
#: (B3 8 SQ3D, h = 5 ms: eps_T 2.93e-6 at k = 4 and 5, 3.10e-6 at k = 3; B3-16 2.89e-6 / 3.01e-6 at k = 4 / 3, B2
#: equal; at equal eps_T k = 3 is no cheaper on any of the four problems: docs/energy_momentum.md).
CORRECTED_SILENT_STAGES = 4
ENERGY_CORRECTIONS = ("velocity", "newton")
ENERGY_DEFECTS = ("rule", "potential")
_S = 2          # fundamental stages: order 4


def hbvm_options(model: Model, silent_stages, energy_correction: str, energy_defect: str) -> tuple[str, str, int]:
    """``(energy_correction, energy_defect, k)`` resolved from the user's choices ("auto" or a value) and the model.

    Raises ``ValueError`` naming the argument for a choice outside its set, ``silent_stages`` not an integer
    ``>= 2``, the velocity correction on a constrained model, or the potential's defect without the velocity
    correction.
    """
    correction = validate.choice("energy_correction", energy_correction, ("auto",) + ENERGY_CORRECTIONS)
    constrained = "constraints" in capabilities(model)
    if correction == "auto":
        correction = "newton" if constrained else "velocity"
    elif correction == "velocity" and constrained:
        raise ValueError("`energy_correction` 'velocity' cannot keep the constraints (it changes v1 alone); "
                         "use 'newton' or 'auto' for a model with the 'constraints' capability.")
    defect = validate.choice("energy_defect", energy_defect, ("auto",) + ENERGY_DEFECTS)
    if defect == "potential" and correction != "velocity":
        raise ValueError("`energy_defect` 'potential' is removed by the velocity correction only; got "
                         f"energy_correction={correction!r}.")
    degree = getattr(model, "potential_degree", None)
    if isinstance(silent_stages, str) and silent_stages == "auto":
        corrected = correction == "velocity" and defect != "rule"
        k = max(_S, int(degree)) if degree is not None else (
            CORRECTED_SILENT_STAGES if corrected else SMOOTH_SILENT_STAGES)
    elif isinstance(silent_stages, (int, np.integer)) and not isinstance(silent_stages, bool) \
            and silent_stages >= _S:
        k = int(silent_stages)
    else:
        raise ValueError(f"`silent_stages` must be 'auto' or an integer >= {_S}, got {silent_stages!r}.")
    if defect == "auto":
        defect = "rule" if correction != "velocity" or (degree is not None and int(degree) <= k) else "potential"
    return correction, defect, k
