"""Mass and grade from the longitudinal dynamics (RLS with forgetting): convergence and excitation."""
import math

import numpy as np
import pytest

from cushion_clutch.errors import ParameterError
from cushion_clutch.launch.tcu.mass_grade import G, MassGrade, MassGradeEstimator

I_TOT, R, ETA, J_D, CR, AIR = 15.58, 0.31, 0.95, 0.03, 0.012, 0.42


def plant_torque(m, slope_percent, a, v):
    """Clutch torque that gives acceleration a at speed v (the truth the estimator sees through noise)."""
    al = math.atan(slope_percent / 100)
    m_eq = m + ETA * J_D * (I_TOT / R) ** 2
    f = m_eq * a + m * G * (math.sin(al) + CR * math.cos(al)) + AIR * v * v
    return f * R / (ETA * I_TOT)


def launches(est, m, slope, n=4, noise_Nm=2.0, seed=0, accel=True):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        v = 0.0
        for k in range(600):                    # 6 s at the TCU's 10 ms
            a = (1.6 * min(1.0, k / 50) if k < 200 else 0.3 * math.exp(-(k - 200) / 30)) if accel else 0.0
            v = max(v + a * 0.01, 0.5 if not accel else v + a * 0.01)
            t = plant_torque(m, slope, a, v) + rng.normal(0, noise_Nm)
            est.update(t, v, a + rng.normal(0, 0.05))


def test_rls_recovers_mass_and_grade_from_launches():
    est = MassGradeEstimator(MassGrade(), I_TOT, R, ETA, J_D, CR, AIR)
    launches(est, 1900.0, 8.0)
    assert est.mass_kg == pytest.approx(1900.0, rel=0.03)
    assert est.slope_percent == pytest.approx(8.0, abs=0.3)
    assert est.ready() == (True, True)
    assert est.holding_torque_Nm() == pytest.approx(plant_torque(1900.0, 8.0, 0.0, 0.0), rel=0.03)


def test_without_acceleration_the_mass_is_not_claimed():
    est = MassGradeEstimator(MassGrade(), I_TOT, R, ETA, J_D, CR, AIR)
    launches(est, 1900.0, 8.0, accel=False)
    mass_ready, load_ready = est.ready()
    assert load_ready and not mass_ready


def test_no_update_below_the_excitation_thresholds():
    est = MassGradeEstimator(MassGrade(), I_TOT, R, ETA, J_D, CR, AIR)
    assert not est.update(5.0, 2.0, 1.0)         # torque below torque_min_Nm
    assert not est.update(100.0, 0.0, 1.0)       # car not moving
    assert est.updates == 0 and est.mass_kg == pytest.approx(1600.0)


def test_parameters_are_checked():
    with pytest.raises(ParameterError) as err:
        MassGrade(forgetting=1.2, ready_sd=0.0)
    assert "mass_grade.forgetting" in str(err.value) and "mass_grade.ready_sd" in str(err.value)
