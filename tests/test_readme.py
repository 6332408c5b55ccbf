"""The README's Python examples run as written (from an empty folder)."""
import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def test_readme_has_python_examples():
    assert BLOCKS


@pytest.mark.parametrize("code", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_readme_python_block_runs(code, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    exec(compile(code, str(README), "exec"), {"__name__": "readme_example"})


def _readme_table(header_start: str) -> list[list[str]]:
    """Rows (cells as text) of the README's markdown table whose header starts with ``header_start``."""
    lines = README.read_text(encoding="utf-8").splitlines()
    i = next(k for k, line in enumerate(lines) if line.startswith(header_start))
    rows = []
    for line in lines[i + 2:]:
        if not line.startswith("|"):
            break
        rows.append([c.strip() for c in line.strip("|").split("|")])
    return rows


def test_committed_table_figures_are_the_readme_s():
    """README "Results" table: delta_kiss, crest growth, full force, k20/k50/k90 and k90/k20 per temperature,
    recomputed from the committed CSVs of lookup_tables/default (each at the README's rounding)."""
    import numpy as np

    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fe.tables import progressivity, read_tables

    t = read_tables(DEFAULT_TABLES)
    crest = dict(np.loadtxt(DEFAULT_TABLES / "crest_growth.csv", delimiter=",", skiprows=1))
    rows = _readme_table("| θ [°C] | δ_kiss [mm]")
    assert [float(r[0]) for r in rows] == list(t.theta_degC)
    for r, theta, u, f, d in zip(rows, t.theta_degC, t.u_m, t.force_N, t.delta_kiss_m):
        assert float(r[1]) == pytest.approx(d * 1e3, abs=0.5e-4), r
        assert float(r[2]) == pytest.approx(crest[theta] * 1e3, abs=0.5e-4), r
        assert float(r[3]) == pytest.approx(f[-1], abs=0.5), r
        k = progressivity(u, f)
        k20, k50, k90 = (float(x) for x in r[4].split("/"))
        assert (k20, k50, k90) == pytest.approx(
            (k["k20_N_per_m"] / 1e6, k["k50_N_per_m"] / 1e6, k["k90_N_per_m"] / 1e6), abs=0.005), r
        assert float(r[5]) == pytest.approx(k["k90_over_k20"], abs=0.005), r
        # the metadata's own figures are those of the CSV
        assert t.metadata["progressivity"][f"{theta:g}"]["k90_over_k20"] == pytest.approx(k["k90_over_k20"],
                                                                                        rel=1e-9)
