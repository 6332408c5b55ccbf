"""The shared pure model (cushion_clutch/model/clutch_model.py) through the Python API."""
import math

import control
import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model import (KELVIN, ClutchParameters, CoverParameters, load_table, outputs, thermal_step, thermal_system,
                                  VARIABLES, x_to_for_torque)
from cushion_clutch.model.table_format import read_tables

P = ClutchParameters()


@pytest.fixture(scope="module")
def table():
    return load_table()


@pytest.fixture(scope="module")
def raw():
    return read_tables(DEFAULT_TABLES)


def test_interpolation_is_scipy_pchip(table, raw):
    for t, u, f, curve in zip(raw.theta_degC, raw.u_m, raw.force_N, table.curves):
        q = np.linspace(u[0], u[-1], 997)
        ref = PchipInterpolator(u, f)(q)
        ours = np.array([table.force(x, t) for x in q])
        assert ours == pytest.approx(ref, rel=1e-12, abs=1e-9)


def test_force_is_monotone_in_u_at_and_between_table_temperatures(table):
    u = np.linspace(-0.3e-3, 1.6e-3, 4001)
    for t in (20.0, 57.0, 195.0, 222.5, 300.0):
        f = np.array([table.force(x, t) for x in u])
        assert np.all(np.diff(f) >= 0)
        assert f[0] == pytest.approx(0.0, abs=1e-9)


def _first_contact(u, f):
    """Last row still at the curve's first force (independent of spring_table)."""
    return u[np.flatnonzero(f == f[0])[-1]]


def test_between_tables_the_curves_blend_on_a_normalised_compression(table, raw):
    """F(u, theta) between 80 and 195 degC: each neighbour read at the same fraction of its own first-contact ->
    full-compression span (spans linear in theta), the forces weighted linearly in theta (scipy's PCHIP)."""
    k80, k195 = list(raw.theta_degC).index(80.0), list(raw.theta_degC).index(195.0)
    w = 0.3
    curves = [(raw.u_m[k], raw.force_N[k]) for k in (k80, k195)]
    a = [_first_contact(u, f) for u, f in curves]
    b = [u[-1] for u, _ in curves]
    a_t, b_t = (1 - w) * a[0] + w * a[1], (1 - w) * b[0] + w * b[1]
    assert table.first_contact(80.0 + w * 115.0) == pytest.approx(a_t, rel=1e-14)
    assert table.full_compression(80.0 + w * 115.0) == pytest.approx(b_t, rel=1e-14)
    for u in np.linspace(a_t - 1e-4, b_t + 1e-4, 301):
        xi = (u - a_t) / (b_t - a_t)
        ref = [float(PchipInterpolator(cu, cf, extrapolate=False)(np.clip(a[j] + xi * (b[j] - a[j]), a[j], b[j])))
               for j, (cu, cf) in enumerate(curves)]
        assert table.force(u, 80.0 + w * 115.0) == pytest.approx((1 - w) * ref[0] + w * ref[1], rel=1e-11, abs=1e-9)
    assert table.delta_kiss(137.5) == pytest.approx(np.interp(137.5, raw.theta_degC, raw.delta_kiss_m))


def test_first_contact_and_full_compression_are_continuous_in_theta(table):
    """No step where theta crosses a table temperature (issue 30: the max/min over the active curves jumped)."""
    for t in table.theta_degC[1:-1]:
        for q in (table.first_contact, table.full_compression):
            assert abs(q(t + 1e-7) - q(t - 1e-7)) < 1e-12
        u = np.linspace(-3e-4, 2e-3, 801)
        jump = max(abs(table.force(x, t + 1e-7) - table.force(x, t - 1e-7)) for x in u)
        assert jump < 1e-3       # N; the force's theta slope is < 10 N/K


def test_first_contact_is_where_the_force_starts(table, tmp_path):
    """A curve that begins with two 0 N rows (the FE's first increments can both carry nothing; the shipped tables
    had two such curves before the predicted joint, now none, so one is made from the 80 degC curve) has its first
    contact at the second row; every temperature's first contact is where the force starts."""
    import shutil
    folder = tmp_path / "doubled"
    shutil.copytree(DEFAULT_TABLES, folder)
    rows = (folder / "force_deflection.csv").read_text().splitlines()
    first = next(i for i, r in enumerate(rows[1:], 1) if r.startswith("80,"))
    u0, u1 = float(rows[first].split(",")[1]), float(rows[first + 1].split(",")[1])
    assert float(rows[first].split(",")[2]) == 0.0
    rows.insert(first + 1, f"80,{0.5 * (u0 + u1):.9e},0.000000")
    (folder / "force_deflection.csv").write_text("\n".join(rows) + "\n")
    made = load_table(folder)
    for tab in (table, made):
        doubled = [(th, c) for th, c in zip(tab.theta_degC, tab.curves) if c.y[0] == c.y[1] == 0.0]
        for th, c in doubled:
            assert 0.0 < c.y[2] and tab.first_contact(th) == c.x[1]
        for t in (-40.0, -10.0, 20.0, 137.5, 195.0, 260.0, 300.0, 350.0):
            a = tab.first_contact(t)
            assert tab.force(a, t) == 0.0 < tab.force(a + 1e-7, t)
    assert [th for th, c in zip(made.theta_degC, made.curves) if c.y[0] == c.y[1] == 0.0] == [80.0]


def test_clamped_outside_table_temperatures(table):
    # only the tables clamp: the cover's E(theta) and the stack's growth go on beyond them
    table_only = ClutchParameters(cover=CoverParameters(diaphragm_modulus_drop_per_K=0.0, facing_expansion_per_K=0.0,
                                                        pressure_plate_expansion_per_K=0.0,
                                                        flywheel_expansion_per_K=0.0))
    hot = outputs(0.006, 400.0 + KELVIN, table, table_only)
    edge = outputs(0.006, table.theta_degC[-1] + KELVIN, table, table_only)
    assert hot.clamped and not edge.clamped
    assert hot.torque == edge.torque
    assert outputs(0.006, 400.0 + KELVIN, table, P).torque != edge.torque


def test_thermal_step_is_the_exponential_solution():
    theta0, theta_cm = 300.0, 500.0
    tau = P.C / (P.U + P.H)
    theta_inf = (P.U * theta_cm + P.H * P.theta_a) / (P.U + P.H)
    for dt in (1e-3, 0.1, 5.0, 100.0):
        expected = theta_inf + (theta0 - theta_inf) * math.exp(-dt / tau)
        assert thermal_step(theta0, theta_cm, dt, P) == pytest.approx(expected, rel=1e-14)
    assert tau == pytest.approx(7.142857142857, rel=1e-12)


def test_exact_step_equals_zero_order_hold_discretisation():
    rng = np.random.default_rng(1)
    theta_cm = 293.15 + 250 * rng.random(200)
    for dt in (1e-3, 0.1, 5.0):
        sysd = control.c2d(thermal_system(P), dt, method="zoh")
        u = np.vstack([theta_cm, np.full_like(theta_cm, P.theta_a)])
        resp = control.forced_response(sysd, U=u, X0=[P.theta_cs_start])
        theta, ours = P.theta_cs_start, []
        for k in range(len(theta_cm)):
            ours.append(theta)
            theta = thermal_step(theta, theta_cm[k], dt, P)
        assert np.array(ours) == pytest.approx(np.squeeze(resp.outputs), rel=1e-12)


def test_steady_gain_and_time_constant():
    sys = thermal_system(P)
    assert control.dcgain(sys)[0, 0] == pytest.approx(P.U / (P.U + P.H))
    assert -1 / sys.poles()[0].real == pytest.approx(P.C / (P.U + P.H))


@pytest.mark.parametrize("theta_c", [20.0, 137.0, 195.0, 300.0])
def test_inverse_gives_back_the_torque(table, theta_c):
    theta = theta_c + KELVIN
    t_full = outputs(0.025, theta, table, P).torque
    for frac in (0.02, 0.1, 0.5, 0.9, 0.99):
        x = x_to_for_torque(frac * t_full, theta, table, P)
        assert outputs(x, theta, table, P).torque == pytest.approx(frac * t_full, rel=1e-7)


def test_inverse_saturates(table):
    theta = 195.0 + KELVIN
    x_full = x_to_for_torque(1e9, theta, table, P)
    assert outputs(x_full, theta, table, P).torque == pytest.approx(outputs(0.025, theta, table, P).torque)
    # first contact, back through the cover's Newton solve: zero to rounding (1e-15 N.m)
    assert outputs(x_to_for_torque(0.0, theta, table, P), theta, table, P).torque == pytest.approx(0.0, abs=1e-12)


def test_parameter_problems_name_the_parameter():
    bad = ClutchParameters(C=0.0, mu=-0.1, lever_ratio=0.0, R_eq=math.nan)
    msg = "\n".join(bad.problems())
    for name in ("C = 0.0", "mu = -0.1", "lever_ratio = 0.0", "R_eq = nan"):
        assert name in msg
    assert ClutchParameters().problems() == []


def test_malformed_table_is_a_clear_error(tmp_path):
    (tmp_path / "force_deflection.csv").write_text("theta_degC,u_m,force_N\n20,0,1\n20,1e-4,x\n")
    (tmp_path / "kiss_point.csv").write_text("theta_degC,delta_kiss_m\n20,0\n")
    with pytest.raises(ValueError, match="force_deflection.csv"):
        load_table(tmp_path)


def test_negative_table_force_is_refused_with_its_row(tmp_path):
    (tmp_path / "force_deflection.csv").write_text("theta_degC,u_m,force_N\n20,0,-5\n20,1e-4,-1\n20,2e-4,3\n")
    (tmp_path / "kiss_point.csv").write_text("theta_degC,delta_kiss_m\n20,0\n")
    with pytest.raises(ValueError, match=r"force_deflection.csv: row 1 \(line 2\): force_N = -5.0 < 0"):
        load_table(tmp_path)


def test_thermal_system_names_a_zero_heat_capacity():
    with pytest.raises(ValueError, match="^C = 0"):
        thermal_system(ClutchParameters(C=0))


@pytest.mark.parametrize("bad, message", [
    ({"mu": -0.1}, "p.mu = -0.1 is out of range [0, 2]"),
    ({"mu": math.nan}, "p.mu = nan is out of range [0, 2]"),
    ({"R_eq": 0.0}, "p.R_eq = 0.0 is out of range (0, 1]"),
    ({"n_surfaces": 0.0}, "p.n_surfaces = 0.0 is out of range [1, 16]"),
    ({"n_surfaces": 2.5}, "p.n_surfaces = 2.5 must be a positive integer in [1, 16]"),
    ({"lever_ratio": 0.0}, "p.lever_ratio = 0.0 is out of range (0, 100]"),
    ({"x_kiss_ref": 2.0}, "p.x_kiss_ref = 2.0 is out of range [-1, 1]: did you mean 0.002 m?"),
    ({"x_kiss_ref": math.inf}, "p.x_kiss_ref = inf is out of range [-1, 1]"),
])
def test_api_refuses_bad_clutch_parameters(table, bad, message):
    p = ClutchParameters(**bad)
    for call in (lambda: outputs(0.006, 400.0, table, p), lambda: x_to_for_torque(100.0, 400.0, table, p)):
        with pytest.raises(ValueError) as err:
            call()
        assert str(err.value) == message


@pytest.mark.parametrize("args, message", [
    ((math.inf, 400.0), "x_to = inf m is outside [-0.002, 0.025] m"),
    ((0.006, 100.0), "theta_cs = 100.0 K is outside [200, 800] K: did you mean 373.15 K (100 degC)?"),
    ((12.0, 400.0), "x_to = 12.0 m is outside [-0.002, 0.025] m: did you mean 0.012 m?"),
    ((0.006, 800.5), "theta_cs = 800.5 K is outside [200, 800] K"),
    ((0.1, 190.0), "x_to = 0.1 m is outside [-0.002, 0.025] m: did you mean 0.0001 m?; theta_cs = 190.0 K is outside [200, 800] K: "
                   "did you mean 463.15 K (190 degC)?"),
])
def test_api_argument_errors_name_every_bad_argument(table, args, message):
    with pytest.raises(ValueError) as err:
        outputs(*args, table, P)
    assert str(err.value) == message


@pytest.mark.parametrize("cover, names", [
    # the diaphragm cannot carry the release: the compliance rule names the lever arm's parameters
    ({"fulcrum_radius_m": 0.105}, ("release_compliance_m_per_N", "fulcrum_radius_m", "pressure_plate_radius_m",
                                   "lever_ratio")),
    ({"fulcrum_radius_m": 0.2}, ("radii must satisfy", "< fulcrum_radius_m <", "0.2 < 0.111")),
    ({"diaphragm_cone_height_m": 0.01}, ("diaphragm_cone_height_m / diaphragm_thickness_m", "2 sqrt(2)")),
    ({"diaphragm_poisson_ratio": math.nan}, ("p.cover.diaphragm_poisson_ratio = nan is out of range [0, 0.5)",)),
])
def test_api_errors_name_the_cover_rule(table, cover, names):
    """Every cover problem reaches the API's error with the parameter and the rule (issue 31), in each
    function that uses the cover; none of them says only "invalid arguments"."""
    import dataclasses
    from cushion_clutch.model import kiss_point, x_to_for_torque

    p = ClutchParameters(cover=dataclasses.replace(CoverParameters(), **cover))
    for call in (lambda: outputs(0.012, 400.0, table, p), lambda: x_to_for_torque(10.0, 400.0, table, p),
                 lambda: kiss_point(400.0, table, p)):
        with pytest.raises(ValueError) as err:
            call()
        text = str(err.value)
        assert text.startswith("p.cover") and "invalid arguments" not in text, text
        for name in names:
            assert name in text, (name, text)


def test_release_compliance_bound_in_the_message_is_the_rule(table):
    """The largest compliance the message states is where the rule flips: 0.1 % below it passes, above fails."""
    import dataclasses
    import re

    bad = ClutchParameters(cover=dataclasses.replace(CoverParameters(), fulcrum_radius_m=0.105))
    c_max = float(re.search(r"= ([0-9.e+-]+) m/N", bad.problems()[0]).group(1))
    for factor, ok in ((0.999, True), (1.001, False)):
        p = ClutchParameters(cover=dataclasses.replace(bad.cover, release_compliance_m_per_N=factor * c_max))
        assert (p.problems() == []) == ok, (factor, p.problems())


def test_thermal_step_refuses_bad_arguments_and_parameters():
    with pytest.raises(ValueError) as err:
        thermal_step(300.0, 400.0, -1.0, ClutchParameters(C=0.0))
    assert str(err.value) == "dt = -1.0 s is outside [0, 1e+09] s; p.C = 0.0 is out of range (0, 1e+06]"


def test_cold_characteristic_error_grows_with_temperature(table):
    """README (launch results): "the naive error grows with theta_cs". On the model: a bearing position
    chosen from the 20 degC characteristic over-delivers the slipping-launch torques (2-30 % of the closed
    torque, 312 N.m) when the spring is hot, more the hotter it is (the kiss point moves 0.56 mm towards the
    open side at 250 degC, cushion and stack growth less the release compliance; the over-delivery at 250 degC
    is 110 %, 45 % and 9.9 % at the three levels); the temperature-aware inverse has no such error."""
    full = outputs(0.025, 20.0 + KELVIN, table, P).torque
    for frac in (0.02, 0.1, 0.3):
        target = frac * full
        x_cold = x_to_for_torque(target, 20.0 + KELVIN, table, P)
        ratios = [outputs(x_cold, th + KELVIN, table, P).torque / target for th in (20.0, 80.0, 195.0, 250.0, 300.0)]
        assert ratios[0] == pytest.approx(1.0, rel=1e-6)
        assert all(b > a for a, b in zip(ratios, ratios[1:])), ratios
        assert ratios[3] > 1.05
        x_hot = x_to_for_torque(target, 250.0 + KELVIN, table, P)
        assert outputs(x_hot, 250.0 + KELVIN, table, P).torque == pytest.approx(target, rel=1e-6)


#: the parameter ranges, written out by hand from the docstring of ClutchParameters and the FMUs' checks
#: (not read from the code): (low, high, low_open, high_open)
DOCUMENTED_RANGES = {"n_surfaces": (1.0, 16.0, False, False), "mu": (0.0, 2.0, False, False),
                     "R_eq": (0.0, 1.0, True, False), "U": (0.0, 1e4, False, False), "H": (0.0, 1e4, False, False),
                     "C": (0.0, 1e6, True, False), "theta_a": (200.0, 800.0, False, False),
                     "theta_cs_start": (200.0, 800.0, False, False), "x_kiss_ref": (-1.0, 1.0, False, False),
                     "lever_ratio": (0.0, 100.0, True, False)}


@pytest.mark.parametrize("name", sorted(DOCUMENTED_RANGES))
def test_parameter_range_bounds_are_open_or_closed_as_documented(name):
    lo, hi, lo_open, hi_open = DOCUMENTED_RANGES[name]
    text = f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"
    for v, is_open in ((lo, lo_open), (hi, hi_open)):
        got = ClutchParameters(**{name: v}).problems()
        if name == "lever_ratio" and v == hi:
            # inside its range, but the default cover cannot take it: the bearing radius r_f - i (r_pp - r_f)
            # would be negative (89 mm - 100 x 22 mm), which the cover's consistency check names
            assert got == ["lever_ratio = 100 puts the bearing at r_b = r_f - i (r_pp - r_f) = -2.111 m; "
                           "must be > 0"], got
            continue
        assert got == ([f"{name} = {v!r} is out of range {text}"] if is_open else []), (name, v, got)
    from cushion_clutch.number_check import unit_hint
    unit = next(u for n, _, u, _ in VARIABLES if n == name)
    for v in (lo - 1e-3 * (hi - lo), hi + 1e-3 * (hi - lo)):
        hint = unit_hint(v, unit, lo, hi)          # e.g. theta_a = 199.4: "did you mean 472.55 K (199.4 degC)?"
        assert ClutchParameters(**{name: v}).problems() == [f"{name} = {v!r} is out of range {text}"
                                                            + (f": {hint}" if hint else "")]
    assert unit_hint(lo - 1e-3 * (hi - lo), unit, lo, hi) or unit not in ("K",), name   # degC below a K range


def test_a_spring_without_a_heat_path_is_refused():
    msg = "U + H must be > 0 (the cushion spring needs a heat path)"
    assert ClutchParameters(U=0.0, H=0.0).problems() == [msg]
    assert ClutchParameters(U=0.0, H=1e-9).problems() == []
    with pytest.raises(ValueError) as err:
        thermal_step(300.0, 400.0, 1.0, ClutchParameters(U=0.0, H=0.0))
    assert str(err.value) == "p." + msg


def test_argument_bounds(table):
    """Closed bounds are accepted, values past them refused (x_to in [-0.002, 0.025] m, theta_cs in
    [200, 800] K, omega_slip in [-1500, 1500] rad/s, dt in [0, 1e9] s)."""
    for x in (-0.002, 0.025):
        outputs(x, 400.0, table, P)
    for w in (-1500.0, 1500.0):
        outputs(0.006, 400.0, table, P, omega_slip=w)
    with pytest.raises(ValueError) as err:
        outputs(0.006, 400.0, table, P, omega_slip=1500.0 * (1 + 1e-12))
    assert str(err.value).startswith("omega_slip = 1500.0000000015002 rad/s is outside [-1500, 1500] rad/s")
    for ok in (200.0, 800.0):
        outputs(0.006, ok, table, P)
    for bad in (199.999, 800.001):
        with pytest.raises(ValueError, match=r"^theta_cs = .* K is outside \[200, 800\] K"):
            outputs(0.006, bad, table, P)
    assert thermal_step(300.0, 400.0, 0.0, P) == 300.0
    assert thermal_step(300.0, 400.0, 1e9, P) == pytest.approx((P.U * 400.0 + P.H * P.theta_a) / (P.U + P.H))


def test_kiss_point_is_the_outputs_kiss_point():
    """The frame-free kiss point equals the cover balance's, to the bit, over temperatures and wear."""
    from cushion_clutch.model import kiss_point

    table = load_table()
    rng = np.random.default_rng(3)
    for wear in (0.0, 0.3e-3):
        p = ClutchParameters(facing_wear=wear)
        for th, tm in rng.uniform([250.0, 250.0], [560.0, 700.0], size=(200, 2)):
            assert kiss_point(th, table, p, tm) == outputs(0.004, th, table, p, tm).x_kiss
        assert kiss_point(300.0, table, p) == outputs(0.0, 300.0, table, p).x_kiss
    with pytest.raises(ValueError, match="theta_cs"):
        kiss_point(-1.0, table, ClutchParameters())


def test_inverse_at_zero_torque_is_where_the_torque_starts(table):
    """x_to_for_torque(0) is the first position with torque, at every temperature (issue 31: at 300 degC it
    answered 0.1 mm early, at the first of the 300 degC curve's two 0 N rows)."""
    for t in np.linspace(10.0, 320.0, 32):
        th = t + KELVIN
        x0 = x_to_for_torque(0.0, th, table, P)
        lo, hi = x0 - 2e-4, x0 + 2e-4               # bisection on the forward model for the first torque > 0
        assert outputs(lo, th, table, P).torque == 0.0 < outputs(hi, th, table, P).torque
        while hi - lo > 1e-10:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if outputs(mid, th, table, P).torque == 0.0 else (lo, mid)
        assert abs(x0 - hi) < 1.5e-6, t


@pytest.mark.parametrize("name", ["n_surfaces", "mu", "R_eq", "x_kiss_ref", "lever_ratio", "facing_wear"])
@pytest.mark.parametrize("value", [True, False])
def test_api_refuses_a_boolean_parameter(table, name, value):
    """Issue 43: a bool is never a number, even where its 0/1 lies in the range (mu = True is 1.0 in Python);
    the message names the one parameter."""
    p = ClutchParameters(**{name: value})
    for call in (lambda: outputs(0.006, 400.0, table, p), lambda: x_to_for_torque(100.0, 400.0, table, p)):
        with pytest.raises(ValueError) as err:
            call()
        assert str(err.value).startswith(f"p.{name} = {value!r} is out of range"), str(err.value)


@pytest.mark.parametrize("call, name", [
    (lambda t: outputs(0.006, 400.0, t, P, omega_slip=True), "omega_slip"),
    (lambda t: outputs(False, 400.0, t, P), "x_to"),
    (lambda t: x_to_for_torque(True, 400.0, t, P), "torque"),
    (lambda t: x_to_for_torque(100.0, 400.0, t, P, tol_m=True), "tol_m"),
    (lambda t: thermal_step(300.0, 400.0, True, P), "dt"),
])
def test_api_refuses_a_boolean_argument(table, call, name):
    with pytest.raises(ValueError) as err:
        call(table)
    assert str(err.value).startswith(f"{name} = True ") or str(err.value).startswith(f"{name} = False "), str(err.value)


def test_thermal_step_and_system_refuse_a_boolean_parameter():
    with pytest.raises(ValueError, match=r"^p.C = True is out of range"):
        thermal_step(300.0, 400.0, 1.0, ClutchParameters(C=True))
    with pytest.raises(ValueError, match=r"^p.U = False is out of range"):
        thermal_step(300.0, 400.0, 1.0, ClutchParameters(U=False, H=0.04))
    with pytest.raises(ValueError, match="^C = True"):
        thermal_system(ClutchParameters(C=True))
