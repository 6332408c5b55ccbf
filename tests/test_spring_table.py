"""The FMUs' table reader (model/spring_table.py): rows in any order, against hand-written tables."""
import dataclasses
import shutil

import pytest

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model import ClutchParameters, load_table, outputs

#: the committed kiss_point.csv (issue 37's sweep with the predicted joint, -40 to 350 degC, ccx 2.20)
KISS = {-40.0: -3.508207974e-05, 20.0: 0.0, 80.0: 3.973719259e-05, 195.0: 1.279075552e-04, 250.0: 1.751206232e-04,
        300.0: 2.212228249e-04, 350.0: 2.702355802e-04}


def test_delta_kiss_is_the_committed_table_at_every_temperature():
    table = load_table()
    for theta, d in KISS.items():
        assert table.delta_kiss(theta) == d
    # linear in between, by hand: halfway from 195 to 250 degC
    assert table.delta_kiss(222.5) == pytest.approx(0.5 * (KISS[195.0] + KISS[250.0]), rel=1e-12)


def test_kiss_rows_in_any_order_give_the_same_kiss_point(tmp_path):
    shutil.copytree(DEFAULT_TABLES, tmp_path / "t")
    kp = tmp_path / "t" / "kiss_point.csv"
    head, *rows = kp.read_text().splitlines()
    kp.write_text("\n".join([head, *reversed(rows)]) + "\n")
    shuffled, table = load_table(tmp_path / "t"), load_table()
    for theta, d in KISS.items():
        assert shuffled.delta_kiss(theta) == d
    # the cushion spring's share alone: a stiff release system (the paper's constant lever) and a stack that
    # does not grow, so the kiss point is x_kiss_ref - lever * delta_kiss by hand
    p = ClutchParameters()
    p = ClutchParameters(cover=dataclasses.replace(p.cover, release_compliance_m_per_N=0.0, facing_expansion_per_K=0.0,
                                                   pressure_plate_expansion_per_K=0.0, flywheel_expansion_per_K=0.0))
    # a bearing position that matters: 5.5 mm at 250 degC (the kiss point has moved 0.39 mm)
    x_kiss = p.x_kiss_ref - p.lever_ratio * KISS[250.0]
    got = outputs(0.0055, 250.0 + 273.15, shuffled, p)
    assert got.x_kiss == pytest.approx(x_kiss, rel=1e-12)
    assert got.torque == outputs(0.0055, 250.0 + 273.15, table, p).torque > 0.0
