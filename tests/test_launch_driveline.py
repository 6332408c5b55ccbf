"""The compliant driveline: first mode against the two-inertia closed form, exact energy books."""
import dataclasses
import math

import numpy as np
import pytest

from cushion_clutch.launch.plant.driveline import Driveline, first_mode_hz
from cushion_clutch.launch.scenario import load_scenario, scenario_path


def frictionless(sc, damping=0.0):
    """No grade, rolling or air resistance; shaft damping as given (N.m s/rad at the wheels)."""
    return dataclasses.replace(
        sc, vehicle=dataclasses.replace(sc.vehicle, slope_percent=0.0, rolling_resistance=0.0, drag_area_m2=0.0),
        driveline=dataclasses.replace(sc.driveline, damping_Nm_s_per_rad=damping))


@pytest.mark.parametrize("name", ["default", "creep", "cooldown", "fade"])
def test_first_mode_of_the_shipped_scenarios_is_a_passenger_car_shuffle(name):
    assert 3.0 <= first_mode_hz(load_scenario(scenario_path(name))) <= 8.0


def test_first_mode_matches_the_two_inertia_closed_form_and_energy_is_conserved():
    sc = frictionless(load_scenario())
    dl = Driveline(**sc.driveline_sections(), w_e=100.0)
    dl.w_d, dl.v, dl.locked, dl.phi = 100.0, 100.0 * dl.r / dl.i_tot, True, 0.01
    e0 = dl.kinetic() + dl.elastic()
    phi, n = [], int(2.0 / dl.h)
    for _ in range(n):
        assert dl.step(0.0, 1e6, True, False) == 0
        phi.append(dl.phi)
    phi = np.array(phi)
    up = np.nonzero((phi[:-1] < 0.0) & (phi[1:] >= 0.0))[0]
    t_up = (up + phi[up] / (phi[up] - phi[up + 1])) * dl.h          # interpolated upward zero crossings
    f_sim = (len(t_up) - 1) / (t_up[-1] - t_up[0])
    dl_, veh = sc.driveline, sc.vehicle
    i = dl_.gear_ratio * dl_.final_drive_ratio
    j1 = sc.engine.inertia_kg_m2 + dl_.disc_inertia_kg_m2
    j2 = veh.mass_kg * dl_.wheel_radius_m ** 2 / (dl_.efficiency * i ** 2)      # the vehicle as the shaft feels it
    f_closed = math.sqrt(dl_.stiffness_Nm_per_rad / i ** 2 * (1 / j1 + 1 / j2)) / (2 * math.pi)
    assert first_mode_hz(sc) == pytest.approx(f_closed, rel=1e-12)
    assert f_sim == pytest.approx(f_closed, rel=1e-3)               # midpoint rule: (w h)^2 / 12 ~ 1e-4
    # the gearbox loss (1 - eta) T_s w_v is booked as resistance: the books close to round-off
    e = dl.en
    assert abs(e.engine_work - (dl.kinetic() + dl.elastic() - e0 + e.resistance + e.damping + e.slip)) < 1e-9 * e0


def test_damping_decays_the_shuffle_and_books_close_to_round_off():
    sc = frictionless(load_scenario(), damping=300.0)
    dl = Driveline(**sc.driveline_sections(), w_e=100.0)
    dl.w_d, dl.v, dl.locked, dl.phi = 100.0, 100.0 * dl.r / dl.i_tot, True, 0.01
    e0 = dl.kinetic() + dl.elastic()
    for _ in range(int(3.0 / dl.h)):
        dl.step(0.0, 1e6, True, False)
    assert abs(dl.phi) < 1e-4 and dl.en.damping > 0.5 * 0.5 * dl.k * 0.01 ** 2
    e = dl.en
    assert abs(e.engine_work - (dl.kinetic() + dl.elastic() - e0 + e.resistance + e.damping)) < 1e-9 * e0


def test_the_clutch_slips_when_the_locked_torque_exceeds_the_capacity():
    sc = frictionless(load_scenario())
    dl = Driveline(**sc.driveline_sections(), w_e=150.0)
    dl.w_d, dl.v, dl.locked = 150.0, 150.0 * dl.r / dl.i_tot, True
    events = [dl.step(200.0, 30.0, True, False) for _ in range(50)]
    assert -1 in events and not dl.locked and dl.w_e > dl.w_d
