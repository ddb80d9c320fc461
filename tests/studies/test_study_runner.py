"""The studies' runner keeps every finished case: stored as it finishes, reused, failures isolated, Ctrl-C safe."""
import json
import os
import runpy
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from support import study_toy
from ancfdae.result import Result
from ancfdae.studies import _cli
from ancfdae.studies._common import Case, output_dir, run_cases

HERE = Path(__file__).resolve().parents[1]   # tests/: the folder that holds the support package
_MAIN = "import sys; from support import study_toy; from ancfdae.studies import _cli; sys.exit(_cli.main(study_toy, sys.argv[1:]))"
# A terminal's Ctrl-C: the child gets Python's SIGINT handler even when the test session itself runs in the
# background (where the shell made SIGINT ignored, and children inherit that)
_CTRL_C = "import signal; signal.signal(signal.SIGINT, signal.default_int_handler); " + _MAIN


def test_each_case_is_stored_and_a_rerun_reuses_it(tmp_path):
    res = study_toy.run(out=tmp_path, progress=False)
    assert res["sweep"].reused == 0 and [r["square"] for r in res["sweep"].records] == [0, 1, 4, 9]
    meta = json.loads((tmp_path / "cases" / "case_2.json").read_text())
    assert meta["record"]["square"] == 4 and meta["case"]["i"] == 2
    stored = Result.load(tmp_path / "cases" / meta["file"])          # the library's self-describing format
    assert np.all(stored.q == 2.0) and stored.stats["steps"] == 3
    again = study_toy.run(out=tmp_path, progress=False)
    assert again["sweep"].reused == 4                                 # nothing recomputed ...
    assert [r["square"] for r in again["sweep"].records] == [0, 1, 4, 9]
    assert np.all(again["sweep"].records[3]["result"].q == 3.0)      # ... and the records come from the files
    changed = study_toy.run(out=tmp_path, sleep=0.02, progress=False)
    assert changed["sweep"].reused == 0                               # other options: the cases run again


def test_a_case_that_raises_is_recorded_and_the_others_go_on(tmp_path):
    res = study_toy.run(out=tmp_path, fail=1, progress=False)
    sweep = res["sweep"]
    assert sweep.records[1] is None and list(sweep.errors) == ["case 1"]
    assert sweep.errors["case 1"].startswith("RuntimeError: case 1 is broken (at study_toy.py:")   # where it raised
    assert [r["square"] for r in sweep.finished()] == [0, 4, 9]
    assert "RuntimeError" in json.loads((tmp_path / "cases" / "case_1.json").read_text())["error"]
    again = study_toy.run(out=tmp_path, fail=1, progress=False)
    assert again["sweep"].reused == 3 and "case 1" in again["sweep"].errors    # the failed case is tried again


def test_a_case_that_raises_in_a_worker_is_recorded(tmp_path):
    res = study_toy.run(out=tmp_path, fail=0, jobs=2, progress=False)
    assert list(res["sweep"].errors) == ["case 0"] and len(res["sweep"].finished()) == 3
    error = res["sweep"].errors["case 0"]
    assert "RuntimeError: case 0 is broken" in error and "study_toy.py" in error     # the worker's traceback


class _RecordingExecutor:
    """Runs each submitted case at once, in the caller, and remembers the order of submission."""

    def __init__(self):
        from concurrent.futures import Future
        self.order, self._future = [], Future

    def submit(self, fn, case):
        self.order.append(case["i"])
        fut = self._future()
        fut.set_result(fn(case))
        return fut


def test_an_executor_gets_the_longest_cases_first_and_the_records_keep_their_order():
    # Catches: cases submitted in the given order (a long case started last keeps one worker busy while
    # the other idles: the multibody study's B5 IDA case), records returned in the submission order.
    ex = _RecordingExecutor()
    cases = [Case(i=i, label=f"case {i}") for i in range(4)]
    sweep = run_cases(lambda c: {"square": c["i"] ** 2}, cases, executor=ex, progress=False,
                      cost=lambda c: [1.0, 5.0, 2.0, 9.0][c["i"]])
    assert ex.order == [3, 1, 2, 0]
    assert [r["square"] for r in sweep.records] == [0, 1, 4, 9]


def test_output_folder_checked_before_any_work(tmp_path, monkeypatch, capsys):
    file = tmp_path / "results.txt"
    file.write_text("not a folder")
    calls = []
    with pytest.raises(ValueError, match="`out` must be a folder.*existing file"):
        output_dir("toy", file)
    t0 = time.perf_counter()
    code = _cli.main(study_toy, ["--out", str(file), "--sleep", "5"])
    assert code == 2 and time.perf_counter() - t0 < 2.0               # at once, not after the runs
    err = capsys.readouterr().err.strip()
    assert "existing file" in err and len(err.splitlines()) == 1      # one line, no usage block
    monkeypatch.chdir(tmp_path)
    assert output_dir("toy", quick=True) == Path("out/toy-quick")     # quick never overwrites the full results
    assert output_dir("toy") == Path("out/toy")
    with pytest.raises(ValueError, match="unique labels"):
        run_cases(calls.append, [Case(label="a"), Case(label="a")])


def test_cli_help_states_the_defaults(capsys):
    with pytest.raises(SystemExit):
        _cli.main(study_toy, ["--help"])
    text = " ".join(capsys.readouterr().out.split()).replace("- ", "-")     # argparse wraps at hyphens
    assert "number of cases (default: 4; with --quick: 2)" in text and "out/toy-quick" in text


# runpy warns that the session has imported the study already: harmless, -m starts from a fresh interpreter
@pytest.mark.filterwarnings("ignore:.*found in sys.modules after import of package:RuntimeWarning")
@pytest.mark.parametrize("name", ["cantilever", "energy", "flying2d", "flying3d", "integrators"])
def test_python_dash_m_runs_each_study_under_its_own_name(name, monkeypatch, capsys):
    """Catches a study without the `python -m ancfdae.studies.NAME` entry (energy and integrators had none)
    and a command line that calls the study "__main__" (the __name__ of a module run by -m)."""
    monkeypatch.setattr(sys, "argv", [name, "--help"])
    with pytest.raises(SystemExit) as exc:
        runpy.run_module(f"ancfdae.studies.{name}", run_name="__main__", alter_sys=True)
    assert exc.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: ancfdae study {name} [-h] [--quick]")


def _interrupt(tmp_path, jobs, how="ctrl-c"):
    """Start the toy study in its own session; once 2 cases are stored, Ctrl-C (SIGINT to the process group,
    as a terminal sends it) or ``kill PID`` (SIGTERM to the main process only)."""
    env = dict(os.environ, PYTHONPATH=str(HERE), TOY_SLOW_FROM="2")
    args = [sys.executable, "-c", _CTRL_C, "--out", str(tmp_path), "--sleep", "0.1"]
    if jobs:
        args += ["--jobs", str(jobs)]
    # cwd outside the checkout: `python -c` puts its folder first on sys.path, and a checkout's ancfdae,
    # not installed, has no ancfdae.studies
    proc = subprocess.Popen(args, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, cwd=tmp_path)
    deadline = time.monotonic() + 120
    while len(list((tmp_path / "cases").glob("*.json"))) < 2:
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.1)
    time.sleep(0.5)                                   # the slow cases are running now
    t0 = time.monotonic()
    if how == "ctrl-c":
        os.killpg(proc.pid, signal.SIGINT)
    else:
        os.kill(proc.pid, signal.SIGTERM)
    out, err = proc.communicate(timeout=30)
    return proc.returncode, time.monotonic() - t0, err


def _alive(pid):
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    return "zombie" not in status


@pytest.mark.parametrize("jobs, how", [(None, "ctrl-c"), (2, "ctrl-c"), (2, "kill")])
def test_ctrl_c_stops_within_seconds_keeps_finished_cases_and_exits_130(tmp_path, jobs, how):
    code, seconds, err = _interrupt(tmp_path, jobs, how)
    assert code == 130 and seconds < 10.0, (code, seconds, err)
    assert "Traceback" not in err
    last = [line for line in err.replace("\r", "\n").splitlines() if line.strip()][-1]
    assert "interrupted: 2 of 4 cases finished and kept" in last
    workers = [int(p.name) for p in (tmp_path / "pids").iterdir()]
    time.sleep(0.5)
    assert not any(_alive(pid) for pid in workers), "a worker outlived Ctrl-C"
    # the same command again reuses the two finished cases and runs the other two
    again = subprocess.run([sys.executable, "-c", _MAIN, "--out", str(tmp_path), "--sleep", "0.1"],
                           env=dict(os.environ, PYTHONPATH=str(HERE)), cwd=tmp_path,
                           capture_output=True, text=True, timeout=120)
    assert again.returncode == 0 and "reusing 2 of 4 finished cases" in again.stderr, again.stderr
    assert "| case 3 | 9 |" in again.stdout
