import math

import numpy as np
import pytest

from cushion_clutch.launch.fleet.engagements import EngagementCycle


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


CRASH_SCRIPT = r'''
import sys
import numpy as np
from fmpy import simulate_fmu
from cushion_clutch.launch.fleet.engagements import simulate
from cushion_clutch.launch.plant.fmu_client import ClutchFmu

fmu = sys.argv[1]
sig = np.array([(0.0, np.nan), (1.0, np.nan)], dtype=[("time", float), ("x_to", float)])
try:                                   # a custom logger, freed after the run; the NaN input is refused (Discard
    simulate_fmu(fmu, input=sig, stop_time=1.0, logger=lambda *args: None)  # on the read: fmpy raises)
except Exception as exc:
    print(type(exc).__name__)
import gc; gc.collect()
for run in (lambda: ClutchFmu(fmu, {"theta_cs_start": 20.0}), lambda: simulate(fmu, n_engagements=1,
                                                                              start_values={"theta_cs_start": 20.0})):
    try:
        run()                    # the FMU logs its refusal through fmpy's default callbacks
    except Exception as exc:     # refused at initialisation, with the message
        print(type(exc).__name__)
print("alive")
'''


@pytest.mark.fmu
def test_project_fmpy_code_survives_an_earlier_custom_logger(tmp_path):
    """fmpy's global logger proxy: after ``simulate_fmu(logger=...)`` a later instance with fmpy's default callbacks
    calls a freed logger as soon as the FMU logs (a segfault); the launch client and ``simulate`` re-point it first
    (:func:`cushion_clutch.fmpy_logger.restore_fmpy_logger`). Run in a child process: a crash kills only it."""
    import subprocess
    import sys

    from native_builds import native_fmus

    script = tmp_path / "crash.py"
    script.write_text(CRASH_SCRIPT)
    r = subprocess.run([sys.executable, str(script), str(native_fmus()[2])], capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0 and r.stdout.rstrip().endswith("alive"), (r.returncode, r.stdout[-2000:], r.stderr[-2000:])
    assert "did you mean 293.15 K (20 degC)?" in r.stdout, r.stdout[-2000:]
