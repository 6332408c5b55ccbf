"""Six TCU variants, the metrics CSV, the summary and the CLI."""
import csv

import pytest

from cushion_clutch.cli import main
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model import load_table
from cushion_clutch.launch.metrics import METRIC_COLUMNS
from cushion_clutch.launch.report import run_all, summary_rows, summary_table, write_outputs
from cushion_clutch.launch.scenario import load_scenario
from cushion_clutch.launch.tcu import VARIANTS

from test_launch import short

pytestmark = pytest.mark.fmu


def test_summary_has_a_row_per_variant(tmp_path):
    fmu = build_fmu(DEFAULT_TABLES, tmp_path / "c.fmu")
    sc = short(load_scenario(), launches=2, initial_degC=200.0)
    results = run_all(fmu, sc, load_table())
    assert list(results) == list(VARIANTS) == ["naive", "aware", "aware_estimated", "adaptive",
                                              "adaptive_aware_estimated", "production"]
    for group in ("hot", "all"):
        assert [r["tcu"] for r in summary_rows(results) if r["group"] == group] == list(VARIANTS)
    table = summary_table(results)
    assert all(f"| hot | {n} |" in table for n in VARIANTS)
    paths = write_outputs(results, tmp_path / "out")
    with open(tmp_path / "out" / "launch_metrics.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == METRIC_COLUMNS and {r["tcu"] for r in rows} == set(VARIANTS) and len(rows) == 12
    assert all(p.exists() and p.stat().st_size > 0 for p in paths)


def test_cli_launch_runs_every_variant(tmp_path, capsys):
    text = (load_scenario.__globals__["DEFAULT_SCENARIO"].read_text()
            .replace("launches = 12", "launches = 2").replace("period_s = 60.0", "period_s = 20.0")
            .replace("drive_time_s = 8.0", "drive_time_s = 6.0"))
    path = tmp_path / "tiny.toml"
    path.write_text(text)
    assert main(["launch", "--scenario", str(path), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    rows = [line.split() for line in out.splitlines() if line.startswith(("hot ", "all "))]
    assert {r[1] for r in rows} == set(VARIANTS)            # the terminal summary (issue 27: <= 100 columns)
    assert all(len(line) <= 100 for line in out.splitlines() if "━" not in line and "/" not in line)
    assert "x real time (CPU" in out and "launch_summary.csv" in out
    assert main(["launch", "--scenario", str(tmp_path / "missing.toml"), "--out", str(tmp_path)]) == 2
