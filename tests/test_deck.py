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


def small_paddle_deck() -> str:
    p = SpringParams()
    asm = half_pair_assembly(p.geometry, 6e-3, p.solver.initial_gap_m)
    return paddle_deck(asm, p, 195.0)[0]


def small_strip_deck() -> str:
    return strip_deck(strip_mesh(0.004, 0.002, 0.4e-3, 2e-3), Material(), tip_force_N=0.1)


CASES = {"paddle_6mm_195C.inp": small_paddle_deck, "strip_cantilever.inp": small_strip_deck}


@pytest.mark.parametrize("name", sorted(CASES))
def test_deck_matches_golden(name):
    assert CASES[name]() == (GOLDEN / name).read_text()


def test_pair_deck_has_paddle_to_paddle_contact_and_symmetric_plates():
    p = SpringParams()
    text, info = paddle_deck(pair_assembly(p.geometry, 6e-3, p.solver.initial_gap_m), p, 20.0)
    assert "S_A_BOT, M_B_TOP" in text
    assert f"{info.ref_upper}, 3, 3, -" in text and f"{info.ref_lower}, 3, 3, 0." in text


def test_thermal_distortion_off_writes_zero_expansion():
    p = SpringParams().replace(sweep={"thermal_distortion": False})
    text = paddle_deck(half_pair_assembly(p.geometry, 6e-3, 1e-4), p, 300.0)[0]
    assert "*EXPANSION, ZERO=20\n0\n" in text


if __name__ == "__main__":
    for name, make in CASES.items():
        (GOLDEN / name).write_text(make())
        print("wrote", GOLDEN / name)
