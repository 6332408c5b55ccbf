"""The launch simulation's results pinned: a speed change of the loop, the plant or the TCUs must not move them.

``tests/golden/launch_metrics_short.json`` holds the per-launch metrics and the energy terms of short runs
(``creep``: two launches, all six TCU variants; ``protection``: three launches from a hot start, where the
thermal protection acts). The real-time-factor work was checked against main f0e6b1a's numbers (bit-identical);
the file was rewritten once since, for the production TCU's friction and thermal-estimate changes and the cover
solvers' round-off changes merged with it (Halley in C, a fused curve evaluation in Python: the closed loop's
5 um position quantiser turns 1e-15 into 1e-8). Every number must agree within 1e-9 relative (round-off of a
reordered sum, no more). Rewrite the file only for a change of the physics, the solvers or the TCUs, never for
a speed change of the loop:

    PYTHONPATH=. python tests/test_launch_golden.py --write
"""
import dataclasses
import json
import math
import sys
import tempfile
from pathlib import Path

import pytest

GOLDEN = Path(__file__).parent / "golden" / "launch_metrics_short.json"
VARIANTS = ("naive", "aware", "aware_estimated", "adaptive", "adaptive_aware_estimated", "production")
#: (scenario, launches, initial facing temperature degC or None, variants)
CASES = (("creep", 2, None, VARIANTS), ("protection", 3, 275.0, ("aware_estimated", "production")))
REL = 1e-9

pytestmark = pytest.mark.fmu


def _runs(fmu_dir: Path) -> dict:
    """{"scenario/variant": {"metrics": [...], "energy": {...}, "lock_events": [...]}} of the short runs."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.model import load_table

    out = {}
    for name, launches, theta0, variants in CASES:
        sc = load_scenario(scenario_path(name))
        sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, launches=launches))
        if theta0 is not None:
            sc = dataclasses.replace(sc, facing=dataclasses.replace(sc.facing, initial_degC=theta0))
        table = load_table(sc.tables_path("tcu") or Path(DEFAULT_TABLES))
        fmu = build_plant_fmu(Path(DEFAULT_TABLES), sc, fmu_dir / name / "CushionClutch.fmu")
        for v in variants:
            r = simulate_launches(fmu, sc, table, v)
            out[f"{name}/{v}"] = {"metrics": r.metrics, "energy": dict(vars(r.energy)),
                                  "lock_events": [list(e) for e in r.lock_events]}
    return out


def _close(a, b, where: str, bad: list) -> None:
    if isinstance(a, dict):
        if set(a) != set(b):
            bad.append(f"{where}: keys {sorted(set(a) ^ set(b))} differ")
            return
        for k in a:
            _close(a[k], b[k], f"{where}.{k}", bad)
    elif isinstance(a, list):
        if len(a) != len(b):
            bad.append(f"{where}: {len(a)} items, golden {len(b)}")
            return
        for i, (x, y) in enumerate(zip(a, b)):
            _close(x, y, f"{where}[{i}]", bad)
    elif isinstance(a, float) or isinstance(b, float):
        a, b = float(a), float(b)
        if not (math.isnan(a) and math.isnan(b)) and not abs(a - b) <= REL * max(abs(a), abs(b)):
            bad.append(f"{where}: {a!r}, golden {b!r}")
    elif a != b:
        bad.append(f"{where}: {a!r}, golden {b!r}")


def test_short_runs_reproduce_the_pinned_metrics(tmp_path):
    golden = json.loads(GOLDEN.read_text())
    got = json.loads(json.dumps(_runs(tmp_path)))        # the same JSON round trip as the golden file
    bad: list[str] = []
    _close(got, golden, "runs", bad)
    assert not bad, f"{len(bad)} values moved, first: " + "; ".join(bad[:8])


def test_the_comparison_can_fail():
    bad: list[str] = []
    _close({"a": [1.0, math.nan, "x"]}, {"a": [1.0 + 3e-9, math.nan, "x"]}, "r", bad)
    assert bad == ["r.a[0]: 1.0, golden 1.000000003"]
    bad.clear()
    _close({"a": [1.0, math.nan]}, {"a": [1.0 + 1e-12, math.nan]}, "r", bad)
    assert not bad


if __name__ == "__main__" and "--write" in sys.argv:
    with tempfile.TemporaryDirectory() as tmp:
        GOLDEN.write_text(json.dumps(_runs(Path(tmp)), indent=1, allow_nan=True) + "\n")
    print(f"wrote {GOLDEN}")


def test_the_tcu_memo_returns_what_it_computed_and_stays_bounded():
    """The TCU's model memo (tcu._memo): exact keys only; -0.0 is not remembered under 0.0's key."""
    from cushion_clutch.launch.tcu.controller import MEMO_SIZE, _memo

    memo: dict = {}
    calls = []

    def f(v):
        calls.append(v)
        return v * 2.0

    assert _memo(memo, (1.5, 300.0), lambda: f(1.5)) == 3.0
    assert _memo(memo, (1.5, 300.0), lambda: f(1.5)) == 3.0 and calls == [1.5]
    assert _memo(memo, (1.5, 300.0 + 1e-13), lambda: f(1.5)) == 3.0 and len(calls) == 2
    _memo(memo, (-0.0, 300.0), lambda: f(-0.0))
    assert (0.0, 300.0) not in memo
    for i in range(3 * MEMO_SIZE):
        _memo(memo, (float(i), 1.0), lambda: f(1.0))
    assert len(memo) <= MEMO_SIZE
