/*
 * The diaphragm-spring cover (clutch_cover.c): its force balance with the cushion spring, prepared once per
 * parameter set, the forward map from the bearing position, and what it can hold (cushion_clutch/model/cover.py).
 * Knows the tables, not the FMU.
 */
#ifndef CLUTCH_COVER_H
#define CLUTCH_COVER_H

#include "clutch_tables.h"

/* the cover's parameters CV_<FIELD> and CV_NPAR, in the order of cover.CoverParameters' fields (cushion_clutch/model/
   cover.py): generated from the dataclass by the build (cushion_clutch.fmu.variable_table.cover_header) */
#include "cushion_cover.h"

/* the cover's force balance, prepared once per parameter set (clutch_cover.c) */
typedef struct {
    double p[CV_NPAR];
    double e, L_pp, L_b, kb, kp, fal; /* arms (m), bearing/pp travel per unit s, F_AL factor without E */
    double u_full_ref;                /* cushion full compression at the reference temperature, m */
    double xc;                        /* bearing-system constant X_c, m */
    double ck, ckl, ckp;              /* c / L_b, c L_pp / L_b, c L_pp kp / L_b, m/N */
    double tt, dstack, ck_fal, p1h;   /* t^2; the stack's expansion per K of theta_cm; ck fal; 1 + h^2 / t^2 */
    int hint, hint_k;                 /* last cells of the bracket's CurvePair, solver and kiss point (search starts) */
    int hint_t;                       /* last interval of the table temperatures (the frame's bracket) */
    /* the frame of the last (theta_cs K, theta_cm K, wear m): bracket, E, positions and forces */
    double f_theta_cs, f_theta_cm, f_wear, f_e;
    TBracket f_br;
    double s_kiss, s_solid, fc_solid, m_solid, fto_solid, fto_kiss, x_solid, x_kiss;
    double p1, p2, p3;                /* the solver's P(s) = X_c - x_to + p1 s + p2 s^2 + p3 s^3, m */
    int open_ok; /* every CurvePair's cell 0 is the clamped constant: the open solve's shortcut (cc_cover_prepare) */
} CcCover;

typedef struct {
    double clamp, bearing, cushion; /* F_pp, F_to, F_c, N */
    double u, s;                    /* cushion compression from its kiss point, diaphragm deflection, m */
    double x_kiss, x_solid, x_lift; /* bearing positions, m */
} CcCoverState;

/* a warm start of the cover's solve (cc_cover_solve): the last answer's bearing position x (m; NaN: none),
   diaphragm deflection s (m), dx_to/ds near it (the last Halley step's slope; 0: none) and residual r (m); the
   history of the open start: s1 and s2 the answers of the two open solves before the last, refined by a Newton
   step (m; NaN: none; a solve after x NaN starts it again, so setting x NaN makes the whole warm start cold) */
typedef struct {
    double x, s, slope, r, s1, s2;
} CcWarm;
/* the largest bearing travel (m) between two solves for which the last answer, moved along its tangent, starts the
   next; a larger jump starts from the chord, as cc_cover_state does */
#define CC_WARM_DX 1e-4

void cc_cover_prepare(CcCover *cv, const double *par, double lever_ratio, double x_kiss_ref, const Table *tb);
/* cc_cover_state from the warm start *w (if the bearing moved by at most CC_WARM_DX since w->x and the start lies
   in the bracket: the tangent at w->s, or open in the cushion's force-free cell the parabola through the history
   s2, s1 and w->s; else from the chord), then *w = this answer (x NaN in the solid phase and on refusal): the answer passes the same residual
   test, so it agrees with cc_cover_state's to that residual, not bit for bit */
int cc_cover_solve(CcCover *cv, const Table *tb, double x_to, double theta_cs, double theta_cm, double wear,
                   CcWarm *w, CcCoverState *out);
double cc_cover_slope_bound(const CcCover *cv);
/* 0, or -1 if the diaphragm cannot hold the cushion (bearing force < 0); out is filled either way */
int cc_cover_state(CcCover *cv, const Table *tb, double x_to, double theta_cs, double theta_cm, double wear,
                   CcCoverState *out);
/* what the cover can hold (cover.hold_problem / wear_limit): the temperature grid of the check (K), 1 if the
   diaphragm holds the cushion at wear for every pair of it (else 0, with the first failing pair), and the
   largest such wear (m; -1 if none) */
#define CC_HOLD_GRID_MAX 128
int cc_cover_grid(const Table *tb, double lo, double hi, double *g);
int cc_cover_holds(const CcCover *cv, const Table *tb, double wear, double lo, double hi, double *fto,
                   double *theta_cs, double *theta_cm);
double cc_cover_wear_limit(const CcCover *cv, const Table *tb, double lo, double hi);

#endif
