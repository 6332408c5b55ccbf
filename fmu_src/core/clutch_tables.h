/*
 * The cushion spring's tables (clutch_tables.c): the F(u) curves per table temperature with their interval
 * locator and cubic coefficients, the kiss shift, the optional friction table, and the temperature bracket that
 * blends two curves (cushion_clutch/model/spring_table.py, operation for operation). Knows nothing of the FMU.
 */
#ifndef CLUTCH_TABLES_H
#define CLUTCH_TABLES_H

#include <math.h> /* NAN */
#include <stddef.h>

typedef struct {
    int n;
    double *x, *y, *d;
    double x_first; /* first contact: the last row still at the first force, m (spring_table.Curve.x_first) */
    /* the interval locator's buckets: nb uniform buckets of width 1/inv_bw from x[0], each holding the interval
       of its lower edge (a start only: cc_curve_locate corrects it, so it finds the binary search's interval) */
    int nb;
    double inv_bw;
    unsigned short *bk;
    /* the cubic of interval i in t = (u - x[i]) / (x[i+1] - x[i]): F = y[i] + t (q0 + t (q1 + t q2)), and
       q3 = 1 / (x[i+1] - x[i]); pc[4 i + k] = qk (read when the table loads, to build the CurvePairs' cells) */
    double *pc;
} Curve;

/* One curve, or two adjacent ones, as cubics of the normalised compression phi = (u - first) / (full - first)
   (0 at first contact, 1 at full compression; spring_table.Bracket's common coordinate): the knots of both curves
   in phi, merged, cut phi into cells; in cell j both curves are single cubics in tau = phi - org (org = lo but in
   the outer cells, where the curves are clamped to constants), F_0 = a0 + tau (a1 + tau (a2 + tau a3)) and
   F_1 - F_0 the same with d, so the blend (1 - w) F_0 + w F_1 is one cubic with coefficients a + w d (the cover's
   solver: one search and one polynomial per evaluation instead of two). cell[0].lo = -inf, cell[m + 1].lo = +inf
   (a sentinel); the buckets locate as Curve's */
typedef struct {
    double lo, org, a[4], d[4];
} PairCell;

typedef struct {
    int m;          /* cells 0..m, cell m + 1 the sentinel */
    PairCell *cell;
    int nb;
    double phi0, inv_bw, zmax; /* zmax = nb - 1 */
    unsigned short *bk;
} CurvePair;

/* F(u) at one temperature: curves c0 and c1 (weight w of c1; c1 = c0 where w = 0) blended on a common
   normalised compression between the first contact and the full compression, both linear in theta
   (spring_table.Bracket); r0, r1 = d(u_k)/du */
typedef struct {
    const Curve *c0, *c1;
    double w, first, full, r0, r1;
    int i; /* c0 = curves[i] (the table index of theta) */
    const CurvePair *pr; /* the two curves (w != 0) or c0 alone (w = 0) in phi */
    double inv_span;     /* 1 / (full - first), 1/m (0 where full = first: every curve then constant) */
} TBracket;

typedef struct {
    int nt;
    double *theta; /* degC, increasing */
    double *delta; /* m */
    Curve *curves;
    CurvePair *pairs; /* nt curves alone, then the nt - 1 adjacent pairs (curves k, k + 1 at nt + k) */
    /* optional friction table mu(theta_cm degC, |omega_slip| rad/s), row-major [ntf][nw] */
    int ntf, nw;
    double *f_theta, *f_omega, *f_mu;
} Table;

int cc_table_load(Table *tb, const char *dir, char *err, size_t errlen);
/* Table sets (one FMU, several springs; cushion_clutch.fmu.table_sets): set 1 in <dir>/tables, set k >= 2 in
   <dir>/tables_<k>, numbered without gaps, at most CC_MAX_SETS; every set is loaded (and checked) at once. The FMU's
   enumeration parameter `spring` picks one before initialisation ends */
#define CC_MAX_SETS 64
typedef struct {
    int n;      /* sets loaded */
    Table *set; /* set[k]: table set k + 1 */
    double kiss_offset[CC_MAX_SETS]; /* m: set k + 1's own kiss point minus set 1's (<folder>/x_kiss_ref_offset_m.txt,
                                        written by the build for a set measured from its own kiss point; else 0) */
} TableSets;
#define CC_KISS_OFFSET_FILE "x_kiss_ref_offset_m.txt"
int cc_table_sets_load(TableSets *s, const char *dir, char *err, size_t errlen);
void cc_table_sets_free(TableSets *s);
void cc_table_free(Table *tb);
double cc_table_force(const Table *tb, double u, double theta_degC);
double cc_table_delta(const Table *tb, double theta_degC);
/* the interval i of x[0] < u < x[n-1]: x[i] <= u < x[i+1] (the binary search's), from the bucket of u, corrected
   until x[i] <= u < x[i+1] holds, so it is the one interval the binary search finds whatever the rounding of the
   bucket index (buckets are no wider than the narrowest interval: at most one step up from the bucket's start in
   exact arithmetic) */
int cc_curve_locate(const Curve *c, double u);
/* the cell j of phi in a CurvePair: cell[j].lo <= phi < cell[j + 1].lo (the one cell; from its bucket) */
static inline int cc_pair_locate(const CurvePair *p, double phi) {
    const double z = (phi - p->phi0) * p->inv_bw;
    const PairCell *c = p->cell + p->bk[z >= 0.0 ? (z < p->zmax ? (int)z : p->nb - 1) : 0];
    while (phi < c->lo) --c;
    while (phi >= c[1].lo) ++c;
    return (int)(c - p->cell);
}
/* the cushion force F(u) of a bracket (spring_table.Bracket.force; its curves' Hermite forms blended, to about
   2e-13 relative: tests/test_native_speed.py): the
   blended cubic of the cell of phi = (u - first) / (full - first) in the bracket's CurvePair; its coefficients
   1..3 and argument tau in *pt (slopes: dF/du = (c1 + tau (2 c2 + 3 c3 tau)) inv_span); *hint: the last cell, a
   start for the search only (the cell of phi is unique) */
typedef struct {
    double c1, c2, c3, tau;
} CellPt;

static inline double cc_bracket_force(const TBracket *b, double u, int *hint, CellPt *pt) {
    const CurvePair *p = b->pr;
    const PairCell *c;
    double phi = (u - b->first) * b->inv_span, w = b->w, tau;
    int i = *hint;
    if (!((unsigned)i <= (unsigned)p->m && p->cell[i].lo <= phi && phi < p->cell[i + 1].lo))
        i = *hint = cc_pair_locate(p, phi);
    c = &p->cell[i];
    tau = phi - c->org;
    pt->c1 = c->a[1] + w * c->d[1];
    pt->c2 = c->a[2] + w * c->d[2];
    pt->c3 = c->a[3] + w * c->d[3];
    pt->tau = tau;
    return (c->a[0] + w * c->d[0]) + tau * (pt->c1 + tau * (pt->c2 + tau * pt->c3));
}

double cc_table_mu(const Table *tb, double theta_degC, double omega);
double cc_table_full(const Table *tb, double theta_degC);
/* table temperatures i and i+1 around theta with weight w of i+1 (clamped: w = 0 or 1) */
void cc_table_bracket(const Table *tb, double theta_degC, TBracket *br);
/* the binary search of g[0] <= v < g[n-1] in g[0..n-1]: i with g[i] <= v < g[i+1] */
int cc_table_search(const double *g, int n, double v);
/* the cover's bracket (inline): cc_table_bracket's fields but r0 and r1 (NaN: the CurvePair needs neither; the same
   bits in the others), trying the table interval *hint first (the last one found, kept in *hint); returns the kiss
   shift delta (cc_table_delta's number), m */
static inline double cc_table_bracket_hint(const Table *tb, double theta, TBracket *br, int *hint) {
    const double *g = tb->theta;
    const Curve *c0;
    int n = tb->nt, i = *hint;
    double w;
    if (n == 1 || theta <= g[0]) { i = 0; w = 0.0; }
    else if (theta >= g[n - 1]) { i = n - 1; w = 0.0; }
    else {
        if (!((unsigned)i < (unsigned)(n - 1) && g[i] <= theta && theta < g[i + 1])) i = *hint = cc_table_search(g, n, theta);
        w = (theta - g[i]) / (g[i + 1] - g[i]);
        if (w == 1.0) { i += 1; w = 0.0; }
    }
    c0 = &tb->curves[i];
    br->i = i;
    br->c0 = c0;
    br->w = w;
    br->r0 = br->r1 = NAN;
    if (w == 0.0) {
        br->c1 = c0;
        br->first = c0->x_first;
        br->full = c0->x[c0->n - 1];
        br->pr = &tb->pairs[i];
        br->inv_span = br->full > br->first ? 1.0 / (br->full - br->first) : 0.0;
        return tb->delta[i];
    } else {
        const Curve *c1 = c0 + 1;
        double span;
        br->c1 = c1;
        br->first = (1.0 - w) * c0->x_first + w * c1->x_first;
        br->full = (1.0 - w) * c0->x[c0->n - 1] + w * c1->x[c1->n - 1];
        span = br->full - br->first;
        br->pr = &tb->pairs[n + i];
        br->inv_span = span > 0.0 ? 1.0 / span : 0.0;
        return (1.0 - w) * tb->delta[i] + w * tb->delta[i + 1];
    }
}

#endif
