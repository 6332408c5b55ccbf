/*
 * CushionClutch: native FMI 2.0 co-simulation FMU of the temperature-aware dry
 * clutch (the same model as fmu_src/clutch_model.py, operation for operation).
 *
 *   theta_cs: exact solution of C dtheta/dt = U (theta_cm - theta) + H (theta_a - theta)
 *             for theta_cm held over the step;
 *   x_kiss  = x_kiss_ref - lever_ratio * delta_kiss(theta_cs);
 *   u       = (x_to - x_kiss) / lever_ratio,  u_f = max(u, 0);
 *   F       = PCHIP in u per table temperature, linear in theta, clamped;
 *   torque  = n_surfaces * mu * R_eq * F.
 *
 * Tables are read from <resources>/tables/{force_deflection,kiss_point}.csv (and the optional
 * friction.csv: mu(theta_cm, |omega_slip|), bilinear, clamped; else the parameter mu) at
 * instantiation, so one binary serves every table set. Value references follow
 * clutch_model.VARIABLES. No global state: any number of instances.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define KELVIN 273.15
#define X_TO_LIMIT 1.0
#define THETA_CM_LIMIT 2000.0
#define NVARS 18
#define OMEGA_SLIP_LIMIT 1e4
#define MU_LIMIT 2.0
#define STATE_MAGIC 0x43434631u /* "CCF1" */

enum {
    VR_X_TO, VR_THETA_CM, VR_TORQUE, VR_FORCE, VR_THETA_CS, VR_U_F, VR_X_KISS,
    VR_N_SURFACES, VR_MU, VR_R_EQ, VR_U, VR_H, VR_C, VR_THETA_A, VR_THETA_CS_START,
    VR_X_KISS_REF, VR_LEVER_RATIO, VR_OMEGA_SLIP
};

static const char *VAR_NAMES[NVARS] = {
    "x_to", "theta_cm", "torque", "force", "theta_cs", "u_f", "x_kiss", "n_surfaces", "mu",
    "R_eq", "U", "H", "C", "theta_a", "theta_cs_start", "x_kiss_ref", "lever_ratio", "omega_slip"};

/* defaults: inputs, outputs (start), parameters (clutch_model.ClutchParameters) */
static const double DEFAULTS[NVARS] = {
    0.0, 293.15, 0.0, 0.0, 293.15, 0.0, 0.004, 2.0, 0.28, 0.089, 0.1, 0.04, 1.0, 293.15, 293.15,
    0.004, 3.0, 0.0};

/* allowed parameter ranges: low, high, low open, high open (clutch_model.RANGES) */
static const double RANGES[NVARS][4] = {
    {0}, {0}, {0}, {0}, {0}, {0}, {0},
    {1.0, 16.0, 0, 0}, {0.0, 2.0, 0, 0}, {0.0, 1.0, 1, 0}, {0.0, 1e4, 0, 0}, {0.0, 1e4, 0, 0},
    {0.0, 1e6, 1, 0}, {0.0, 2000.0, 1, 0}, {0.0, 2000.0, 1, 0}, {-1.0, 1.0, 0, 0},
    {0.0, 100.0, 1, 0}, {0}};

typedef struct {
    int n;
    double *x, *y, *d;
} Curve;

typedef struct {
    int nt;
    double *theta; /* degC */
    double *delta; /* m */
    Curve *curves;
    /* optional friction table mu(theta_cm degC, |omega_slip| rad/s), row-major [ntf][nw] */
    int ntf, nw;
    double *f_theta, *f_omega, *f_mu;
} Table;

typedef enum { ST_INSTANTIATED, ST_INIT, ST_STEP, ST_TERMINATED, ST_ERROR } Phase;

typedef struct {
    double r[NVARS];
    int range_warned;
    double time;
    Phase phase;
    int params_ok;
    Table table;
    int table_ok;
    char table_error[512];
    fmi2CallbackFunctions cb;
    char *name;
    int logging_on;
} Comp;

typedef struct {
    unsigned magic;
    double r[NVARS];
    int range_warned;
    double time;
    int phase;
    int params_ok;
} State;

/* ------------------------------------------------------------------ logging */
static void logf_(Comp *c, fmi2Status status, const char *category, const char *fmt, ...) {
    char msg[1024];
    va_list ap;
    if (!c->cb.logger) return;
    if (!c->logging_on && status == fmi2OK) return;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    c->cb.logger(c->cb.componentEnvironment, c->name, status, category, "%s", msg);
}

/* ------------------------------------------------------------------- tables */
static double sign_(double v) { return (v > 0) - (v < 0); }

static double end_slope(double h0, double h1, double m0, double m1) {
    double d = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
    if (sign_(d) != sign_(m0)) return 0.0;
    if (sign_(m0) != sign_(m1) && fabs(d) > fabs(3 * m0)) return 3 * m0;
    return d;
}

/* slopes of the monotone cubic Hermite interpolant (as clutch_model.pchip_slopes) */
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
    d[0] = end_slope(x[1] - x[0], x[2] - x[1], (y[1] - y[0]) / (x[1] - x[0]),
                     (y[2] - y[1]) / (x[2] - x[1]));
    d[n - 1] = end_slope(x[n - 1] - x[n - 2], x[n - 2] - x[n - 3],
                         (y[n - 1] - y[n - 2]) / (x[n - 1] - x[n - 2]),
                         (y[n - 2] - y[n - 3]) / (x[n - 2] - x[n - 3]));
}

static double curve_eval(const Curve *c, double u) {
    int lo = 0, hi = c->n - 1, i;
    double h, t, t2, t3;
    if (u <= c->x[0]) return c->y[0];
    if (u >= c->x[c->n - 1]) return c->y[c->n - 1];
    while (hi - lo > 1) { /* x[lo] <= u < x[hi] */
        int mid = (lo + hi) / 2;
        if (c->x[mid] <= u) lo = mid; else hi = mid;
    }
    i = lo;
    h = c->x[i + 1] - c->x[i];
    t = (u - c->x[i]) / h;
    t2 = t * t;
    t3 = t * t * t;
    return (2 * t3 - 3 * t2 + 1) * c->y[i] + (t3 - 2 * t2 + t) * h * c->d[i] +
           (-2 * t3 + 3 * t2) * c->y[i + 1] + (t3 - t2) * h * c->d[i + 1];
}

static void bracket(const Table *tb, double theta, int *i, double *w) {
    int lo = 0, hi = tb->nt - 1;
    if (theta <= tb->theta[0] || tb->nt == 1) { *i = 0; *w = 0.0; return; }
    if (theta >= tb->theta[tb->nt - 1]) { *i = tb->nt - 2; *w = 1.0; return; }
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (tb->theta[mid] <= theta) lo = mid; else hi = mid;
    }
    *i = lo;
    *w = (theta - tb->theta[lo]) / (tb->theta[lo + 1] - tb->theta[lo]);
}

static double table_force(const Table *tb, double u, double theta) {
    int i; double w, f0;
    bracket(tb, theta, &i, &w);
    f0 = curve_eval(&tb->curves[i], u);
    return w == 0.0 ? f0 : (1.0 - w) * f0 + w * curve_eval(&tb->curves[i + 1], u);
}

static double table_delta(const Table *tb, double theta) {
    int i; double w;
    bracket(tb, theta, &i, &w);
    return w == 0.0 ? tb->delta[i] : (1.0 - w) * tb->delta[i] + w * tb->delta[i + 1];
}

/* grid index and weight of v in g[0..n-1] (clamped) */
static void grid_bracket(const double *g, int n, double v, int *i, double *w) {
    int lo = 0, hi = n - 1;
    if (n == 1 || v <= g[0]) { *i = 0; *w = 0.0; return; }
    if (v >= g[n - 1]) { *i = n - 2; *w = 1.0; return; }
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (g[mid] <= v) lo = mid; else hi = mid;
    }
    *i = lo;
    *w = (v - g[lo]) / (g[lo + 1] - g[lo]);
}

/* mu(theta_cm degC, |omega|): bilinear on the friction grid, clamped (as friction.FrictionTable) */
static double table_mu(const Table *tb, double theta, double omega) {
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

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* sorted unique values of column col of rows x ncol data; returns count */
static int unique_sorted(const double *data, int rows, int ncol, int col, double *out) {
    int k, n = 0;
    for (k = 0; k < rows; ++k) out[k] = data[k * ncol + col];
    qsort(out, rows, sizeof(double), cmp_double);
    for (k = 0; k < rows; ++k)
        if (n == 0 || out[k] != out[n - 1]) out[n++] = out[k];
    return n;
}

static void table_free(Table *tb) {
    int k;
    if (tb->curves) {
        for (k = 0; k < tb->nt; ++k) {
            free(tb->curves[k].x); free(tb->curves[k].y); free(tb->curves[k].d);
        }
    }
    free(tb->curves); free(tb->theta); free(tb->delta);
    free(tb->f_theta); free(tb->f_omega); free(tb->f_mu);
    memset(tb, 0, sizeof *tb);
}

/* Read a CSV with a fixed header into rows of ncol doubles. Returns rows or -1. */
static int read_csv(const char *path, const char *header, int ncol, double **out, char *err, size_t errlen) {
    FILE *f = fopen(path, "r");
    char line[4096];
    int rows = 0, cap = 256, lineno = 1;
    double *data;
    if (!f) { snprintf(err, errlen, "cannot open %s", path); return -1; }
    if (!fgets(line, sizeof line, f)) { snprintf(err, errlen, "%s is empty", path); fclose(f); return -1; }
    line[strcspn(line, "\r\n")] = 0;
    if (strcmp(line, header) != 0) {
        snprintf(err, errlen, "%s: header must be '%s'", path, header); fclose(f); return -1;
    }
    data = (double *)malloc(sizeof(double) * cap * ncol);
    if (!data) { snprintf(err, errlen, "out of memory"); fclose(f); return -1; }
    while (fgets(line, sizeof line, f)) {
        char *p = line, *end;
        int k;
        ++lineno;
        if (strspn(line, " \t\r\n") == strlen(line)) continue;
        if (rows == cap) {
            double *grown = (double *)realloc(data, sizeof(double) * (cap *= 2) * ncol);
            if (!grown) { free(data); snprintf(err, errlen, "out of memory"); fclose(f); return -1; }
            data = grown;
        }
        for (k = 0; k < ncol; ++k) {
            double v = strtod(p, &end);
            if (end == p || !isfinite(v) || (k < ncol - 1 && *end != ',') ||
                (k == ncol - 1 && strspn(end, " \t\r\n") != strlen(end))) {
                snprintf(err, errlen, "%s line %d: expected %d finite numbers", path, lineno, ncol);
                free(data); fclose(f); return -1;
            }
            data[rows * ncol + k] = v;
            p = end + 1;
        }
        ++rows;
    }
    fclose(f);
    *out = data;
    return rows;
}

static int table_load(Table *tb, const char *dir, char *err, size_t errlen) {
    char path[4096];
    double *fd = NULL, *kp = NULL;
    int nfd, nkp, k, start, t;
    memset(tb, 0, sizeof *tb);
    if (strlen(dir) > sizeof path - 64) { snprintf(err, errlen, "resource path too long"); return -1; }
    snprintf(path, sizeof path, "%s/tables/force_deflection.csv", dir);
    nfd = read_csv(path, "theta_degC,u_m,force_N", 3, &fd, err, errlen);
    if (nfd < 0) return -1;
    snprintf(path, sizeof path, "%s/tables/kiss_point.csv", dir);
    nkp = read_csv(path, "theta_degC,delta_kiss_m", 2, &kp, err, errlen);
    if (nkp < 0) { free(fd); return -1; }
    if (nkp < 1) { snprintf(err, errlen, "kiss_point.csv has no rows"); goto fail; }
    /* temperatures of kiss_point.csv must be strictly increasing and match the curves */
    tb->nt = nkp;
    tb->theta = (double *)calloc(nkp, sizeof(double));
    tb->delta = (double *)calloc(nkp, sizeof(double));
    tb->curves = (Curve *)calloc(nkp, sizeof(Curve));
    if (!tb->theta || !tb->delta || !tb->curves) { snprintf(err, errlen, "out of memory"); goto fail; }
    for (k = 0; k < nkp; ++k) {
        tb->theta[k] = kp[2 * k];
        tb->delta[k] = kp[2 * k + 1];
        if (k > 0 && !(tb->theta[k] > tb->theta[k - 1])) {
            snprintf(err, errlen, "kiss_point.csv: temperatures must increase"); goto fail;
        }
    }
    start = 0;
    for (t = 0; t < nkp; ++t) {
        int n = 0, j;
        Curve *c = &tb->curves[t];
        while (start + n < nfd && fd[3 * (start + n)] == tb->theta[t]) ++n;
        if (n < 2) {
            snprintf(err, errlen, "force_deflection.csv: temperature %g degC needs >= 2 rows in "
                     "ascending temperature order matching kiss_point.csv", tb->theta[t]);
            goto fail;
        }
        c->n = n;
        c->x = (double *)malloc(sizeof(double) * n);
        c->y = (double *)malloc(sizeof(double) * n);
        c->d = (double *)malloc(sizeof(double) * n);
        if (!c->x || !c->y || !c->d) { snprintf(err, errlen, "out of memory"); goto fail; }
        for (j = 0; j < n; ++j) {
            c->x[j] = fd[3 * (start + j) + 1];
            c->y[j] = fd[3 * (start + j) + 2];
            if (j > 0 && (!(c->x[j] > c->x[j - 1]) || c->y[j] < c->y[j - 1])) {
                snprintf(err, errlen, "force_deflection.csv at %g degC: u must increase and force "
                         "must not decrease", tb->theta[t]);
                goto fail;
            }
        }
        pchip_slopes(c->x, c->y, c->d, n);
        start += n;
    }
    if (start != nfd) {
        snprintf(err, errlen, "force_deflection.csv has rows at temperatures not in kiss_point.csv");
        goto fail;
    }
    free(fd); free(kp);
    fd = kp = NULL;
    snprintf(path, sizeof path, "%s/tables/friction.csv", dir);
    {
        FILE *probe = fopen(path, "r");
        if (probe) {
            double *fr = NULL;
            int nfr, r;
            fclose(probe);
            nfr = read_csv(path, "theta_degC,omega_slip_rad_s,mu", 3, &fr, err, errlen);
            if (nfr < 0) goto fail;
            tb->f_theta = (double *)malloc(sizeof(double) * (nfr + 1));
            tb->f_omega = (double *)malloc(sizeof(double) * (nfr + 1));
            if (!tb->f_theta || !tb->f_omega) { free(fr); snprintf(err, errlen, "out of memory"); goto fail; }
            tb->ntf = nfr ? unique_sorted(fr, nfr, 3, 0, tb->f_theta) : 0;
            tb->nw = nfr ? unique_sorted(fr, nfr, 3, 1, tb->f_omega) : 0;
            if (nfr == 0 || tb->ntf * tb->nw != nfr || tb->f_omega[0] < 0.0) {
                snprintf(err, errlen, "%s: rows must form a full grid of temperatures x slip speeds >= 0, "
                         "each once", path);
                free(fr); goto fail;
            }
            tb->f_mu = (double *)malloc(sizeof(double) * nfr);
            if (!tb->f_mu) { free(fr); snprintf(err, errlen, "out of memory"); goto fail; }
            for (r = 0; r < nfr; ++r) tb->f_mu[r] = -1.0;
            for (r = 0; r < nfr; ++r) {
                double *pt = (double *)bsearch(&fr[3 * r], tb->f_theta, tb->ntf, sizeof(double), cmp_double);
                double *pw = (double *)bsearch(&fr[3 * r + 1], tb->f_omega, tb->nw, sizeof(double), cmp_double);
                double mu = fr[3 * r + 2];
                int at = (int)(pt - tb->f_theta) * tb->nw + (int)(pw - tb->f_omega);
                if (!(mu >= 0.0 && mu <= MU_LIMIT) || tb->f_mu[at] >= 0.0) {
                    snprintf(err, errlen, "%s data row %d: mu must be in [0, %g] and each grid point given once",
                             path, r + 1, MU_LIMIT);
                    free(fr); goto fail;
                }
                tb->f_mu[at] = mu;
            }
            free(fr);
        }
    }
    return 0;
fail:
    free(fd); free(kp);
    table_free(tb);
    return -1;
}

/* file:///a/b%20c -> /a/b c */
static void uri_to_path(const char *uri, char *out, size_t len) {
    const char *p = uri;
    size_t o = 0;
    if (strncmp(p, "file://", 7) == 0) {
        p += 7;
        if (strncmp(p, "localhost/", 10) == 0) p += 9;
    } else if (strncmp(p, "file:", 5) == 0) {
        p += 5;
    }
    while (*p && o + 1 < len) {
        if (p[0] == '%' && p[1] && p[2]) {
            char hex[3] = {p[1], p[2], 0};
            out[o++] = (char)strtol(hex, NULL, 16);
            p += 3;
        } else {
            out[o++] = *p++;
        }
    }
    while (o > 0 && out[o - 1] == '/') --o;
    out[o] = 0;
}

/* -------------------------------------------------------------------- model */
static void update_outputs(Comp *c) {
    double *r = c->r;
    double theta_c = r[VR_THETA_CS] - KELVIN;
    double x_kiss = r[VR_X_KISS_REF] - r[VR_LEVER_RATIO] * table_delta(&c->table, theta_c);
    double u = (r[VR_X_TO] - x_kiss) / r[VR_LEVER_RATIO];
    double force = table_force(&c->table, u, theta_c);
    double mu = c->table.f_mu ? table_mu(&c->table, r[VR_THETA_CM] - KELVIN, r[VR_OMEGA_SLIP]) : r[VR_MU];
    r[VR_TORQUE] = r[VR_N_SURFACES] * mu * r[VR_R_EQ] * force;
    r[VR_FORCE] = force;
    r[VR_U_F] = u > 0.0 ? u : 0.0;
    r[VR_X_KISS] = x_kiss;
    if (!(c->table.theta[0] + KELVIN <= r[VR_THETA_CS] &&
          r[VR_THETA_CS] <= c->table.theta[c->table.nt - 1] + KELVIN) && !c->range_warned) {
        c->range_warned = 1;
        logf_(c, fmi2Warning, "logStatusWarning",
              "theta_cs = %.2f K is outside the table range [%.2f, %.2f] K; F and the kiss point "
              "are clamped to the nearest table temperature (warned once)", r[VR_THETA_CS],
              c->table.theta[0] + KELVIN, c->table.theta[c->table.nt - 1] + KELVIN);
    }
}

static int check_parameters(Comp *c) {
    int k, ok = 1;
    for (k = VR_N_SURFACES; k <= VR_LEVER_RATIO; ++k) {
        double v = c->r[k];
        const double *g = RANGES[k];
        int good = isfinite(v) && (g[2] ? v > g[0] : v >= g[0]) && (g[3] ? v < g[1] : v <= g[1]);
        if (!good) {
            logf_(c, fmi2Error, "logStatusError", "parameter %s = %g is out of range %c%g, %g%c",
                  VAR_NAMES[k], v, g[2] ? '(' : '[', g[0], g[1], g[3] ? ')' : ']');
            ok = 0;
        }
    }
    if (ok && !(c->r[VR_U] + c->r[VR_H] > 0.0)) {
        logf_(c, fmi2Error, "logStatusError", "U + H must be > 0 (the cushion spring needs a heat path)");
        ok = 0;
    }
    return ok;
}

static int check_inputs(Comp *c, double t) {
    int ok = 1;
    double x = c->r[VR_X_TO], th = c->r[VR_THETA_CM];
    if (!(isfinite(x) && fabs(x) <= X_TO_LIMIT)) {
        logf_(c, fmi2Error, "logStatusError",
              "t = %g s: input x_to = %g m is not finite or |x_to| > %g m; step refused", t, x, X_TO_LIMIT);
        ok = 0;
    }
    if (!(isfinite(th) && th > 0.0 && th < THETA_CM_LIMIT)) {
        logf_(c, fmi2Error, "logStatusError",
              "t = %g s: input theta_cm = %g K is not finite or outside (0, %g) K; step refused", t, th,
              THETA_CM_LIMIT);
        ok = 0;
    }
    if (!(isfinite(c->r[VR_OMEGA_SLIP]) && fabs(c->r[VR_OMEGA_SLIP]) <= OMEGA_SLIP_LIMIT)) {
        logf_(c, fmi2Error, "logStatusError",
              "t = %g s: input omega_slip = %g rad/s is not finite or |omega_slip| > %g rad/s; step refused", t,
              c->r[VR_OMEGA_SLIP], OMEGA_SLIP_LIMIT);
        ok = 0;
    }
    return ok;
}

/* -------------------------------------------------------------- FMI 2.0 API */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean loggingOn, size_t n, const fmi2String cats[]) {
    (void)n; (void)cats;
    ((Comp *)comp)->logging_on = loggingOn;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    Comp *c;
    char dir[2048];
    (void)guid; (void)visible;
    if (!functions || !name) return NULL;
    c = (Comp *)calloc(1, sizeof(Comp));
    if (!c) return NULL;
    c->cb = *functions;
    c->name = (char *)malloc(strlen(name) + 1);
    if (!c->name) { free(c); return NULL; }
    strcpy(c->name, name);
    c->logging_on = loggingOn;
    if (type != fmi2CoSimulation) {
        logf_(c, fmi2Error, "logStatusError", "only co-simulation is supported");
        free(c->name); free(c);
        return NULL;
    }
    memcpy(c->r, DEFAULTS, sizeof c->r);
    c->phase = ST_INSTANTIATED;
    if (!resources) {
        snprintf(c->table_error, sizeof c->table_error, "no resource location given: tables missing");
    } else {
        uri_to_path(resources, dir, sizeof dir);
        c->table_ok = table_load(&c->table, dir, c->table_error, sizeof c->table_error) == 0;
    }
    if (!c->table_ok)
        logf_(c, fmi2Error, "logStatusError", "cannot load the F(u, theta) tables: %s", c->table_error);
    return c;
}

void fmi2FreeInstance(fmi2Component comp) {
    Comp *c = (Comp *)comp;
    if (!c) return;
    table_free(&c->table);
    free(c->name);
    free(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean tolDef, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stopDef, fmi2Real stop) {
    (void)tolDef; (void)tol; (void)stopDef; (void)stop;
    ((Comp *)comp)->time = start;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component comp) {
    Comp *c = (Comp *)comp;
    if (!c->table_ok) {
        logf_(c, fmi2Error, "logStatusError", "cannot load the F(u, theta) tables: %s", c->table_error);
        return fmi2Error;
    }
    c->phase = ST_INIT;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component comp) {
    Comp *c = (Comp *)comp;
    if (!c->table_ok) return fmi2Error;
    c->params_ok = check_parameters(c);
    c->r[VR_THETA_CS] = c->r[VR_THETA_CS_START];
    if (!c->params_ok) {
        c->r[VR_TORQUE] = c->r[VR_FORCE] = c->r[VR_U_F] = 0.0;
        c->phase = ST_ERROR;
        return fmi2Error;
    }
    c->phase = ST_STEP;
    if (isfinite(c->r[VR_X_TO]) && fabs(c->r[VR_X_TO]) <= X_TO_LIMIT) update_outputs(c);
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component comp) {
    ((Comp *)comp)->phase = ST_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component comp) {
    Comp *c = (Comp *)comp;
    memcpy(c->r, DEFAULTS, sizeof c->r);
    c->range_warned = 0;
    c->params_ok = 0;
    c->time = 0.0;
    c->phase = ST_INSTANTIATED;
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Comp *c = (Comp *)comp;
    size_t k;
    for (k = 0; k < n; ++k) {
        if (vr[k] >= NVARS) {
            logf_(c, fmi2Error, "logStatusError", "fmi2GetReal: unknown value reference %u", vr[k]);
            return fmi2Error;
        }
        value[k] = c->r[vr[k]];
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Comp *c = (Comp *)comp;
    size_t k;
    for (k = 0; k < n; ++k) {
        if (vr[k] >= NVARS || (vr[k] >= VR_TORQUE && vr[k] <= VR_X_KISS)) {
            logf_(c, fmi2Error, "logStatusError", "fmi2SetReal: value reference %u is not settable", vr[k]);
            return fmi2Error;
        }
        if (vr[k] >= VR_N_SURFACES && vr[k] <= VR_LEVER_RATIO && c->phase == ST_STEP) {
            logf_(c, fmi2Error, "logStatusError",
                  "fmi2SetReal: parameter %s is fixed after initialization", VAR_NAMES[vr[k]]);
            return fmi2Error;
        }
        c->r[vr[k]] = value[k];
    }
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    Comp *c = (Comp *)comp;
    double g, theta_inf, *r = c->r;
    (void)noSetPrior;
    if (c->phase != ST_STEP) {
        logf_(c, fmi2Error, "logStatusError", "fmi2DoStep: not initialized or parameters invalid");
        return fmi2Error;
    }
    if (!(isfinite(h) && h >= 0.0)) {
        logf_(c, fmi2Error, "logStatusError", "t = %g s: step size %g must be finite and >= 0", t, h);
        return fmi2Discard;
    }
    if (!check_inputs(c, t)) return fmi2Discard;
    g = r[VR_U] + r[VR_H];
    theta_inf = (r[VR_U] * r[VR_THETA_CM] + r[VR_H] * r[VR_THETA_A]) / g;
    r[VR_THETA_CS] = theta_inf + (r[VR_THETA_CS] - theta_inf) * exp(-h * g / r[VR_C]);
    update_outputs(c);
    c->time = t + h;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component comp) { (void)comp; return fmi2Error; }

/* FMU state: the variables, the warning flag, the time and the phase */
fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    Comp *c = (Comp *)comp;
    State *s = *state ? (State *)*state : (State *)malloc(sizeof(State));
    if (!s) return fmi2Error;
    s->magic = STATE_MAGIC;
    memcpy(s->r, c->r, sizeof c->r);
    s->range_warned = c->range_warned;
    s->time = c->time;
    s->phase = c->phase;
    s->params_ok = c->params_ok;
    *state = s;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state) {
    Comp *c = (Comp *)comp;
    const State *s = (const State *)state;
    if (!s || s->magic != STATE_MAGIC) {
        logf_(c, fmi2Error, "logStatusError", "fmi2SetFMUstate: not a CushionClutch state");
        return fmi2Error;
    }
    memcpy(c->r, s->r, sizeof c->r);
    c->range_warned = s->range_warned;
    c->time = s->time;
    c->phase = (Phase)s->phase;
    c->params_ok = s->params_ok;
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    (void)comp;
    if (state && *state) { free(*state); *state = NULL; }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state, size_t *size) {
    (void)comp; (void)state;
    *size = sizeof(State);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    if (size < sizeof(State)) {
        logf_((Comp *)comp, fmi2Error, "logStatusError", "fmi2SerializeFMUstate: buffer too small");
        return fmi2Error;
    }
    memcpy(bytes, state, sizeof(State));
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) {
    State *s;
    if (size != sizeof(State) || ((const State *)bytes)->magic != STATE_MAGIC) {
        logf_((Comp *)comp, fmi2Error, "logStatusError", "fmi2DeSerializeFMUstate: not a CushionClutch state");
        return fmi2Error;
    }
    s = (State *)malloc(sizeof(State));
    if (!s) return fmi2Error;
    memcpy(s, bytes, sizeof(State));
    *state = s;
    return fmi2OK;
}

/* ----------------------------------------------------- unsupported / unused */
static fmi2Status unsupported(fmi2Component comp, const char *what) {
    logf_((Comp *)comp, fmi2Error, "logStatusError", "%s is not supported", what);
    return fmi2Error;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    (void)vr; (void)v; return n ? unsupported(c, "fmi2GetInteger") : fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
    (void)vr; (void)v; return n ? unsupported(c, "fmi2GetBoolean") : fmi2OK;
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    (void)vr; (void)v; return n ? unsupported(c, "fmi2GetString") : fmi2OK;
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    (void)vr; (void)v; return n ? unsupported(c, "fmi2SetInteger") : fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
    (void)vr; (void)v; return n ? unsupported(c, "fmi2SetBoolean") : fmi2OK;
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    (void)vr; (void)v; return n ? unsupported(c, "fmi2SetString") : fmi2OK;
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real du[],
                                        fmi2Real dz[]) {
    (void)u; (void)nu; (void)z; (void)nz; (void)du; (void)dz;
    return unsupported(c, "fmi2GetDirectionalDerivative");
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)n; (void)order; (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives");
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)n; (void)order; (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives");
}
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v) {
    (void)s; (void)v; return unsupported(c, "fmi2GetStatus");
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *v) {
    if (s == fmi2LastSuccessfulTime) { *v = ((Comp *)c)->time; return fmi2OK; }
    return unsupported(c, "fmi2GetRealStatus");
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *v) {
    (void)s; (void)v; return unsupported(c, "fmi2GetIntegerStatus");
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v) {
    (void)s; (void)v; return unsupported(c, "fmi2GetBooleanStatus");
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v) {
    (void)s; (void)v; return unsupported(c, "fmi2GetStringStatus");
}
