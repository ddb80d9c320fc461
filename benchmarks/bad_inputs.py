"""Bad-input probe: what a new user gets for bad or edge inputs across the public API, the CLI and result files.

Run from the repository root: ``python benchmarks/bad_inputs_cli.py [--skip-cli] [--flips N]`` (this module holds
the API and result-file probes, that one the CLI probes and the report). It prints one
count per class and outcome, then every probe whose outcome is not the expected one.

Outcomes: ``clear error`` (an exception -- or a CLI exit != 0 without a traceback -- whose message names
what the probe expects, e.g. the argument), ``correct acceptance`` (a valid edge input accepted),
``flagged`` (a run or solve that returns, but says it failed or is suspect), ``cryptic error`` (an
exception or message that does not name it, a raw traceback, an unexpected exception type),
``silent answer`` (accepted although it should be refused or flagged), ``wrongly refused``.
Damaged result files are counted apart: one bit flipped at N offsets of a saved file, each load is a
``clear error``, an ``identical load`` or a ``silent wrong load``.

Why in benchmarks/ and not tests/: it is a survey that reports counts (like the other scripts here
report timings), it runs the CLI in subprocesses and the studies until they refuse or time out, and
its classification of a message as clear is a keyword heuristic; the properties it surveys are
asserted exactly by the tests (tests/io/test_result_integrity.py, tests/io/test_cli_errors.py,
tests/integrators/test_driver_checks.py, tests/test_static_stability.py).
"""
from __future__ import annotations

import argparse
import collections
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

from ancfdae import (CircularSection, EnergyMonitor, Gravity, Material, PointForce, PointSensor, Probe,  # noqa: E402
                     RectangularSection, Result, constant, hat, pulse, ramp, simulate, solve_static)
from ancfdae.integrators import Integrator, StepOutcome  # noqa: E402
from ancfdae.models import BE2D, Beam  # noqa: E402

MAT = Material(E=1e6, nu=0.3, rho=1000.0)
SEC = RectangularSection(0.1)
STEEL, SQUARE = Material(E=2.07e11, nu=0.3, rho=7800.0), RectangularSection(0.1)
BAD_NUMBERS = [0, -1, float("nan"), float("inf"), -float("inf"), "1", None, True, [1.0], 1j]
PROBES: list = []           # (class, label, thunk, expect)


def probe(cls, label, expect):
    def wrap(fn):
        PROBES.append((cls, label, fn, expect))
        return fn
    return wrap


def add(cls, label, fn, expect):
    PROBES.append((cls, label, fn, expect))


def beam(n=2, **kw):
    kw.setdefault("supports", {0: "clamp"})
    kw.setdefault("loads", [Gravity((0.0, -9.81))])
    return Beam(BE2D(MAT, SEC), n, 1.0, **kw)


# -- constructors --------------------------------------------------------------------------------------
for arg in ("E", "nu", "rho"):
    for bad in BAD_NUMBERS + ([0.5, 0.7] if arg == "nu" else []):
        args = {**dict(E=1e6, nu=0.3, rho=1000.0), arg: bad}
        ok = arg == "nu" and bad == 0          # a Poisson ratio of 0 is physical (cork)
        add("api: materials, sections", f"Material({arg}={bad!r})", lambda a=args: Material(**a),
            ("accept",) if ok else ("error", [arg]))
for bad in BAD_NUMBERS:
    if bad is not None:
        add("api: materials, sections", f"RectangularSection(h={bad!r})", lambda b=bad: RectangularSection(b),
            ("error", ["h"]))
        add("api: materials, sections", f"CircularSection(d={bad!r})", lambda b=bad: CircularSection(b),
            ("error", ["d"]))
        add("api: materials, sections", f"RectangularSection(0.1, b={bad!r})",
            lambda b=bad: RectangularSection(0.1, b), ("error", ["b"]))
add("api: materials, sections", "Material(np.float32 E)", lambda: Material(np.float32(1e6), 0.3, 1000.0), ("accept",))
for opt, bad in [("formulation", "xyz"), ("axial_points", 0), ("axial_points", -1), ("axial_points", 2.5),
                 ("axial_points", "3"), ("bending_points", 0), ("kernel", "gpu"), ("formulation", None)]:
    add("api: models", f"BE2D({opt}={bad!r})", lambda o=opt, b=bad: BE2D(MAT, SEC, **{o: b}), ("error", [opt]))
for bad in [0, -1, 2.5, "2", True, float("nan")]:
    add("api: models", f"Beam(n_elements={bad!r})", lambda b=bad: beam(b), ("error", ["n_elements"]))
for bad in [0, -1, float("nan"), "1", float("inf")]:
    add("api: models", f"Beam(length={bad!r})",
        lambda b=bad: Beam(BE2D(MAT, SEC), 2, b, supports={0: "clamp"}), ("error", ["length"]))
for bad in [{5: "clamp"}, {0: "weld"}, [0], "clamp", {-9: "pin"}, {0.5: "clamp"}]:
    add("api: models", f"Beam(supports={bad!r})", lambda b=bad: beam(supports=b), ("error", ["supports"]))
for bad in [["x"], [1], "gravity", [None]]:
    add("api: models", f"Beam(loads={bad!r})", lambda b=bad: beam(loads=b), ("error", ["loads"]))
add("api: models", "Beam(element='BE2D')", lambda: Beam("BE2D", 2, 1.0), ("error", ["element"]))
add("api: models", "Beam(n_elements=np.int64(2))", lambda: beam(np.int64(2)), ("accept",))

# -- loads and time functions ---------------------------------------------------------------------------
for bad in [[np.nan, 0.0], "ab", [1, 2, 3, 4], [], [[1, 2]]]:
    add("api: loads", f"PointForce(force={bad!r})", lambda b=bad: beam(loads=[PointForce(b, node=-1)]),
        ("error", ["force"]))
for key, bad in [("node", 99), ("node", 1.5), ("s", -1.0), ("s", 5.0), ("s", "1")]:
    add("api: loads", f"PointForce({key}={bad!r})",
        lambda k=key, b=bad: beam(loads=[PointForce((0.0, 1.0), **{k: b})]), ("error", [key]))
for bad in [[np.nan, 0.0], "g", [1.0], [1, 2, 3, 4]]:
    add("api: loads", f"Gravity({bad!r})", lambda b=bad: beam(loads=[Gravity(b)]), ("error", ["g"]))
for fn, name in [(ramp, "t_end"), (hat, "t_peak"), (pulse, "T")]:
    for bad in [0, -1, float("nan"), "1", None]:
        add("api: loads", f"{fn.__name__}({bad!r})", lambda f=fn, b=bad: f(b), ("error", [name]))
for bad in ["1", float("nan"), None]:
    add("api: loads", f"constant({bad!r})", lambda b=bad: constant(b), ("error", ["value"]))

# -- simulate -------------------------------------------------------------------------------------------
for bad in [(1.0, 0.0), (0.0, float("nan")), (0.0, float("inf")), ("0", "0.01"), "01", (0.0,), None, (0.0, 0.0),
            (0.0, 0.01, 0.02)]:
    add("api: simulate", f"t_span={bad!r}", lambda b=bad: simulate(beam(), b, h=0.005), ("error", ["t_span"]))
add("api: simulate", "t_span=[0, 0.01] (list)", lambda: simulate(beam(), [0, 0.01], h=0.005), ("accept",))
for bad in ["xyz", 3, None, "IDA"]:
    add("api: simulate", f"method={bad!r}", lambda b=bad: simulate(beam(), (0, 0.01), b, h=0.005),
        ("error", ["method"]))
for bad in [0, -1, float("nan"), "0.01", None, [0.01], 1j]:
    add("api: simulate", f"h={bad!r}", lambda b=bad: simulate(beam(), (0, 0.01), h=b), ("error", ["h"]))
for bad in [[2.0], [0.008, 0.004], [float("nan")], ["0.005"], [], [[0.005]], "0.005", [-1.0]]:
    add("api: simulate", f"t_eval={bad!r}", lambda b=bad: simulate(beam(), (0, 0.01), h=0.005, t_eval=b),
        ("error", ["t_eval"]))
for arg in ("q0", "v0"):
    for bad in ["nan", "short", "text", "2d", "none_list"]:
        def f(a=arg, b=bad):
            m = beam()
            x = {"nan": np.full(m.n_dof, np.nan), "short": np.zeros(3), "text": np.array(["1"] * m.n_dof),
                 "2d": np.zeros((m.n_dof, 1)), "none_list": [None] * m.n_dof}[b]
            other = "v0" if a == "q0" else "q0"
            return simulate(m, (0, 0.01), h=0.005, **{a: x, other: m.initial_state()[1 if other == "v0" else 0]})
        add("api: simulate", f"{arg}={bad}", f, ("error", [arg]))
for bad in [0, -1, 2.5, "5"]:
    add("api: simulate", f"max_steps={bad!r}", lambda b=bad: simulate(beam(), (0, 0.01), h=0.005, max_steps=b),
        ("error", ["max_steps"]))
for arg, bad in [("monitors", [1]), ("monitors", ["energy"]), ("hooks", [1]), ("hooks", ["x"]),
                 ("state0", {"x": 1}), ("rtolx", 1e-6)]:
    add("api: simulate", f"{arg}={bad!r}", lambda a=arg, b=bad: simulate(beam(), (0, 0.01), h=0.005, **{a: b}),
        ("error", [arg]))
for arg, bad in [("rtol", 0), ("rtol", -1), ("rtol", "1e-6"), ("rtol", float("nan")), ("atol", -1.0),
                 ("atol", [1e-6, 1e-6, 1e-6]), ("atol", "x"), ("max_order", 7), ("max_order", 0)]:
    add("api: simulate", f"ida {arg}={bad!r}", lambda a=arg, b=bad: simulate(beam(), (0, 0.01), "ida", **{a: b}),
        ("error", [arg]))
for method in ("lobatto3", "lobatto2", "newmark", "hht", "generalized-alpha", "energy-momentum"):
    for bad in [0, -1, float("nan"), "0.01"]:
        add("api: simulate", f"{method} h={bad!r}", lambda m=method, b=bad: simulate(beam(), (0, 0.01), m, h=b),
            ("error", ["h"]))
add("api: simulate", "ida h=0.01", lambda: simulate(beam(), (0, 0.01), "ida", h=0.01), ("error", ["h"]))
for bad in ["short", "nan"]:
    def f(b=bad):
        m = beam()
        q = np.zeros(3) if b == "short" else np.full(m.n_dof, np.nan)
        return m.residual(0.0, q, np.zeros(m.n_dof), np.zeros(m.n_dof))
    # the model's functions are the hot path: NaN in, NaN out (the front doors check q0 and each step)
    add("api: models", f"Beam.residual(q={bad})", f, ("error", ["q"]) if bad == "short" else ("accept",))
for label, fn in [("Material(np.int64 E)", lambda: Material(np.int64(1000000), 0.3, 1000.0)),
                  ("RectangularSection(np.float64)", lambda: RectangularSection(np.float64(0.1))),
                  ("t_eval of ints", lambda: simulate(beam(), (0, 2), h=0.5, t_eval=[0, 1, 2])),
                  ("solve_static(load_steps=np.int64(2))", lambda: solve_static(beam(), np.int64(2))),
                  ("Result.save(pathlib path)", lambda: GOOD.save(TMP / "again.nc")),
                  ("Result.load(good file)", lambda: Result.load(GOOD_FILE))]:
    add("api: edge acceptances", label, fn, ("accept",))
add("api: simulate", "h=np.float32(0.005)", lambda: simulate(beam(), (0, 0.01), h=np.float32(0.005)), ("accept",))
add("api: simulate", "t_eval=np.array", lambda: simulate(beam(), (0, 0.01), h=0.005, t_eval=np.array([0.01])),
    ("accept",))

# -- solve_static ---------------------------------------------------------------------------------------
def b1(n=2, support="clamp", force=None):
    force = (0.0, 3.0 * STEEL.E * SQUARE.I3 / 4.0) if force is None else force
    return Beam(BE2D(STEEL, SQUARE), n, 2.0, supports={0: support}, loads=[PointForce(force, node=-1)])


for arg, bads in [("load_steps", [0, -1, 2.5, "10"]), ("t", [float("nan"), "0", float("inf"), None]),
                  ("tol", [0, -1, float("nan"), "1"]), ("residual_atol", [-1, float("nan"), "0"]),
                  ("max_iter", [0, -1, 2.5]), ("jacobian", ["xyz", None])]:
    for bad in bads:
        add("api: solve_static", f"{arg}={bad!r}",
            lambda a=arg, b=bad: solve_static(b1(), **({"load_steps": b} if a == "load_steps" else {a: b})),
            ("error", [arg]))
for bad in ["nan", "short", "text", "2d"]:
    def f(b=bad):
        m = b1()
        x = {"nan": np.full(m.n_dof, np.nan), "short": np.zeros(3), "text": np.array(["1"] * m.n_dof),
             "2d": np.zeros((m.n_dof, 1))}[b]
        return solve_static(m, q0=x)
    add("api: solve_static", f"q0={bad}", f, ("error", ["q0"]))
add("api: solve_static", "a load whose time function returns NaN",
    lambda: solve_static(Beam(BE2D(STEEL, SQUARE), 2, 2.0, supports={0: "clamp"},
                              loads=[PointForce((0.0, 1.0), node=-1, time=lambda t: np.nan)])),
    ("error", ["load"]))


def suspect(res):
    return res.status == "failed" or bool(getattr(res, "warnings", None)) or getattr(res, "stable", None) is False


add("api: solve_static", "pin-only B1 cantilever (unstable equilibrium)", lambda: solve_static(b1(2, "pin")),
    ("flag", suspect))
add("api: solve_static", "tip load 1e15 N", lambda: solve_static(b1(4, force=(0.0, 1e15))), ("flag", suspect))
add("api: solve_static", "axial compression 1e11 N", lambda: solve_static(b1(4, force=(-1e11, 0.0))),
    ("flag", suspect))
add("api: solve_static", "B1 clamped (valid)", lambda: solve_static(b1(4)),
    ("flag", lambda r: r.success and not suspect(r)))

# -- monitors -------------------------------------------------------------------------------------------
for arg, bad in [("blowup", 0), ("blowup", -1), ("blowup", float("nan")), ("blowup", "x"), ("stop_on_blowup", "yes")]:
    add("api: monitors", f"EnergyMonitor({arg}={bad!r})", lambda a=arg, b=bad: EnergyMonitor(**{a: b}), ("error", [arg]))
for kw, word in [({"s": -1.0}, "s"), ({"s": float("nan")}, "s"), ({"s": "1"}, "s"),
                 ({"s": 1.0, "function": abs}, "function"), ({}, "s"), ({"function": 1}, "function")]:
    add("api: monitors", f"PointSensor({kw})", lambda k=kw: PointSensor(**k), ("error", [word]))
add("api: monitors", "Probe(function=1)", lambda: Probe("p", 1), ("error", ["function"]))
add("api: monitors", "PointSensor(s=5.0) beyond the beam",
    lambda: simulate(beam(), (0, 0.01), h=0.005, monitors=[PointSensor(s=5.0)]), ("failed", ["s"]))


# -- a user's stepper and callbacks ---------------------------------------------------------------------
class Faulty(Integrator):
    """Explicit Euler (h = 0.005) that turns faulty at its 2nd step."""

    name, fixed_step, fault = "faulty", False, None

    def step(self):
        h, t = 0.005, min(self.t + 0.005, self.t_bound)
        q, v, a = self.q + h * self.v, self.v + h * self.a, self.a.copy()
        if self.n_steps >= 1:
            f = self.fault
            if f == "nan":
                q = q * np.nan
            elif f == "short":
                q = q[:-1]
            elif f == "past_end":
                t = self.t_bound + 1.0
            elif f == "none":
                return None
            elif f == "text_t":
                t = "0.01"
            elif f == "grow":
                q, v = self.q * 1e120, self.v * 1e120
        return StepOutcome(ok=True, t=t, q=q, v=v, a=a)


def faulty_run(fault, **kw):
    m = beam()
    s = Faulty(m)
    s.fault = fault
    return simulate(m, (0.0, 0.02), s, **kw)


for fault in ("nan", "short", "past_end", "none", "text_t"):
    add("stepper and callbacks", f"stepper: {fault}", lambda f=fault: faulty_run(f), ("failed", ["faulty"]))
add("stepper and callbacks", "probe changing shape",
    lambda: faulty_run(None, monitors=[Probe("p", lambda t, q, v, a: q[: 2 + int(t > 0.007)])]),
    ("failed", ["Probe 'p'"]))
add("stepper and callbacks", "hook returning numpy.bool_(True)",
    lambda: faulty_run(None, hooks=[lambda t, q, v, a: np.bool_(True)]),
    ("flag", lambda r: r.success and r.t.size == 2))
add("stepper and callbacks", "hook returning an array",
    lambda: faulty_run(None, hooks=[lambda t, q, v, a: q]), ("failed", ["hook"]))
add("stepper and callbacks", "hook writing into q",
    lambda: faulty_run(None, hooks=[lambda t, q, v, a: q.__setitem__(0, 1e9)]), ("failed", ["read-only"]))


def interrupted():
    def ctrl_c(t, q, v, a):
        if t > 0.012:
            raise KeyboardInterrupt
    try:
        faulty_run(None, hooks=[ctrl_c])
    except KeyboardInterrupt as exc:
        res = getattr(exc, "result", None)
        if res is None:
            raise RuntimeError("KeyboardInterrupt without the run's result") from None
        return res
    return Result(np.zeros(1), np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)))


add("stepper and callbacks", "KeyboardInterrupt in a hook", interrupted, ("failed", ["interrupted"]))


def overflow():
    res = faulty_run("grow", monitors=[EnergyMonitor()])
    log = res.monitors["energy"]
    if log["blow_up"] and log["relative_drift"] == 0.0:
        return Result(res.t, res.q, res.v, res.a)      # a "success" with nothing said: silent
    return Result(res.t, res.q, res.v, res.a, status="failed", message="blow-up reported")


add("stepper and callbacks", "overflowing run: EnergyMonitor relative_drift", overflow, ("failed", ["blow-up"]))

# -- Result objects and files ---------------------------------------------------------------------------
TMP = Path(tempfile.mkdtemp(prefix="bad_inputs_"))
GOOD = simulate(beam(), (0.0, 0.02), h=0.005, monitors=[EnergyMonitor()])
GOOD_FILE = GOOD.save(TMP / "good.nc")
for label, kw in [("q rows != t", dict(t=np.zeros(3), q=np.zeros((2, 4)), v=np.zeros((3, 4)), a=np.zeros((3, 4)))),
                  ("status 'ok'", dict(t=np.zeros(1), q=np.zeros((1, 1)), v=np.zeros((1, 1)), a=np.zeros((1, 1)),
                                       status="ok"))]:
    add("result files", f"Result({label})", lambda k=kw: Result(**k), ("error", ["q" if "rows" in label else "status"]))
add("result files", "save into a missing folder", lambda: GOOD.save(TMP / "nowhere" / "r.nc"), ("error", ["folder"]))
(TMP / "adir.nc").mkdir()
add("result files", "save onto a folder", lambda: GOOD.save(TMP / "adir.nc"), ("error", ["folder"]))
(TMP / "text.nc").write_text("hello")
np.savez(TMP / "old.npz", t=np.zeros(1))
(TMP / "trunc.nc").write_bytes(GOOD_FILE.read_bytes()[:2000])
for name, word in [("missing.nc", "no such"), ("adir.nc", "no such"), ("text.nc", "HDF5"), ("old.npz", "npz"),
                   ("trunc.nc", "trunc")]:
    add("result files", f"load {name}", lambda n=name: Result.load(TMP / n), ("error", [name]))


def edited(kind):
    import xarray as xr
    with xr.open_dataset(GOOD_FILE) as ds:
        ds.load()
    if kind == "dof cut":
        ds = ds.isel(dof=slice(0, 5))
    else:
        ds.attrs["stats"] = ds.attrs["stats"].replace("1", "2")
    path = TMP / f"{kind.replace(' ', '_')}.nc"
    ds.to_netcdf(path, encoding={k: {"fletcher32": True} for k in ds.data_vars if ds[k].dtype.kind == "f"})
    return Result.load(path)


add("result files", "file with its dof dimension cut to 5", lambda: edited("dof cut"), ("error", ["dof_cut.nc"]))
add("result files", "file with an edited stats attribute", lambda: edited("stats"), ("error", ["stats"]))


# -- running the probes ---------------------------------------------------------------------------------
def classify(fn, expect):
    kind = expect[0]
    try:
        out = fn()
    except (ValueError, TypeError, KeyError, IndexError) as exc:
        text = f"{type(exc).__name__}: {exc}"
        if kind == "error":
            clear = isinstance(exc, (ValueError, TypeError)) and all(w in str(exc) for w in expect[1])
            return ("clear error" if clear else "cryptic error"), text
        return ("wrongly refused" if kind == "accept" else "cryptic error"), text
    except Exception as exc:   # noqa: BLE001 - the survey records anything
        return ("wrongly refused" if kind == "accept" else "cryptic error"), f"{type(exc).__name__}: {exc}"
    if kind == "accept":
        return "correct acceptance", ""
    if kind == "error":
        return "silent answer", repr(out)[:120]
    if kind == "failed":
        ok = getattr(out, "status", None) == "failed" and all(w in out.message for w in expect[1])
        return ("flagged" if ok else "silent answer"), getattr(out, "message", repr(out))[:160]
    return ("flagged" if expect[1](out) else "silent answer"), repr(out)[:160]


def flips(n):
    """Flip one bit at n offsets (seeded) of GOOD_FILE; classify each load."""
    data = GOOD_FILE.read_bytes()
    rng = np.random.default_rng(400)
    counts = collections.Counter()
    bad = TMP / "flip.nc"
    for k in rng.choice(len(data), size=min(n, len(data)), replace=False):
        d = bytearray(data)
        d[k] ^= 1 << int(rng.integers(8))
        bad.write_bytes(bytes(d))
        try:
            back = Result.load(bad)
        except ValueError:
            counts["clear error"] += 1
            continue
        except Exception:      # noqa: BLE001
            counts["cryptic error"] += 1
            continue
        same = all(np.array_equal(getattr(back, a), getattr(GOOD, a)) for a in ("t", "q", "v", "a")) and \
            (back.status, back.message, back.stats, back.options, back.model) == \
            (GOOD.status, GOOD.message, GOOD.stats, GOOD.options, GOOD.model) and \
            all(np.array_equal(back.monitors["energy"][k], v, equal_nan=True) if isinstance(v, np.ndarray)
                else back.monitors["energy"][k] == v or (v != v and back.monitors["energy"][k] != back.monitors["energy"][k])
                for k, v in GOOD.monitors["energy"].items())
        counts["identical load" if same else "silent wrong load"] += 1
    return counts
