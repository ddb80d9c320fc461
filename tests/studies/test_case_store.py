"""The study case store reuses a case only when it is the same computation, intact; otherwise it says why."""
import json

import numpy as np

from support import study_toy
from ancfdae.studies._common import Case
from ancfdae.studies._store import CaseStore
from ancfdae.result import Result


def _first(tmp_path):
    meta = json.loads((tmp_path / "cases" / "case_1.json").read_text())
    return meta, tmp_path / "cases" / meta["file"]


def test_a_flipped_bit_in_a_stored_result_is_recomputed_and_said(tmp_path, capsys):
    """Catches the audit's flipped bit in a stored case reused silently (eps_T changed without a word)."""
    study_toy.run(out=tmp_path, progress=False)
    _, file = _first(tmp_path)
    data = bytearray(file.read_bytes())
    at = bytes(data).find(np.full(2, 1.0).tobytes())   # q = 1.0 of case 1
    data[at + 7] ^= 0x01                                 # 1.0 -> 1.0000000000000002 if it were read
    file.write_bytes(bytes(data))
    capsys.readouterr()
    again = study_toy.run(out=tmp_path, progress=False)
    err = capsys.readouterr().err
    assert again["sweep"].reused == 3 and "case 'case 1'" in err and "computing it again" in err
    assert np.all(again["sweep"].records[1]["result"].q == 1.0)


def test_a_result_file_left_by_an_interrupted_run_with_other_options_is_not_reused(tmp_path, capsys):
    """Catches the audit's hole: options A stored, options B overwrote the file and died before its record,
    options A again reused B's file. The file name carries the key and the record the file's SHA-256."""
    study_toy.run(out=tmp_path, progress=False)
    meta, file = _first(tmp_path)
    other = Result(np.linspace(0, 1, 3), np.full((3, 2), 7.0), np.zeros((3, 2)), np.zeros((3, 2)))
    other.save(file)                                     # what the interrupted run wrote under the same name
    capsys.readouterr()
    again = study_toy.run(out=tmp_path, progress=False)
    assert "is not the one its record was written with" in capsys.readouterr().err
    assert again["sweep"].reused == 3 and np.all(again["sweep"].records[1]["result"].q == 1.0)
    changed = study_toy.run(out=tmp_path, sleep=0.02, progress=False)
    files = sorted(p.name for p in (tmp_path / "cases").glob("case_1-*.nc"))
    assert changed["sweep"].reused == 0 and len(files) == 2      # other options: another file, none overwritten


def test_an_edited_record_or_another_definition_is_recomputed(tmp_path, capsys):
    study_toy.run(out=tmp_path, progress=False)
    path = tmp_path / "cases" / "case_1.json"
    meta = json.loads(path.read_text())
    meta["record"]["square"] = 2                         # hand-edited: the digest no longer matches
    path.write_text(json.dumps(meta))
    capsys.readouterr()
    again = study_toy.run(out=tmp_path, progress=False)
    assert "does not match its digest" in capsys.readouterr().err
    assert again["sweep"].reused == 3 and again["sweep"].records[1]["square"] == 1
    store = CaseStore(tmp_path, study_toy.case_fn)
    case = Case(json.loads(path.read_text())["case"])
    assert store.load(case) is not None
    store.definition = "changed code"                    # the case function's module changed
    assert store.load(case) is None and "another definition" in store.notes[-1]
