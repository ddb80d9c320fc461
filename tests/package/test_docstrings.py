"""Documentation rules: every public name has a numpydoc docstring; no reference to files outside the repository.

Catches: a new public function without a docstring, a Parameters section that drifted from the signature
(a renamed or added argument), a section numpydoc does not know (it would vanish from the API pages), a
docstring or comment pointing at design notes that users of the package cannot see, and a public name
missing from the API reference page.
"""
import importlib
import inspect
import pkgutil
import re
import warnings
from pathlib import Path

import pytest
from numpydoc.docscrape import ClassDoc, FunctionDoc

import ancfdae

ROOT = Path(__file__).resolve().parents[2]
MODULES = ["ancfdae", "ancfdae.models", "ancfdae.integrators", "ancfdae.export", "ancfdae.plot", "ancfdae.cli"]
# Dataclass-generated and protocol plumbing that carries no documentation of its own.
SKIP_METHODS = {"__init__", "__post_init__", "__repr__"}


def _public_objects():
    seen = {}
    for modname in MODULES:
        mod = importlib.import_module(modname)
        for name in getattr(mod, "__all__", []):
            obj = getattr(mod, name)
            if inspect.isclass(obj) or inspect.isfunction(obj):
                seen.setdefault(f"{obj.__module__}.{obj.__qualname__}", (f"{modname}.{name}", obj))
    return sorted(seen.values())


PUBLIC = _public_objects()


def _methods(cls):
    for name, member in vars(cls).items():
        if name.startswith("_"):
            continue
        if isinstance(member, (staticmethod, classmethod)):
            member = member.__func__
        if inspect.isfunction(member) or isinstance(member, property):
            yield name, member


def _parse(obj, kind):
    with warnings.catch_warnings():
        warnings.simplefilter("error")        # numpydoc warns on unknown sections
        return kind(obj) if kind is ClassDoc else FunctionDoc(obj)


def _signature_params(func, drop_self):
    try:
        params = list(inspect.signature(func).parameters.values())
    except (TypeError, ValueError):
        return []
    if drop_self and params and params[0].name in ("self", "cls"):
        params = params[1:]
    return [p.name for p in params]


def _documented(doc, sections=("Parameters", "Other Parameters")):
    names = set()
    for section in sections:
        for p in doc[section]:
            for n in p.name.split(","):
                names.add(n.strip().lstrip("*"))
    return names


@pytest.mark.parametrize("qualname, obj", PUBLIC, ids=[q for q, _ in PUBLIC])
def test_public_name_has_numpydoc_docstring(qualname, obj):
    assert inspect.getdoc(obj), f"{qualname} has no docstring"
    if inspect.isclass(obj):
        doc = _parse(obj, ClassDoc)
        protocol = getattr(obj, "_is_protocol", False)     # a Protocol's __init__ is typing's
        init = obj.__init__ if "__init__" in vars(obj) and not protocol else None
        params = _signature_params(init, True) if init is not None else []
        if not params and hasattr(obj, "__dataclass_fields__"):
            params = [f for f in obj.__dataclass_fields__ if not f.startswith("_")]
        documented = _documented(doc, ("Parameters", "Other Parameters", "Attributes"))
    else:
        doc = _parse(obj, FunctionDoc)
        params = _signature_params(obj, False)
        documented = _documented(doc)
    assert doc["Summary"], f"{qualname}: no one-line summary"
    missing = [p for p in params if p not in documented]
    assert not missing, f"{qualname}: parameters {missing} are not in its Parameters section"
    if inspect.isclass(obj):
        for name, member in _methods(obj):
            if name in SKIP_METHODS:
                continue
            target = member.fget if isinstance(member, property) else member
            assert inspect.getdoc(target), f"{qualname}.{name} has no docstring"
            mdoc = _parse(target, FunctionDoc)
            stale = _documented(mdoc) - set(_signature_params(target, True))
            assert not stale, f"{qualname}.{name}: documents parameters {sorted(stale)} it does not take"


def _sources():
    for base in ("ancfdae", "studies"):
        yield from sorted((ROOT / base).rglob("*.py"))


def test_no_reference_to_files_outside_the_repository():
    pattern = re.compile(r"design\.md|benchmarks\.md|notes/")
    hits = [f"{path.relative_to(ROOT)}:{i}" for path in _sources()
            for i, line in enumerate(path.read_text().splitlines(), 1) if pattern.search(line)]
    assert not hits, f"references to design.md/benchmarks.md/notes/: {hits}"


def test_every_public_name_is_in_the_api_reference():
    text = (ROOT / "docs" / "api.rst").read_text()
    listed = set(re.findall(r"^   ([\w.]+)$", text, flags=re.M))
    constants = {"METHODS", "LOBATTO_IIIA_2", "LOBATTO_IIIA_3"}
    missing = [q for q, obj in PUBLIC if q.split(".")[-1] not in listed and q.split(".", 1)[-1] not in listed]
    missing += [c for c in constants if c not in text]
    assert not missing, f"not in docs/api.rst: {missing}"


def test_every_module_imports_and_py_typed_ships():
    assert (ROOT / "ancfdae" / "py.typed").exists()
    for info in pkgutil.walk_packages(ancfdae.__path__, "ancfdae."):
        if info.name.startswith("ancfdae.studies") or info.name == "ancfdae.__main__":
            continue
        importlib.import_module(info.name)
