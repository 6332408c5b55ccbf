"""The thermal FMU's fault catalogue (issue 39 item 8): every case of ``tests/thermal_fault_cases.py`` in its own
process against ``build-fmu --thermal`` (FMI 2.0); each case judges itself (status, message, state afterwards) and a
host crash fails its row."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.fmu

RUNNER = Path(__file__).with_name("thermal_fault_cases.py")
CASES = subprocess.run([sys.executable, str(RUNNER), "--list"], capture_output=True, text=True,
                       check=True).stdout.split()


@pytest.fixture(scope="module")
def thermal_fmu(tmp_path_factory):
    from cushion_clutch.cli import main
    out = tmp_path_factory.mktemp("thermal_faults") / "T2.fmu"
    assert main(["build-fmu", "--thermal", "-o", str(out)]) == 0
    return out


def test_the_catalogue_covers_every_kind_of_fault():
    kinds = {"input": ("nan_", "inf_", "x_to_one", "read_after", "_step"), "slip": ("huge_slip",),
             "parameter": ("network_start", "capacity", "shares", "wear", "declared_parameter"),
             "state": ("state_",), "order": ("before_init", "after_terminate", "set_", "twice", "reset"),
             "me": ("me_",)}
    for kind, marks in kinds.items():
        assert sum(any(m in c for m in marks) for c in CASES) >= 2, kind
    assert len(CASES) >= 25


@pytest.mark.parametrize("case", CASES)
def test_thermal_fault_case(thermal_fmu, case):
    r = subprocess.run([sys.executable, str(RUNNER), case, str(thermal_fmu)], capture_output=True, text=True,
                       timeout=600)
    lines = [line for line in r.stdout.splitlines() if line.startswith("RESULT ")]
    assert r.returncode == 0 and lines, f"the host process died (exit {r.returncode}): {r.stderr[-2000:]}"
    result = json.loads(lines[-1][7:])
    assert result["ok"], f"{case}: " + "; ".join(result["why"])
