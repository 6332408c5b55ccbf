"""The carrier joint (fe/joint.py): the tab's CalculiX model against closed forms, the rivets, the wiring."""
import dataclasses

import numpy as np
import pytest

from cushion_clutch.errors import ParameterError
from cushion_clutch.fe import joint as J
from cushion_clutch.fe.deck import far_end_anchors
from cushion_clutch.fe.geometry import half_pair_assembly
from cushion_clutch.fe.params import Joint, load_params, params_from_dict


def test_default_spring_predicts_its_joint():
    p = load_params()
    assert p.carrier.far_end_stiffness_N_per_m is None            # no hand-set tab: the joint model decides
    assert p.joint == Joint()                                     # the file's design values are the defaults
    assert p.joint.carrier_thickness_m == pytest.approx(1.5e-3)   # the heat-path FE's carrier sheet
    from cushion_clutch.fe.heat_params import HeatPathParams
    assert p.joint.carrier_thickness_m == HeatPathParams().carrier_thickness_m


def test_joint_keys_checked():
    with pytest.raises(ParameterError) as err:
        params_from_dict({"name": "x", "joint": {"tab_width_m": -1.0, "rivets": 2.5, "tab_lenght_m": 1.0},
                          "carrier": {"far_end_stiffness_N_per_m": -5.0}})
    text = str(err.value)
    assert "joint.tab_width_m = -1.0: out of range, allowed [0.0005, 0.05]" in text
    assert "joint.rivets = 2.5: must be an integer" in text
    assert "joint.tab_lenght_m: unknown key" in text
    assert "carrier.far_end_stiffness_N_per_m = -5.0: out of range" in text


def test_timoshenko_closed_form_by_hand():
    j = Joint(tab_length_m=10e-3, tab_width_m=4e-3, carrier_thickness_m=1e-3, carrier_youngs_modulus_Pa=200e9,
              carrier_poisson_ratio=0.25)
    inertia = 1e-3 * 4e-3 ** 3 / 12
    bending = 10e-3 ** 3 / (3 * 200e9 * inertia)
    shear = 10e-3 / (10 * 1.25 / (12 + 2.75) * 80e9 * 4e-6)
    assert J.timoshenko_tab_stiffness(j) == pytest.approx(1 / (bending + shear), rel=1e-12)


def test_rivet_formulas_agree_and_add_up():
    j, t, e = Joint(), 0.42e-3, 206e9
    huth, swift = J.huth_rivet_stiffness(j, t, e), J.swift_rivet_stiffness(j, t, e)
    assert huth == pytest.approx(swift, rel=0.10)                 # two published fastener formulas
    thicker = dataclasses.replace(j, rivet_diameter_m=6e-3)
    assert J.huth_rivet_stiffness(thicker, t, e) > huth            # a thicker rivet is stiffer
    both = J.JointStiffness(tab_N_per_m=2.0, rivets_N_per_m=3.0)
    assert both.series_N_per_m == pytest.approx(1.2)



@pytest.mark.ccx
def test_tab_fe_matches_timoshenko_with_a_clamped_root():
    j = Joint()
    closed = J.timoshenko_tab_stiffness(j)
    k4 = J.tab_stiffness_fe(j, 4, root="clamped")
    k8 = J.tab_stiffness_fe(j, 8, root="clamped")
    # a clamped 3D face also stops the root's Poisson contraction: a little stiffer than beam theory
    assert k8 == pytest.approx(closed, rel=0.04)
    assert abs(k8 - closed) < abs(k4 - closed)                     # converges towards the closed form


@pytest.mark.ccx
def test_tab_fe_root_compliance_and_mesh_refinement():
    j = Joint()
    clamped = J.tab_stiffness_fe(j, 8, root="clamped")
    k = {n: J.tab_stiffness_fe(j, n) for n in (4, 8)}
    assert k[8] < 0.7 * clamped                                    # the root turns in the carrier body
    assert k[4] > k[8] and (k[4] - k[8]) / k[8] < 0.06             # converging from above (16: -0.1 %)


@pytest.mark.ccx
def test_tab_fe_scales_with_modulus_and_thickness():
    j = Joint()
    k = J.tab_stiffness_fe(j, 4)
    assert J.tab_stiffness_fe(dataclasses.replace(j, carrier_youngs_modulus_Pa=412e9), 4) == pytest.approx(2 * k, rel=1e-4)
    assert J.tab_stiffness_fe(dataclasses.replace(j, carrier_thickness_m=3e-3), 4) == pytest.approx(2 * k, rel=5e-3)
    assert J.tab_stiffness_fe(dataclasses.replace(j, tab_length_m=12e-3), 4) < k


@pytest.mark.ccx
def test_resolve_far_end_predicts_or_keeps_the_override():
    p = load_params()
    resolved = J.resolve_far_end(p)
    js = J.joint_stiffness(p)
    assert resolved.carrier.far_end_stiffness_N_per_m == pytest.approx(js.series_N_per_m)
    assert js.series_N_per_m < min(js.tab_N_per_m, js.rivets_N_per_m)
    given = p.replace(carrier={"far_end_stiffness_N_per_m": 6.0e6})
    assert J.resolve_far_end(given) is given and J.far_end_stiffness(given) == 6.0e6
    free = p.replace(geometry={"far_end": "free"})
    assert J.resolve_far_end(free) is free


def test_deck_refuses_an_unresolved_joint():
    p = load_params()
    asm = half_pair_assembly(p.geometry, 4e-3, p.solver.initial_gap_m, "S4")
    with pytest.raises(ValueError, match="resolve the joint first"):
        far_end_anchors(asm, p)
    anchors = far_end_anchors(asm, p.replace(carrier={"far_end_stiffness_N_per_m": 6.0e6}))
    assert sum(k for *_, k in anchors) == pytest.approx(6.0e6 / 1e3)  # N/mm over the edge, shared
    assert np.all(np.array([k for *_, k in anchors]) > 0)


def test_spring_with_and_without_the_override_reads_back_from_toml(tmp_path):
    """TOML has no null: the predicted joint (None) is written by leaving the key out, an override as a number."""
    from cushion_clutch.fe.studies.calibration_report import params_toml
    for p in (load_params(), load_params().replace(carrier={"far_end_stiffness_N_per_m": 7.5e6})):
        f = tmp_path / "s.toml"
        f.write_text(params_toml(p))
        assert load_params(f) == p
