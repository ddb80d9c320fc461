"""Typing rule: every public function and method carries parameter and return annotations.

Catches: a new public function or method (or a new argument of an existing one) added without a type
annotation, so that ``py.typed`` would promise types the package does not give to a type checker or an IDE.
Walks the same public names as ``tests/package/test_docstrings.py`` and, for classes, their public methods and
properties, including those inherited from the package's own mixins and base classes.
"""
import inspect

import pytest

from test_docstrings import PUBLIC, SKIP_METHODS

# ``__init__`` of a dataclass is generated from annotated fields; a hand-written one is checked below.
_SKIP = SKIP_METHODS - {"__init__"}


def _own_methods(cls):
    """Public methods/properties of ``cls`` defined in the package (its own or from ancfdae bases)."""
    seen = set()
    for klass in cls.__mro__:
        if not klass.__module__.startswith("ancfdae"):
            continue
        for name, member in vars(klass).items():
            if name in seen or (name.startswith("_") and name != "__init__") or name in _SKIP:
                continue
            seen.add(name)
            if isinstance(member, (staticmethod, classmethod)):
                member = member.__func__
            if isinstance(member, property):
                # the getter and, where there is one, the setter
                members = [m for m in (member.fget, member.fset) if m is not None]
            else:
                members = [member]
            for func in members:
                if not (inspect.isfunction(func) and func.__module__.startswith("ancfdae")):
                    continue
                if name == "__init__" and (hasattr(klass, "__dataclass_fields__")
                                           or getattr(klass, "_is_protocol", False)):
                    continue
                yield f"{klass.__name__}.{name}", func


def _targets():
    out = {}
    for qualname, obj in PUBLIC:
        if inspect.isclass(obj):
            for name, func in _own_methods(obj):
                key = f"{func.__module__}.{func.__qualname__}"
                out.setdefault(key if key not in out or out[key] is func else key + ".setter", func)
        elif inspect.isfunction(obj):
            out.setdefault(f"{obj.__module__}.{obj.__qualname__}", obj)
    return sorted(out.items())


TARGETS = _targets()


def _missing(func):
    sig = inspect.signature(func)
    missing = []
    params = list(sig.parameters.values())
    for i, p in enumerate(params):
        if i == 0 and p.name in ("self", "cls"):
            continue
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            continue
        if p.annotation is inspect.Parameter.empty:
            missing.append(p.name)
    if sig.return_annotation is inspect.Signature.empty:
        missing.append("return")
    return missing


def test_the_walk_finds_the_public_api():
    # A broken walk (empty list, or one that skips methods inherited from the package's base classes or
    # property setters) would make the annotation test pass vacuously.
    assert len(TARGETS) > 100
    names = {q for q, _ in TARGETS}
    assert "ancfdae.models.beam.beam.Beam.potential_gradient" in names
    assert "ancfdae.models.element.Element.kernel.setter" in names


def test_the_check_sees_a_missing_annotation():
    def f(self, a: int, b, *args, c=1, **kwargs) -> None:
        """Unannotated ``b`` and ``c``."""

    def g(x: int):
        """No return annotation."""

    assert _missing(f) == ["b", "c"]
    assert _missing(g) == ["return"]


@pytest.mark.parametrize("qualname, func", TARGETS, ids=[q for q, _ in TARGETS])
def test_public_callable_is_annotated(qualname, func):
    missing = _missing(func)
    assert not missing, f"{qualname}: no annotation on {missing}"
