/* The production TCU's clutch model: see tcu_model.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "clutch_cover.h"
#include "clutch_tables.h"
#include "tcu_model.h"

#include "host_export.h"

struct TcuModel {
    Table table;
    CcCover cover; /* this instance's: its frame memo and search hints follow this model's calls alone */
    double wear, gain, lever;
};

#define TM_KELVIN 273.15 /* K at 0 degC, as the cover's frame converts theta_cs for the table */
/* a bearing position beyond any cover's solid position (m): its state is the lifted bearing's, without a solve */
#define TM_X_FAR 1.0
/* the position of a compression is found to this fraction of the inverse's tolerance (a secant step that small is
   the last: the step after it would be far smaller still) */
#define TM_X_TOL 1e-3

HOST_EXPORT TcuModel *tm_open(const char *dir, const double *cover, int n_cover, double lever_ratio, double x_kiss_ref,
                  double wear, double gain, char *err, size_t errlen) {
    TcuModel *m;
    if (n_cover != CV_NPAR) {
        snprintf(err, errlen, "tcu_model: %d cover parameters given, the cover takes %d", n_cover, CV_NPAR);
        return NULL;
    }
    m = (TcuModel *)calloc(1, sizeof *m);
    if (!m) { snprintf(err, errlen, "tcu_model: out of memory"); return NULL; }
    if (cc_table_load(&m->table, dir, err, errlen) != 0) { free(m); return NULL; }
    cc_cover_prepare(&m->cover, cover, lever_ratio, x_kiss_ref, &m->table);
    m->wear = wear;
    m->gain = gain;
    m->lever = lever_ratio;
    return m;
}

HOST_EXPORT void tm_close(TcuModel *m) {
    if (!m) return;
    cc_table_free(&m->table);
    free(m);
}

HOST_EXPORT double tm_torque(TcuModel *m, double x_to, double theta_cs, double theta_cm) {
    CcCoverState st;
    if (cc_cover_state(&m->cover, &m->table, x_to, theta_cs, theta_cm, m->wear, &st) != 0) return NAN;
    return m->gain * st.clamp;
}

/* the bearing position (m) where the cushion compression is u_t (first <= u_t <= u_full; the first contact may lie
   below the kiss point's u = 0, where the cold cushion has shrunk): the secant method on the forward map's u(x)
   (nearly linear) from x_kiss (u = 0) and the chord to x_solid (u = u_full), kept in the bracket the evaluations
   give (bisection where a step leaves it), warm-started solves; to tol_x (m) */
static double x_at_u(TcuModel *m, double u_t, double theta_cs, double theta_cm, double x_kiss, double x_solid,
                     double u_full, double tol_x) {
    CcCoverState st;
    CcWarm w = {NAN, 0.0, 0.0};
    const double span = x_solid - x_kiss;
    double a = -INFINITY, b = x_solid, x, g, x_prev, g_prev, x_new;
    int k;
    if (u_t == 0.0) return x_kiss;
    if (u_t >= u_full) return x_solid;
    if (u_t > 0.0) a = x_kiss;
    else b = x_kiss;
    x_prev = x_kiss;
    g_prev = -u_t;
    x = x_kiss + span * (u_t / u_full);
    for (k = 0; k < 60; ++k) {
        if (cc_cover_solve(&m->cover, &m->table, x, theta_cs, theta_cm, m->wear, &w, &st) != 0) return NAN;
        g = st.u - u_t;
        if (g == 0.0) return x;
        if (g < 0.0) a = x; else b = x;
        if (b - a <= tol_x) break;
        x_new = g != g_prev ? x - g * (x - x_prev) / (g - g_prev) : NAN;
        if (!(x_new > a && x_new < b)) x_new = a > -INFINITY ? 0.5 * (a + b) : b - span;
        if (fabs(x_new - x) <= tol_x) return x_new;
        x_prev = x;
        g_prev = g;
        x = x_new;
    }
    return x;
}

/* the compression (m) where one curve reaches force (N) (spring_table.Curve.u_at): x_first at or below its first
   force, its last compression above its last; in between the cubic of the interval where it is reached, three
   Newton steps in t from the chord */
static double curve_u_at(const Curve *c, double force) {
    int lo = 0, hi = c->n, i, k;
    double c0, c1, c2, c3, t;
    while (lo < hi) { /* bisect_left: the first row with y >= force */
        int mid = (lo + hi) / 2;
        if (c->y[mid] < force) lo = mid + 1;
        else hi = mid;
    }
    if (lo == 0) return c->x_first;
    if (lo == c->n) return c->x[c->n - 1];
    i = lo - 1;
    c0 = c->y[i];
    c1 = c->pc[4 * i];
    c2 = c->pc[4 * i + 1];
    c3 = c->pc[4 * i + 2];
    t = (force - c0) / (c->y[lo] - c0);
    for (k = 0; k < 3; ++k) {
        double d = c1 + t * (2.0 * c2 + 3.0 * t * c3);
        if (!(d > 0.0)) break;
        t -= (c0 + t * (c1 + t * (c2 + t * c3)) - force) / d;
        t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    }
    return c->x[i] + t / c->pc[4 * i + 3];
}

/* the inverse's Newton start (spring_table.Bracket.u_start): one curve's root; between two tables each curve's root
   on the common normalised compression, blended with the weights */
static double bracket_u_start(const TBracket *b, double force) {
    const Curve *c0 = b->c0, *c1 = b->c1;
    double span, r0, r1;
    if (b->w == 0.0) return curve_u_at(c0, force);
    span = b->full - b->first;
    r0 = span > 0.0 ? (c0->x[c0->n - 1] - c0->x_first) / span : 0.0;
    r1 = span > 0.0 ? (c1->x[c1->n - 1] - c1->x_first) / span : 0.0;
    if (!(r0 > 0.0 && r1 > 0.0)) return 0.5 * (b->first + b->full);
    return b->first + ((1.0 - b->w) * (curve_u_at(c0, force) - c0->x_first) / r0 +
                       b->w * (curve_u_at(c1, force) - c1->x_first) / r1);
}

HOST_EXPORT double tm_x_for_torque(TcuModel *m, double torque, double theta_cs, double theta_cm, double tol_m) {
    CcCoverState st;
    TBracket br;
    CellPt pt;
    double force = m->gain > 0.0 ? torque / m->gain : 0.0;
    double x_kiss, x_solid, x_lift, fc_solid, c_inst, u_full, lo, hi, f_lo, tol, half, u;
    int hint = 0, hint_t = 0;
    /* the frame through a lifted bearing's state: the positions, the installed clamp force (the closed one), the
       cushion fully compressed */
    if (cc_cover_state(&m->cover, &m->table, TM_X_FAR, theta_cs, theta_cm, m->wear, &st) != 0) return NAN;
    x_kiss = st.x_kiss;
    x_solid = st.x_solid;
    x_lift = st.x_lift;
    c_inst = st.clamp;
    fc_solid = st.cushion;
    u_full = st.u;
    if (force >= c_inst) return x_lift;
    if (force > fc_solid) /* solid phase: the clamp force linear in x from (x_solid, fc_solid) to (x_lift, c_inst) */
        return x_solid + (x_lift - x_solid) * ((force - fc_solid) / (c_inst - fc_solid));
    /* the cushion at theta_cs, as the frame brackets it */
    cc_table_bracket_hint(&m->table, theta_cs - TM_KELVIN, &br, &hint_t);
    lo = br.first;
    hi = br.full;
    f_lo = cc_bracket_force(&br, lo, &hint, &pt);
    if (force <= f_lo) return x_at_u(m, lo, theta_cs, theta_cm, x_kiss, x_solid, u_full, TM_X_TOL * tol_m);
    /* the smallest compression u with F(u) >= force, to tol_m / lever (cover.py _Frame.x_for_clamp): a bracket
       F(lo) < force <= F(hi) closed by Newton steps (bisection where a step leaves it); once a step is below tol
       the other side of the root is probed, so the bracket, not the step, ends the search */
    tol = tol_m / m->lever;
    half = 0.5 * tol;
    u = bracket_u_start(&br, force); /* from the curves' own inverses (inputs only), as cover.py starts */
    if (!(lo < u && u < hi)) u = 0.5 * (lo + hi);
    while (hi - lo > tol) {
        double f = cc_bracket_force(&br, u, &hint, &pt), r = f - force, u_new;
        double d = (pt.c1 + pt.tau * (2.0 * pt.c2 + 3.0 * pt.c3 * pt.tau)) * br.inv_span;
        if (r < 0.0) lo = u;
        else hi = u;
        u_new = d > 0.0 ? u - r / d : 0.5 * (lo + hi);
        if (fabs(u_new - u) < half) u_new += r < 0.0 ? half : -half;
        u = (lo < u_new && u_new < hi) ? u_new : 0.5 * (lo + hi);
    }
    return x_at_u(m, hi, theta_cs, theta_cm, x_kiss, x_solid, u_full, TM_X_TOL * tol_m);
}
