"""The native FMUs (FMI 2.0 and 3.0, all platforms) built once per test session, shared by test modules."""
from __future__ import annotations

import atexit
import functools
import shutil
import tempfile
from pathlib import Path

import pytest

from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model import ClutchParameters, load_table, outputs, thermal_step


@functools.cache
def native_fmus() -> dict[int, Path]:
    """{2: FMI 2.0 FMU, 3: FMI 3.0 FMU} of the default tables, every platform's binary inside."""
    tmp = Path(tempfile.mkdtemp(prefix="cushion_native_tests_"))
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)
    return {v: build_fmu(DEFAULT_TABLES, tmp / f"fmi{v}.fmu", fmi_version=v) for v in (2, 3)}


def model_final(steps: int, h: float) -> list[float]:
    """The Python model after the hosts' fixed input sequence: [torque N.m, force N, theta_cs K, u_f m, x_kiss m]."""
    table, p = load_table(), ClutchParameters()
    theta = p.theta_cs_start
    for k in range(steps):
        x = 0.003 + 0.005 * ((k * 7919) % 1000) / 1000.0
        th = 300.0 + 300.0 * ((k * 104729) % 1000) / 1000.0
        theta = thermal_step(theta, th, h, p)
    o = outputs(x, theta, table, p, theta_cm=th)        # the FMU grows the stack at its input theta_cm
    return [o.torque, o.force, theta, o.u_f, o.x_kiss]


def assert_final_matches_model(got: list[float], steps: int, h: float, context: object = "") -> None:
    """The hosts' final outputs equal :func:`model_final` to what the two solvers can agree on.

    The C cover and ``cover.py`` both stop at a 1e-15 m residual of the bearing position, with different
    iterations (Halley in C, Newton in Python), so forces and torques agree to 1e-11 relative or 1e-9 N
    (1e-10 N.m for the torque, about n mu R_eq times 1e-9 N), positions to 4e-15 m (tests/test_native_speed.py states why),
    theta_cs (the same exponential step) to 1e-12 relative.
    """
    want = model_final(steps, h)
    torque, force, theta, u_f, x_kiss = want
    assert got[0] == pytest.approx(torque, rel=1e-11, abs=1e-10), context
    assert got[1] == pytest.approx(force, rel=1e-11, abs=1e-9), context
    assert got[2] == pytest.approx(theta, rel=1e-12), context
    assert abs(got[3] - u_f) <= 4e-15 and abs(got[4] - x_kiss) <= 4e-15, (context, got, want)
