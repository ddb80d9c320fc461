"""A beam described as plain data: what a result file records and what rebuilds the beam.

:func:`describe` turns a :class:`~ancfdae.models.Beam` into a JSON-able dict
(element type and options, material, section, mesh, supports, loads);
:func:`dof_labels` names each free coordinate by its node and coordinate name;
:func:`beam_arguments` reads the dict back into the element and the keyword
arguments of the beam, which :meth:`ancfdae.models.Beam.from_description`
builds, for the tools that read a result file without the script that made it
(``ancfdae export vtk``, ``ancfdae animate``). The element type is looked up by name in the registry of
:class:`~ancfdae.models.Element`, so a user's element rebuilds too once its
class is defined. Loads are recorded by their ``repr`` only: their time
functions are Python callables, and the geometry tools need none of them.

The functions take the beam as an argument and never import it: this module
sits below the beam.
"""
from __future__ import annotations

import dataclasses
import inspect
import math
from typing import Any

import numpy as np

from ... import materials
from ..element import Element

__all__ = ["describe", "dof_labels", "beam_arguments", "MODEL_FORMAT"]

#: Version tag of the dict that :func:`describe` returns.
MODEL_FORMAT = "ancfdae.Beam/1"

# Constructor arguments every element takes positionally; the others are its options.
_COMMON_ARGS = ("self", "material", "section")


def _plain(value: Any) -> Any:
    """JSON-able copy of an option value (arrays to lists, numpy scalars to Python)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def element_options(element: Element) -> dict:
    """The element's constructor options (beyond material and section) read back from the instance.

    Parameters
    ----------
    element : Element

    Returns
    -------
    dict
        ``{argument name: value}`` for every constructor argument the
        instance keeps under the same name; passing them back rebuilds an
        equal element.
    """
    params = inspect.signature(type(element).__init__).parameters
    return {name: _plain(getattr(element, name)) for name in params
            if name not in _COMMON_ARGS and hasattr(element, name)}


def _dataclass_record(obj) -> dict:
    return {"type": type(obj).__name__, **{f.name: _plain(getattr(obj, f.name)) for f in dataclasses.fields(obj)}}


def describe(beam) -> dict:
    """JSON-able description of a beam.

    Parameters
    ----------
    beam : Beam

    Returns
    -------
    dict
        Keys ``format``, ``element`` (type name and options), ``formulation``,
        ``material``, ``section`` (type name and fields), ``dim``,
        ``node_coordinates``, ``nodes`` (reference node positions, a list of
        rows), ``normal`` (the cross-section axis the beam was built with, or
        None), ``element_nodes``, ``fixed`` (names of the fixed coordinates per
        node), ``loads`` (their ``repr``) and ``n_dof``. Floats are Python
        floats, so the JSON text round-trips them exactly.
    """
    el = beam.element
    names = el.node_coordinates
    fixed_mask = beam.fixed.reshape(beam.n_nodes, -1)
    fixed = {str(i): [names[k] for k in np.flatnonzero(row)] for i, row in enumerate(fixed_mask) if row.any()}
    return {
        "format": MODEL_FORMAT,
        "element": {"type": el.name, "options": element_options(el)},
        "formulation": getattr(el, "formulation", "structural"),
        "material": _dataclass_record(el.material),
        "section": _dataclass_record(el.section) if dataclasses.is_dataclass(el.section) else
        {"type": type(el.section).__name__},
        "dim": int(el.dim),
        "node_coordinates": list(names),
        "nodes": beam.points.tolist(),
        "normal": None if getattr(beam, "normal", None) is None else _plain(np.asarray(beam.normal, float)),
        "element_nodes": beam.element_nodes.tolist(),
        "fixed": fixed,
        "loads": [repr(load) for load in getattr(beam, "loads", ())],
        "n_dof": int(beam.n_dof),
    }


def dof_labels(beam) -> tuple[np.ndarray, np.ndarray]:
    """Node index and coordinate name of each free coordinate.

    Parameters
    ----------
    beam : Beam

    Returns
    -------
    node : ndarray of int, shape (n_dof,)
    coordinate : ndarray of str, shape (n_dof,)
        Names from ``element.node_coordinates``, e.g. ``"x"``, ``"y'"``, ``"theta"``.
    """
    nnd = beam.element.n_node_dof
    names = np.array(beam.element.node_coordinates)
    return beam.free // nnd, names[beam.free % nnd]


def _from_record(record: dict, allowed: tuple):
    classes = {cls.__name__: cls for cls in allowed}
    kind = record.get("type")
    if kind not in classes:
        raise ValueError(f"type must be one of {sorted(classes)}, got {kind!r}.")
    return classes[kind](**{k: v for k, v in record.items() if k != "type"})


def beam_arguments(description: dict) -> tuple[Element, dict]:
    """The element and the :class:`~ancfdae.models.Beam` keyword arguments of a :func:`describe` dict.

    Parameters
    ----------
    description : dict
        As returned by :func:`describe` (e.g. read from a result file).

    Returns
    -------
    element : Element
        Same type (looked up with :meth:`Element.by_name`), options, material
        and section.
    kwargs : dict
        ``nodes``, ``normal`` and ``supports``: with the element they make the
        same coordinates and reference configuration; no loads.

    Raises
    ------
    ValueError
        If the dict is not a beam description or names an unknown element,
        material or section type.
    """
    if not isinstance(description, dict) or description.get("format") != MODEL_FORMAT:
        got = description.get("format") if isinstance(description, dict) else type(description).__name__
        raise ValueError(f"`description` must be a beam description of format {MODEL_FORMAT!r}, got {got!r}.")
    cls = Element.by_name(description["element"]["type"])
    material = _from_record(description["material"], (materials.Material,))
    section = _from_record(description["section"], (materials.RectangularSection, materials.CircularSection))
    options = dict(description["element"]["options"])
    element = cls(material, section, **options)
    supports = {int(node): tuple(names) for node, names in description["fixed"].items()}
    nodes = np.array(description["nodes"], dtype=float)
    if nodes.ndim != 2 or not all(math.isfinite(x) for x in nodes.ravel()):
        raise ValueError(f"`nodes` of the description must be a finite 2-D array, got shape {nodes.shape}.")
    return element, {"nodes": nodes, "normal": description.get("normal"), "supports": supports}
