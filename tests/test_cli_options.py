"""The command line's shape (issue 27): --version, --out/-o and --jobs/--workers everywhere, a description and
an example per subcommand, --debug after the subcommand, build-fmu's output checks, terminal width."""
from __future__ import annotations

import argparse
import math
import tomllib
from pathlib import Path

import pytest

from cushion_clutch import __version__
from cushion_clutch.cli import build_parser, launch_terminal_table, main
from cushion_clutch.fe.params import DEFAULT_SPRING
from cushion_clutch.launch.tcu.controller import VARIANTS


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    action = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def test_version_is_the_package_s(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"cushion-clutch {__version__}"
    pyproject = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())
    assert pyproject["project"]["version"] == __version__


def test_top_level_help_is_written_not_a_docstring():
    text = build_parser().format_help()
    assert "Only this module prints" not in text and "six TCU variants" in text


@pytest.mark.parametrize("name", sorted(_subparsers()))
def test_every_subcommand_has_a_description_and_an_example(name):
    p = _subparsers()[name]
    assert p.description and len(p.description) > 40
    assert f"example:\n  cushion-clutch {name}" in p.format_help()


def test_launch_help_counts_the_variants():
    text = _subparsers()["launch"].format_help() + build_parser().format_help()
    assert "five" not in text and f"{len(VARIANTS)} TCU variants" in text and len(VARIANTS) == 6


@pytest.mark.parametrize("name", sorted(_subparsers()))
def test_out_has_short_form_o(name):
    if name == "check-spring":
        return                                              # writes nothing
    opts = {o for a in _subparsers()[name]._actions for o in a.option_strings}
    assert {"-o", "--out"} <= opts, name


@pytest.mark.parametrize("name", ["sweep", "calibrate", "tolerance", "fleet"])
def test_jobs_and_workers_are_one_option(name):
    p = _subparsers()[name]
    action = next(a for a in p._actions if "--jobs" in a.option_strings)
    assert {"-j", "--jobs", "--workers"} <= set(action.option_strings)
    base = {"calibrate": ["--measured", "m.csv", "--fit", "t", "--out", "c.toml"]}.get(name, [])
    a = build_parser().parse_args([name, *base, "--workers", "3"])
    b = build_parser().parse_args([name, *base, "--jobs", "3"])
    assert getattr(a, action.dest) == getattr(b, action.dest) == 3


def test_build_fmu_out_and_the_old_output_name():
    assert build_parser().parse_args(["build-fmu", "--out", "a.fmu"]).output == Path("a.fmu")
    assert build_parser().parse_args(["build-fmu", "-o", "a.fmu"]).output == Path("a.fmu")
    assert build_parser().parse_args(["build-fmu", "--output", "b.fmu"]).output == Path("b.fmu")
    assert "--output" not in _subparsers()["build-fmu"].format_help()        # hidden alias


def test_debug_and_verbose_after_the_subcommand(tmp_path):
    empty = tmp_path / "empty.toml"
    empty.write_text("")
    assert build_parser().parse_args(["check-spring", str(empty), "--debug", "-v"]).debug is True
    assert build_parser().parse_args(["--debug", "check-spring", str(empty)]).debug is True
    assert build_parser().parse_args(["check-spring", str(empty)]).debug is False
    with pytest.raises(ValueError):                         # --debug: the exception, not one line
        main(["check-spring", str(empty), "--debug"])


def test_check_spring_takes_spring_option_too(capsys):
    assert main(["check-spring", "--spring", str(DEFAULT_SPRING)]) == 0
    assert "is valid" in capsys.readouterr().out


@pytest.mark.parametrize("target,needle", [("x", "must end in .fmu"), ("folder.fmu", "is a folder")])
def test_build_fmu_refuses_a_bad_output_and_leaves_nothing(tmp_path, capsys, target, needle):
    (tmp_path / "folder.fmu").mkdir()
    before = sorted(tmp_path.rglob("*"))
    assert main(["build-fmu", "--out", str(tmp_path / target)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and needle in err and "Traceback" not in err
    assert sorted(tmp_path.rglob("*")) == before            # no .fmu.tmp, no file without .fmu


@pytest.mark.parametrize("argv", [["build-fmu", "--out", "{d}/a.fmu"], ["export", "--out", "{d}/o"],
                                  ["simulate", "--out", "{d}/o"], ["launch", "--out", "{d}/o"]])
def test_tables_on_an_empty_folder_is_one_clear_message(tmp_path, capsys, argv):
    (tmp_path / "empty").mkdir()
    rc = main([a.format(d=tmp_path) for a in argv] + ["--tables", str(tmp_path / "empty")])
    err = capsys.readouterr().err
    assert rc == 2 and "no table set there" in err and "Errno" not in err, err
    assert "force_deflection.csv" in err


@pytest.mark.fmu
def test_build_fmu_out_file_works(tmp_path, capsys):
    assert main(["build-fmu", "--out", str(tmp_path / "c.fmu")]) == 0
    assert (tmp_path / "c.fmu").stat().st_size > 0
    assert [p.name for p in tmp_path.iterdir()] == ["c.fmu"]
    assert f"built {tmp_path / 'c.fmu'}" in capsys.readouterr().out


def test_fleet_terminal_table_fits_100_columns():
    from cushion_clutch.cli import FLEET_TERMINAL, fleet_terminal_table
    rows = [{"tcu": "adaptive_aware_estimated", "metric": m, "p50": 1234.5678, "p95": math.nan, "p99": -0.001,
             "max": 99999.99} for m in FLEET_TERMINAL]
    text = fleet_terminal_table(rows)
    assert max(len(line) for line in text.splitlines()) <= 100, text
    assert len(text.splitlines()) == len(FLEET_TERMINAL) + 3


def test_launch_terminal_table_fits_100_columns():
    row = {"group": "cool-down", "tcu": "adaptive_aware_estimated", "n": 18,
           "characteristic_error_max_Nm_worst": 123.456, "characteristic_error_rms_Nm_mean": 12.3,
           "tracking_error_rms_Nm_worst": 1234.5, "creep_error_Nm_worst": -12.34,
           "theta_cs_error_K_worst": -146.0, "engagement_time_s_mean": math.nan}
    text = launch_terminal_table([row, row])
    assert max(len(line) for line in text.splitlines()) <= 100, text
    assert "adaptive_aware_estimated" in text and "-146.0" in text


def test_a_slow_fmu_build_says_why(capsys):
    """The zig notice appears once a build outlasts its delay, and never for a quick one."""
    import time

    from cushion_clutch.cli import ZIG_NOTICE, _slow_notice

    with _slow_notice(ZIG_NOTICE, after_s=0.05):
        time.sleep(0.3)
    with _slow_notice("quick", after_s=0.5):
        pass
    time.sleep(0.6)
    err = capsys.readouterr().err
    assert err.count("zig") >= 1 and "first build" in err and "quick" not in err
