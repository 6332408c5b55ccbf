/*
 * CushionClutch model core, part 2: variables, parameter and input checks, outputs, the thermal
 * step (Co-Simulation) and derivative (Model Exchange), the state machine checks shared by both
 * FMI versions, and the saved state (versioned, checksummed, validated).
 */
#define CC_DEFINE_VARIABLE_TABLE /* CC_VARIABLES (cushion_variables.h) is defined in this file */
#include "clutch_core.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#define KELVIN 273.15
/* X_TO_MIN/MAX, THETA_MIN_K/MAX_K, OMEGA_SLIP_LIMIT and the variable table CC_VARIABLES (names, causalities,
   start values, input and parameter ranges, units) come from cushion_variables.h, generated from clutch_model */
#define VAR_NAME(vr) (CC_VARIABLES[vr].name)

static int is_input(unsigned int vr) { return vr < CC_NVARS && CC_VARIABLES[vr].causality == CC_INPUT; }
static int is_parameter(unsigned int vr) { return vr < CC_NVARS && CC_VARIABLES[vr].causality == CC_PARAMETER; }

/* every variable at its start value (parameters: their defaults) */
static void set_starts(double *r) {
    int k;
    for (k = 0; k < CC_NVARS; ++k) r[k] = CC_VARIABLES[k].start;
}

/* the cover's parameters are one block of variables in CV_* order (clutch_model.VARIABLES lists them so) */
typedef char cover_block_is_contiguous[(VR_REFERENCE_TEMPERATURE_K - VR_DIAPHRAGM_OUTER_RADIUS_M == CV_NPAR - 1 &&
                                        VR_FULCRUM_RADIUS_M - VR_DIAPHRAGM_OUTER_RADIUS_M == CV_RF) ? 1 : -1];

static const char *phase_name(int phase) {
    switch (phase) {
    case PH_INSTANTIATED: return "Instantiated";
    case PH_INIT: return "Initialization Mode";
    case PH_STEP: return "Step Mode";
    case PH_EVENT: return "Event Mode";
    case PH_CONT: return "Continuous-Time Mode";
    case PH_TERMINATED: return "Terminated";
    default: return "Error";
    }
}

/* ------------------------------------------------------------------ logging */
void cc_log(CcModel *m, int status, const char *fmt, ...) {
    char msg[1200];
    va_list ap;
    const char *cat = status == CC_OK ? "logAll" : status == CC_WARNING ? "logStatusWarning"
                    : status == CC_DISCARD ? "logStatusDiscard" : "logStatusError";
    if (!m->logger) return;
    if (!m->logging_on && status < CC_WARNING) return; /* warnings, errors and discards: always */
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    m->logger(m->log_ctx, status, cat, msg);
}

int cc_allowed(CcModel *m, int mask, const char *fn) {
    if (m->phase & mask) return 1;
    cc_log(m, CC_ERROR, "%s is not allowed in %s", fn, phase_name(m->phase));
    return 0;
}

/* ------------------------------------------------------------ instantiation */
int cc_instantiate(CcModel *m, const char *dir, int me, CcLogger logger, void *ctx, int logging_on) {
    memset(m, 0, sizeof *m);
    m->logger = logger;
    m->log_ctx = ctx;
    m->logging_on = logging_on;
    m->me = me;
    set_starts(m->r);
    m->phase = PH_INSTANTIATED;
    m->dirty = 1;
    m->decay_h = NAN;
    m->warm.x = NAN;
    m->table_ok = cc_table_load(&m->table, dir, m->table_error, sizeof m->table_error) == 0;
    if (!m->table_ok) cc_log(m, CC_ERROR, "cannot load the F(u, theta) tables: %s", m->table_error);
    return m->table_ok ? 0 : -1;
}

void cc_free(CcModel *m) { cc_table_free(&m->table); }

void cc_reset(CcModel *m) {
    set_starts(m->r);
    m->range_warned = 0;
    m->terminated = 0;
    m->time = 0.0;
    m->dirty = 1;
    m->cover_ok = 0;
    m->warm.x = m->decay_h = NAN;
    m->phase = PH_INSTANTIATED;
}

/* ------------------------------------------------------------------- checks */
static int range_ok(int k, double v) {
    const double *g = CC_VARIABLES[k].range;
    return isfinite(v) && (g[2] ? v > g[0] : v >= g[0]) && (g[3] ? v < g[1] : v <= g[1]);
}

/* the cover parameters of a variable vector (CV_* order) */
static const double *cover_params(const double *r) { return r + VR_DIAPHRAGM_OUTER_RADIUS_M; }

/* the cover's consistency rules of cover.CoverParameters.problems (ranges are checked before);
   logs each problem when m is not NULL; returns 1 if the cover is consistent */
static int cover_consistent(CcModel *m, const double *r, const char *fn) {
    const double *c = cover_params(r);
    double lever = r[VR_LEVER_RATIO];
    int ok = 1;
    if (!(c[CV_B] < c[CV_RF] && c[CV_RF] < c[CV_RPP] && c[CV_RPP] <= c[CV_A])) {
        if (m) cc_log(m, CC_ERROR, "%s: radii must satisfy diaphragm_inner_radius_m < fulcrum_radius_m < "
                      "pressure_plate_radius_m <= diaphragm_outer_radius_m (got %.17g < %.17g < %.17g <= %.17g)", fn, c[CV_B],
                      c[CV_RF], c[CV_RPP], c[CV_A]);
        ok = 0;
    }
    if (!(c[CV_H] < 2.0 * sqrt(2.0) * c[CV_T])) {
        if (m) cc_log(m, CC_ERROR, "%s: diaphragm_cone_height_m / diaphragm_thickness_m = %.17g must be < 2 sqrt(2) "
                      "(above, the diaphragm's valley force is negative: it snaps through)", fn, c[CV_H] / c[CV_T]);
        ok = 0;
    }
    if (!(c[CV_SINST] <= 2.0 * c[CV_H])) {
        if (m) cc_log(m, CC_ERROR, "%s: installed_deflection_m = %.17g must be <= 2 diaphragm_cone_height_m = %.17g m (past "
                      "that the diaphragm is turned inside out)", fn, c[CV_SINST], 2.0 * c[CV_H]);
        ok = 0;
    }
    if (!(c[CV_KE] * (2000.0 - c[CV_TREF]) < 1.0)) {
        if (m) cc_log(m, CC_ERROR, "%s: diaphragm_modulus_drop_per_K: E(theta) must stay > 0 up to 2000 K", fn);
        ok = 0;
    }
    if (ok && !(lever * (c[CV_RPP] - c[CV_RF]) < c[CV_RF])) {
        if (m) cc_log(m, CC_ERROR, "%s: lever_ratio = %.17g puts the bearing at r_b = r_f - i (r_pp - r_f) = %g m; "
                      "must be > 0", fn, lever, c[CV_RF] - lever * (c[CV_RPP] - c[CV_RF]));
        ok = 0;
    }
    if (ok && m) {
        CcCover cv;
        cc_cover_prepare(&cv, c, lever, r[VR_X_KISS_REF], &m->table);
        if (!(cc_cover_slope_bound(&cv) > 0.0)) {
            cc_log(m, CC_ERROR, "%s: release_compliance_m_per_N = %.17g: the release snaps through (x_to(s) not "
                   "monotone on the diaphragm's falling branch); reduce it", fn, c[CV_C]);
            ok = 0;
        }
    }
    return ok;
}

/* 1 if every parameter of a equals that of b (bit for bit) */
static int same_parameters(const double *a, const double *b) {
    int k;
    for (k = 0; k < CC_NVARS; ++k)
        if (is_parameter((unsigned int)k) && memcmp(&a[k], &b[k], sizeof a[k]) != 0) return 0;
    return 1;
}

/* every parameter problem is logged (prefix names the call); returns 1 if all are valid */
static int check_parameters(CcModel *m, const double *r, const char *fn) {
    int k, ok = 1;
    for (k = 0; k < CC_NVARS; ++k) {
        const double *g = CC_VARIABLES[k].range;
        if (is_parameter((unsigned int)k) && !range_ok(k, r[k])) {
            cc_log(m, CC_ERROR, "%s: parameter %s = %.17g is out of range %c%g, %g%c", fn, VAR_NAME(k), r[k],
                   g[2] ? '(' : '[', g[0], g[1], g[3] ? ')' : ']');
            ok = 0;
        }
    }
    if (range_ok(VR_N_SURFACES, r[VR_N_SURFACES]) && r[VR_N_SURFACES] != floor(r[VR_N_SURFACES])) {
        cc_log(m, CC_ERROR, "%s: parameter n_surfaces = %.17g must be a whole number in [1, 16]", fn, r[VR_N_SURFACES]);
        ok = 0;
    }
#if CC_THERMAL
    if (!cc_net_parameters_ok(m, r, fn)) ok = 0; /* the network's own rules (clutch_thermal.c) */
#endif
    if (ok && !cover_consistent(m, r, fn)) ok = 0;
    if (ok && !(r[VR_U] + r[VR_H] > 0.0)) {
        cc_log(m, CC_ERROR, "%s: U + H must be > 0 (the cushion spring needs a heat path)", fn);
        ok = 0;
    }
    if (ok && m->table_ok && !(m->held_valid && same_parameters(m->held, r))) {
        /* the diaphragm must hold the cushion at this wear at every temperature in range (about 1 ms: the
           parameters that passed are kept, so restoring states of the same instance does not repeat it) */
        CcCover cv;
        double fto = 0.0, t_cs = 0.0, t_cm = 0.0;
        cc_cover_prepare(&cv, cover_params(r), r[VR_LEVER_RATIO], r[VR_X_KISS_REF], &m->table);
        if (!cc_cover_holds(&cv, &m->table, r[VR_FACING_WEAR], THETA_MIN_K, THETA_MAX_K, &fto, &t_cs, &t_cm)) {
            double limit = cc_cover_wear_limit(&cv, &m->table, THETA_MIN_K, THETA_MAX_K);
            char where[120];
            if (limit >= 0.0) snprintf(where, sizeof where, "the wear limit of this cover is %.6g m", limit);
            else snprintf(where, sizeof where, "this cover cannot hold the cushion even with new facings");
            cc_log(m, CC_ERROR, "%s: parameter facing_wear = %.17g m: the diaphragm cannot hold the fully compressed "
                   "cushion (bearing force %.4g N < 0 at theta_cs = %g K, theta_cm = %g K); %s over theta in "
                   "[%g, %g] K", fn, r[VR_FACING_WEAR], fto, t_cs, t_cm, where, THETA_MIN_K, THETA_MAX_K);
            ok = 0;
        } else {
            memcpy(m->held, r, sizeof m->held);
            m->held_valid = 1;
        }
    }
    return ok;
}

static int inputs_ok(const double *r) {
    return r[VR_X_TO] >= X_TO_MIN && r[VR_X_TO] <= X_TO_MAX && r[VR_THETA_CM] >= THETA_MIN_K &&
           r[VR_THETA_CM] <= THETA_MAX_K && fabs(r[VR_OMEGA_SLIP]) <= OMEGA_SLIP_LIMIT; /* false for NaN */
}

/* every input outside its range (INPUT_RANGES), named with value, range and unit; a temperature below its
   range is said to be in kelvin */
static void log_inputs(CcModel *m, int status, double t, const char *what) {
    int k;
    for (k = 0; k < CC_NVARS; ++k) {
        const double *g = CC_VARIABLES[k].range;
        const char *unit = CC_VARIABLES[k].unit;
        double v = m->r[k];
        if (!is_input((unsigned int)k) || range_ok(k, v)) continue;
        if (!strcmp(unit, "K") && v < g[0])
            cc_log(m, status, "t = %g s: input %s = %.17g K is outside %c%g, %g%c K (the input is in kelvin: %.17g "
                   "degC would be %g K); %s", t, VAR_NAME(k), v, g[2] ? '(' : '[', g[0], g[1], g[3] ? ')' : ']', v,
                   v + KELVIN, what);
        else
            cc_log(m, status, "t = %g s: input %s = %.17g %s is not finite or outside %c%g, %g%c %s; %s", t, VAR_NAME(k),
                   v, unit, g[2] ? '(' : '[', g[0], g[1], g[3] ? ')' : ']', unit, what);
    }
}

/* the validity output (clutch_model.validity): 2 facings above their damage limit, 1 a temperature beyond the
   tables (cushion table for theta_cs, friction table for theta_cm), 0 inside */
static int validity(const CcModel *m) {
    const double *r = m->r;
    const Table *tb = &m->table;
    if (r[VR_THETA_CM] > r[VR_FACING_DAMAGE_TEMPERATURE_K]) return 2;
    if (!(tb->theta[0] + KELVIN <= r[VR_THETA_CS] && r[VR_THETA_CS] <= tb->theta[tb->nt - 1] + KELVIN)) return 1;
    if (tb->f_mu && !(tb->f_theta[0] + KELVIN <= r[VR_THETA_CM] && r[VR_THETA_CM] <= tb->f_theta[tb->ntf - 1] + KELVIN))
        return 1;
    return 0;
}

/* -------------------------------------------------------------------- model */
static double facing_wear(const CcModel *m) { return m->r[VR_FACING_WEAR]; }

/* outputs of the current inputs and state; CC_DISCARD (logged) if the diaphragm cannot hold the cushion.
   The cover's solve starts from the last answer (m->warm) when the bearing moved by at most CC_WARM_DX: the answer
   passes the same residual test as a cold solve, so it agrees with it to that residual, not bit for bit (the
   outputs depend on the inputs and the saved state, which holds the warm start) */
static int update_outputs(CcModel *m) {
    double *r = m->r;
    const Table *tb = &m->table;
    CcCoverState st;
    int status;
    double mu = tb->f_mu ? cc_table_mu(tb, r[VR_THETA_CM] - KELVIN, r[VR_OMEGA_SLIP]) : r[VR_MU];
    double g = r[VR_U] + r[VR_H];
    if (!m->cover_ok) {
        cc_cover_prepare(&m->cover, cover_params(r), r[VR_LEVER_RATIO], r[VR_X_KISS_REF], tb);
        m->cover_ok = 1;
    }
    r[CC_VR_DER_THETA_CS] = (r[VR_U] * r[VR_THETA_CM] + r[VR_H] * r[VR_THETA_A] - g * r[VR_THETA_CS]) / r[VR_C];
    /* warm start: the last answer moved along its tangent (in a launch 1.9 instead of 3.0 evaluations per step) */
    status = cc_cover_solve(&m->cover, tb, r[VR_X_TO], r[VR_THETA_CS], r[VR_THETA_CM], facing_wear(m), &m->warm, &st);
    if (status != 0) {
        cc_log(m, CC_DISCARD, "t = %g s: the diaphragm cannot hold the cushion at theta_cs = %g K, theta_cm = %g K, "
               "facing_wear = %g m (bearing force %g N < 0); outputs not updated", m->time, r[VR_THETA_CS],
               r[VR_THETA_CM], facing_wear(m), st.bearing);
        return CC_DISCARD;
    }
    r[VR_TORQUE] = r[VR_N_SURFACES] * mu * r[VR_R_EQ] * st.clamp;
    r[VR_FORCE] = st.cushion;
    r[VR_U_F] = st.u > 0.0 ? st.u : 0.0;
    r[VR_X_KISS] = st.x_kiss;
    r[VR_CLAMP_FORCE] = st.clamp;
    r[VR_BEARING_FORCE] = st.bearing;
#if CC_THERMAL
    if (cc_net_outputs(m) != CC_OK) return CC_DISCARD; /* slip_power, the nodes' derivatives (clutch_thermal.c) */
#endif
    m->dirty = 0;
    {
        int v = validity(m);
        r[VR_VALIDITY] = v;
        if (v != m->range_warned && v == 2)
            cc_log(m, CC_WARNING, "facing temperature theta_cm = %.2f K is above facing_damage_temperature_K = %.2f K: "
                   "the facings are being damaged; the model keeps answering with clamped tables (validity = 2)",
                   r[VR_THETA_CM], r[VR_FACING_DAMAGE_TEMPERATURE_K]);
        else if (v != m->range_warned && v == 1)
            cc_log(m, CC_WARNING, "temperature beyond the tables: theta_cs = %.2f K (table [%.2f, %.2f] K), "
                   "theta_cm = %.2f K; F, the kiss shift and mu are clamped to the nearest table temperature "
                   "(validity = 1; warned once per entry)", r[VR_THETA_CS], tb->theta[0] + KELVIN,
                   tb->theta[tb->nt - 1] + KELVIN, r[VR_THETA_CM]);
        m->range_warned = v;
    }
    return CC_OK;
}

/* outputs of the current inputs and state (in Initialization Mode: theta_cs = theta_cs_start).
   Invalid inputs: the outputs keep their last values and CC_DISCARD is returned (logged) */
static int refresh(CcModel *m, const char *fn) {
    if (!m->dirty) return CC_OK;
    if (!inputs_ok(m->r)) {
        char what[200];
        snprintf(what, sizeof what, "%s: outputs not updated", fn);
        log_inputs(m, CC_DISCARD, m->time, what);
        return CC_DISCARD;
    }
    if (m->phase == PH_INIT) {
        int k;
        for (k = 0; k < CC_NVARS; ++k)
            if (is_parameter((unsigned int)k) && !range_ok(k, m->r[k])) return CC_OK; /* reported at ExitInit */
        if (!cover_consistent(NULL, m->r, fn)) return CC_OK;
        m->r[VR_THETA_CS] = m->r[VR_THETA_CS_START];
    } else if (!(m->phase & (PH_STEP | PH_EVENT | PH_CONT | PH_TERMINATED))) {
        return CC_OK;
    }
    return update_outputs(m);
}

#if defined(__GNUC__)
__attribute__((noinline))
#endif
static int set_real_checked(CcModel *m, const unsigned int vr[], size_t n, const double v[], const char *fn);

int cc_set_real(CcModel *m, const unsigned int vr[], size_t n, const double v[], const char *fn) {
#if !CC_THERMAL
    /* the step's usual call: inputs only, in a phase that allows setting them (what the checks of set_real_checked
       allow; anything else goes there) */
    if ((m->phase & (PH_INSTANTIATED | PH_INIT | PH_STEP | PH_EVENT | PH_CONT)) && n && vr && v) {
        size_t k;
        if (n == 2 && vr[0] == VR_X_TO && vr[1] == VR_THETA_CM) { /* the usual pair, as the loop below does it */
            m->r[VR_X_TO] = v[0];
            m->r[VR_THETA_CM] = v[1];
            m->dirty = 1;
            return CC_OK;
        }
        for (k = 0; k < n && vr[k] < CC_NVARS && CC_VARIABLES[vr[k]].causality == CC_INPUT; ++k) {}
        if (k == n) {
            for (k = 0; k < n; ++k) m->r[vr[k]] = v[k];
            m->dirty = 1;
            return CC_OK;
        }
    }
#endif
    return set_real_checked(m, vr, n, v, fn);
}

static int set_real_checked(CcModel *m, const unsigned int vr[], size_t n, const double v[], const char *fn) {
    size_t k;
    int after_init = (m->phase & (PH_STEP | PH_EVENT | PH_CONT)) != 0;
    if (!cc_allowed(m, PH_INSTANTIATED | PH_INIT | PH_STEP | PH_EVENT | PH_CONT, fn)) return CC_ERROR;
    if (n && (!vr || !v)) { cc_log(m, CC_ERROR, "%s: NULL value reference or value array", fn); return CC_ERROR; }
    for (k = 0; k < n; ++k) { /* validate all first: a refused call changes nothing */
        if (vr[k] >= CC_NVARS) {
            cc_log(m, CC_ERROR, "%s: unknown value reference %u", fn, vr[k]);
            return CC_ERROR;
        }
        if (!is_input(vr[k]) && !is_parameter(vr[k])) {
            cc_log(m, CC_ERROR, "%s: %s (value reference %u) is not an input or parameter and cannot be set", fn,
                   VAR_NAME(vr[k]), vr[k]);
            return CC_ERROR;
        }
        if (is_parameter(vr[k]) && after_init) {
            cc_log(m, CC_ERROR, "%s: parameter %s is fixed after initialization", fn, VAR_NAME(vr[k]));
            return CC_ERROR;
        }
    }
    for (k = 0; k < n; ++k) {
        m->r[vr[k]] = v[k];
        if (is_parameter(vr[k])) { m->cover_ok = 0; m->warm.x = m->decay_h = NAN; }
    }
#if CC_THERMAL
    if (!after_init) cc_net_start(m->r); /* the nodes at theta_network_start until initialisation ends */
#endif
    if (n) m->dirty = 1;
    return CC_OK;
}

#if defined(__GNUC__)
__attribute__((noinline))
#endif
static int get_real_checked(CcModel *m, const unsigned int vr[], size_t n, double v[], const char *fn);

int cc_get_real(CcModel *m, const unsigned int vr[], size_t n, double v[], const char *fn) {
    if ((m->phase & (PH_ANY & ~PH_INSTANTIATED)) && !m->dirty && vr && v) {
        /* the usual call after a step: every reference known, outputs up to date (what the checks below allow) */
        size_t k;
        for (k = 0; k < n && vr[k] < CC_NVARS; ++k) v[k] = m->r[vr[k]];
        if (k == n) return CC_OK;
    }
    return get_real_checked(m, vr, n, v, fn);
}

static int get_real_checked(CcModel *m, const unsigned int vr[], size_t n, double v[], const char *fn) {
    size_t k;
    if (!cc_allowed(m, PH_ANY & ~PH_INSTANTIATED, fn)) return CC_ERROR;
    if (n && (!vr || !v)) { cc_log(m, CC_ERROR, "%s: NULL value reference or value array", fn); return CC_ERROR; }
    for (k = 0; k < n; ++k)
        if (vr[k] >= CC_NVARS) {
            cc_log(m, CC_ERROR, "%s: unknown value reference %u", fn, vr[k]);
            return CC_ERROR;
        }
    if (m->dirty && refresh(m, fn) != CC_OK) {
        /* outputs of invalid inputs (or of a state the cover cannot hold) are refused, in Co-Simulation as in Model
           Exchange (docs/reference/statuses.md): Discard, the values are the last ones computed; the states
           (theta_cs, the thermal variant's nodes and theta_cm) and the parameters read OK */
        int status = CC_OK;
        for (k = 0; k < n; ++k) {
            v[k] = m->r[vr[k]];
            if ((CC_VARIABLES[vr[k]].causality == CC_OUTPUT && vr[k] != VR_THETA_CS
#if CC_THERMAL
                 && !cc_net_state_output(vr[k]) /* the nodes and their facing mean are states too */
#endif
                 ) || vr[k] == CC_VR_DER_THETA_CS)
                status = CC_DISCARD;
        }
        return status;
    }
    for (k = 0; k < n; ++k) v[k] = m->r[vr[k]];
    return CC_OK;
}

int cc_enter_init(CcModel *m, double start_time, const char *fn) {
    if (!cc_allowed(m, PH_INSTANTIATED, fn)) return CC_ERROR;
    if (!m->table_ok) {
        cc_log(m, CC_ERROR, "%s: cannot load the F(u, theta) tables: %s", fn, m->table_error);
        return CC_ERROR;
    }
    m->time = start_time;
    m->phase = PH_INIT;
    return CC_OK;
}

int cc_exit_init(CcModel *m, const char *fn) {
    if (!cc_allowed(m, PH_INIT, fn)) return CC_ERROR;
    if (!check_parameters(m, m->r, fn)) {
        m->r[VR_TORQUE] = m->r[VR_FORCE] = m->r[VR_U_F] = m->r[VR_CLAMP_FORCE] = m->r[VR_BEARING_FORCE] = 0.0;
        m->r[VR_VALIDITY] = 0.0;
        m->phase = PH_ERROR;
        return CC_ERROR;
    }
    m->r[VR_THETA_CS] = m->r[VR_THETA_CS_START];
    m->phase = m->me ? PH_EVENT : PH_STEP;
    m->dirty = 1;
    m->cover_ok = 0;
    m->warm.x = NAN;
    if (inputs_ok(m->r)) update_outputs(m);
    return CC_OK;
}

#if CC_THERMAL
/* the model's state before a thermal step: a refused step restores it (theta_cs, every node and so theta_cm, the
   time, the cover's warm start, the validity last warned); the outputs and derivatives, computed from it, are
   recomputed at the next read */
typedef struct {
    double theta_cs, time;
    double nodes[CC_NSTATES - 1];
    CcWarm warm;
    int range_warned;
} CcStepStart;

static void step_start_save(CcModel *m, CcStepStart *s) {
    s->theta_cs = m->r[VR_THETA_CS];
    s->time = m->time;
    cc_net_get_states(m, s->nodes);
    s->warm = m->warm;
    s->range_warned = m->range_warned;
}

static int step_refused(CcModel *m, const CcStepStart *s) {
    m->r[VR_THETA_CS] = s->theta_cs;
    m->time = s->time;
    cc_net_set_states(m, s->nodes); /* the nodes and theta_cm; dirty: outputs and derivatives at the next read */
    m->warm = s->warm;
    m->range_warned = s->range_warned;
    cc_net_restore(m);
    return CC_DISCARD;
}
#endif

int cc_do_step(CcModel *m, double t, double h, const char *fn) {
    double g, theta_inf, theta_old, *r = m->r;
    int status = CC_OK;
#if CC_THERMAL
    CcStepStart start;
#endif
    if (!cc_allowed(m, PH_STEP, fn)) return CC_ERROR;
    if (!(h >= 0.0 && h <= DBL_MAX && fabs(t) <= DBL_MAX)) { /* finite, h >= 0 (false for NaN): three compares */
        cc_log(m, CC_DISCARD, "%s: t = %g s: step size %.17g s must be finite and >= 0; step refused", fn, t, h);
        return CC_DISCARD;
    }
    if (!inputs_ok(r)) {
        log_inputs(m, CC_DISCARD, t, "step refused");
        return CC_DISCARD;
    }
#if CC_THERMAL
    if (!cc_net_begin_step(m, t, "step refused")) return CC_DISCARD;
    step_start_save(m, &start);
#endif
    if (fabs(t - m->time) > 1e-9 * (1.0 + fabs(t))) {
        cc_log(m, CC_WARNING, "%s: currentCommunicationPoint = %.17g s does not follow the previous step "
               "(expected %.17g s); accepted", fn, t, m->time);
        status = CC_WARNING;
    }
    g = r[VR_U] + r[VR_H];
    theta_inf = (r[VR_U] * r[VR_THETA_CM] + r[VR_H] * r[VR_THETA_A]) / g;
    theta_old = r[VR_THETA_CS];
    if (!(h == m->decay_h)) { /* exp(-h g / C), kept with its step (parameters change: decay_h NaN) */
        m->decay_h = h;
        m->decay = exp(-h * g / r[VR_C]);
    }
    {
        r[VR_THETA_CS] = theta_inf + (r[VR_THETA_CS] - theta_inf) * m->decay;
    }
    if (update_outputs(m) != CC_OK) { /* a discarded step leaves state and time where they were */
#if CC_THERMAL
        return step_refused(m, &start);
#else
        r[VR_THETA_CS] = theta_old;
        r[CC_VR_DER_THETA_CS] = (r[VR_U] * r[VR_THETA_CM] + r[VR_H] * r[VR_THETA_A] - g * theta_old) / r[VR_C];
        return CC_DISCARD;
#endif
    }
#if CC_THERMAL
    /* the launch plant's order: the torque just computed (new theta_cs, held theta_cm) heats the network, then
       the outputs at the step's end (clutch_thermal.c); a refused network step rolls everything back */
    (void)theta_old;
    m->time = t;
    if (cc_net_step(m, h, fn, update_outputs) != CC_OK) return step_refused(m, &start);
#endif
    m->time = t + h;
    return status;
}

int cc_derivative(CcModel *m, double *der, const char *fn) {
    const double *r = m->r;
    double theta;
    if (!cc_allowed(m, PH_INIT | PH_EVENT | PH_CONT | PH_TERMINATED | PH_ERROR, fn)) return CC_ERROR;
    if (!inputs_ok(r)) {
        char what[200];
        snprintf(what, sizeof what, "%s: no derivative", fn);
        log_inputs(m, CC_DISCARD, m->time, what);
        return CC_DISCARD;
    }
    theta = m->phase == PH_INIT ? r[VR_THETA_CS_START] : r[VR_THETA_CS];
#if CC_THERMAL
    {   /* the slip power needs the torque: the outputs of the current states and inputs */
        int status = m->dirty ? refresh(m, fn) : CC_OK;
        if (status != CC_OK) return status;
        theta = r[VR_THETA_CS];
        cc_net_get_derivatives(m, der + 1);
    }
#endif
    *der = (r[VR_U] * r[VR_THETA_CM] + r[VR_H] * r[VR_THETA_A] - (r[VR_U] + r[VR_H]) * theta) / r[VR_C];
    return CC_OK;
}

int cc_set_time(CcModel *m, double t, const char *fn) {
    if (!cc_allowed(m, PH_EVENT | PH_CONT, fn)) return CC_ERROR;
    if (!isfinite(t)) {
        cc_log(m, CC_ERROR, "%s: time = %.17g s is not finite; refused", fn, t);
        return CC_ERROR;
    }
    m->time = t;
    return CC_OK;
}

int cc_set_state_value(CcModel *m, double theta_cs, const char *fn) {
    if (!cc_allowed(m, PH_CONT, fn)) return CC_ERROR;
    if (!(theta_cs >= THETA_MIN_K && theta_cs <= THETA_MAX_K)) {
        cc_log(m, CC_ERROR, "%s: theta_cs = %.17g K is not finite or outside [%g, %g] K", fn, theta_cs, THETA_MIN_K,
               THETA_MAX_K);
        return CC_ERROR;
    }
    m->r[VR_THETA_CS] = theta_cs;
    m->dirty = 1;
    return CC_OK;
}

int cc_get_state_value(CcModel *m, double *theta_cs, const char *fn) {
    if (!cc_allowed(m, PH_INIT | PH_EVENT | PH_CONT | PH_TERMINATED | PH_ERROR, fn)) return CC_ERROR;
    *theta_cs = m->phase == PH_INIT ? m->r[VR_THETA_CS_START] : m->r[VR_THETA_CS];
    return CC_OK;
}

int cc_set_states(CcModel *m, const double *x, const char *fn) {
    int status;
#if CC_THERMAL
    if (!cc_allowed(m, PH_CONT, fn)) return CC_ERROR;
    if (!cc_net_states_ok(m, x + 1, CC_DISCARD, fn, "states not set")) return CC_DISCARD; /* as a refused CS step */
#endif
    status = cc_set_state_value(m, x[0], fn);
#if CC_THERMAL
    if (status == CC_OK) cc_net_set_states(m, x + 1);
#endif
    return status;
}

int cc_get_states(CcModel *m, double *x, const char *fn) {
    int status = cc_get_state_value(m, x, fn);
#if CC_THERMAL
    if (status == CC_OK) cc_net_get_states(m, x + 1);
#endif
    return status;
}

/* -------------------------------------------------------------- saved state */
static uint64_t fnv1a(const void *data, size_t n) {
    const unsigned char *p = (const unsigned char *)data;
    uint64_t h = 1469598103934665603ull;
    size_t k;
    for (k = 0; k < n; ++k) { h ^= p[k]; h *= 1099511628211ull; }
    return h;
}

void cc_state_save(const CcModel *m, CcState *s) {
    memset(s, 0, sizeof *s);
    s->magic = CC_STATE_MAGIC;
    s->version = CC_STATE_VERSION;
    s->size = (uint32_t)sizeof *s;
    s->phase = m->phase;
    s->me = m->me;
    s->range_warned = m->range_warned;
    s->terminated = m->terminated;
    s->time = m->time;
    memcpy(s->r, m->r, sizeof s->r);
    s->warm = m->warm;
    s->checksum = fnv1a(s, offsetof(CcState, checksum));
}

/* 1 if bytes hold a valid state for this instance; otherwise logs why and returns 0 */
int cc_state_check(CcModel *m, const void *bytes, size_t size, const char *fn) {
    CcState s;
    int k, valid_phases = m->me ? (PH_ANY & ~PH_STEP) : (PH_ANY & ~PH_CONT);
    if (!bytes || size != sizeof s) {
        cc_log(m, CC_ERROR, "%s: not a CushionClutch state (%lu bytes, expected %lu)", fn, (unsigned long)size,
               (unsigned long)sizeof s);
        return 0;
    }
    memcpy(&s, bytes, sizeof s);
    if (s.magic != CC_STATE_MAGIC || s.version != CC_STATE_VERSION || s.size != sizeof s) {
        cc_log(m, CC_ERROR, "%s: not a CushionClutch state of version %u", fn, CC_STATE_VERSION);
        return 0;
    }
    if (s.checksum != fnv1a(&s, offsetof(CcState, checksum))) {
        cc_log(m, CC_ERROR, "%s: the state's checksum does not match: corrupted", fn);
        return 0;
    }
    if (s.me != m->me || (s.phase & valid_phases) == 0 || (s.phase & (s.phase - 1)) != 0) {
        cc_log(m, CC_ERROR, "%s: the state's phase %d is not valid for this %s instance", fn, s.phase,
               m->me ? "Model Exchange" : "Co-Simulation");
        return 0;
    }
    for (k = 0; k < CC_NVARS; ++k)
        if (!isfinite(s.r[k])) {
            cc_log(m, CC_ERROR, "%s: the state's %s = %.17g is not finite", fn, VAR_NAME(k), s.r[k]);
            return 0;
        }
    if (!isfinite(s.time) || !(s.r[VR_THETA_CS] >= THETA_MIN_K && s.r[VR_THETA_CS] <= THETA_MAX_K) ||
        !(s.range_warned >= 0 && s.range_warned <= 2) || !(s.terminated == 0 || s.terminated == 1) ||
        !(isnan(s.warm.x) || isfinite(s.warm.x)) || !isfinite(s.warm.s) || !isfinite(s.warm.slope) ||
        !(isnan(s.warm.r) || isfinite(s.warm.r)) || !(isnan(s.warm.s1) || isfinite(s.warm.s1)) ||
        !(isnan(s.warm.s2) || isfinite(s.warm.s2))) {
        cc_log(m, CC_ERROR, "%s: the state's time, theta_cs, flags or warm start are out of range", fn);
        return 0;
    }
    if (s.phase != PH_INSTANTIATED && s.phase != PH_INIT && s.phase != PH_ERROR && !check_parameters(m, s.r, fn))
        return 0;
#if CC_THERMAL
    if (s.phase != PH_INSTANTIATED && s.phase != PH_INIT && s.phase != PH_ERROR && !cc_net_saved_ok(m, s.r, fn))
        return 0; /* the nodes in their declared ranges, as every step and ME state */
#endif
    return 1;
}

void cc_state_load(CcModel *m, const CcState *s) {
    memcpy(m->r, s->r, sizeof m->r);
    m->phase = s->phase;
    m->range_warned = s->range_warned;
    m->terminated = s->terminated;
    m->time = s->time;
    m->warm = s->warm;
    m->decay_h = NAN;
    m->dirty = 1;
    m->cover_ok = 0;
#if CC_THERMAL
    if (m->phase != PH_INSTANTIATED && m->phase != PH_INIT && m->phase != PH_ERROR) cc_net_restore(m);
#endif
}
