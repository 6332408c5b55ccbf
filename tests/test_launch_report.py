"""Six TCU variants, the metrics CSV, the summary and the CLI."""
import csv

import pytest

from cushion_clutch.cli import main
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model import load_table
from cushion_clutch.launch.results.metrics import METRIC_COLUMNS
from cushion_clutch.launch.report import run_all, summary_rows, summary_table, write_outputs
from cushion_clutch.launch.scenario import load_scenario
from cushion_clutch.launch.tcu.controller import VARIANTS

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
    with open(tmp_path / "out" / "launch_naive.csv") as fh:
        assert sum(1 for _ in fh) == len(results["naive"].series) + 1          # every recorded row
    # --every 3: rows 0, 3, 6, ... of the recorded series, the metrics and plots unchanged
    from cushion_clutch.launch.report import Provenance
    paths3 = write_outputs(results, tmp_path / "out3", Provenance("short", "a command", 100.0), every=3)
    with open(tmp_path / "out3" / "launch_naive.csv") as fh:
        thinned = list(csv.DictReader(fh))
    series = results["naive"].series
    assert len(thinned) == -(-len(series) // 3)
    assert [float(r["time_s"]) for r in thinned[:4]] == pytest.approx(list(series["time_s"][:12:3]), abs=1e-9)
    metrics_csv = "launch_metrics.csv"
    assert (tmp_path / "out3" / metrics_csv).read_text() == (tmp_path / "out" / metrics_csv).read_text()
    assert {p.name for p in paths3} == {p.name for p in paths}
    assert _png_description(tmp_path / "out3" / "launch_metrics.png") == "scenario 'short' · cushion-clutch " + \
        __import__("cushion_clutch").__version__ + " · a command"
    with pytest.raises(ValueError, match="every = 0"):
        write_outputs(results, tmp_path / "out0", every=0)


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


def _png_description(path) -> str:
    """The provenance line a plot stores in its PNG text chunk (what its footer prints)."""
    from PIL import Image
    with Image.open(path) as im:
        return im.text.get("Description", "")


def test_lockup_counts_and_lines():
    """Each launch is counted once: locked up, inhibited (protection level 3, no lock-up) or launched and
    never locked up; a line names the TCU and 'k of n launches locked up'."""
    from types import SimpleNamespace

    from cushion_clutch.launch.report import lockup_counts, lockup_lines

    nan = float("nan")
    rows = [{"engagement_time_s": 2.0, "protection_level": 0, "engine_stall": False},
            {"engagement_time_s": 2.5, "protection_level": 2, "engine_stall": False},
            {"engagement_time_s": nan, "protection_level": 3, "engine_stall": False},
            {"engagement_time_s": nan, "protection_level": 1, "engine_stall": True}]
    res = SimpleNamespace(metrics=rows, stopped="")
    assert lockup_counts(res) == {"n": 4, "locked": 2, "inhibited": 1, "no_lockup": 1, "stalls": 1}
    lines = lockup_lines({"production": res, "naive": SimpleNamespace(metrics=rows[:1], stopped="")}).splitlines()
    assert lines[1] == ("production: 2 of 4 launches locked up; 1 inhibited, 1 launched but never locked up, "
                        "1 engine stalls")
    assert lines[2] == "naive: 1 of 1 launches locked up"
    narrow = lockup_lines({"production": res}, width=40).splitlines()
    assert narrow[1] == "production: 2 of 4 launches locked up;" and narrow[2].startswith("  1 inhibited")
    early = SimpleNamespace(metrics=rows[:1], stopped="launch 1, t = 3.00 s: the plant left the model's domain")
    assert lockup_lines({"aware": early}).splitlines()[2] == (
        "aware STOPPED EARLY, launch 1, t = 3.00 s: the plant left the model's domain")


def test_a_run_that_leaves_the_model_s_domain_stops_there_and_says_so(tmp_path):
    """A plant driven past the model's range (a facing above 800 K) ends the run at the refused step: the
    launches up to it are kept, ``stopped`` names the launch and the time, and no later launch is invented."""
    import dataclasses

    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.model import load_table

    sc = load_scenario(scenario_path("fade"))
    sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, launches=3),
                             facing=dataclasses.replace(sc.facing, initial_degC=400.0))
    fmu = build_plant_fmu(DEFAULT_TABLES, sc, tmp_path / "CushionClutch.fmu")
    res = simulate_launches(fmu, sc, load_table(), "naive")
    assert res.stopped.startswith("launch 2, t = ") and "left the model's domain" in res.stopped
    assert len(res.metrics) == 2 and res.series["launch"].max() == 2.0
    assert res.series["theta_cm_K"].max() <= 800.0


def test_cli_protection_summary_counts_lock_ups_and_plots_name_the_scenario(tmp_path, capsys):
    """The bar of issue 41: on production's line the terminal summary says how many of its launches locked up;
    every plot and the manifest name the scenario, the version and the command; --every thins the series."""
    import json
    import math

    from cushion_clutch import __version__

    path = tmp_path / "hot_protection.toml"          # the shipped protection scenario, short and from a hot start
    path.write_text('extends = "protection"\nname = "hot_protection"\n[run]\nlaunches = 2\n'
                    '[facing]\ninitial_degC = 320.0\n')
    out = tmp_path / "out"
    argv = ["launch", "--scenario", str(path), "--out", str(out), "--every", "7"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    with open(out / "launch_metrics.csv") as fh:
        metrics = [r for r in csv.DictReader(fh)]
    for name in VARIANTS:
        mine = [r for r in metrics if r["tcu"] == name]
        locked = sum(not math.isnan(float(r["engagement_time_s"])) for r in mine)
        assert f"\n{name}: {locked} of {len(mine)} launches locked up" in text, (name, text)
    prod = [r for r in metrics if r["tcu"] == "production"]
    assert sum(int(float(r["protection_level"])) >= 3 for r in prod) >= 1       # the hot start inhibits
    assert "inhibited" in next(line for line in text.splitlines() if line.startswith("production: "))
    ours = [line for line in text.splitlines() if line.startswith((*VARIANTS, "launches locked up", "  production"))]
    assert len(ours) >= 2 * len(VARIANTS) and all(len(line) <= 100 for line in ours), ours     # the FMU's log aside
    assert "launches with 6 TCUs simulated in" in text
    assert " MB, written to " in text or " kB, written to " in text
    assert "one recorded row in 7 (--every 7)" in text
    command = "cushion-clutch " + " ".join(argv)
    manifest = json.loads((out / "launch.manifest.json").read_text())
    assert (manifest["scenario"], manifest["version"], manifest["command"], manifest["every"]) == \
        ("hot_protection", __version__, command, 7)
    assert manifest["bytes_written"] == sum(f["bytes"] for f in manifest["files"].values())
    for png in ("launch_last.png", "launch_temperatures.png", "launch_metrics.png"):
        assert _png_description(out / png) == f"scenario 'hot_protection' · cushion-clutch {__version__} · {command}"
    # --every 7 keeps rows 0, 7, 14, ... of what was recorded (every 10 ms)
    with open(out / "launch_naive.csv") as fh:
        t = [float(r["time_s"]) for r in csv.DictReader(fh)]
    assert min(b - a for a, b in zip(t, t[1:])) == pytest.approx(0.07, abs=1e-9)
    assert manifest["series_interval_s"] == pytest.approx(0.07, abs=1e-9)


def test_every_must_be_a_whole_number_at_least_one(tmp_path, capsys):
    for bad in ("0", "-3", "2.5", "x"):
        with pytest.raises(SystemExit) as exc:
            main(["launch", "--every", bad, "--out", str(tmp_path / "o")])
        assert exc.value.code == 2
        err = capsys.readouterr().err
        assert "--every" in err and "whole number >= 1" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()
