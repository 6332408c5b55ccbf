/*
 * CushionClutch model core, part 3: the cover assembly (diaphragm spring, finger lever, clamp load).
 * The equations are those of cushion_clutch/model/cover.py (module docstring), the reference implementation:
 *
 *   F_AL(s) = 4 E/(1-nu^2) t^4/(K1 D_e^2) (s/t) [(h/t - s/t)(h/t - s/(2t)) + 1]   (Almen-Laszlo)
 *   M(s) = F_AL(s) e = F_pp L_pp + F_to L_b                                       (moment balance)
 *   u(s) = (s_kiss - s) L_pp/e,  F_pp = F_c(u, theta_cs) while s > s_solid         (cushion phase)
 *   x_to = X_c - (L_b/e) s - c F_to(s)                                             (bearing kinematics)
 *   x_to >= x_solid: s = s_solid, F_to = max(0, F_to(s_solid) - (x_to - x_solid)/c),
 *                    F_pp = (M(s_solid) - F_to L_b)/L_pp                           (solid phase)
 *
 * The forward map is a safeguarded Halley iteration on s in [s_solid, s_rigid]. cc_cover_state starts it from a
 * chord (3.1 evaluations per call on average): the start depends on the inputs only, so its results are the same
 * bits whatever the call history. cc_cover_solve starts from the last answer moved along its tangent when the
 * bearing moved by at most CC_WARM_DX (2.0 evaluations per call in a launch's 1 ms steps), or, with the clutch
 * open and the cushion in its force-free cell, from the parabola through its last three answers (1.1 evaluations
 * per call in a braked standstill's 1 ms steps); its answer passes the same residual test, so it agrees with
 * cc_cover_state's to that residual, and depends on the CcWarm passed in (the FMU keeps it in its saved state).
 * Where the cushion is in that cell the solve iterates on the cubic P(s) alone, with the same bits as with the
 * table (open clutch: no table lookups).
 */
#include "clutch_cover.h"

#include <math.h>
#include <string.h>

#define KELVIN 273.15
#define PI 3.14159265358979323846

static double k1(double a, double b) {
    double d = a / b;
    return ((d - 1.0) / d) * ((d - 1.0) / d) / ((d + 1.0) / (d - 1.0) - 2.0 / log(d)) / PI;
}

/* M(s) = F_AL(s) e (E folded into fal) and dM/ds */
static double moment(const CcCover *cv, double s, double e_mod) {
    double t = cv->p[CV_DIAPHRAGM_THICKNESS_M], h = cv->p[CV_DIAPHRAGM_CONE_HEIGHT_M];
    return cv->fal * e_mod * (s / t) * ((h - s) * (h - 0.5 * s) / cv->tt + 1.0) * cv->e;
}

static double moment_slope(const CcCover *cv, double s, double e_mod) {
    double t = cv->p[CV_DIAPHRAGM_THICKNESS_M], h = cv->p[CV_DIAPHRAGM_CONE_HEIGHT_M];
    return cv->fal * e_mod / t * ((h - s) * (h - 0.5 * s) / (t * t) + 1.0 - s * (1.5 * h - s) / (t * t)) * cv->e;
}

static double youngs(const CcCover *cv, double theta_K) {
    return cv->p[CV_DIAPHRAGM_YOUNGS_MODULUS_PA] *
           (1.0 - cv->p[CV_DIAPHRAGM_MODULUS_DROP_PER_K] * (theta_K - cv->p[CV_REFERENCE_TEMPERATURE_K]));
}

void cc_cover_prepare(CcCover *cv, const double *par, double lever_ratio, double x_kiss_ref, const Table *tb) {
    double s_k0, f_to, th_ref;
    memcpy(cv->p, par, sizeof cv->p);
    cv->e = par[CV_DIAPHRAGM_OUTER_RADIUS_M] - par[CV_DIAPHRAGM_INNER_RADIUS_M];
    cv->L_pp = par[CV_PRESSURE_PLATE_RADIUS_M] - par[CV_FULCRUM_RADIUS_M];
    cv->L_b = lever_ratio * cv->L_pp;
    cv->kb = cv->L_b / cv->e;
    cv->kp = cv->L_pp / cv->e;
    cv->fal = 4.0 / (1.0 - par[CV_DIAPHRAGM_POISSON_RATIO] * par[CV_DIAPHRAGM_POISSON_RATIO]) *
              pow(par[CV_DIAPHRAGM_THICKNESS_M], 4) /
              (k1(par[CV_DIAPHRAGM_OUTER_RADIUS_M], par[CV_DIAPHRAGM_INNER_RADIUS_M]) * 4.0 *
               par[CV_DIAPHRAGM_OUTER_RADIUS_M] * par[CV_DIAPHRAGM_OUTER_RADIUS_M]);
    /* the frame's parameter-only subexpressions, each evaluated as the frame had it (the same bits) */
    cv->tt = par[CV_DIAPHRAGM_THICKNESS_M] * par[CV_DIAPHRAGM_THICKNESS_M];
    cv->dstack = par[CV_FACING_THICKNESS_M] * par[CV_FACING_EXPANSION_PER_K] +
                 par[CV_PRESSURE_PLATE_THICKNESS_M] * par[CV_PRESSURE_PLATE_EXPANSION_PER_K] +
                 par[CV_FLYWHEEL_LENGTH_M] * par[CV_FLYWHEEL_EXPANSION_PER_K];
    th_ref = par[CV_REFERENCE_TEMPERATURE_K] - KELVIN;
    cv->u_full_ref = cc_table_full(tb, th_ref);
    s_k0 = par[CV_INSTALLED_DEFLECTION_M] + cv->u_full_ref / cv->kp;
    f_to = (moment(cv, s_k0, par[CV_DIAPHRAGM_YOUNGS_MODULUS_PA]) - cc_table_force(tb, 0.0, th_ref) * cv->L_pp) /
           cv->L_b;
    cv->xc = x_kiss_ref + cv->kb * s_k0 + par[CV_RELEASE_COMPLIANCE_M_PER_N] * f_to;
    /* the solver's residual: ck = c / L_b and its products (see cc_cover_state) */
    cv->ck = par[CV_RELEASE_COMPLIANCE_M_PER_N] / cv->L_b;
    cv->ckl = cv->ck * cv->L_pp;
    cv->ckp = cv->ckl * cv->kp;
    cv->ck_fal = cv->ck * cv->fal;
    cv->p1h = 1.0 + par[CV_DIAPHRAGM_CONE_HEIGHT_M] * par[CV_DIAPHRAGM_CONE_HEIGHT_M] / cv->tt;
    cv->f_theta_cs = NAN; /* no frame yet */
    cv->hint = cv->hint_k = cv->hint_t = 0;
    /* the open solve's shortcut (cc_cover_solve) needs every CurvePair's cell 0 to be the clamped constant:
       coefficients 1..3 +0 in both curves, and a first knot (clutch_tables.c builds them so; else it stays off;
       -DCC_NO_OPEN_SHORTCUT turns it off, for tests/test_native_speed.py's comparison) */
    cv->open_ok = 1;
    {
        int j, r;
        for (j = 0; j < 2 * tb->nt - 1; ++j) {
            const CurvePair *pr = &tb->pairs[j];
            if (pr->m < 1) cv->open_ok = 0;
            for (r = 1; r < 4 && pr->m >= 1; ++r)
                if (!(pr->cell[0].a[r] == 0.0 && !signbit(pr->cell[0].a[r]) && pr->cell[0].d[r] == 0.0 &&
                      !signbit(pr->cell[0].d[r])))
                    cv->open_ok = 0;
        }
    }
#ifdef CC_NO_OPEN_SHORTCUT
    cv->open_ok = 0;
#endif
}

/* -(dx_to/ds) at its smallest (open phase, s = h) at the largest E: > 0 means no snap-through */
double cc_cover_slope_bound(const CcCover *cv) {
    double e_max = cv->p[CV_DIAPHRAGM_YOUNGS_MODULUS_PA] *
                   (1.0 + cv->p[CV_DIAPHRAGM_MODULUS_DROP_PER_K] * cv->p[CV_REFERENCE_TEMPERATURE_K]);
    return cv->kb +
           cv->p[CV_RELEASE_COMPLIANCE_M_PER_N] * moment_slope(cv, cv->p[CV_DIAPHRAGM_CONE_HEIGHT_M], e_max) / cv->L_b;
}

/* the solver's curve functions are inlined (the loop's constants stay in registers) */
#if defined(__GNUC__)
#define CC_INLINE static inline __attribute__((always_inline))
#else
#define CC_INLINE static inline
#endif

/* the cushion force F_c(u) at the bracket's temperature: cc_bracket_force (clutch_tables.h), inlined */
CC_INLINE double cushion(const TBracket *b, double u, int *hint, CellPt *pt) { return cc_bracket_force(b, u, hint, pt); }

/* dF_c/du in *d1 and d2F_c/du2 in *d2 at the point of the last cushion() call (0 where F_c is clamped) */
CC_INLINE void cushion_deriv(const TBracket *b, const CellPt *pt, double *d1, double *d2) {
    double tau = pt->tau, k = b->inv_span;
    *d1 = (pt->c1 + tau * (2.0 * pt->c2 + 3.0 * pt->c3 * tau)) * k;
    *d2 = (2.0 * pt->c2 + 6.0 * pt->c3 * tau) * (k * k);
}

/* the cushion force alone (the frame's points); *hint as in cushion */
static double cushion_value(const TBracket *b, double u, int *hint) {
    CellPt pt;
    return cushion(b, u, hint, &pt);
}

/* the frame: everything that depends on temperature and wear, not on x_to */
static void frame(CcCover *cv, const Table *tb, double theta_cs, double theta_cm, double wear) {
    const double *p = cv->p;
    double kb = cv->kb, kp = cv->kp, comp = p[CV_RELEASE_COMPLIANCE_M_PER_N];
    double stack, m_solid, e_mod, fk;
    TBracket b;
    e_mod = youngs(cv, theta_cs);
    stack = cc_table_bracket_hint(tb, theta_cs - KELVIN, &b, &cv->hint_t) +
            cv->dstack * (theta_cm - p[CV_REFERENCE_TEMPERATURE_K]);
    cv->f_e = e_mod;
    cv->f_br = b;
    cv->s_kiss = p[CV_INSTALLED_DEFLECTION_M] + (cv->u_full_ref + stack - wear) / kp;
    cv->s_solid = cv->s_kiss - b.full / kp;
    /* the full compression: each curve at its last row, (1 - w) y0 + w y1 (Bracket.force there up to the
       rounding of u_full and the curves' argument, an ulp or two of u, where dF/du is finite) */
    {
        const Curve *c0 = b.c0, *c1 = b.c1;
        cv->fc_solid = b.w == 0.0 ? c0->y[c0->n - 1] : (1.0 - b.w) * c0->y[c0->n - 1] + b.w * c1->y[c1->n - 1];
    }
    m_solid = moment(cv, cv->s_solid, e_mod);
    cv->m_solid = m_solid;
    cv->fto_solid = (m_solid - cv->fc_solid * cv->L_pp) / cv->L_b;
    cv->x_solid = cv->xc - kb * cv->s_solid - comp * cv->fto_solid;
    fk = cushion_value(&b, 0.0, &cv->hint_k);
    cv->fto_kiss = (moment(cv, cv->s_kiss, e_mod) - fk * cv->L_pp) / cv->L_b;
    cv->x_kiss = cv->xc - kb * cv->s_kiss - comp * cv->fto_kiss;
    {   /* P(s)'s coefficients (operation for operation as the solver had them: the same root to the last bit
           where it matters, e.g. at the cushion's first contact, where F has a kink) */
        const double t = p[CV_DIAPHRAGM_THICKNESS_M], h = p[CV_DIAPHRAGM_CONE_HEIGHT_M], tt = cv->tt,
                     km = cv->ck_fal * e_mod * cv->e / t;
        cv->p1 = -kb - km * cv->p1h;
        cv->p2 = km * 1.5 * h / tt;
        cv->p3 = -km * 0.5 / tt;
    }
    cv->f_theta_cs = theta_cs;
    cv->f_theta_cm = theta_cm;
    cv->f_wear = wear;
}


/* the safeguarded Halley step of the cover's solve from s with residual r, slope r' and curvature r'' in the bracket
   (lo, hi): Halley's 2 r r' / (2 r'^2 - r r'') (third order where x(s) is smooth; one division), or Newton's where
   it would change the Newton step by more than a factor 2; bisection where r' >= 0 or the step leaves the bracket */
static inline double halley_next(double s, double r, double slope, double curv, double lo, double hi) {
    double s_new;
    if (slope < 0.0) {
        double s2 = slope * slope, den = 2.0 * s2 - r * curv;
        s_new = den > s2 && den < 4.0 * s2 ? s - 2.0 * r * slope / den : s - r / slope;
    } else s_new = 0.5 * (lo + hi);
    return (s_new > lo && s_new < hi) ? s_new : 0.5 * (lo + hi);
}

#ifdef CC_COUNT_EVALS /* tests/test_native_speed.py counts the solver's cushion evaluations (and the open ones) */
long cc_count_evals, cc_count_open;
#define COUNT_EVAL() (++cc_count_evals)
#define COUNT_OPEN() (++cc_count_open)
#else
#define COUNT_EVAL() ((void)0)
#define COUNT_OPEN() ((void)0)
#endif

int cc_cover_solve(CcCover *cv, const Table *tb, double x_to, double theta_cs, double theta_cm, double wear,
                   CcWarm *w, CcCoverState *out) {
    const double *p = cv->p;
    double kb = cv->kb, kp = cv->kp, comp = p[CV_RELEASE_COMPLIANCE_M_PER_N];
    double lo, hi, s, r, fc, fto, dfc, d2fc, slope = 0.0;
    CellPt pt;
    int k;
    if (!(theta_cs == cv->f_theta_cs && theta_cm == cv->f_theta_cm && wear == cv->f_wear))
        frame(cv, tb, theta_cs, theta_cm, wear);
    out->x_solid = cv->x_solid;
    out->x_lift = cv->x_solid + comp * (cv->fto_solid > 0.0 ? cv->fto_solid : 0.0);
    out->x_kiss = cv->x_kiss;
    if (cv->fto_solid < 0.0) { out->bearing = cv->fto_solid; w->x = NAN; return -1; }
    if (x_to >= cv->x_solid) {
        fto = comp > 0.0 ? cv->fto_solid - (x_to - cv->x_solid) / comp : 0.0;
        if (fto < 0.0) fto = 0.0;
        out->bearing = fto;
        out->clamp = (cv->m_solid - fto * cv->L_b) / cv->L_pp;
        out->cushion = cv->fc_solid;
        out->u = (cv->s_kiss - cv->s_solid) * kp;
        out->s = cv->s_solid;
        w->x = NAN;
        return 0;
    }
    {
        /* the residual r(s) = x_to(s) - x_to = P(s) + ck L_pp F_c(u(s)), P(s) = X_c - x_to - kb s - ck M(s) a cubic
           (ck = c / L_b; M(s) = F_AL(s) e expanded in powers of s: p1..p3 of the frame): r, dr/ds and d2r/ds2 by
           Horner */
        const TBracket *b = &cv->f_br;
        const double s_kiss = cv->s_kiss, xc = cv->xc;
        const double tol_r = 1e-15 * (1.0 + fabs(x_to)), ckl = cv->ckl, ckp = cv->ckp;
        const double p0 = xc - x_to, p1 = cv->p1, p2 = cv->p2, p3 = cv->p3;
        const double d = x_to - w->x; /* the bearing's travel since the warm start (NaN: none) */
        int hint = cv->hint;
        lo = cv->s_solid;
        hi = (xc - x_to) / kb;
        /* start: the warm start's answer moved along its tangent, if the bearing moved by at most CC_WARM_DX and it
           lies in the bracket (false for a slope of 0: inf or NaN); else (from the inputs only) the chord of x(s)
           between the solid and kiss points (cushion phase) or the rigid lever shifted by the kiss-point
           compliance (open). Open, the parabola through the warm start's history below replaces it */
        if (fabs(d) <= CC_WARM_DX && (s = w->s + d / w->slope, s > lo && s < hi)) {
            slope = w->slope; /* the tangent kept if this start passes the test at once */
        } else {
            if (x_to >= cv->x_kiss)
                s = cv->s_solid + (s_kiss - cv->s_solid) * (cv->x_solid - x_to) / (cv->x_solid - cv->x_kiss);
            else s = (xc - x_to - comp * cv->fto_kiss) / kb;
            if (!(s > lo && s < hi)) s = hi;
        }
        k = 0;
        if (x_to < cv->x_kiss) {
            /* open: the answer lies past the kiss point. Where phi = ((s_kiss - s) kp - first) inv_span, as
               cc_bracket_force computes it, lies below the CurvePair's first knot, phi is in cell 0, where
               cc_bracket_force returns (a0 + w d0) + tau (c1 + tau (c2 + tau c3)) with c1..c3 = +0 and tau < 0, i.e.
               a0 + w d0 bit for bit, and dF_c/du, d2F_c/du2 are +0, which leave the slope and the curvature as they
               are without them (x - (+0) = x; the curvature only enters as r times it against 2 slope^2). There
               r(s) is the cubic P(s) + ckl F_c: the steps of the loop below without the table, the same bits
               (tests/test_native_speed.py), until an iterate leaves cell 0 (then that loop goes on) */
            const PairCell *c = b->pr->cell;
            const double first = b->first, isp = b->inv_span, lo1 = c[1].lo;
            double sq = NAN;
            /* the open start: with a history of three answers (the last one, w->s, and CcWarm s1, s2 of the two
               open solves before, each refined by a Newton step), their parabola in the order of the solves,
               s2 + 3 (s0 - s1), if the bearing moved by at most CC_WARM_DX and it lies in the bracket and in cell 0
               (where the cushion carries its constant, so the torque does not depend on the start). The open
               clutch's answer drifts smoothly with theta_cs and a decaying bearing: in the 1 ms steps of a launch's
               braked standstill the first evaluation passes the test in 9 of 10 steps, the tangent's in none */
            if (w->x == w->x) { /* the history goes on with the last answer refined (finite) */
                const double s0 = w->slope < -1e-200 ? w->s - w->r / w->slope : w->s;
                sq = w->s2 + 3.0 * (s0 - w->s1);
                w->s2 = w->s1;
                w->s1 = s0;
            } else w->s1 = w->s2 = NAN;
            if (fabs(d) <= CC_WARM_DX && sq > lo && sq < hi && ((s_kiss - sq) * kp - first) * isp < lo1) {
                s = sq;
                slope = w->slope;
            }
            if (cv->open_ok && ((s_kiss - s) * kp - first) * isp < lo1) {
                double r0;
                fc = c[0].a[0] + b->w * c[0].d[0];
                r0 = ckl * fc;
                r = p0 + s * (p1 + s * (p2 + s * p3)) + r0;
                COUNT_EVAL(); COUNT_OPEN();
                for (; k < 100; ++k) {
                    if (fabs(r) <= tol_r || hi - lo <= 1e-15 * (1.0 + hi)) goto done;
                    if (r > 0.0) lo = s; else hi = s;
                    slope = p1 + s * (2.0 * p2 + 3.0 * p3 * s);
                    s = halley_next(s, r, slope, 2.0 * p2 + 6.0 * p3 * s, lo, hi);
                    if (!(((s_kiss - s) * kp - first) * isp < lo1)) { ++k; goto table; }
                    r = p0 + s * (p1 + s * (p2 + s * p3)) + r0;
                    COUNT_EVAL(); COUNT_OPEN();
                }
                goto done;
            }
        } else w->s1 = NAN; /* the open history starts again after a solve in the cushion phase */
    table:
        fc = cushion(b, (s_kiss - s) * kp, &hint, &pt);
        r = p0 + s * (p1 + s * (p2 + s * p3)) + ckl * fc;
        COUNT_EVAL();
        for (; k < 100; ++k) {
            if (fabs(r) <= tol_r || hi - lo <= 1e-15 * (1.0 + hi)) break;
            if (r > 0.0) lo = s; else hi = s;
            cushion_deriv(b, &pt, &dfc, &d2fc);
            slope = p1 + s * (2.0 * p2 + 3.0 * p3 * s) - ckp * dfc;
            s = halley_next(s, r, slope, 2.0 * p2 + 6.0 * p3 * s + ckp * kp * d2fc, lo, hi);
            fc = cushion(b, (s_kiss - s) * kp, &hint, &pt);
            r = p0 + s * (p1 + s * (p2 + s * p3)) + ckl * fc;
            COUNT_EVAL();
        }
    done:
        /* the bearing force at the answer as cover.py writes it */
        fto = (moment(cv, s, cv->f_e) - fc * cv->L_pp) / cv->L_b;
        cv->hint = hint;
        out->clamp = fc;
        out->bearing = fto;
        out->cushion = fc;
        out->u = (s_kiss - s) * kp;
        out->s = s;
        w->r = r;
        w->x = x_to;
        w->s = s;
        w->slope = slope;
    }
    return fto < 0.0 ? -1 : 0;
}

int cc_cover_state(CcCover *cv, const Table *tb, double x_to, double theta_cs, double theta_cm, double wear,
                   CcCoverState *out) {
    CcWarm w = {NAN, 0.0, 0.0};
    return cc_cover_solve(cv, tb, x_to, theta_cs, theta_cm, wear, &w, out);
}

/* ---- what the cover can hold (cover.py: temperature_grid, _holds, hold_problem, wear_limit) */

/* the temperatures (K) of the check: lo..hi in 25 K steps and every table temperature inside, sorted, unique;
   g must hold CC_HOLD_GRID_MAX values; returns their number */
int cc_cover_grid(const Table *tb, double lo, double hi, double *g) {
    int n = (int)ceil((hi - lo) / 25.0), k, j, m = 0;
    for (k = 0; k <= n && m < CC_HOLD_GRID_MAX; ++k) g[m++] = lo + (hi - lo) * k / n;
    for (k = 0; k < tb->nt && m < CC_HOLD_GRID_MAX; ++k) {
        double t = tb->theta[k] + KELVIN;
        if (t >= lo && t <= hi) g[m++] = t;
    }
    for (k = 1; k < m; ++k) { /* insertion sort */
        double v = g[k];
        for (j = k - 1; j >= 0 && g[j] > v; --j) g[j + 1] = g[j];
        g[j + 1] = v;
    }
    for (k = 1, j = 0; k < m; ++k)
        if (g[k] != g[j]) g[++j] = g[k];
    return m ? j + 1 : 0;
}

/* the smallest bearing force (N) of the cushion phase at one temperature pair (cover._holds): at the points
   u_k = u_full (9 - k)/9, k = 0..8 (k = 0: solid), s_k = s_kiss - u_k / kp (< 0: cannot hold the cushion) */
static double holds(const CcCover *cv, const Table *tb, double wear, double theta_cs, double theta_cm) {
    const double *p = cv->p;
    double th = theta_cs - KELVIN, e_mod = youngs(cv, theta_cs), worst = INFINITY, s_kiss, u_full;
    double d = theta_cm - p[CV_REFERENCE_TEMPERATURE_K];
    double stack = cc_table_delta(tb, th) +
                   (p[CV_FACING_THICKNESS_M] * p[CV_FACING_EXPANSION_PER_K] * d +
                    p[CV_PRESSURE_PLATE_THICKNESS_M] * p[CV_PRESSURE_PLATE_EXPANSION_PER_K] * d +
                    p[CV_FLYWHEEL_LENGTH_M] * p[CV_FLYWHEEL_EXPANSION_PER_K] * d);
    int k;
    s_kiss = p[CV_INSTALLED_DEFLECTION_M] + (cv->u_full_ref + stack - wear) / cv->kp;
    u_full = cc_table_full(tb, th);
    for (k = 0; k < 9; ++k) {
        double u = u_full * (9 - k) / 9;
        double fto = (moment(cv, s_kiss - u / cv->kp, e_mod) - cc_table_force(tb, u, th) * cv->L_pp) / cv->L_b;
        if (fto < worst) worst = fto;
    }
    return worst;
}

int cc_cover_holds(const CcCover *cv, const Table *tb, double wear, double lo, double hi, double *fto,
                   double *theta_cs, double *theta_cm) {
    double g[CC_HOLD_GRID_MAX];
    int n = cc_cover_grid(tb, lo, hi, g), a, b;
    for (a = 0; a < n; ++a)
        for (b = 0; b < n; ++b) {
            double f = holds(cv, tb, wear, g[a], g[b]);
            if (f < 0.0) {
                if (fto) *fto = f;
                if (theta_cs) *theta_cs = g[a];
                if (theta_cm) *theta_cm = g[b];
                return 0;
            }
        }
    return 1;
}

double cc_cover_wear_limit(const CcCover *cv, const Table *tb, double lo, double hi) {
    double a = 0.0, b = 0.01;
    if (!cc_cover_holds(cv, tb, 0.0, lo, hi, NULL, NULL, NULL)) return -1.0;
    while (b - a > 1e-7) {
        double mid = 0.5 * (a + b);
        if (cc_cover_holds(cv, tb, mid, lo, hi, NULL, NULL, NULL)) a = mid; else b = mid;
    }
    return a;
}
