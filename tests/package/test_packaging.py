"""Packaging: a checkout without symlinks builds, every package folder ships, the studies import under one name."""
import re
import shutil
import subprocess
from pathlib import Path

import pytest

import ancfdae.studies
import ancfdae.studies.cantilever

ROOT = Path(__file__).resolve().parents[2]
tomllib = pytest.importorskip("tomllib", reason="tomllib is in the standard library from Python 3.11")


def _pyproject() -> dict:
    with open(ROOT / "pyproject.toml", "rb") as fh:
        return tomllib.load(fh)


def test_the_git_index_holds_no_symlink():
    """Catches a symlink committed again: a checkout without symlinks (the Windows default, a zip download)
    gets a text file in its place, and the build stops ("package directory ... is not a directory")."""
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    listing = subprocess.run(["git", "ls-files", "-s"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    links = [line.split("\t", 1)[1] for line in listing.splitlines() if line.startswith("120000 ")]
    assert not links, f"symlinks in the git index: {links}"


def test_every_package_folder_is_listed_for_the_wheel():
    """Catches a new folder under ancfdae/ (or a study folder) that an editable install imports but a wheel
    leaves out, because setuptools installs only the packages pyproject.toml lists."""
    tool = _pyproject()["tool"]["setuptools"]
    assert tool["package-dir"] == {"ancfdae.studies": "studies"}
    folders = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "ancfdae").rglob("__init__.py")}
    folders |= {"ancfdae.studies" + "".join("." + part for part in p.parent.relative_to(ROOT / "studies").parts)
                for p in (ROOT / "studies").rglob("__init__.py")}
    assert set(tool["packages"]) == folders


def test_the_studies_import_as_ancfdae_studies_only():
    """Catches a test, benchmark or study importing the top-level folder as `studies`: the same files would
    load a second time under another module name (two sets of globals), and fail on an installed package."""
    assert ancfdae.studies.cantilever.__name__ == "ancfdae.studies.cantilever"
    assert Path(ancfdae.studies.__file__).parent == Path(ancfdae.studies.cantilever.__file__).parent
    bare = re.compile(r"^\s*(from|import)\s+studies\b", flags=re.M)
    hits = [str(p.relative_to(ROOT)) for base in ("tests", "benchmarks", "studies", "ancfdae", "docs")
            for p in (ROOT / base).rglob("*.py") if bare.search(p.read_text())]
    assert not hits, f"`studies` imported by its folder name in {hits}"
