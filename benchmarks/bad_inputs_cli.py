"""The command-line part of the bad-input probe, and the probe's main: ``python benchmarks/bad_inputs_cli.py``.

Runs the API and result-file probes of ``bad_inputs.py`` in this process, then ``python -m ancfdae``
in subprocesses: export and animate with bad output paths and options, every study with zero or
negative sizes (each must refuse before computing: within the time limit and without creating its
output folder), the unknown study, ``--jobs`` on the serial study. Prints the counts per class and
outcome and the probes that did not give the expected outcome.

Options: ``--flips N`` (bit flips of a result file, default 400), ``--skip-cli``, ``--timeout S``
(seconds a study may take to refuse, default 40).
"""
from __future__ import annotations

import argparse
import collections
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bad_inputs as bi  # noqa: E402

STUDY_OPTIONS = {"cantilever": [["--n-elements", "0"], ["--repeats", "0"], ["--n-elements", "-2"]],
                 "energy": [["--n", "0"], ["--h", "-1"], ["--t-end-b2", "0"], ["--t-end-b3", "-1"]],
                 "flying2d": [["--n-elements", "0"], ["--n-ref", "-2"], ["--h", "0"], ["--t-end", "nan"]],
                 "flying3d": [["--be-meshes", "0"], ["--t-end", "-1"], ["--h", "0"], ["--sq-meshes", "-4"]],
                 "integrators": [["--steps", "0"], ["--n", "0"], ["--t-end", "-1"], ["--rtols", "-0.5"]]}


def cli_probes(tmp: Path, good: Path):
    """(label, argv, words that the one-line message must hold, folder that must not be created)."""
    (tmp / "afile").write_text("x")
    (tmp / "adir").mkdir(exist_ok=True)
    out = [("export vtk into an existing file", ["export", "vtk", good, tmp / "afile"], ["directory"], None),
           ("export vtk into an uncreatable folder", ["export", "vtk", good, "/proc/nope"], ["directory"], None),
           ("export vtk --name a/b", ["export", "vtk", good, tmp / "adir", "--name", "a/b"], ["name"], None),
           ("export vtk --name ''", ["export", "vtk", good, tmp / "adir", "--name", ""], ["name"], None),
           ("export vtk --every 0", ["export", "vtk", good, tmp / "adir", "--every", "0"], ["every"], None),
           ("export vtk --every x", ["export", "vtk", good, tmp / "adir", "--every", "x"], ["every", "'x'"], None),
           ("export vtk of a missing file", ["export", "vtk", tmp / "missing.nc", tmp / "adir"], ["missing.nc"], None),
           ("animate into a folder", ["animate", good, tmp / "adir"], ["path"], None),
           ("animate into a missing folder", ["animate", good, tmp / "no" / "x.gif"], ["path"], None),
           ("animate to out.txt", ["animate", good, tmp / "out.txt"], ["path"], None),
           ("animate --fps 0", ["animate", good, tmp / "x.gif", "--fps", "0"], ["fps"], None),
           ("animate a text file", ["animate", tmp / "afile", tmp / "x.gif"], ["afile"], None),
           ("unknown study", ["study", "nothing"], ["nothing"], None),
           ("study cantilever --jobs 2", ["study", "cantilever", "--jobs", "2"], ["jobs", "serial"], None),
           ("study integrators --jobs 0", ["study", "integrators", "--jobs", "0"], ["jobs"], None)]
    for name, options in STUDY_OPTIONS.items():
        for opt in options:
            folder = tmp / f"out_{name}_{opt[0][2:]}"
            out.append((f"study {name} --quick {' '.join(opt)}", ["study", name, "--quick", "--out", folder, *opt],
                        [opt[0]], folder))
    return out


def run_cli(argv, words, folder, timeout):
    try:
        proc = subprocess.run([sys.executable, "-m", "ancfdae", *map(str, argv)], capture_output=True, text=True,
                              timeout=timeout)
    except subprocess.TimeoutExpired:
        return "silent answer", f"still computing after {timeout:g} s"
    text = (proc.stderr + proc.stdout).strip()
    if proc.returncode == 0:
        return "silent answer", f"exit 0: {text[-160:]}"
    if "Traceback" in text:
        return "cryptic error", text.splitlines()[-1][:160]
    if folder is not None and Path(folder, "cases").exists():
        return "silent answer", f"computed before refusing: {text.splitlines()[-1][:160]}"
    last = text.splitlines()[-1] if text else ""
    return ("clear error" if all(w in last for w in words) else "cryptic error"), last[:160]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--flips", type=int, default=400)
    p.add_argument("--skip-cli", action="store_true")
    p.add_argument("--timeout", type=float, default=40.0)
    args = p.parse_args(argv)
    table = collections.defaultdict(collections.Counter)
    odd = []
    for cls, label, fn, expect in bi.PROBES:
        outcome, text = bi.classify(fn, expect)
        table[cls][outcome] += 1
        if outcome not in ("clear error", "correct acceptance", "flagged"):
            odd.append((cls, label, outcome, text))
    if not args.skip_cli:
        for label, argv_, words, folder in cli_probes(bi.TMP, bi.GOOD_FILE):
            outcome, text = run_cli(argv_, words, folder, args.timeout)
            table["cli"][outcome] += 1
            if outcome != "clear error":
                odd.append(("cli", label, outcome, text))
    total = collections.Counter()
    print(f"{'class':28s} {'probes':>6s}  outcomes")
    for cls, counts in table.items():
        total.update(counts)
        print(f"{cls:28s} {sum(counts.values()):6d}  " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    print(f"{'all':28s} {sum(total.values()):6d}  " + ", ".join(f"{k} {v}" for k, v in sorted(total.items())))
    flips = bi.flips(args.flips)
    print(f"\nresult file ({bi.GOOD_FILE.stat().st_size} bytes), one bit flipped at {sum(flips.values())} offsets: "
          + ", ".join(f"{k} {v}" for k, v in sorted(flips.items())))
    print("\nprobes without the expected outcome:")
    for cls, label, outcome, text in odd:
        print(f"  [{cls}] {label}: {outcome}: {text}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
