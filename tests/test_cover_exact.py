"""The fast paths of the Python model (cover.py, spring_table.py, clutch_model.py) against a straightforward
evaluation written from the documented equations, over the whole accepted domain, and history independence.

The reference here evaluates the PCHIP cubic in its Hermite basis from the curve's rows and slopes, blends the
two neighbouring curves as the spring_table docstring states, takes the diaphragm's moment from
``almen_laszlo_force`` and solves the cover balance by plain bisection (no Newton start, no cache, no fused
evaluation). The model's answers must agree with it to round-off: forces within 1e-9 relative (+1e-9 N),
positions within 1e-13 m, the inverse within 3e-12 m (its tolerance, 1e-12 m of bearing travel on the
cushion, seen through the release compliance). Measured on 2026-11-26: forces within 1.8e-11 relative, u within
3e-16 m, the inverse within 1.3e-12 m (the model before the speed-up: the same and 1.2e-12 m).
"""
import random
from bisect import bisect_right

import pytest

from cushion_clutch.model import ClutchParameters, kiss_point, load_table, outputs, x_to_for_torque
from cushion_clutch.model import clutch_model
from cushion_clutch.model.clutch_model import THETA_MAX_K, THETA_MIN_K, X_TO_MAX, X_TO_MIN, cover_frame
from cushion_clutch.model.cover import CoverMap, almen_laszlo_force, wear_limit

#: agreement with the reference: relative force, absolute force (N), position (m), inverse position (m)
REL_F, ABS_F, TOL_X, TOL_INV = 1e-9, 1e-9, 1e-13, 3e-12


@pytest.fixture(scope="module")
def table():
    return load_table()


@pytest.fixture(scope="module")
def limit(table):
    p = ClutchParameters()
    return wear_limit(p.cover, p.lever_ratio, table, p.x_kiss_ref, THETA_MIN_K, THETA_MAX_K)


def hermite(c, u):
    """F(u) of one table curve in the Hermite basis from its rows (x, y) and PCHIP slopes d."""
    x, y, d = c.x, c.y, c.d
    if u <= c.x_first:
        return y[0]
    if u >= x[-1]:
        return y[-1]
    i = bisect_right(x, u) - 1
    h = x[i + 1] - x[i]
    t = (u - x[i]) / h
    return ((2 * t ** 3 - 3 * t ** 2 + 1) * y[i] + (t ** 3 - 2 * t ** 2 + t) * h * d[i]
            + (-2 * t ** 3 + 3 * t ** 2) * y[i + 1] + (t ** 3 - t ** 2) * h * d[i + 1])


def ref_force(table, u, theta_c):
    """F(u, theta) as the spring_table docstring states it: clamped, or two curves on a common normalised
    compression weighted linearly in theta."""
    ts, cs = table.theta_degC, table.curves
    if theta_c <= ts[0]:
        return hermite(cs[0], u)
    if theta_c >= ts[-1]:
        return hermite(cs[-1], u)
    i = bisect_right(ts, theta_c) - 1
    w = (theta_c - ts[i]) / (ts[i + 1] - ts[i])
    if w == 0.0:
        return hermite(cs[i], u)
    c0, c1 = cs[i], cs[i + 1]
    a = (1 - w) * c0.x_first + w * c1.x_first
    b = (1 - w) * c0.x_max + w * c1.x_max
    v = (u - a) / (b - a)
    return ((1 - w) * hermite(c0, c0.x_first + v * (c0.x_max - c0.x_first))
            + w * hermite(c1, c1.x_first + v * (c1.x_max - c1.x_first)))


class Reference:
    """The cover balance at one temperature pair and wear, solved by bisection from the module's equations."""

    def __init__(self, table, p, theta_cs, theta_cm):
        c, g = p.cover, CoverMap(p.cover, p.lever_ratio)
        self.g, self.table, self.theta_c = g, table, theta_cs - 273.15
        self.e_mod = c.diaphragm_youngs_modulus_Pa * (1 - c.diaphragm_modulus_drop_per_K
                                                      * (theta_cs - c.reference_temperature_K))
        self.geo = (c.diaphragm_outer_radius_m, c.diaphragm_inner_radius_m, c.diaphragm_thickness_m,
                    c.diaphragm_cone_height_m)
        self.nu = c.diaphragm_poisson_ratio
        dT = theta_cm - c.reference_temperature_K
        stack = table.delta_kiss(self.theta_c) + dT * (c.facing_thickness_m * c.facing_expansion_per_K
                                                       + c.pressure_plate_thickness_m * c.pressure_plate_expansion_per_K
                                                       + c.flywheel_length_m * c.flywheel_expansion_per_K)
        u_full_ref = table.full_compression(c.reference_temperature_K - 273.15)
        self.s_kiss = c.installed_deflection_m + (u_full_ref + stack - p.facing_wear) / g.kp
        self.s_solid = self.s_kiss - table.full_compression(self.theta_c) / g.kp
        # X_c: the kiss point at the reference state lies at x_kiss_ref
        s_k0 = c.installed_deflection_m + u_full_ref / g.kp
        m0 = almen_laszlo_force(s_k0, *self.geo, c.diaphragm_youngs_modulus_Pa, self.nu) * g.e
        f0 = ref_force(table, 0.0, c.reference_temperature_K - 273.15)
        self.xc = p.x_kiss_ref + g.kb * s_k0 + g.comp * (m0 - f0 * g.L_pp) / g.L_b

    def moment(self, s):
        return almen_laszlo_force(s, *self.geo, self.e_mod, self.nu) * self.g.e

    def forces(self, s):
        """(bearing force, cushion force) at deflection s, N."""
        fc = ref_force(self.table, (self.s_kiss - s) * self.g.kp, self.theta_c)
        return (self.moment(s) - fc * self.g.L_pp) / self.g.L_b, fc

    def x_of(self, s):
        return self.xc - self.g.kb * s - self.g.comp * self.forces(s)[0]

    def state(self, x_to):
        """(clamp force, bearing force, u, s)."""
        g = self.g
        x_solid = self.x_of(self.s_solid)
        if x_to >= x_solid:
            fto_solid, fc_solid = self.forces(self.s_solid)
            fto = max(0.0, fto_solid - (x_to - x_solid) / g.comp)
            return ((self.moment(self.s_solid) - fto * g.L_b) / g.L_pp, fto,
                    (self.s_kiss - self.s_solid) * g.kp, self.s_solid)
        lo, hi = self.s_solid, (self.xc - x_to) / g.kb          # x_of decreases in s
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if mid in (lo, hi):
                break
            lo, hi = (mid, hi) if self.x_of(mid) > x_to else (lo, mid)
        s = 0.5 * (lo + hi)
        fto, fc = self.forces(s)
        return fc, fto, (self.s_kiss - s) * g.kp, s

    def x_for_clamp(self, force):
        """Smallest x with clamp force >= force, in the cushion phase (bisection on u)."""
        b = self.table.bracket(self.theta_c)
        lo, hi = b.first, b.full
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if mid in (lo, hi):
                break
            lo, hi = (mid, hi) if ref_force(self.table, mid, self.theta_c) < force else (lo, mid)
        return self.x_of(self.s_kiss - hi / self.g.kp)


def close(a, b):
    return abs(a - b) <= ABS_F + REL_F * abs(b)


def test_curve_evaluation_matches_the_hermite_basis(table):
    for c in table.curves:
        for k in range(2001):
            u = c.x_min - 1e-4 + (c.x_max - c.x_min + 2e-4) * k / 2000
            f, d = c.value_slope(u)
            assert close(f, hermite(c, u)), (u, f, hermite(c, u))
            if c.x_first < u < c.x_max:       # the slope against a central difference of the reference
                e = 1e-9
                fd = (hermite(c, u + e) - hermite(c, u - e)) / (2 * e)
                assert abs(d - fd) <= 1e-5 * max(abs(fd), 1e3), (u, d, fd)


def test_forward_map_matches_the_bisection_reference_over_the_domain(table, limit):
    rng = random.Random(28)
    worst = {"F": 0.0, "x": 0.0}
    n = 0
    for wear in (0.0, 0.4 * limit, limit):
        p = ClutchParameters(facing_wear=wear)
        thetas = [THETA_MIN_K, 293.15, 353.15, 468.15, 523.15, 573.15, THETA_MAX_K] + [
            rng.uniform(THETA_MIN_K, THETA_MAX_K) for _ in range(3)]
        for theta_cs in thetas:
            for theta_cm in (theta_cs, THETA_MIN_K, THETA_MAX_K, rng.uniform(THETA_MIN_K, THETA_MAX_K)):
                ref = Reference(table, p, theta_cs, theta_cm)
                xs = [X_TO_MIN, X_TO_MAX] + [rng.uniform(X_TO_MIN, X_TO_MAX) for _ in range(12)]
                for x in xs:
                    o = outputs(x, theta_cs, table, p, theta_cm)
                    fpp, fto, u, s = ref.state(x)
                    assert close(o.clamp_force, fpp) and close(o.bearing_force, fto), (wear, theta_cs, theta_cm, x)
                    assert abs(o.u_f - max(u, 0.0)) <= TOL_X, (wear, theta_cs, theta_cm, x, o.u_f, u)
                    assert abs(o.x_kiss - ref.x_of(ref.s_kiss)) <= TOL_X
                    worst["F"] = max(worst["F"], abs(o.clamp_force - fpp) / max(fpp, 1.0))
                    worst["x"] = max(worst["x"], abs(o.u_f - max(u, 0.0)))
                    n += 1
    assert n >= 1600
    assert worst["F"] < REL_F and worst["x"] < TOL_X


def test_inverse_matches_the_bisection_reference_over_the_domain(table, limit):
    rng = random.Random(26)
    for wear in (0.0, 0.5 * limit, limit):
        p = ClutchParameters(facing_wear=wear)
        gain = p.n_surfaces * p.mu * p.R_eq
        for _ in range(12):
            theta_cs, theta_cm = rng.uniform(THETA_MIN_K, THETA_MAX_K), rng.uniform(THETA_MIN_K, THETA_MAX_K)
            ref = Reference(table, p, theta_cs, theta_cm)
            fr = cover_frame(table, p, theta_cs, theta_cm)
            for k in range(15):
                force = fr.fc_solid * (k + 0.5) / 15          # the cushion phase
                x = x_to_for_torque(force * gain, theta_cs, table, p, theta_cm=theta_cm)
                assert abs(x - ref.x_for_clamp(force)) <= TOL_INV, (wear, theta_cs, theta_cm, force)
                assert outputs(x, theta_cs, table, p, theta_cm).clamp_force >= force * (1 - 1e-12)


def _answers(table, cases, params):
    out = []
    for kind, wear, theta_cs, theta_cm, v in cases:
        p = params[wear]
        if kind == "o":
            o = outputs(v, theta_cs, table, p, theta_cm)
            out.append((o.torque, o.force, o.u_f, o.x_kiss, o.clamp_force, o.bearing_force, o.validity))
        elif kind == "i":
            out.append(x_to_for_torque(v, theta_cs, table, p, theta_cm=theta_cm))
        else:
            out.append(kiss_point(theta_cs, table, p, theta_cm))
    return out


def test_answers_do_not_depend_on_the_call_history(table, limit):
    rng = random.Random(17)
    cases = []
    wear = 0.5 * limit                # one wear: alternating two would redo the (slow, cached) hold check
    for _ in range(150):              # more temperature pairs than the frame cache holds, each asked repeatedly
        theta_cs, theta_cm = rng.uniform(THETA_MIN_K, THETA_MAX_K), rng.uniform(THETA_MIN_K, THETA_MAX_K)
        cases += [("o", wear, theta_cs, theta_cm, rng.uniform(X_TO_MIN, X_TO_MAX)) for _ in range(3)]
        cases += [("i", wear, theta_cs, theta_cm, rng.uniform(0.0, 330.0)), ("k", wear, theta_cs, theta_cm, None)]
    params = {wear: ClutchParameters(facing_wear=wear)}
    first = _answers(table, cases, params)
    order = list(range(len(cases)))
    rng.shuffle(order)
    shuffled = _answers(table, [cases[k] for k in order], params)
    again = [None] * len(cases)
    for k, a in zip(order, shuffled):
        again[k] = a
    assert again == first                              # bit for bit
    clutch_model._FRAMES.clear()                       # and from cold caches, in reverse
    assert _answers(table, cases[::-1], params)[::-1] == first
