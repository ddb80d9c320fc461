"""``docs/own_integrator.md`` runs as written and prints what it says.

Catches: a page whose example no longer runs against the base classes (a renamed hook, a changed
``initialize`` or ``StepOutcome``), and a page whose stated results drifted from the code -- every
``print(...)  # expected`` line of its python blocks is compared with what the code prints, e.g. the
symplectic Euler's measured order 1.00 and the counters that the base class keeps for it.
"""
import contextlib
import io
import re
from pathlib import Path

PAGE = Path(__file__).resolve().parents[2] / "docs" / "own_integrator.md"


def _blocks(text):
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def _claims(code):
    """The expected output of each top-level ``print(...)  # expected`` line, in order."""
    return [line.rsplit("#", 1)[1].strip() for line in code.splitlines()
            if line.startswith("print(") and "#" in line]


def test_the_page_runs_and_prints_what_it_claims():
    blocks = _blocks(PAGE.read_text())
    assert len(blocks) >= 4, "the page lost its examples"
    namespace, claims, printed = {"__name__": "own_integrator_page"}, [], []
    for code in blocks:
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(compile(code, str(PAGE), "exec"), namespace)    # noqa: S102 - the page's own code
        claims += _claims(code)
        printed += out.getvalue().splitlines()
    assert claims and printed == claims
    # the example is a FixedStepIntegrator with nothing but _step_impl: the grid is the base's
    se = namespace["SymplecticEuler"]
    assert {k for k in vars(se) if not k.startswith("__")} - {"_abc_impl"} == {"name", "order", "_step_impl"}
