"""SHA-256 of every contract output and of the quick studies' numbers: a behaviour fingerprint.

A refactoring that must not change behaviour is checked by running this before and after and
comparing the two files (``--compare``). It uses only the public API, so the same script runs on
both sides of a redesign.

What is hashed (the bits of float64 arrays, not printed digits):

* for each element (BE2D, Cable3D, BE3D, SQ2D, SQ3D), each formulation, each kernel (``numpy``,
  ``numba``) and each assembly path (``fused``; ``numpy``: the element subclassed with a
  ``fused_kernel`` that returns None, so the beam scatters with ``np.bincount``): on a 3-element
  beam clamped at node 0 with a point force, a point moment, gravity and a distributed load, at a perturbed state
  ``(t, q, v, a)``: ``residual``, the three Jacobian blocks (data, indices, indptr),
  ``residual_jacobian``, ``mass`` and ``energy``; ``residual_stages`` and ``potential_gradient``
  where declared;
* for each study, its ``--quick`` run's rows with every timing entry removed (CPU and wall times
  are not behaviour).

Usage::

    python -m benchmarks.behaviour_hashes --out before.json            # contract outputs only
    python -m benchmarks.behaviour_hashes --studies --out before.json  # and the quick studies
    python -m benchmarks.behaviour_hashes --studies --compare before.json
"""
from __future__ import annotations

import argparse
import hashlib
import json
import sys
import tempfile

import numpy as np

from ancfdae import Gravity, Material, PointForce, PointMoment, RectangularSection, DistributedLoad
from ancfdae import models

ELEMENTS = {
    "BE2D": ("structural", "continuum"),
    "Cable3D": (None,),
    "BE3D": (None,),
    "SQ2D": ("structural", "continuum", "continuum-locking"),
    "SQ3D": ("structural", "continuum", "continuum-locking"),
}
STUDIES = ("cantilever", "flying2d", "flying3d", "integrators", "energy")
_TIMING = ("time", "cpu", "wall", "seconds", "per_step", "speed")


def _digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(np.asarray(a))
        h.update(str(a.dtype).encode())
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _blocks(J):
    out = []
    for m in (J.K, J.D, J.M):
        m = m.tocsr()
        out += [m.data, m.indices, m.indptr]
    return out


def _unfused(cls):
    """``cls`` without a fused entry point: the same kernels, assembled by the beam's NumPy path."""
    return type(f"Unfused{cls.__name__}", (cls,), {"fused_kernel": lambda self, geom: None})


def _beam(name, formulation, kernel, assembly):
    steel = Material(E=2.07e11, nu=0.3, rho=7800.0)
    section = RectangularSection(0.1, 0.1 if name == "Cable3D" else 0.06)
    cls = getattr(models, name)
    if assembly == "numpy":
        cls = _unfused(cls)
    kw = {"kernel": kernel}
    if formulation is not None:
        kw["formulation"] = formulation
    el = cls(steel, section, **kw)
    dim = el.dim
    force = np.arange(1, dim + 1) * 1e5
    moment = 2e4 if dim == 2 else np.array([1e4, -2e4, 3e4])
    loads = [PointForce(force, node=-1, time=lambda t: 1.0 + t), PointMoment(moment, s=1.3),
             Gravity(-9.81 * np.eye(dim)[1]), DistributedLoad(np.full(dim, 1e3))]
    return Beam(el, 3, 2.0, supports={0: "clamp"}, loads=loads)


Beam = models.Beam


def contract_hashes() -> dict:
    """``{label: sha256}`` of every contract output, per element, formulation, kernel and assembly path."""
    out = {}
    for name, forms in ELEMENTS.items():
        for form in forms:
            for kernel in ("numpy", "numba"):
                for assembly in ("fused", "numpy"):
                    beam = _beam(name, form, kernel, assembly)
                    rng = np.random.default_rng(7)
                    q0, v0 = beam.initial_state()
                    n = beam.n_dof
                    q = q0 + 1e-2 * rng.standard_normal(n)
                    v = rng.standard_normal(n)
                    a = rng.standard_normal(n)
                    t = 0.3
                    label = f"{name}/{form or 'structural'}/{kernel}/{assembly}"
                    out[label + "/residual"] = _digest(beam.residual(t, q, v, a))
                    out[label + "/jacobian"] = _digest(*_blocks(beam.jacobian(t, q, v, a)))
                    r, J = beam.residual_jacobian(t, q, v, a)
                    out[label + "/residual_jacobian"] = _digest(r, *_blocks(J))
                    M = beam.mass(q).tocsr()
                    out[label + "/mass"] = _digest(M.data, M.indices, M.indptr)
                    e = beam.energy(t, q, v)
                    out[label + "/energy"] = _digest(np.array([e.kinetic, e.strain, e.potential]))
                    caps = getattr(beam, "capabilities", ())
                    if "residual_stages" in caps:
                        ts = np.array([t, t + 1e-3, t + 2e-3])
                        Q = np.stack([q, q * 1.001, q * 0.999], axis=1)
                        Vs = np.stack([v, -v, 2 * v], axis=1)
                        A = np.stack([a, a * 0.5, -a], axis=1)
                        out[label + "/residual_stages"] = _digest(beam.residual_stages(ts, Q, Vs, A))
                    if "potential" in caps:
                        g, H = beam.potential_gradient(t, q, True)
                        H = H.tocsr()
                        out[label + "/potential"] = _digest(np.array([beam.potential(t, q)]), g, H.data,
                                                            H.indices, H.indptr)
    return out


def _strip(obj):
    """``obj`` without timing entries (keys naming a time), as plain JSON-able data."""
    if isinstance(obj, dict):
        return {str(k): _strip(v) for k, v in sorted(obj.items(), key=lambda kv: str(kv[0]))
                if not any(w in str(k).lower() for w in _TIMING)}
    if isinstance(obj, (list, tuple)):
        return [_strip(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return {"sha256": _digest(obj)}
    if isinstance(obj, (np.floating, float)):
        return float(obj).hex()
    if isinstance(obj, (np.integer, int, bool, str)) or obj is None:
        return obj if not isinstance(obj, np.integer) else int(obj)
    return repr(type(obj).__name__)


def study_hashes() -> dict:
    """``{study: sha256}`` of each quick study's rows with timing entries removed."""
    import importlib

    out = {}
    for name in STUDIES:
        mod = importlib.import_module(f"ancfdae.studies.{name}")
        with tempfile.TemporaryDirectory() as tmp:
            res = mod.run(quick=True, out=tmp, plots=False, progress=False)
        rows = res.get("rows", res.get("records"))
        text = json.dumps(_strip(rows), sort_keys=True)
        out[f"study/{name}"] = hashlib.sha256(text.encode()).hexdigest()
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--studies", action="store_true", help="also hash the quick studies (minutes)")
    p.add_argument("--out", help="write the hashes to this JSON file")
    p.add_argument("--compare", help="compare with the hashes in this JSON file; exit 1 when any differ")
    args = p.parse_args(argv)
    hashes = contract_hashes()
    if args.studies:
        hashes.update(study_hashes())
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(hashes, fh, indent=1, sort_keys=True)
    print(f"{len(hashes)} hashes")
    if args.compare:
        with open(args.compare) as fh:
            ref = json.load(fh)
        keys = sorted(set(ref) & set(hashes))
        diff = [k for k in keys if ref[k] != hashes[k]]
        missing = sorted(set(ref) ^ set(hashes))
        for k in diff:
            print("DIFFERS", k)
        for k in missing:
            print("ONLY ON ONE SIDE", k)
        print(f"{len(keys) - len(diff)} of {len(keys)} equal")
        return 1 if diff else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
