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
 * The forward map is a safeguarded Newton iteration on s in [s_solid, s_rigid] from a chord start
 * (3-4 iterations); the start depends on the inputs only, so results are reproducible bit for bit
 * (saved and restored states, any call history).
 */
#include "clutch_core.h"

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
    double t = cv->p[CV_T], h = cv->p[CV_H];
    return cv->fal * e_mod * (s / t) * ((h - s) * (h - 0.5 * s) / (t * t) + 1.0) * cv->e;
}

static double moment_slope(const CcCover *cv, double s, double e_mod) {
    double t = cv->p[CV_T], h = cv->p[CV_H];
    return cv->fal * e_mod / t * ((h - s) * (h - 0.5 * s) / (t * t) + 1.0 - s * (1.5 * h - s) / (t * t)) * cv->e;
}

static double youngs(const CcCover *cv, double theta_K) {
    return cv->p[CV_E] * (1.0 - cv->p[CV_KE] * (theta_K - cv->p[CV_TREF]));
}

void cc_cover_prepare(CcCover *cv, const double *par, double lever_ratio, double x_kiss_ref, const Table *tb) {
    double s_k0, f_to, th_ref;
    memcpy(cv->p, par, sizeof cv->p);
    cv->e = par[CV_A] - par[CV_B];
    cv->L_pp = par[CV_RPP] - par[CV_RF];
    cv->L_b = lever_ratio * cv->L_pp;
    cv->kb = cv->L_b / cv->e;
    cv->kp = cv->L_pp / cv->e;
    cv->fal = 4.0 / (1.0 - par[CV_NU] * par[CV_NU]) * pow(par[CV_T], 4) / (k1(par[CV_A], par[CV_B]) * 4.0 *
                                                                             par[CV_A] * par[CV_A]);
    th_ref = par[CV_TREF] - KELVIN;
    cv->u_full_ref = cc_table_full(tb, th_ref);
    s_k0 = par[CV_SINST] + cv->u_full_ref / cv->kp;
    f_to = (moment(cv, s_k0, par[CV_E]) - cc_table_force(tb, 0.0, th_ref) * cv->L_pp) / cv->L_b;
    cv->xc = x_kiss_ref + cv->kb * s_k0 + par[CV_C] * f_to;
    cv->f_theta_cs = NAN; /* no frame yet */
    cv->hint[0] = cv->hint[1] = cv->hint_k[0] = cv->hint_k[1] = cv->hint_t = 0;
    memset(cv->memo_c, 0, sizeof cv->memo_c);
}

/* -(dx_to/ds) at its smallest (open phase, s = h) at the largest E: > 0 means no snap-through */
double cc_cover_slope_bound(const CcCover *cv) {
    double e_max = cv->p[CV_E] * (1.0 + cv->p[CV_KE] * cv->p[CV_TREF]);
    return cv->kb + cv->p[CV_C] * moment_slope(cv, cv->p[CV_H], e_max) / cv->L_b;
}

/* the Newton loop's curve functions are inlined (the loop's constants stay in registers) */
#if defined(__GNUC__)
#define CC_INLINE static inline __attribute__((always_inline))
#else
#define CC_INLINE static inline
#endif

/* a point of one curve where F was evaluated: its interval i (-1: beyond either end, dF/du = 0), t, t^2, h */
typedef struct {
    int i;
    double t, t2, h;
} CurvePt;

/* F(u) of one curve (PCHIP, as clutch_tables.c); *hint: the last interval, checked before use; the point is
   kept in *pt for curve_slope */
CC_INLINE double curve_value(const Curve *c, double u, int *hint, CurvePt *pt) {
    int n = c->n, i = *hint;
    double h, t, t2;
    if (u <= c->x[0]) { pt->i = -1; return c->y[0]; }
    if (u >= c->x[n - 1]) { pt->i = -1; return c->y[n - 1]; }
    if (!(i >= 0 && i < n - 1 && c->x[i] <= u && u < c->x[i + 1])) i = *hint = cc_curve_locate(c, u);
    h = c->x[i + 1] - c->x[i];
    t = (u - c->x[i]) / h;
    t2 = t * t;
    pt->i = i;
    pt->t = t;
    pt->t2 = t2;
    pt->h = h;
    return (2 * t2 * t - 3 * t2 + 1) * c->y[i] + (t2 * t - 2 * t2 + t) * h * c->d[i] + (-2 * t2 * t + 3 * t2) *
           c->y[i + 1] + (t2 * t - t2) * h * c->d[i + 1];
}

/* dF/du of one curve at a point of curve_value (computed only where Newton needs it) */
CC_INLINE double curve_slope(const Curve *c, const CurvePt *pt) {
    int i = pt->i;
    double t = pt->t, t2 = pt->t2, h = pt->h;
    if (i < 0) return 0.0;
    return (6 * t2 - 6 * t) * (c->y[i] - c->y[i + 1]) / h + (3 * t2 - 4 * t + 1) * c->d[i] +
           (3 * t2 - 2 * t) * c->d[i + 1];
}

/* the cushion force at one temperature (as spring_table.Bracket.force); the points in pt[0..1] */
CC_INLINE double cushion(const TBracket *b, double u, int *hint, CurvePt *pt) {
    double f0, f1, v;
    if (b->w == 0.0) return curve_value(b->c0, u, &hint[0], &pt[0]);
    v = u - b->first;
    f0 = curve_value(b->c0, b->c0->x_first + v * b->r0, &hint[0], &pt[0]);
    f1 = curve_value(b->c1, b->c1->x_first + v * b->r1, &hint[1], &pt[1]);
    return (1.0 - b->w) * f0 + b->w * f1;
}

/* its slope at the points of the last cushion() call (as spring_table.Bracket.slope) */
CC_INLINE double cushion_slope(const TBracket *b, const CurvePt *pt) {
    if (b->w == 0.0) return curve_slope(b->c0, &pt[0]);
    return (1.0 - b->w) * curve_slope(b->c0, &pt[0]) * b->r0 + b->w * curve_slope(b->c1, &pt[1]) * b->r1;
}

/* the frame's cushion force at u (the full compression or the kiss point, slot 0 or 1): the curves' values
   are kept per curve and the curve's own compression, so a new temperature that reads a curve at the same
   point costs no curve evaluation (exact: the same numbers as cushion()) */
/* F of curve c at uk through memo slot j (exact: the value curve_value gives) */
static inline double memo_value(CcCover *cv, int j, const Curve *c, double uk, int *hint) {
    CurvePt pt;
    if (!(cv->memo_c[j] == c && cv->memo_u[j] == uk)) {
        cv->memo_c[j] = c;
        cv->memo_u[j] = uk;
        cv->memo_f[j] = curve_value(c, uk, hint, &pt);
    }
    return cv->memo_f[j];
}

static double frame_cushion(CcCover *cv, const TBracket *b, double u, int slot) {
    double f0, f1, v;
    if (b->w == 0.0) return memo_value(cv, 2 * slot, b->c0, u, &cv->hint_k[0]);
    v = u - b->first;
    f0 = memo_value(cv, 2 * slot, b->c0, b->c0->x_first + v * b->r0, &cv->hint_k[0]);
    f1 = memo_value(cv, 2 * slot + 1, b->c1, b->c1->x_first + v * b->r1, &cv->hint_k[1]);
    return (1.0 - b->w) * f0 + b->w * f1;
}

int cc_cover_state(CcCover *cv, const Table *tb, double x_to, double theta_cs, double theta_cm, double wear,
                   CcCoverState *out) {
    const double *p = cv->p;
    double th = theta_cs - KELVIN, kb = cv->kb, kp = cv->kp, comp = p[CV_C];
    double lo, hi, s, r, fc, fto, dfc, e_mod;
    CurvePt pt[2] = {{-1, 0.0, 0.0, 0.0}, {-1, 0.0, 0.0, 0.0}}; /* pt[1]: used only where w != 0 */
    int k;
    if (!(theta_cs == cv->f_theta_cs && theta_cm == cv->f_theta_cm && wear == cv->f_wear)) {
        /* the frame: everything that depends on temperature and wear, not on x_to */
        double stack, m_solid;
        TBracket b;
        e_mod = youngs(cv, theta_cs);
        cc_table_bracket_hint(tb, th, &b, &cv->hint_t);
        stack = cc_table_delta_at(tb, &b) +
                (p[CV_TF] * p[CV_AF] + p[CV_TPP] * p[CV_APP] + p[CV_LFW] * p[CV_AFW]) * (theta_cm - p[CV_TREF]);
        cv->f_e = e_mod;
        cv->f_br = b;
        cv->s_kiss = p[CV_SINST] + (cv->u_full_ref + stack - wear) / kp;
        cv->s_solid = cv->s_kiss - b.full / kp;
        cv->fc_solid = frame_cushion(cv, &b, (cv->s_kiss - cv->s_solid) * kp, 0);
        m_solid = moment(cv, cv->s_solid, e_mod);
        cv->m_solid = m_solid;
        cv->fto_solid = (m_solid - cv->fc_solid * cv->L_pp) / cv->L_b;
        cv->x_solid = cv->xc - kb * cv->s_solid - comp * cv->fto_solid;
        fc = frame_cushion(cv, &b, 0.0, 1);
        cv->fto_kiss = (moment(cv, cv->s_kiss, e_mod) - fc * cv->L_pp) / cv->L_b;
        cv->x_kiss = cv->xc - kb * cv->s_kiss - comp * cv->fto_kiss;
        cv->f_theta_cs = theta_cs;
        cv->f_theta_cm = theta_cm;
        cv->f_wear = wear;
    }
    e_mod = cv->f_e;
    out->x_solid = cv->x_solid;
    out->x_lift = cv->x_solid + comp * (cv->fto_solid > 0.0 ? cv->fto_solid : 0.0);
    out->x_kiss = cv->x_kiss;
    if (cv->fto_solid < 0.0) { out->bearing = cv->fto_solid; return -1; }
    if (x_to >= cv->x_solid) {
        fto = comp > 0.0 ? cv->fto_solid - (x_to - cv->x_solid) / comp : 0.0;
        if (fto < 0.0) fto = 0.0;
        out->bearing = fto;
        out->clamp = (cv->m_solid - fto * cv->L_b) / cv->L_pp;
        out->cushion = cv->fc_solid;
        out->u = (cv->s_kiss - cv->s_solid) * kp;
        out->s = cv->s_solid;
        return 0;
    }
    {
        /* the frame's constants in locals (the same operations as moment() and moment_slope(), in the same
           order: (fal E) (s/t) (...) e and ((fal E)/t) (...) e; only loads are saved) */
        const TBracket b = cv->f_br;
        const double s_kiss = cv->s_kiss, xc = cv->xc, L_pp = cv->L_pp, L_b = cv->L_b, e = cv->e;
        const double t = p[CV_T], h = p[CV_H], tt = t * t, h15 = 1.5 * h, fe = cv->fal * e_mod, fe_t = fe / t;
        const double tol_r = 1e-15 * (1.0 + fabs(x_to));
        int hint[2];
        hint[0] = cv->hint[0];
        hint[1] = cv->hint[1];
        lo = cv->s_solid;
        hi = (xc - x_to) / kb;
        /* start (from the inputs only, so the result never depends on the call history): the chord of
           x(s) between the solid and kiss points (cushion phase) or the rigid lever shifted by the
           kiss-point compliance (open) */
        if (x_to >= cv->x_kiss)
            s = cv->s_solid + (cv->s_kiss - cv->s_solid) * (cv->x_solid - x_to) / (cv->x_solid - cv->x_kiss);
        else s = (xc - x_to - comp * cv->fto_kiss) / kb;
        if (!(s > lo && s < hi)) s = hi;
        fc = cushion(&b, (s_kiss - s) * kp, hint, pt);
        fto = (fe * (s / t) * ((h - s) * (h - 0.5 * s) / tt + 1.0) * e - fc * L_pp) / L_b;
        r = xc - kb * s - comp * fto - x_to;
        for (k = 0; k < 100; ++k) {
            double slope, s_new, m_s;
            if (fabs(r) <= tol_r || hi - lo <= 1e-15 * (1.0 + hi)) break;
            if (r > 0.0) lo = s; else hi = s;
            dfc = cushion_slope(&b, pt);
            m_s = fe_t * ((h - s) * (h - 0.5 * s) / tt + 1.0 - s * (h15 - s) / tt) * e;
            slope = -kb - comp * (m_s + dfc * kp * L_pp) / L_b;
            s_new = slope < 0.0 ? s - r / slope : 0.5 * (lo + hi);
            s = (s_new > lo && s_new < hi) ? s_new : 0.5 * (lo + hi);
            fc = cushion(&b, (s_kiss - s) * kp, hint, pt);
            fto = (fe * (s / t) * ((h - s) * (h - 0.5 * s) / tt + 1.0) * e - fc * L_pp) / L_b;
            r = xc - kb * s - comp * fto - x_to;
        }
        cv->hint[0] = hint[0];
        cv->hint[1] = hint[1];
        out->clamp = fc;
        out->bearing = fto;
        out->cushion = fc;
        out->u = (s_kiss - s) * kp;
        out->s = s;
    }
    return fto < 0.0 ? -1 : 0;
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
    double d = theta_cm - p[CV_TREF];
    double stack = cc_table_delta(tb, th) + (p[CV_TF] * p[CV_AF] * d + p[CV_TPP] * p[CV_APP] * d +
                                             p[CV_LFW] * p[CV_AFW] * d);
    int k;
    s_kiss = p[CV_SINST] + (cv->u_full_ref + stack - wear) / cv->kp;
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
