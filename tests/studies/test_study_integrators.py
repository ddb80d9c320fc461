"""The integrators study in quick mode: a stable work-precision ordering and the observed orders."""
import pytest

from ancfdae.studies import integrators


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("integrators")
    return integrators.run(quick=True, out=out, jobs=2, progress=False)


def _eps(quick, method):
    return {r["h"] if method != "ida" else r["rtol"]: r["eps_T"] for r in quick["rows"]
            if r["method"] == method and r["model"] == "B2"}


def test_observed_orders(quick):
    o = quick["orders"]["B2"]
    for m in ("lobatto3", "lobatto3-full"):
        assert 3.8 < o[m] < 4.2
    for m in ("lobatto2", "lobatto2-full", "newmark", "hht", "generalized-alpha"):
        assert 1.9 < o[m] < 2.1


def test_work_precision_ordering_is_stable(quick):
    l3, l2, nm, hht, ga = (_eps(quick, m) for m in ("lobatto3", "lobatto2", "newmark", "hht", "generalized-alpha"))
    for h in (1e-2, 5e-3, 2.5e-3):
        assert l3[h] < 1e-2 * l2[h]                          # order 4 against order 2 at equal h
        assert nm[h] == pytest.approx(l2[h], rel=1e-4)       # Newmark 1/4, 1/2 is the trapezoidal rule
        assert l2[h] < min(hht[h], ga[h])                    # numerical dissipation adds error (B2 rev. 2: 1-2 %)
    # Lobatto3 at the coarsest step beats every second-order method at the finest
    assert l3[1e-2] < 0.1 * min(l2[2.5e-3], nm[2.5e-3], hht[2.5e-3], ga[2.5e-3])
    ida = _eps(quick, "ida")
    assert ida[1e-7] < ida[1e-5] / 10


def test_modified_and_full_newton_agree_and_count_their_work(quick):
    rows = {(r["method"], r["h"]): r for r in quick["rows"] if r["method"].startswith("lobatto")}
    for s in ("lobatto3", "lobatto2"):
        for h in (1e-2, 5e-3, 2.5e-3):
            mod, full = rows[(s, h)], rows[(s + "-full", h)]
            assert mod["eps_T"] == pytest.approx(full["eps_T"], rel=1e-2)
            assert full["lu_per_step"] >= 1.0                # full Newton: one LU per iteration
            assert mod["lu_per_step"] < 0.1                   # modified: the LU is reused across steps
            assert mod["its_per_step"] >= full["its_per_step"]


def test_writes_table_and_figure(quick):
    assert "Observed order" in (quick["path"] / "integrators.md").read_text()
    assert (quick["path"] / "work_precision.png").is_file() and (quick["path"] / "work_precision.svg").is_file()
    work, equal_h = quick["figures"]["work_precision"].axes
    assert work.get_xlabel() == "CPU time (s)" and equal_h.get_xlabel() == "step h (s)"
    labels = [ln.get_label() for ln in equal_h.get_lines()]
    assert f"lobatto3 (fitted order {quick['orders']['B2']['lobatto3']:.2f})" in labels
    # Newmark and Lobatto IIIA-2 coincide (the same scheme): drawn with different markers, both present
    markers = {ln.get_label().split(" ")[0]: ln.get_marker() for ln in work.get_lines()}
    assert markers["newmark"] != markers["lobatto2"] and "ida" in markers


def test_rejects_unknown_method():
    with pytest.raises(ValueError, match="methods"):
        integrators.run(methods=["euler"], quick=True, plots=False, progress=False)


def test_sweeps_run_through_any_executor(quick):
    """A concurrent.futures executor (or Dask's ``Client().get_executor()``) drives the sweep."""
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=2) as ex:
        res = integrators.run(quick=True, methods=["lobatto3"], rtols=(), executor=ex, plots=False, progress=False)
    assert {r["h"]: r["eps_T"] for r in res["rows"]} == _eps(quick, "lobatto3")   # same as the process pool
    assert 3.8 < res["orders"]["B2"]["lobatto3"] < 4.2
