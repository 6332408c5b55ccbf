import math

import numpy as np
import pytest

from cushion_clutch.launch.engagements import EngagementCycle


def test_facing_temperature_is_the_exact_piecewise_solution():
    c = EngagementCycle()
    tau = c.facing_capacity_J_per_K / c.facing_loss_W_per_K
    hot = c.slip_power_W / c.facing_loss_W_per_K
    # first slip phase from ambient: theta = hot (1 - exp(-t/tau))
    t = np.array([0.5, 1.0, c.slip_time_s])
    assert c.facing_temperature(t) - c.theta_a_K == pytest.approx(hot * (1 - np.exp(-t / tau)), rel=1e-12)
    # then exponential cooling
    end = hot * (1 - math.exp(-c.slip_time_s / tau))
    t2 = np.array([10.0, 59.0])
    expected = end * np.exp(-(t2 - c.slip_time_s) / tau)
    assert c.facing_temperature(t2) - c.theta_a_K == pytest.approx(expected, rel=1e-12)


def test_default_cycle_reaches_the_papers_band():
    c = EngagementCycle()
    t = np.arange(0.0, 12 * 60.0, 0.5)
    theta = c.facing_temperature(t) - 273.15
    last = t >= 11 * 60.0
    assert 200.0 <= theta[last].min() and theta[last].max() <= 300.0


def test_bearing_ramps_holds_and_opens():
    c = EngagementCycle()
    x = c.bearing_position(np.array([0.0, 1.0, 2.0, 10.0, 30.0, 60.5]))
    assert x == pytest.approx([0.0, 0.5 * c.x_to_closed_m, c.x_to_closed_m, c.x_to_closed_m, 0.0,
                               0.25 * c.x_to_closed_m])
