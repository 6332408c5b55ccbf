"""The results pages' writer (cushion_clutch/benchmarks/page.py) and the launch page's layout
(cushion_clutch/benchmarks/launch.py): a page names its commit and a command relative to the repository, is
refused from a dirty tree unless marked as a draft, and the launch page gives each scenario a short table in
words and units with the full tables collapsed."""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from cushion_clutch.benchmarks import page as P


def _git(repo: Path, *args: str) -> None:
    subprocess.run(["git", "-C", str(repo), *args], check=True, capture_output=True,
                   env={"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t", "GIT_COMMITTER_NAME": "t",
                        "GIT_COMMITTER_EMAIL": "t@t", "PATH": "/usr/bin:/bin"})


@pytest.fixture
def repo(tmp_path, monkeypatch) -> Path:
    """A clean git checkout standing in for the repository (page.ROOT)."""
    root = tmp_path / "checkout"
    root.mkdir()
    _git(root, "init", "-q")
    (root / "a.txt").write_text("1\n")
    _git(root, "add", "a.txt")
    _git(root, "commit", "-q", "-m", "one")
    monkeypatch.setattr(P, "ROOT", root)
    return root


def _write(out: Path, argv: list[str]) -> str:
    with P.results_page(out, "T", "cushion_clutch.benchmarks.x", argv) as page:
        page.markdown("| a |\n|---|\n| 1 |")
        print(f"printed from {P.ROOT}/deep/file.csv")
    return out.read_text(encoding="utf-8")


def test_page_names_commit_and_relative_command_never_the_checkout(repo):
    out = repo / "docs" / "results" / "x.md"
    text = _write(out, ["--out", str(out), "--csv=/elsewhere/y.csv"])
    head = subprocess.run(["git", "-C", str(repo), "rev-parse", "--short", "HEAD"], capture_output=True,
                          text=True).stdout.strip()
    assert f"- commit: `{head}`\n" in text
    assert "`python3 -m cushion_clutch.benchmarks.x --out docs/results/x.md --csv=y.csv`" in text
    assert str(repo) not in text and "+dirty" not in text and P.DRAFT_MARK not in text
    assert "printed from deep/file.csv" in text


def test_dirty_tree_is_refused_before_the_benchmark_runs(repo):
    (repo / "a.txt").write_text("2\n")
    ran = []
    with pytest.raises(P.DirtyTreeError, match="--draft"):
        with P.results_page(repo / "x.md", "T", "m", ["--out", "x.md"]):
            ran.append(1)
    assert not ran and not (repo / "x.md").exists()


def test_draft_from_a_dirty_tree_is_marked_loudly(repo):
    (repo / "a.txt").write_text("2\n")
    text = _write(repo / "x.md", ["--out", "x.md", "--draft"])
    assert text.index(P.DRAFT_MARK) < text.index("Generated, not edited")
    assert "with uncommitted changes" in text and "+dirty" not in text


def test_relative_arg():
    assert P.relative_arg(str(P.ROOT / "docs" / "results" / "launch.md")) == "docs/results/launch.md"
    assert P.relative_arg("/tmp/x.md") == "x.md"
    assert P.relative_arg("--out=/tmp/x.md") == "--out=x.md"
    assert P.relative_arg("default,trailer") == "default,trailer"


@pytest.mark.fmu
def test_launch_page_layout_on_a_short_run(repo):
    """One launch of `default` and of `cooldown` through the page writer: per scenario a key table (at most
    nine columns, headers in words, every figure with its unit), the full tables only inside <details>, no
    raw CSV column name as a header, the check figures at the end."""
    from cushion_clutch.benchmarks.launch import CHECK_HEADING, KEY_HEADERS, write_page

    out = repo / "launch.md"
    write_page(out, ["default", "cooldown"], "native", ["--markdown", "--launches", "1", "--out", str(out)],
               launches=1)
    text = out.read_text(encoding="utf-8")
    assert "--launches 1 --out launch.md" in text and CHECK_HEADING in text
    for h in KEY_HEADERS[2:7]:
        assert re.search(r"\[(N·m|K|°C)\]$", h), h
    opened = closed = 0
    inside = False
    key_rows = []
    for line in text.split(CHECK_HEADING)[0].splitlines():
        opened += "<details" in line
        closed += "</details>" in line
        inside = (inside or "<details" in line) and "</details>" not in line
        if line.startswith("| ") and not inside:
            header = line
            cells = header.strip("|").split("|")
            assert len(cells) <= 10, header[:80]
            assert not re.search(r"\b[a-z_]+_(Nm|K|degC|m_s2)\b(?!`)", header), header[:120]
            key_rows += [line] if re.search(r"\| \d+\sof\s\d+ \|", line) else []
    assert opened == closed == 2                              # one collapsed section per scenario
    assert "adaptive_<wbr>aware_<wbr>estimated" in text       # long TCU names may wrap in a narrow column
    assert len(key_rows) == 6 + 6 + 6                          # default; cooldown all + its cool-down group


def test_doc_numbers_are_the_model_s():
    """The {cc} role's numbers: the closed torque from the cover's budget equals the clutch model's torque with
    the bearing far past lift-off (a second path through the model); an unknown name is refused by name."""
    from cushion_clutch.benchmarks.doc_numbers import closed_torque_Nm, evaluate
    from cushion_clutch.model import ClutchParameters, load_table, outputs

    for theta, wear in ((20.0, 0.0), (195.0, 0.0), (300.0, 0.0), (20.0, 1.0)):
        o = outputs(0.02, theta + 273.15, load_table(), ClutchParameters(facing_wear=wear * 1e-3))
        assert closed_torque_Nm(theta, wear) == pytest.approx(o.torque, rel=1e-9), (theta, wear)
    assert evaluate("closed_torque_Nm(20):.2f") == f"{closed_torque_Nm(20):.2f}"
    with pytest.raises(KeyError, match="nonsense"):
        evaluate("nonsense(1)")


def test_doc_numbers_network_modes_are_the_network_s():
    """thermal.md's slow modes: the network's eigenvalues at the default idle (open) and 1800 rpm (clamped),
    ascending; clamping couples the facings to the metal, so every slow mode is faster clamped."""
    import math

    import numpy as np

    from cushion_clutch.benchmarks.doc_numbers import evaluate, network_idle_rad_s, network_mode_s
    from cushion_clutch.model.thermal_network import NetworkParams, ThermalNetwork

    a, _ = ThermalNetwork(NetworkParams(), 293.15, 293.15).matrices(network_idle_rad_s(), 0.0, False)
    slow = np.sort(-1.0 / np.linalg.eigvals(a).real)
    assert network_mode_s(-1) == pytest.approx(slow[-1], rel=1e-12)
    assert network_idle_rad_s() == pytest.approx(800.0 * math.pi / 30.0)
    for clamped in (False, True):
        modes = [network_mode_s(i, clamped) for i in range(-4, 0)]
        assert all(0.0 < x <= y for x, y in zip(modes, modes[1:])), modes
    assert all(network_mode_s(i, True) < network_mode_s(i) for i in range(-4, 0))
    assert evaluate("network_mode_s(-1)") == f"{network_mode_s(-1):.0f}"
