"""The generated blocks of docs/explanation/thermal.md: markers, format and the helpers that fill them.

The blocks' numbers themselves are checked against a fresh run by tests/test_figures.py (the generator draws the
figure and rewrites a copy of the page; about 15 s of launch runs, marked ``fmu``); here nothing runs a launch.
"""
from __future__ import annotations

import math
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from cushion_clutch.benchmarks import thermal_validation as tv
from cushion_clutch.model import KELVIN

PAGE = Path(__file__).resolve().parents[1] / "docs" / "explanation" / "thermal.md"
MARKERS = ((tv.VALIDATION_BEGIN, tv.VALIDATION_END), (tv.DUTY_BEGIN, tv.DUTY_END))


def _numbers_out(text: str) -> str:
    return re.sub(r"[-+]?\d+(\.\d+)?", "N", text)


def _fake_summary(n: int = 12, start: float = 20.0) -> dict:
    return {"n": n, "locked": n, "slip_kJ": (18.4, 20.2), "surface_rise_K": (12.3, 17.8), "theta_cm_max_degC": 70.1,
            "theta_cs_max_degC": 55.7, "surface_max_degC": 83.9, "plate_max_degC": 63.7,
            "theta_cm_start_degC": start, "cm_step_K": 2.2, "plate_step_K": 2.3}


def _fake_result(cm_starts_degC, slip_kJ, lock_times_s):
    """A LaunchResult-like object: two samples per launch, θ_cm rising by 5 K within each launch."""
    launch, cm, surf = [], [], []
    for i, c in enumerate(cm_starts_degC, start=1):
        launch += [i, i]
        cm += [c + KELVIN, c + 5.0 + KELVIN]
        surf += [c + KELVIN, c + 30.0 + KELVIN]
    arr = np.array
    series = {"launch": arr(launch), "theta_cm_K": arr(cm), "theta_surface_K": arr(surf),
              "theta_pressure_plate_K": arr(cm) - 1.0, "theta_cs_K": arr(cm) - 10.0}
    metrics = [{"launch": i, "slip_energy_kJ": e, "engagement_time_s": t, "theta_cs_start_degC": 0.0}
               for i, (e, t) in enumerate(zip(slip_kJ, lock_times_s), start=1)]
    return SimpleNamespace(series=series, metrics=metrics)


def test_page_has_each_marker_once_in_order():
    text = PAGE.read_text(encoding="utf-8")
    for begin, end in MARKERS:
        assert text.count(begin) == 1 and text.count(end) == 1, (begin, end)
        assert text.index(begin) < text.index(end)
        block = tv.page_block_text(text, begin, end)
        assert block.startswith("<!-- written by `python -m cushion_clutch.benchmarks.thermal_validation --write "
                                "docs/explanation/thermal.md`; do not edit -->")


def test_page_blocks_have_the_renderers_format():
    """The page's blocks are the renderers' output up to the numbers (same rows, columns, labels, captions)."""
    text = PAGE.read_text(encoding="utf-8")
    m = {name: _fake_summary(16 if name == "fade" else 12, 150.0 if name == "creep" else 20.0)
         for name in tv.DUTY_SCENARIOS}
    command = "python -m cushion_clutch.benchmarks.thermal_validation --write docs/explanation/thermal.md"
    fresh = {tv.VALIDATION_BEGIN: tv.validation_markdown(m, _fake_summary(), 0.042, command),
             tv.DUTY_BEGIN: tv.duty_markdown(m, command)}
    for begin, end in MARKERS:
        page_lines = _numbers_out(tv.page_block_text(text, begin, end)).splitlines()
        fresh_lines = _numbers_out(fresh[begin]).splitlines()
        assert len(page_lines) == len(fresh_lines), begin
        for got, want in zip(page_lines, fresh_lines):
            if not want.startswith("| "):
                assert got == want
                continue
            # a table row: the same number of cells and the same first cells (the verdicts depend on the numbers)
            assert got.count("|") == want.count("|"), got
            assert got.split("|")[1:3] == want.split("|")[1:3], got


def test_page_carries_no_dated_measurement():
    """History belongs in CHANGELOG.md; the page's measured figures are the script's blocks."""
    text = PAGE.read_text(encoding="utf-8")
    assert not re.search(r"\b20\d\d-\d\d-\d\d\b", text)


def test_rewrite_replaces_only_the_block(tmp_path):
    page = tmp_path / "p.md"
    page.write_text(f"head\n{tv.DUTY_BEGIN}\nold\n{tv.DUTY_END}\ntail\n", encoding="utf-8")
    tv.rewrite(page, tv.DUTY_BEGIN, tv.DUTY_END, "new 1\nnew 2\n")
    assert page.read_text(encoding="utf-8") == f"head\n{tv.DUTY_BEGIN}\nnew 1\nnew 2\n{tv.DUTY_END}\ntail\n"
    assert tv.page_block_text(page.read_text(encoding="utf-8"), tv.DUTY_BEGIN, tv.DUTY_END) == "new 1\nnew 2\n"
    page.write_text(f"{tv.DUTY_END}\n{tv.DUTY_BEGIN}\n", encoding="utf-8")
    with pytest.raises(ValueError, match="needs one"):
        tv.rewrite(page, tv.DUTY_BEGIN, tv.DUTY_END, "x\n")


def test_write_refuses_a_page_without_markers_before_running(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("no markers\n", encoding="utf-8")
    with pytest.raises(SystemExit, match="each marker must occur once"):
        tv.main(["--no-figure", "--write", str(page)])


def test_summary_ranges_steps_and_lockups():
    res = _fake_result([20.0, 30.0, 37.0], [18.0, 21.0, 19.5], [1.2, math.nan, 1.4])
    s = tv.summary(res)
    assert s["n"] == 3 and s["locked"] == 2
    assert s["slip_kJ"] == (18.0, 21.0)
    assert s["surface_rise_K"] == pytest.approx((30.0, 30.0))
    assert s["theta_cm_max_degC"] == pytest.approx(42.0)
    assert s["surface_max_degC"] == pytest.approx(67.0)
    assert s["cm_step_K"] == pytest.approx(7.0) and s["plate_step_K"] == pytest.approx(7.0)
    assert s["theta_cm_start_degC"] == pytest.approx(20.0)


@pytest.mark.parametrize("lo_hi, side", [((12, 18), "lower"), ((52, 67), "higher"), ((31, 34), "within"),
                                         ((25, 40), "across"), ((25, 32), "across")])
def test_side_against_the_published_band(lo_hi, side):
    assert tv._side(lo_hi, tv.RISE_PER_ENGAGEMENT_K) == side


def test_span_collapses_equal_ends():
    assert tv._span((3.6, 3.65), "kJ") == "4 kJ"
    assert tv._span((113.3, 125.0), "kJ") == "113–125 kJ"
