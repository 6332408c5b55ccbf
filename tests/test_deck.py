"""The deck writer only returns text; it is checked against small golden files.

Regenerate a golden file after an intended change with
``python tests/test_deck.py`` and review the diff.
"""
from pathlib import Path

import pytest

from cushion_clutch.fe.deck import paddle_deck, strip_deck
from cushion_clutch.fe.geometry import half_pair_assembly, pair_assembly, strip_mesh
from cushion_clutch.fe.params import Material, SpringParams

GOLDEN = Path(__file__).parent / "golden"
#: the deck writer runs nothing, so the far edge's stiffness is given (the sweep resolves the predicted joint
#: first, fe/joint.py); the golden decks were written with this value
TAB_N_PER_M = 4.5e6


def spring(**sections) -> SpringParams:
    return SpringParams().replace(carrier={"far_end_stiffness_N_per_m": TAB_N_PER_M}, **sections)


def small_paddle_deck() -> str:
    p = spring()
    asm = half_pair_assembly(p.geometry, 6e-3, p.solver.initial_gap_m)
    return paddle_deck(asm, p, 195.0)[0]


def small_strip_deck() -> str:
    return strip_deck(strip_mesh(0.004, 0.002, 0.4e-3, 2e-3), Material(), tip_force_N=0.1)


def small_shaped_deck() -> str:
    """Tilted, two flat-topped waves, far zone resting on the carrier."""
    p = spring(geometry={"wave_tilt_m": 0.3e-3, "waves": 2, "wave_profile": "flat_top",
                                         "far_zone_support": "carrier"})
    asm = half_pair_assembly(p.geometry, 6e-3, p.solver.initial_gap_m)
    return paddle_deck(asm, p, 195.0)[0]


def small_table_s8r_deck() -> str:
    """A tabulated (asymmetric) profile on eight-node shells, surface-to-surface contact."""
    p = spring(
        geometry={"wave_profile": "table", "profile_s": (0.0, 0.3, 0.6, 1.0),
                  "profile_z": (0.0, 1.0, 0.8, 0.0)},
        mesh={"element_type": "S8R"}, solver={"contact": "surface_to_surface"})
    asm = half_pair_assembly(p.geometry, 6e-3, p.solver.initial_gap_m, "S8R")
    return paddle_deck(asm, p, 20.0)[0]


CASES = {"paddle_6mm_195C.inp": small_paddle_deck, "strip_cantilever.inp": small_strip_deck,
         "paddle_tilted_flat_top_carrier_6mm_195C.inp": small_shaped_deck,
         "paddle_table_s8r_6mm_20C.inp": small_table_s8r_deck}


@pytest.mark.parametrize("name", sorted(CASES))
def test_deck_matches_golden(name):
    assert CASES[name]() == (GOLDEN / name).read_text()


def test_pair_deck_has_paddle_to_paddle_contact_and_symmetric_plates():
    p = spring()
    text, info = paddle_deck(pair_assembly(p.geometry, 6e-3, p.solver.initial_gap_m), p, 20.0)
    assert "S_A_BOT, M_B_TOP" in text
    assert f"{info.ref_upper}, 3, 3, -" in text and f"{info.ref_lower}, 3, 3, 0." in text


def test_thermal_distortion_off_writes_zero_expansion():
    p = spring(sweep={"thermal_distortion": False})
    text = paddle_deck(half_pair_assembly(p.geometry, 6e-3, 1e-4), p, 300.0)[0]
    assert "*EXPANSION, ZERO=20\n0\n" in text


def test_contact_slopes_use_their_own_keys_and_units():
    p = spring(solver={"node_penalty_N_per_m": 2e8})
    text = paddle_deck(half_pair_assembly(p.geometry, 6e-3, 1e-4), p, 20.0)[0]
    assert "NODE TO SURFACE" in text and "\n200000, 0.01\n" in text          # N/mm per node
    p = spring(solver={"contact": "surface_to_surface", "surface_penalty_Pa_per_m": 3e14})
    text = paddle_deck(half_pair_assembly(p.geometry, 6e-3, 1e-4), p, 20.0)[0]
    assert "SURFACE TO SURFACE" in text and "\n300000, 0.01\n" in text       # MPa/mm


def test_resting_far_zone_has_no_guide_and_joins_the_contact_surface():
    p = spring(geometry={"far_zone_support": "carrier"})
    text = paddle_deck(half_pair_assembly(p.geometry, 6e-3, 1e-4), p, 20.0)[0]
    assert "GUIDE, 3, 3" not in text
    assert "GUIDE, 3, 3" in small_paddle_deck()


if __name__ == "__main__":
    for name, make in CASES.items():
        (GOLDEN / name).write_text(make())
        print("wrote", GOLDEN / name)
