"""Every CLI error path (issue 12, item 6): one message naming the file and the problem, exit 2, no traceback."""
from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from cushion_clutch.cli import main
from cushion_clutch.data import DEFAULT_TABLES, tables_root


@pytest.fixture()
def files(tmp_path):
    (tmp_path / "empty.toml").write_text("")
    (tmp_path / "noname.toml").write_text('description = "a spring without a name"\n')
    (tmp_path / "bad.toml").write_text("name = [unclosed\n")
    (tmp_path / "text.fmu").write_text("not a zip\n")
    with zipfile.ZipFile(tmp_path / "nomd.fmu", "w") as z:
        z.writestr("readme.txt", "no model description")
    with zipfile.ZipFile(tmp_path / "othervars.fmu", "w") as z:
        z.writestr("modelDescription.xml", '<fmiModelDescription fmiVersion="2.0" modelName="M" guid="{x}">'
                   '<CoSimulation modelIdentifier="M"/><ModelVariables><ScalarVariable name="y" '
                   'valueReference="0" causality="output"><Real/></ScalarVariable></ModelVariables>'
                   '</fmiModelDescription>')
    (tmp_path / "afile").write_text("a regular file\n")
    broken = tmp_path / "broken_tables"
    broken.mkdir()
    (broken / "force_deflection.csv").write_text("theta_degC,u_m,force_N\n20,0,0\n20,x,1\n")
    (broken / "kiss_point.csv").write_text("theta_degC,delta_kiss_m\n20,0\n")
    return tmp_path


CASES = [
    (["check-spring", "{d}/empty.toml"], ["empty.toml", "empty"]),
    (["check-spring", "{d}/noname.toml"], ["noname.toml", "name: required key missing"]),
    (["check-spring", "{d}/missing.toml"], ["missing.toml", "does not exist"]),
    (["check-spring", "{d}/bad.toml"], ["bad.toml", "TOML syntax error"]),
    (["sweep", "--spring", "{d}/empty.toml", "--out", "{d}/o"], ["empty.toml", "empty"]),
    (["launch", "--scenario", "{d}/missing.toml", "--out", "{d}/o"], ["missing.toml", "not found"]),
    (["launch", "--scenario", "{d}/empty.toml", "--out", "{d}/o"], ["empty.toml", "empty"]),
    (["launch", "--fmu", "{d}/text.fmu", "--out", "{d}/o"], ["text.fmu", "not a zip"]),
    (["launch", "--fmu", "{d}/nomd.fmu", "--out", "{d}/o"], ["nomd.fmu", "no modelDescription.xml"]),
    (["launch", "--fmu", "{d}/othervars.fmu", "--out", "{d}/o"], ["othervars.fmu", "x_to (input, m) missing"]),
    (["launch", "--fmu", "{d}/missing.fmu", "--out", "{d}/o"], ["missing.fmu", "does not exist"]),
    (["simulate", "--fmu", "{d}/text.fmu", "--out", "{d}/o"], ["text.fmu", "not a zip"]),
    (["launch", "--out", "{d}/afile/sub"], ["afile/sub", "cannot be written"]),
    (["simulate", "--out", "{d}/afile/sub"], ["afile/sub", "cannot be written"]),
    (["export", "--out", "{d}/afile/sub"], ["afile/sub", "cannot be written"]),
    (["export", "--tables", "{d}/nowhere", "--out", "{d}/o"], ["nowhere", "table folder does not exist"]),
    (["export", "--tables", "{d}/broken_tables", "--out", "{d}/o"], ["force_deflection.csv"]),
    (["simulate", "--tables", "{d}/nowhere", "--out", "{d}/o"], ["nowhere"]),
    (["build-fmu", "--tables", "{d}/broken_tables", "-o", "{d}/x.fmu"], ["force_deflection.csv"]),
    (["export", "--out", "{shipped}"], ["--force", "shipped"]),
    (["launch", "--out", "{shipped}"], ["--force", "shipped"]),
    (["sweep", "--out", "{shipped}"], ["--force", "shipped"]),
]


@pytest.mark.parametrize("argv,needles", CASES, ids=[" ".join(a[:2]) + f" #{i}" for i, (a, _) in enumerate(CASES)])
def test_cli_error(argv, needles, files, capsys):
    shipped = str(Path(DEFAULT_TABLES))
    rc = main([a.format(d=files, shipped=shipped) for a in argv])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.startswith("error: ") and "Traceback" not in err
    for needle in needles:
        assert needle in err, f"{needle!r} not in {err!r}"


def test_nothing_written_into_shipped_tables(files):
    before = sorted(p.name for p in Path(tables_root()).rglob("*"))
    main(["export", "--out", str(Path(DEFAULT_TABLES) / "sub")])
    assert sorted(p.name for p in Path(tables_root()).rglob("*")) == before


def test_unwritable_out_fails_before_the_simulation(files, capsys, monkeypatch):
    """--out is checked before any FMU is built or any launch is simulated."""
    import cushion_clutch.launch.report as report
    monkeypatch.setattr(report, "run_both", lambda *a, **k: pytest.fail("simulated before checking --out"))
    assert main(["launch", "--out", str(files / "afile" / "sub")]) == 2


def test_subprocess_no_traceback_and_debug_shows_one(files):
    cmd = [sys.executable, "-m", "cushion_clutch.cli"]
    p = subprocess.run(cmd + ["launch", "--fmu", str(files / "text.fmu"), "--out", str(files / "o")],
                       capture_output=True, text=True)
    assert p.returncode == 2 and "Traceback" not in p.stderr and p.stderr.count("\n") == 1, p.stderr
    p = subprocess.run(cmd + ["--debug", "check-spring", str(files / "empty.toml")], capture_output=True, text=True)
    assert p.returncode != 0 and "Traceback" in p.stderr
