"""Production sensors: 60-2 crank wheel, Hall input-shaft sensor at low speed, torque estimate, position."""
import math
import random

import numpy as np
import pytest

from cushion_clutch.errors import ParameterError
from cushion_clutch.launch.plant.sensors import ProductionSensors, TcuSensors, ToothedWheel


def run_wheel(wheel, speed, seconds, h=1e-3, read_every=10):
    out = []
    for k in range(int(round(seconds / h))):
        t = (k + 1) * h
        wheel.advance(t, speed(t), h)
        if (k + 1) % read_every == 0:
            out.append((t, speed(t), wheel.read(t)))
    return np.array(out)


def test_crank_wheel_reads_constant_speed_across_the_gap():
    w = ToothedWheel(60, 2, 0.0, 1e-6, 0.1, random.Random(0))
    r = run_wheel(w, lambda t: 188.5, 1.0)[5:]
    assert np.max(np.abs(r[:, 2] - 188.5)) < 0.1           # timer quantisation only


def test_tooth_pitch_error_gives_a_bounded_seeded_speed_ripple():
    s = ProductionSensors()
    a = run_wheel(TcuSensors(s).crank, lambda t: 188.5, 0.5)[5:, 2]
    b = run_wheel(TcuSensors(s).crank, lambda t: 188.5, 0.5)[5:, 2]
    assert np.array_equal(a, b)
    err = np.abs(a - 188.5)
    assert err.max() > 0.01 and err.max() < 188.5 * 4 * s.tooth_pitch_error_rad / (2 * math.pi / 60)


def test_hall_sensor_is_coarse_at_low_speed_and_zero_below_pitch_over_timeout():
    pitch = 2 * math.pi / 32
    w = ToothedWheel(32, 0, 0.0, 1e-6, 0.1, random.Random(0))
    fast = run_wheel(w, lambda t: 100.0, 0.5)[3:, 2]
    assert np.max(np.abs(fast - 100.0)) < 0.05
    w = ToothedWheel(32, 0, 0.0, 1e-6, 0.1, random.Random(0))
    slow = run_wheel(w, lambda t: 0.8 * pitch / 0.1, 2.0)[:, 2]     # below pitch / timeout: no edge in time
    assert np.all(slow == 0.0)
    w = ToothedWheel(32, 0, 0.0, 1e-6, 0.1, random.Random(0))
    ramp = run_wheel(w, lambda t: 10.0 * t, 2.0)                    # a launch: disc speed rising from rest
    early = ramp[ramp[:, 0] < 0.15]
    assert np.all(early[:, 2] == 0.0)                                # not yet detected
    late = ramp[ramp[:, 0] > 1.0]
    assert np.max(np.abs(late[:, 2] - late[:, 1])) < 0.6           # lags by about half a read window


def test_torque_position_and_ambient_errors():
    s = ProductionSensors(torque_gain_error=0.05, torque_offset_Nm=2.0, torque_noise_Nm=0.0,
                          position_noise_m=0.0, position_offset_m=30e-6, position_resolution_m=10e-6,
                          ambient_offset_K=1.2, ambient_resolution_K=0.5)
    ts = TcuSensors(s)
    assert ts.engine_torque(100.0) == pytest.approx(107.0)
    assert ts.position(4.0e-3) == pytest.approx(4.03e-3)
    assert ts.ambient(293.15) % 0.5 == pytest.approx(0.0, abs=1e-9)
    noisy = TcuSensors(ProductionSensors(torque_noise_Nm=2.0, torque_gain_error=0.0, torque_offset_Nm=0.0))
    v = np.array([noisy.engine_torque(50.0) for _ in range(4000)])
    assert v.mean() == pytest.approx(50.0, abs=0.2) and v.std() == pytest.approx(2.0, rel=0.1)


def test_parameters_are_checked():
    with pytest.raises(ParameterError) as err:
        ProductionSensors(crank_teeth=60.5, torque_gain_error=0.5, crank_missing_teeth=3)
    text = str(err.value)
    assert "tcu_sensors.crank_teeth" in text and "tcu_sensors.torque_gain_error" in text
