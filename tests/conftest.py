"""Shared fixtures (B1 material and section) and the per-test time guard. Helpers live in the ``support``
package (tests/support)."""
import os
import signal
import threading

import pytest

from ancfdae import Material, RectangularSection


@pytest.fixture
def steel():
    """B1 material: E = 2.07e11, nu = 0.3 (chapter Sect. 5.1), rho = 7800 (steel; statics do not use it)."""
    return Material(E=2.07e11, nu=0.3, rho=7800.0)


@pytest.fixture
def square():
    """B1 section: square of side 0.1 m."""
    return RectangularSection(0.1)


# -- a time guard on every test: a bug must fail its test, not hang the suite -------------------------
#: seconds a test may take (wall clock) before it fails; ANCFDAE_TEST_TIMEOUT overrides it (0: no guard).
#: Generous: see tests/README.md for the slowest tests measured; a cold numba cache adds the compilation of
#: a whole element family to its first test.
TEST_TIMEOUT = float(os.environ.get("ANCFDAE_TEST_TIMEOUT", "1200"))


class TestTimeout(Exception):
    """A test ran longer than TEST_TIMEOUT (raised into it by SIGALRM)."""

    __test__ = False          # not a test class for pytest's collector


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item):
    """Arm a SIGALRM timer around the test's call (main thread, POSIX); compiled code is interrupted
    once it returns to Python."""
    usable = TEST_TIMEOUT > 0 and hasattr(signal, "setitimer") and \
        threading.current_thread() is threading.main_thread()
    if not usable:
        yield
        return

    def expire(signum, frame):
        raise TestTimeout(f"{item.nodeid} ran longer than {TEST_TIMEOUT:g} s (ANCFDAE_TEST_TIMEOUT): a hang or an "
                          "endless loop (e.g. a run without max_steps whose steps never reach the end)")
    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, TEST_TIMEOUT)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
