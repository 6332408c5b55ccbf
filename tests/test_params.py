import math

import pytest

from cushion_clutch.errors import ParameterError
from cushion_clutch.fe.params import DEFAULT_SPRING, SpringParams, load_params, params_from_dict


def test_default_file_loads_and_matches_paper():
    p = load_params(DEFAULT_SPRING)
    assert p.n_pairs == 8
    assert p.geometry.thickness_m == pytest.approx(0.42e-3)     # 0.4 mm in the paper, see the TOML
    assert p.geometry.wave_height_m == pytest.approx(0.7e-3)
    # the paper's Table 1, extended to -40 degC by ASME's carbon-steel ratios (see the TOML and fe_model.md)
    assert p.material.youngs_modulus_Pa == (209.2e9, 206e9, 202e9, 196e9, 186e9)
    assert p.material.temperatures_degC == (-40.0, 20.0, 80.0, 200.0, 350.0)
    assert p.material.expansion_coefficients_per_K == (1.088e-5, 1.12e-5, 1.12e-5, 1.12e-5, 1.12e-5)
    assert p.sweep.temperatures_degC == (-40.0, 20.0, 80.0, 195.0, 250.0, 300.0, 350.0)
    assert p.material.expansion_coefficient_per_K == pytest.approx(1.12e-5)
    assert p.material.expansion_coefficient(-10.0) == pytest.approx(0.5 * (1.088e-5 + 1.12e-5))
    assert p.material.expansion_coefficient(300.0) == 1.12e-5


def test_youngs_modulus_interpolates_table():
    m = load_params().material
    assert m.youngs_modulus(20.0) == pytest.approx(206e9)
    assert m.youngs_modulus(140.0) == pytest.approx(199e9)
    assert m.youngs_modulus(400.0) == pytest.approx(186e9)
    assert m.youngs_modulus(-40.0) == pytest.approx(209.2e9) and m.youngs_modulus(-10.0) == pytest.approx(207.6e9)


def test_expansion_table_is_checked():
    with pytest.raises(ParameterError, match=r"expansion_coefficients_per_K: needs one value per temperatures_degC"):
        params_from_dict({"material": {"expansion_coefficients_per_K": [1e-5, 1.1e-5]}})
    with pytest.raises(ParameterError, match=r"expansion_coefficient_per_K = 1.12e-05: must equal"):
        params_from_dict({"material": {"expansion_coefficients_per_K": [1e-5, 1e-5, 1e-5, 1e-5]}})
    with pytest.raises(ParameterError, match=r"expansion_coefficients_per_K\[1\] = -1e-05: out of range"):
        params_from_dict({"material": {"expansion_coefficients_per_K": [1.12e-5, -1e-5, 1e-5, 1e-5]}})


def test_unknown_key_is_named(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(DEFAULT_SPRING.read_text().replace("[mesh]", "[mesh]\nelement_sise_m = 1e-3"))
    with pytest.raises(ParameterError, match=r"mesh\.element_sise_m: unknown key"):
        load_params(f)


def test_out_of_range_names_key_and_range(tmp_path):
    f = tmp_path / "s.toml"
    text = DEFAULT_SPRING.read_text().replace("thickness_m = 0.42e-3", "thickness_m = 0.04")
    text = text.replace("\npoisson_ratio = 0.3", "\npoisson_ratio = 0.7")      # the material's, not joint.carrier_poisson_ratio
    f.write_text(text)
    with pytest.raises(ParameterError) as info:
        load_params(f)
    msg = str(info.value)
    # all problems are collected before raising
    assert "geometry.thickness_m = 0.04: out of range, allowed [5e-05, 0.005]" in msg
    assert "material.poisson_ratio = 0.7" in msg and "[0, 0.5)" in msg
    assert len(info.value.problems) == 2


def test_corrupted_toml(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(DEFAULT_SPRING.read_text()[:200] + "\n[geometry\nx = ")
    with pytest.raises(ParameterError, match="TOML syntax error"):
        load_params(f)


def test_nan_and_wrong_types_rejected():
    with pytest.raises(ParameterError, match="carrier.temperature_ratio"):
        params_from_dict({"carrier": {"temperature_ratio": math.nan}})
    with pytest.raises(ParameterError, match="n_pairs"):
        params_from_dict({"n_pairs": 2.5})


def test_cross_field_checks():
    with pytest.raises(ParameterError, match="outer_radius_m"):
        params_from_dict({"geometry": {"inner_radius_m": 0.1, "outer_radius_m": 0.09}})
    with pytest.raises(ParameterError, match="must include material.reference_temperature_degC"):
        params_from_dict({"sweep": {"temperatures_degC": [80.0, 195.0]}})
    with pytest.raises(ParameterError, match="far_end"):
        params_from_dict({"geometry": {"far_end": "welded"}})


def test_replace_rechecks():
    p = SpringParams()
    assert p.replace(mesh={"element_size_m": 2e-3}).mesh.element_size_m == 2e-3
    with pytest.raises(ParameterError, match="mesh.element_size_m"):
        p.replace(mesh={"element_size_m": -1.0})


def test_default_is_progressive_by_its_tilt_and_states_alpha():
    p = load_params(DEFAULT_SPRING)
    assert p.geometry.wave_tilt_m == pytest.approx(0.6e-3)
    assert p.geometry.edge_heights_m() == pytest.approx((0.4e-3, 1.0e-3))
    assert p.geometry.far_zone_support == "slot" and p.geometry.far_end == "elastic"
    text = DEFAULT_SPRING.read_text()
    assert "1.12e-6" in text and "11-13 um/(m K)" in text


def test_old_penalty_key_is_rejected_and_new_ones_checked():
    with pytest.raises(ParameterError, match=r"solver\.penalty_stiffness_N_per_m: unknown key"):
        params_from_dict({"solver": {"penalty_stiffness_N_per_m": 1e8}})
    with pytest.raises(ParameterError, match=r"solver\.surface_penalty_Pa_per_m = 10: out of range"):
        params_from_dict({"solver": {"surface_penalty_Pa_per_m": 10}})
    with pytest.raises(ParameterError, match=r"mesh\.element_type = 'S3': allowed"):
        params_from_dict({"mesh": {"element_type": "S3"}})


def test_a_carrier_clearance_below_the_thermal_growth_is_refused_with_the_minimum():
    p = load_params()
    need = p.material.expansion_coefficient_per_K * (350.0 - 20.0) * 0.5 * p.geometry.thickness_m
    assert p.min_carrier_clearance_m() == pytest.approx(need)
    with pytest.raises(ParameterError, match=rf"carrier_clearance_m = 0: below the sheet's thermal growth .* "
                                             rf"at 350 degC .*allowed >= {need:.3g} m"):
        p.replace(geometry={"carrier_clearance_m": 0.0})
    # no heating above the reference, or no thermal distortion: no minimum
    assert p.replace(geometry={"carrier_clearance_m": 0.0}, sweep={"temperatures_degC": (20.0,)})
    assert p.replace(geometry={"carrier_clearance_m": 0.0}, sweep={"thermal_distortion": False})


def test_a_case_whose_plates_take_force_from_heating_alone_is_refused():
    import numpy as np

    from cushion_clutch.errors import ResultError
    from cushion_clutch.fe.results import CaseResult
    from cushion_clutch.fe.cases import check_heating
    p = load_params().replace(geometry={"carrier_clearance_m": 1e-6})
    ok = CaseResult(300.0, 1, 1e-4, np.zeros(3), np.zeros(3), 0.0, 0.0)
    check_heating(ok, p)
    bad = CaseResult(300.0, 1, 1e-4, np.zeros(3), np.zeros(3), 0.0, 54.5)   # measured at 1 um, 2 mm mesh
    with pytest.raises(ResultError, match=r"theta = 300 degC: heating alone pressed the paddle on the carrier "
                                          r"with 54.5 N .*geometry.carrier_clearance_m = 1e-06 m"):
        check_heating(bad, p)
    # the upper plate: the hot crest grew into the start gap (seen with a 20 MN/m far-edge joint at 350 degC, 13 N)
    up = CaseResult(350.0, 1, 1e-4, np.zeros(3), np.zeros(3), 13.0, 0.0)
    with pytest.raises(ResultError, match=r"theta = 350 degC: heating alone pressed the paddle on the upper plate "
                                          r"with 13 N .*solver.initial_gap_m = 0.00015 m"):
        check_heating(up, p)
