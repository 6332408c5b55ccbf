"""The test suite's own rule: in CI a missing ccx or Wine fails the tests that need it; elsewhere they skip."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent

PROBE = '''
import pytest

@pytest.mark.ccx
def test_needs_ccx():
    pass

def test_needs_wine(wine_env):
    pass
'''


@pytest.mark.parametrize("ci, outcome, code", [("true", "2 errors", 1), ("", "2 skipped", 0)])
def test_missing_tools_fail_in_ci_and_skip_elsewhere(tmp_path, ci, outcome, code):
    text = (TESTS / "conftest.py").read_text()
    wine = 'WINE = Path("/usr/lib/wine/wine64")'
    assert wine in text
    (tmp_path / "conftest.py").write_text(text.replace(wine, 'WINE = Path("/nonexistent/wine64")'))
    (tmp_path / "test_probe.py").write_text(PROBE)
    (tmp_path / "pytest.ini").write_text("[pytest]\nmarkers =\n    ccx: x\n    fmu: y\n")
    empty = tmp_path / "bin"
    empty.mkdir()
    env = dict(os.environ, CI=ci, PATH=str(empty))          # no ccx on PATH
    env.pop("PYTEST_ADDOPTS", None)
    res = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rfs", "test_probe.py"],
                         cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=120)
    assert outcome in res.stdout and res.returncode == code, res.stdout + res.stderr
    if ci:
        assert "CI=true: a missing tool is a failure" in res.stdout
