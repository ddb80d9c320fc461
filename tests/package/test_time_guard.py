"""The per-test time guard of conftest.py fails a hanging test instead of hanging the suite."""
import os
import subprocess
import sys
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]


def test_a_hanging_test_fails_after_the_limit(tmp_path):
    """Catches the audit's director-update mutant that made a test run forever (no guard, no max_steps)."""
    (tmp_path / "conftest.py").write_text((TESTS / "conftest.py").read_text())
    (tmp_path / "test_hang.py").write_text("import time\n\ndef test_hangs():\n    while True:\n        time.sleep(0.01)\n")
    env = dict(os.environ, ANCFDAE_TEST_TIMEOUT="1.5")
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(tmp_path)],
                          capture_output=True, text=True, timeout=120, env=env, cwd=tmp_path)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "TestTimeout" in proc.stdout and "ran longer than 1.5 s" in proc.stdout
