"""The FE engine against closed forms, and its failure modes, on decks our code writes."""
import numpy as np
import pytest

from cushion_clutch.fe.ccx import run_ccx
from cushion_clutch.fe.deck import strip_deck
from cushion_clutch.errors import CalculixError, CalculixNotFoundError, ConvergenceError
from cushion_clutch.fe.geometry import strip_mesh
from cushion_clutch.fe.params import Material
from cushion_clutch.fe.results import read_dat

pytestmark = pytest.mark.ccx

L, B, T = 0.040, 0.002, 0.4e-3          # m


def _end1(tmp_path, deck):
    run_ccx(deck, tmp_path)
    (_, u), = read_dat(tmp_path / "case.dat")[("displacements", "END1")]
    return u * 1e-3                         # mm -> m


def test_cantilever_matches_euler_bernoulli(tmp_path):
    mat = Material()
    force = 0.05                            # N, small: linear theory
    mesh = strip_mesh(L, B, T, 1e-3)
    tip = _end1(tmp_path, strip_deck(mesh, mat, tip_force_N=force))
    inertia = B * T**3 / 12
    expected = force * L**3 / (3 * mat.youngs_modulus_Pa[0] * inertia)
    assert -tip[:, 2].mean() == pytest.approx(expected, rel=0.02)


def test_free_thermal_expansion(tmp_path):
    mat = Material()
    mesh = strip_mesh(L, B, T, 2e-3)
    end = _end1(tmp_path, strip_deck(mesh, mat, theta_degC=300.0))
    expected = mat.expansion_coefficient_per_K * (300.0 - 20.0) * L
    assert end[:, 0] == pytest.approx(np.full(len(end), expected), rel=1e-3)
    assert np.abs(end[:, 2]).max() < 1e-3 * expected      # stays flat


@pytest.mark.parametrize("theta", [-40.0, -10.0, 300.0])
def test_free_thermal_expansion_with_a_secant_table(tmp_path, theta):
    # alpha(theta) as a secant coefficient from ZERO (the default spring's table below 20 degC):
    # the strip's strain is alpha(theta) (theta - 20), alpha linear between the table points
    mat = Material(temperatures_degC=(-40.0, 20.0, 350.0), youngs_modulus_Pa=(209.2e9, 206e9, 186e9),
                   expansion_coefficients_per_K=(1.088e-5, 1.12e-5, 1.12e-5))
    mesh = strip_mesh(L, B, T, 2e-3)
    end = _end1(tmp_path, strip_deck(mesh, mat, theta_degC=theta))
    alpha = float(np.interp(theta, [-40.0, 20.0], [1.088e-5, 1.12e-5]))
    assert mat.expansion_coefficient(theta) == pytest.approx(alpha, rel=1e-12)
    assert end[:, 0] == pytest.approx(np.full(len(end), alpha * (theta - 20.0) * L), rel=1e-3)


def test_missing_ccx_says_how_to_install(monkeypatch, tmp_path):
    monkeypatch.setenv("CCX", "ccx-not-installed-here")
    with pytest.raises(CalculixNotFoundError, match="apt-get install -y calculix-ccx"):
        run_ccx("*NODE\n", tmp_path)


def test_input_error_is_reported_not_ignored(tmp_path):
    # ccx exits 0 on a misspelled keyword and only warns; the runner must catch it
    deck = strip_deck(strip_mesh(L, B, T, 4e-3), Material()).replace("*BOUNDARY", "*BOUNDRY")
    with pytest.raises(CalculixError) as info:
        run_ccx(deck, tmp_path, theta_degC=20.0)
    assert not isinstance(info.value, ConvergenceError)
    assert info.value.log_tail
