"""The observed-order rule of the studies (studies/_orders.py): orders only from asymptotic runs."""
import math

import numpy as np
import pytest

from ancfdae.studies._orders import asymptotic_order


def test_an_exact_power_law_gives_its_order():
    # Catches: a slope of log h against log error (1/p), a sign slip, natural vs base-10 mix-ups.
    h = np.array([0.1, 0.05, 0.025])
    order, local = asymptotic_order(zip(h, 3.0 * h ** 2))
    assert order == pytest.approx(2.0, abs=1e-12)
    assert local == pytest.approx([2.0, 2.0], abs=1e-12)


def test_a_single_pair_is_no_order():
    # Catches: the B6 energy-collocation "7.1" (errors 1.39e-3, 9.89e-6 at 8e-4, 4e-4; the 2e-4 run at
    # the reference's floor 8.4e-7 left out): one pair cannot show it is asymptotic.
    pts = [(8e-4, 1.39e-3), (4e-4, 9.89e-6), (2e-4, 8.42e-7)]
    order, local = asymptotic_order(pts, floor=8.4e-7)
    assert order is None
    assert local == pytest.approx([math.log2(1.39e-3 / 9.89e-6)])
    # with the floor ignored the three runs give local orders 7.1 and 3.6, which disagree: still no order
    order, local = asymptotic_order(pts)
    assert order is None and len(local) == 2


def test_the_pre_asymptotic_coarse_run_is_left_out_of_the_fit():
    # Catches: a fit over every run (the coarsest, saturated, pulls the slope below 4).
    h = np.array([0.4, 0.2, 0.1, 0.05])
    e = np.where(h > 0.3, 0.02, 7.0 * h ** 4)     # the coarsest saturated: local order 0.8
    order, local = asymptotic_order(zip(h, e))
    assert order == pytest.approx(4.0, abs=1e-12)
    assert local[0] < 3.0


def test_a_method_that_does_not_converge_has_no_order():
    # Catches: an "order" reported for errors that stagnate or grow (B7's second-order methods at the
    # unresolved axial vibration: 3.2e-3, 1.1e-3, 1.2e-3), or for local orders of opposite signs.
    assert asymptotic_order([(0.02, 1e-3), (0.01, 1e-3), (0.005, 1e-3)])[0] is None
    assert asymptotic_order([(0.02, 3.21e-3), (0.01, 1.07e-3), (0.005, 1.19e-3)])[0] is None
    assert asymptotic_order([(0.02, 1e-3), (0.01, 2e-3), (0.005, 4e-3)])[0] is None


def test_failed_runs_and_runs_at_the_floor_are_left_out():
    # Catches: NaN errors of failed runs entering the fit, the floor compared the wrong way round.
    pts = [(0.2, float("nan")), (0.1, 4e-2), (0.05, 1e-2), (0.025, 2.5e-3), (0.0125, 1e-5)]
    order, local = asymptotic_order(pts, floor=1e-5)
    assert order == pytest.approx(2.0, abs=1e-12)
    assert len(local) == 2


def test_the_agreement_tolerance():
    # Catches: a tolerance so tight that B6's index-3 multipliers (local orders 1.74, 2.03) get no order,
    # or so loose that 2.3 and 0.6 (B7 energy-momentum) agree.
    h = np.array([8e-4, 4e-4, 2e-4])
    order, _ = asymptotic_order(zip(h, [6.06e-2, 1.82e-2, 4.47e-3]))
    assert order == pytest.approx(1.88, abs=0.01)
    assert asymptotic_order([(0.02, 8.36e-3), (0.01, 1.69e-3), (0.005, 1.12e-3)])[0] is None


def test_a_bad_floor_is_refused():
    with pytest.raises(ValueError, match="floor"):
        asymptotic_order([(0.1, 1.0), (0.05, 0.25)], floor=float("nan"))
