/*
 * CushionClutch model core, part 1: the table set (force_deflection.csv, kiss_point.csv, optional
 * friction.csv) read from the FMU's resources, its interpolation (as cushion_clutch/model/spring_table.py and
 * friction.py, operation for operation). The resource URI -> path conversion is in resource_uri.c.
 */
#include "clutch_tables.h"
#include "resource_uri.h" /* cc_fopen */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MU_LIMIT 2.0
#define FORCE_LIMIT 1e12 /* N: n*mu*R_eq*F stays finite for every allowed parameter */

/* ----------------------------------------------------------- interpolation */
static double sign_(double v) { return (v > 0) - (v < 0); }

static double end_slope(double h0, double h1, double m0, double m1) {
    double d = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
    if (sign_(d) != sign_(m0)) return 0.0;
    if (sign_(m0) != sign_(m1) && fabs(d) > fabs(3 * m0)) return 3 * m0;
    return d;
}

/* slopes of the monotone cubic Hermite interpolant (as spring_table.pchip_slopes) */
static void pchip_slopes(const double *x, const double *y, double *d, int n) {
    int k;
    if (n == 2) {
        d[0] = d[1] = (y[1] - y[0]) / (x[1] - x[0]);
        return;
    }
    for (k = 1; k < n - 1; ++k) {
        double h0 = x[k] - x[k - 1], h1 = x[k + 1] - x[k];
        double m0 = (y[k] - y[k - 1]) / h0, m1 = (y[k + 1] - y[k]) / h1;
        double w1 = 2 * h1 + h0, w2 = h1 + 2 * h0;
        d[k] = (m0 * m1 > 0) ? (w1 + w2) / (w1 / m0 + w2 / m1) : 0.0;
    }
    d[0] = end_slope(x[1] - x[0], x[2] - x[1], (y[1] - y[0]) / (x[1] - x[0]), (y[2] - y[1]) / (x[2] - x[1]));
    d[n - 1] = end_slope(x[n - 1] - x[n - 2], x[n - 2] - x[n - 3], (y[n - 1] - y[n - 2]) / (x[n - 1] - x[n - 2]),
                         (y[n - 2] - y[n - 3]) / (x[n - 2] - x[n - 3]));
}

/* the binary search for x[lo] <= u < x[lo + 1] (x[0] < u < x[n-1]) */
static int curve_bsearch(const Curve *c, double u) {
    int lo = 0, hi = c->n - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (c->x[mid] <= u) lo = mid; else hi = mid;
    }
    return lo;
}

int cc_curve_locate(const Curve *c, double u) {
    const double *x = c->x;
    int k = (int)((u - x[0]) * c->inv_bw), i;
    if (k > c->nb - 1) k = c->nb - 1;
    if (k < 0) k = 0;
    i = c->bk[k];
    i += u >= x[i + 1];
    while (u < x[i]) --i;
    while (u >= x[i + 1]) ++i;
    return i;
}

/* the buckets of a loaded curve (n >= 2, x increasing); -1 if out of memory */
static int curve_buckets(Curve *c) {
    double span = c->x[c->n - 1] - c->x[0], dmin = span, bw;
    int j, nb;
    for (j = 1; j < c->n; ++j)
        if (c->x[j] - c->x[j - 1] < dmin) dmin = c->x[j] - c->x[j - 1];
    nb = dmin > 0.0 && span / dmin < 4095.0 ? (int)ceil(span / dmin) : 4096;
    if (nb < 1) nb = 1;
    bw = span / nb;
    c->nb = nb;
    c->inv_bw = 1.0 / bw;
    if (c->n > 65535) return -1;
    c->bk = (unsigned short *)malloc(sizeof(unsigned short) * nb);
    if (!c->bk) return -1;
    for (j = 0; j < nb; ++j) {
        double e = c->x[0] + bw * j;
        c->bk[j] = (unsigned short)(e <= c->x[0] ? 0 : e >= c->x[c->n - 1] ? c->n - 2 : curve_bsearch(c, e));
    }
    c->pc = (double *)malloc(sizeof(double) * 4 * (c->n - 1));
    if (!c->pc) return -1;
    for (j = 0; j < c->n - 1; ++j) { /* the Hermite cubic of curve_eval in powers of t */
        double h = c->x[j + 1] - c->x[j], a = c->y[j], b = h * c->d[j], e = c->y[j + 1], f = h * c->d[j + 1];
        c->pc[4 * j] = b;
        c->pc[4 * j + 1] = 3.0 * (e - a) - 2.0 * b - f;
        c->pc[4 * j + 2] = 2.0 * (a - e) + b + f;
        c->pc[4 * j + 3] = 1.0 / h;
    }
    return 0;
}

static int cmp_double(const void *a, const void *b);

/* curve c in cell [lo, hi) of phi, where x = x_first + phi S (S = x[n-1] - x_first > 0): the cubic in
   tau = phi - org of the interval holding the cell (or the clamped constant), coefficients into f[4] */
static void cell_cubic(const Curve *c, double S, double lo, double hi, double org, double *f) {
    double mid = 0.5 * (lo + hi), xm, h, beta, t, q0, q1, q2;
    int i;
    f[1] = f[2] = f[3] = 0.0;
    if (S <= 0.0) { f[0] = c->y[0]; return; } /* a constant curve */
    xm = c->x_first + mid * S;
    if (!(lo > -INFINITY) || xm <= c->x[0]) { f[0] = c->y[0]; return; }
    if (!(hi < INFINITY) || xm >= c->x[c->n - 1]) { f[0] = c->y[c->n - 1]; return; }
    i = curve_bsearch(c, xm);
    h = c->x[i + 1] - c->x[i];
    q0 = c->pc[4 * i]; q1 = c->pc[4 * i + 1]; q2 = c->pc[4 * i + 2];
    beta = S / h;
    t = (c->x_first + org * S - c->x[i]) / h;
    f[0] = c->y[i] + t * (q0 + t * (q1 + t * q2));
    f[1] = beta * (q0 + t * (2.0 * q1 + 3.0 * q2 * t));
    f[2] = beta * beta * (q1 + 3.0 * q2 * t);
    f[3] = beta * beta * beta * q2;
}

/* the CurvePair of curve a alone (b NULL) or of curves a, b; -1 if out of memory */
static int pair_build(CurvePair *p, const Curve *a, const Curve *b) {
    const Curve *cv[2] = {a, b};
    double S[2], *k, span, dmin, bw;
    int nk = 0, j, q, m;
    memset(p, 0, sizeof *p);
    k = (double *)malloc(sizeof(double) * (a->n + (b ? b->n : 0) + 1));
    if (!k) return -1;
    for (q = 0; q < 2 && cv[q]; ++q) {
        S[q] = cv[q]->x[cv[q]->n - 1] - cv[q]->x_first;
        if (S[q] > 0.0)
            for (j = 0; j < cv[q]->n; ++j) k[nk++] = (cv[q]->x[j] - cv[q]->x_first) / S[q];
    }
    qsort(k, nk, sizeof(double), cmp_double);
    for (j = 0, m = 0; j < nk; ++j)
        if (m == 0 || k[j] != k[m - 1]) k[m++] = k[j];
    p->m = m;
    p->cell = (PairCell *)malloc(sizeof(PairCell) * (m + 2));
    if (!p->cell) { free(k); return -1; }
    for (j = 0; j <= m + 1; ++j) {
        PairCell *c = &p->cell[j];
        double lo = j == 0 ? -INFINITY : j <= m ? k[j - 1] : INFINITY, hi = j < m ? k[j] : INFINITY, f0[4], f1[4];
        int r;
        c->lo = lo;
        c->org = j == 0 ? (m ? k[0] : 0.0) : j <= m ? lo : 0.0;
        if (j == m + 1) { memset(c->a, 0, sizeof c->a); memset(c->d, 0, sizeof c->d); break; }
        cell_cubic(a, S[0], lo, hi, c->org, f0);
        if (b) cell_cubic(b, S[1], lo, hi, c->org, f1);
        for (r = 0; r < 4; ++r) {
            c->a[r] = f0[r];
            c->d[r] = b ? f1[r] - f0[r] : 0.0;
        }
    }
    /* buckets over [k[0], k[m-1]], none wider than the narrowest cell */
    span = m > 1 ? k[m - 1] - k[0] : 1.0;
    dmin = span;
    for (j = 1; j < m; ++j)
        if (k[j] - k[j - 1] < dmin) dmin = k[j] - k[j - 1];
    p->nb = dmin > 0.0 && span / dmin < 4095.0 ? (int)ceil(span / dmin) : 4096;
    if (p->nb < 1) p->nb = 1;
    bw = span / p->nb;
    p->zmax = p->nb - 1;
    p->phi0 = m ? k[0] : 0.0;
    p->inv_bw = 1.0 / bw;
    p->bk = (unsigned short *)malloc(sizeof(unsigned short) * p->nb);
    if (!p->bk || m > 65000) { free(k); return -1; }
    for (j = 0, q = 0; j < p->nb; ++j) { /* the cell of the bucket's lower edge (q: of the edge before) */
        double e = p->phi0 + bw * j;
        while (q <= m && p->cell[q + 1].lo <= e) ++q;
        p->bk[j] = (unsigned short)q;
    }
    free(k);
    return 0;
}

static double curve_eval(const Curve *c, double u) {
    int i;
    double h, t, t2, t3;
    if (u <= c->x[0]) return c->y[0];
    if (u >= c->x[c->n - 1]) return c->y[c->n - 1];
    i = cc_curve_locate(c, u);
    h = c->x[i + 1] - c->x[i];
    t = (u - c->x[i]) / h;
    t2 = t * t;
    t3 = t * t * t;
    return (2 * t3 - 3 * t2 + 1) * c->y[i] + (t3 - 2 * t2 + t) * h * c->d[i] + (-2 * t3 + 3 * t2) * c->y[i + 1] +
           (t3 - t2) * h * c->d[i + 1];
}

int cc_table_search(const double *g, int n, double v) {
    int lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (g[mid] <= v) lo = mid; else hi = mid;
    }
    return lo;
}

/* grid index and weight of v in g[0..n-1] (clamped) */
static void grid_bracket_hint(const double *g, int n, double v, int *i, double *w, int *hint) {
    int lo = 0, hi = n - 1;
    if (n == 1 || v <= g[0]) { *i = 0; *w = 0.0; return; }
    if (v >= g[n - 1]) { *i = n - 2; *w = 1.0; return; }
    if (hint && *hint >= 0 && *hint < n - 1 && g[*hint] <= v && v < g[*hint + 1]) {
        /* the interval of the last call: the one the search finds (g[lo] <= v < g[lo + 1] is unique) */
        lo = *hint;
        *i = lo;
        *w = (v - g[lo]) / (g[lo + 1] - g[lo]);
        return;
    }
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (g[mid] <= v) lo = mid; else hi = mid;
    }
    *i = lo;
    *w = (v - g[lo]) / (g[lo + 1] - g[lo]);
    if (hint) *hint = lo;
}

static void grid_bracket(const double *g, int n, double v, int *i, double *w) {
    grid_bracket_hint(g, n, v, i, w, NULL);
}

/* the table index and weight of theta: w = 0 at a table temperature and beyond either end (as
   SpringTable._bracket) */
static void table_index(const Table *tb, double theta, int *i, double *w, int *hint) {
    grid_bracket_hint(tb->theta, tb->nt, theta, i, w, hint);
    if (*w == 1.0) { *i += 1; *w = 0.0; }
}

void cc_table_bracket(const Table *tb, double theta, TBracket *br) {
    int i;
    double w, span;
    table_index(tb, theta, &i, &w, NULL);
    br->i = i;
    br->c0 = &tb->curves[i];
    br->w = w;
    if (w == 0.0) {
        br->c1 = br->c0;
        br->first = br->c0->x_first;
        br->full = br->c0->x[br->c0->n - 1];
        br->r0 = 1.0;
        br->r1 = 0.0;
        br->pr = &tb->pairs[i];
        br->inv_span = br->full > br->first ? 1.0 / (br->full - br->first) : 0.0;
        return;
    }
    br->c1 = &tb->curves[i + 1];
    br->first = (1.0 - w) * br->c0->x_first + w * br->c1->x_first;
    br->full = (1.0 - w) * br->c0->x[br->c0->n - 1] + w * br->c1->x[br->c1->n - 1];
    span = br->full - br->first;
    br->r0 = span > 0.0 ? (br->c0->x[br->c0->n - 1] - br->c0->x_first) / span : 0.0;
    br->r1 = span > 0.0 ? (br->c1->x[br->c1->n - 1] - br->c1->x_first) / span : 0.0;
    br->pr = &tb->pairs[tb->nt + i];
    br->inv_span = span > 0.0 ? 1.0 / span : 0.0;
}

/* compression from which F no longer grows at theta (linear in theta between the tables) */
double cc_table_full(const Table *tb, double theta) {
    TBracket br;
    cc_table_bracket(tb, theta, &br);
    return br.full;
}

double cc_table_force(const Table *tb, double u, double theta) {
    TBracket br;
    double v;
    cc_table_bracket(tb, theta, &br);
    if (br.w == 0.0) return curve_eval(br.c0, u);
    v = u - br.first;
    return (1.0 - br.w) * curve_eval(br.c0, br.c0->x_first + v * br.r0) +
           br.w * curve_eval(br.c1, br.c1->x_first + v * br.r1);
}

double cc_table_delta(const Table *tb, double theta) {
    int i; double w;
    table_index(tb, theta, &i, &w, NULL);
    return w == 0.0 ? tb->delta[i] : (1.0 - w) * tb->delta[i] + w * tb->delta[i + 1];
}

/* mu(theta_cm degC, |omega|): bilinear on the friction grid, clamped (as friction.FrictionTable) */
double cc_table_mu(const Table *tb, double theta, double omega) {
    int i, j, i1, j1;
    double wi, wj, lo, hi;
    const double *m = tb->f_mu;
    grid_bracket(tb->f_theta, tb->ntf, theta, &i, &wi);
    grid_bracket(tb->f_omega, tb->nw, fabs(omega), &j, &wj);
    i1 = i + 1 < tb->ntf ? i + 1 : tb->ntf - 1;
    j1 = j + 1 < tb->nw ? j + 1 : tb->nw - 1;
    lo = (1.0 - wj) * m[i * tb->nw + j] + wj * m[i * tb->nw + j1];
    hi = (1.0 - wj) * m[i1 * tb->nw + j] + wj * m[i1 * tb->nw + j1];
    return (1.0 - wi) * lo + wi * hi;
}

/* ------------------------------------------------------------------ reading */
static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* sorted unique values of column col of rows x ncol data into out; returns count */
static int unique_sorted(const double *data, int rows, int ncol, int col, double *out) {
    int k, n = 0;
    for (k = 0; k < rows; ++k) out[k] = data[k * ncol + col];
    qsort(out, rows, sizeof(double), cmp_double);
    for (k = 0; k < rows; ++k)
        if (n == 0 || out[k] != out[n - 1]) out[n++] = out[k];
    return n;
}

void cc_table_free(Table *tb) {
    int k;
    if (tb->curves)
        for (k = 0; k < tb->nt; ++k) {
            free(tb->curves[k].x); free(tb->curves[k].y); free(tb->curves[k].d); free(tb->curves[k].bk); free(tb->curves[k].pc);
        }
    if (tb->pairs)
        for (k = 0; k < 2 * tb->nt - 1; ++k) { free(tb->pairs[k].cell); free(tb->pairs[k].bk); }
    free(tb->pairs);
    free(tb->curves); free(tb->theta); free(tb->delta);
    free(tb->f_theta); free(tb->f_omega); free(tb->f_mu);
    memset(tb, 0, sizeof *tb);
}

/* Read a CSV with a fixed header into rows of ncol finite doubles; lines[r] is the file line of row r.
   Returns the number of rows or -1 (message in err, naming the file and line). */
static int read_csv(const char *path, const char *header, int ncol, double **out, int **lines, char *err,
                    size_t errlen) {
    FILE *f = cc_fopen(path, "r");
    char line[4096];
    int rows = 0, cap = 256, lineno = 1;
    double *data;
    int *where;
    if (!f) { snprintf(err, errlen, "cannot open %s", path); return -1; }
    if (!fgets(line, sizeof line, f)) { snprintf(err, errlen, "%s is empty", path); fclose(f); return -1; }
    line[strcspn(line, "\r\n")] = 0;
    if (strcmp(line, header) != 0) {
        snprintf(err, errlen, "%s line 1: header must be %s", path, header); fclose(f); return -1;
    }
    data = (double *)malloc(sizeof(double) * cap * ncol);
    where = (int *)malloc(sizeof(int) * cap);
    if (!data || !where) { free(data); free(where); snprintf(err, errlen, "out of memory"); fclose(f); return -1; }
    while (fgets(line, sizeof line, f)) {
        char *p = line, *end;
        int k;
        ++lineno;
        if (strspn(line, " \t\r\n") == strlen(line)) continue;
        if (rows == cap) {
            double *grown = (double *)realloc(data, sizeof(double) * (size_t)(cap * 2) * ncol);
            int *wgrown = grown ? (int *)realloc(where, sizeof(int) * (size_t)(cap * 2)) : NULL;
            if (grown) data = grown;
            if (!grown || !wgrown) {
                free(data); free(where); snprintf(err, errlen, "out of memory"); fclose(f); return -1;
            }
            where = wgrown;
            cap *= 2;
        }
        for (k = 0; k < ncol; ++k) {
            double v = strtod(p, &end);
            if (end == p || !isfinite(v) || (k < ncol - 1 && *end != ',') ||
                (k == ncol - 1 && strspn(end, " \t\r\n") != strlen(end))) {
                snprintf(err, errlen, "%s line %d: expected %d finite numbers", path, lineno, ncol);
                free(data); free(where); fclose(f); return -1;
            }
            data[rows * ncol + k] = v;
            p = end + 1;
        }
        where[rows++] = lineno;
    }
    fclose(f);
    *out = data;
    *lines = where;
    return rows;
}

static int load_friction(Table *tb, const char *path, char *err, size_t errlen) {
    double *fr = NULL;
    int *ln = NULL, nfr, r;
    nfr = read_csv(path, "theta_degC,omega_slip_rad_s,mu", 3, &fr, &ln, err, errlen);
    if (nfr < 0) return -1;
    tb->f_theta = (double *)malloc(sizeof(double) * (nfr + 1));
    tb->f_omega = (double *)malloc(sizeof(double) * (nfr + 1));
    tb->f_mu = (double *)malloc(sizeof(double) * (nfr + 1));
    if (!tb->f_theta || !tb->f_omega || !tb->f_mu) { snprintf(err, errlen, "out of memory"); goto fail; }
    tb->ntf = nfr ? unique_sorted(fr, nfr, 3, 0, tb->f_theta) : 0;
    tb->nw = nfr ? unique_sorted(fr, nfr, 3, 1, tb->f_omega) : 0;
    if (nfr == 0 || tb->ntf * tb->nw != nfr || tb->f_omega[0] < 0.0) {
        snprintf(err, errlen, "%s: rows must form a full grid of temperatures x slip speeds >= 0, each once", path);
        goto fail;
    }
    for (r = 0; r < nfr; ++r) tb->f_mu[r] = -1.0;
    for (r = 0; r < nfr; ++r) {
        double *pt = (double *)bsearch(&fr[3 * r], tb->f_theta, tb->ntf, sizeof(double), cmp_double);
        double *pw = (double *)bsearch(&fr[3 * r + 1], tb->f_omega, tb->nw, sizeof(double), cmp_double);
        double mu = fr[3 * r + 2];
        int at = (int)(pt - tb->f_theta) * tb->nw + (int)(pw - tb->f_omega);
        if (!(mu >= 0.0 && mu <= MU_LIMIT) || tb->f_mu[at] >= 0.0) {
            snprintf(err, errlen, "%s line %d: mu must be in [0, %g] and each grid point given once", path, ln[r],
                     MU_LIMIT);
            goto fail;
        }
        tb->f_mu[at] = mu;
    }
    free(fr); free(ln);
    return 0;
fail:
    free(fr); free(ln);
    return -1;
}

/* One F(u) curve per temperature; the groups may come in any order, rows keep their file order
   within a group (as SpringTable.from_dir). kiss_point.csv rows may come in any order too. */
static int load_folder(Table *tb, const char *dir, const char *sub, char *err, size_t errlen);

int cc_table_load(Table *tb, const char *dir, char *err, size_t errlen) {
    return load_folder(tb, dir, "tables", err, errlen);
}

/* the folder of table set k (0-based) under the resources: tables, tables_2, tables_3, ... */
static void set_folder(int k, char *sub, size_t len) {
    if (k == 0) snprintf(sub, len, "tables");
    else snprintf(sub, len, "tables_%d", k + 1);
}

/* set k's kiss-point offset (m) from its optional offset file: one finite number, |offset| < 0.1 m */
static int read_offset(TableSets *s, int k, const char *dir, const char *sub, char *err, size_t errlen) {
    char path[4200], rest[8];
    double v;
    int got;
    FILE *f;
    snprintf(path, sizeof path, "%s/%s/%s", dir, sub, CC_KISS_OFFSET_FILE);
    f = cc_fopen(path, "r");
    s->kiss_offset[k] = 0.0;
    if (!f) return 0;
    got = fscanf(f, "%lf", &v);
    if (got == 1 && fscanf(f, " %7s", rest) == 1) got = 0; /* anything after the number */
    fclose(f);
    if (got != 1 || !isfinite(v) || !(fabs(v) < 0.1)) {
        snprintf(err, errlen, "%s: must hold one number, the set's kiss-point offset in m, |offset| < 0.1 m", path);
        return -1;
    }
    s->kiss_offset[k] = v;
    return 0;
}

int cc_table_sets_load(TableSets *s, const char *dir, char *err, size_t errlen) {
    char sub[32], path[4200];
    int k;
    memset(s, 0, sizeof *s);
    if (strlen(dir) > 4000) { snprintf(err, errlen, "resource path too long"); return -1; }
    s->set = (Table *)calloc(CC_MAX_SETS, sizeof(Table));
    if (!s->set) { snprintf(err, errlen, "out of memory"); return -1; }
    for (k = 0; k < CC_MAX_SETS; ++k) {
        set_folder(k, sub, sizeof sub);
        if (k > 0) { /* the sets are numbered without gaps: the first missing folder ends them */
            FILE *probe;
            snprintf(path, sizeof path, "%s/%s/force_deflection.csv", dir, sub);
            probe = cc_fopen(path, "r");
            if (!probe) break;
            fclose(probe);
        }
        if (load_folder(&s->set[k], dir, sub, err, errlen) != 0) {
            cc_table_sets_free(s);
            return -1;
        }
        s->n = k + 1;
        if (k > 0 && read_offset(s, k, dir, sub, err, errlen) != 0) {
            cc_table_sets_free(s);
            return -1;
        }
    }
    return 0;
}

void cc_table_sets_free(TableSets *s) {
    int k;
    if (s->set)
        for (k = 0; k < s->n; ++k) cc_table_free(&s->set[k]);
    free(s->set);
    memset(s, 0, sizeof *s);
}

static int load_folder(Table *tb, const char *dir, const char *sub, char *err, size_t errlen) {
    char path[4200], kpath[4200];
    double *fd = NULL, *kp = NULL, *uniq = NULL;
    int *fdl = NULL, *kpl = NULL, nfd, nkp, k, t, nt;
    FILE *probe;
    memset(tb, 0, sizeof *tb);
    if (strlen(dir) > 4000) { snprintf(err, errlen, "resource path too long"); return -1; }
    snprintf(path, sizeof path, "%s/%s/force_deflection.csv", dir, sub);
    snprintf(kpath, sizeof kpath, "%s/%s/kiss_point.csv", dir, sub);
    nfd = read_csv(path, "theta_degC,u_m,force_N", 3, &fd, &fdl, err, errlen);
    if (nfd < 0) return -1;
    nkp = read_csv(kpath, "theta_degC,delta_kiss_m", 2, &kp, &kpl, err, errlen);
    if (nkp < 0) goto fail;
    for (k = 0; k < nfd; ++k)
        if (!(fabs(fd[3 * k + 2]) <= FORCE_LIMIT)) {
            snprintf(err, errlen, "%s line %d: force_N = %g is outside [-%g, %g] N (the torque would overflow)",
                     path, fdl[k], fd[3 * k + 2], FORCE_LIMIT, FORCE_LIMIT);
            goto fail;
        }
    for (k = 0; k < nfd; ++k)
        if (fd[3 * k + 2] < 0.0) {
            snprintf(err, errlen, "%s line %d: force_N = %g < 0 (a clamp force cannot be negative)", path, fdl[k],
                     fd[3 * k + 2]);
            goto fail;
        }
    uniq = (double *)malloc(sizeof(double) * (nfd + nkp + 1));
    if (!uniq) { snprintf(err, errlen, "out of memory"); goto fail; }
    nt = nfd ? unique_sorted(fd, nfd, 3, 0, uniq) : 0;
    if (nt < 1) { snprintf(err, errlen, "%s has no rows", path); goto fail; }
    tb->nt = nt;
    tb->theta = uniq;
    uniq = NULL;
    tb->delta = (double *)calloc(nt, sizeof(double));
    tb->curves = (Curve *)calloc(nt, sizeof(Curve));
    if (!tb->delta || !tb->curves) { snprintf(err, errlen, "out of memory"); goto fail; }
    /* kiss_point.csv: exactly the temperatures of force_deflection.csv, each once */
    for (t = 0; t < nt; ++t) tb->delta[t] = NAN;
    for (k = 0; k < nkp; ++k) {
        double *at = (double *)bsearch(&kp[2 * k], tb->theta, nt, sizeof(double), cmp_double);
        if (!at || !isnan(tb->delta[at - tb->theta])) {
            snprintf(err, errlen, "%s line %d: temperature %g degC is %s", kpath, kpl[k], kp[2 * k],
                     at ? "given twice" : "not in force_deflection.csv");
            goto fail;
        }
        tb->delta[at - tb->theta] = kp[2 * k + 1];
    }
    for (t = 0; t < nt; ++t)
        if (isnan(tb->delta[t])) {
            snprintf(err, errlen, "%s: temperature %g degC of force_deflection.csv is missing", kpath, tb->theta[t]);
            goto fail;
        }
    for (t = 0; t < nt; ++t) {
        Curve *c = &tb->curves[t];
        int n = 0, j;
        for (k = 0; k < nfd; ++k) n += fd[3 * k] == tb->theta[t];
        c->x = (double *)malloc(sizeof(double) * n);
        c->y = (double *)malloc(sizeof(double) * n);
        c->d = (double *)malloc(sizeof(double) * n);
        if (!c->x || !c->y || !c->d) { snprintf(err, errlen, "out of memory"); goto fail; }
        for (k = 0, j = 0; k < nfd; ++k) {
            if (fd[3 * k] != tb->theta[t]) continue;
            c->x[j] = fd[3 * k + 1];
            c->y[j] = fd[3 * k + 2];
            if (j > 0 && (!(c->x[j] > c->x[j - 1]) || c->y[j] < c->y[j - 1])) {
                snprintf(err, errlen, "%s line %d: curve at %g degC: u must increase and force must not decrease",
                         path, fdl[k], tb->theta[t]);
                c->n = j;
                goto fail;
            }
            ++j;
        }
        c->n = n;
        if (n < 2) {
            snprintf(err, errlen, "%s: curve at %g degC needs at least 2 rows, has %d", path, tb->theta[t], n);
            goto fail;
        }
        pchip_slopes(c->x, c->y, c->d, n);
        if (curve_buckets(c) != 0) { snprintf(err, errlen, "out of memory (or more than 65535 rows per curve)"); goto fail; }
        for (j = 0, c->x_first = c->x[0]; j < n; ++j)
            if (c->y[j] == c->y[0]) c->x_first = c->x[j];
    }
    tb->pairs = (CurvePair *)calloc(2 * nt - 1, sizeof(CurvePair));
    if (!tb->pairs) { snprintf(err, errlen, "out of memory"); goto fail; }
    for (t = 0; t < 2 * nt - 1; ++t)
        if (pair_build(&tb->pairs[t], &tb->curves[t < nt ? t : t - nt], t < nt ? NULL : &tb->curves[t - nt + 1])) {
            snprintf(err, errlen, "out of memory");
            goto fail;
        }
    free(fd); free(kp); free(fdl); free(kpl);
    fd = kp = NULL;
    fdl = kpl = NULL;
    snprintf(path, sizeof path, "%s/%s/friction.csv", dir, sub);
    probe = cc_fopen(path, "r");
    if (probe) {
        fclose(probe);
        if (load_friction(tb, path, err, errlen) != 0) goto fail;
    }
    return 0;
fail:
    free(fd); free(kp); free(fdl); free(kpl); free(uniq);
    cc_table_free(tb);
    return -1;
}
