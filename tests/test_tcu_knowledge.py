"""The TCU variants composed of strategies (launch/tcu/knowledge.py) and the series' row type
(launch/results/series.py)."""
from __future__ import annotations

import ast
import dataclasses
import math
from pathlib import Path

import pytest

from cushion_clutch.launch.results.series import COLUMNS, PLANT_COLUMNS, SERIES_DTYPE, TCU_COLUMNS, row
from cushion_clutch.launch.scenario import load_scenario, scenario_path
from cushion_clutch.launch.tcu import knowledge
from cushion_clutch.launch.tcu.controller import VARIANTS, TcuController
from cushion_clutch.model import ClutchParameters, load_table, thermal_step
from cushion_clutch.model.clutch_model import hold_theta_cm

TA = 293.15


def _tcu(name: str, protection: bool = True) -> TcuController:
    sc = load_scenario(scenario_path("protection"))
    sc = dataclasses.replace(sc, protection=dataclasses.replace(sc.protection, enabled=protection))
    return TcuController(VARIANTS[name], load_table(), ClutchParameters(theta_a=TA), TA, 10.0, 50.0,
                         **sc.tcu_sections())


@pytest.mark.parametrize("name", [n for n in VARIANTS if n != "production"])
def test_only_a_tcu_that_knows_a_temperature_protects(name):
    ctl = _tcu(name)
    blind = VARIANTS[name].temperature is knowledge.TableReference
    assert (ctl.protection is None) == blind
    assert (ctl.learner is not None) == (VARIANTS[name].kiss is knowledge.LearnedKiss)
    assert _tcu(name, protection=False).protection is None


def test_the_told_tcu_follows_the_exact_spring_model():
    ctl = _tcu("aware")
    p, theta_cs = ctl.p, TA
    for theta_cm in (400.0, 900.0, 300.0):        # 900 K: past the model's range, held at its end
        ctl.cycle(1, 0.0, False, 80.0, 0.0, 0.0, theta_cm)
        theta_cs = thermal_step(theta_cs, hold_theta_cm(theta_cm), ctl.period, p)
        assert ctl.theta_used() == theta_cs
        assert ctl.theta_facing_protect() == theta_cm
        assert ctl.theta_cm_used() == hold_theta_cm(theta_cm)
    assert math.isnan(ctl.theta_cm_estimate())


def test_a_blind_tcu_assumes_the_table_reference():
    ctl = _tcu("naive")
    ctl.cycle(1, 0.0, False, 80.0, 0.0, 0.0, 600.0)
    assert ctl.theta_used() == ctl.theta_ref and ctl.theta_cm_used() is None
    assert math.isnan(ctl.theta_cm_estimate()) and ctl.learned_kiss() == []


def test_the_controller_tests_no_variant_name():
    """No comparison with a variant's name or a temperature string in the controller: it asks its strategies."""
    src = Path(knowledge.__file__).with_name("controller.py").read_text(encoding="utf-8")
    names = set(VARIANTS) | {"none", "ideal", "estimated", "ekf"}
    for node in ast.walk(ast.parse(src)):
        if isinstance(node, ast.Compare):
            consts = [c.value for c in [node.left, *node.comparators] if isinstance(c, ast.Constant)]
            assert not names & set(consts), ast.unparse(node)


def test_a_row_puts_every_part_in_its_column():
    r = row("time_s", "launch", PLANT_COLUMNS, TCU_COLUMNS)
    assert r == COLUMNS and SERIES_DTYPE.names == COLUMNS
