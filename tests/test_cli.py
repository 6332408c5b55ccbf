import pytest

from cushion_clutch.cli import main
from cushion_clutch.fe.params import DEFAULT_SPRING


def test_check_spring_accepts_the_default(capsys):
    assert main(["check-spring", str(DEFAULT_SPRING)]) == 0
    assert "is valid" in capsys.readouterr().out


def test_check_spring_names_the_bad_key(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(DEFAULT_SPRING.read_text().replace("n_pairs = 8", "n_pairs = 0\ncolour = 'red'"))
    assert main(["check-spring", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "colour: unknown key" in err and "n_pairs = 0" in err


@pytest.mark.fmu
def test_simulate_and_export_write_their_files(tmp_path, capsys):
    assert main(["simulate", "--out", str(tmp_path), "--engagements", "2", "--step", "0.5"]) == 0
    printed = capsys.readouterr().out
    assert ".staging" not in printed and "missing input" not in printed       # issue 27
    assert "the native FMU built from" in printed
    for name in ("CushionClutch.fmu", "engagements.csv", "engagements.png",
                 "torque_characteristic.png", "thermal_step_response.png"):
        assert (tmp_path / name).stat().st_size > 0
    assert main(["export", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "cushion_spring_tables.mat").exists()
    assert (tmp_path / "cushion_spring_tables.txt").read_text().startswith("#1\n")
