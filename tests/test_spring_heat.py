"""The cushion spring's heat path, declared once (model/spring_heat.py): the sections that carry it, the FMU's
parameters and the named sets give the same ranges and the same rule U + H > 0."""
from __future__ import annotations

import pytest

from cushion_clutch.errors import ParameterError
from cushion_clutch.launch.scenario.tcu_params import Observer, TcuNetworkParams
from cushion_clutch.model import ClutchParameters
from cushion_clutch.model.spring_heat import FMU_NAMES, SpringHeat
from cushion_clutch.model.thermal_set import load_thermal_set

SECTIONS = (Observer, TcuNetworkParams)


@pytest.mark.parametrize("cls", SECTIONS)
def test_sections_share_the_one_type(cls):
    assert issubclass(cls, SpringHeat)
    # the defaults are the FMU's (the paper's example)
    assert cls().spring_parameters() == {"U": ClutchParameters().U, "H": ClutchParameters().H,
                                         "C": ClutchParameters().C}


@pytest.mark.parametrize("cls", SECTIONS)
def test_no_heat_path_is_refused_by_every_section(cls):
    with pytest.raises(ParameterError) as err:
        cls(spring_U_W_per_K=0.0, spring_H_W_per_K=0.0)
    text = str(err.value)
    assert f"{cls._section}.spring_H_W_per_K: spring_U_W_per_K + spring_H_W_per_K = 0 W/K" in text
    assert "needs a heat path" in text


def test_the_fmu_parameters_and_a_set_refuse_it_too(tmp_path):
    assert "U + H must be > 0 (the cushion spring needs a heat path)" in ClutchParameters(U=0.0, H=0.0).problems()
    f = tmp_path / "cold.toml"
    f.write_text("U_W_per_K = 0.0\nH_W_per_K = 0.0\nC_J_per_K = 1.0\n")
    with pytest.raises(ParameterError, match="U_W_per_K \\+ H_W_per_K must be > 0"):
        load_thermal_set(f)


@pytest.mark.parametrize("cls", SECTIONS)
@pytest.mark.parametrize("key", sorted(FMU_NAMES))
@pytest.mark.parametrize("value", [-1e-3, 2e6, float("nan"), "x", True])
def test_ranges_are_the_fmu_s(cls, key, value):
    """A value the FMU's range refuses, the section refuses, naming its key (and nothing else for it)."""
    name = FMU_NAMES[key]
    lo, hi, lo_open, _ = ClutchParameters.RANGES[name]
    with pytest.raises(ParameterError) as err:
        cls(**{key: value})
    problems = err.value.problems
    mine = [p for p in problems if f"{cls._section}.{key}" in p]
    assert len(mine) == 1 and f"{lo:g}, {hi:g}" in mine[0], problems


def test_a_value_inside_the_range_is_taken():
    lo, hi, *_ = ClutchParameters.RANGES["C"]
    assert Observer(spring_C_J_per_K=hi).spring_C_J_per_K == hi
    with pytest.raises(ParameterError):
        Observer(spring_C_J_per_K=lo)          # C's lower bound is open
