/*
 * CushionClutch model core: the temperature-aware dry-clutch model written once, shared by the
 * thin FMI 2.0 (fmi2_frontend.c) and FMI 3.0 (fmi3_frontend.c) front ends.
 *
 *   theta_cs: C dtheta/dt = U (theta_cm - theta) + H (theta_a - theta)        (paper eq. 3)
 *             Co-Simulation: exact solution for theta_cm held over the step;
 *             Model Exchange: theta_cs is the continuous state, der(theta_cs) from the ODE;
 *   x_kiss  = x_kiss_ref - lever_ratio * delta_kiss(theta_cs);
 *   u       = (x_to - x_kiss) / lever_ratio,  u_f = max(u, 0);
 *   F       = PCHIP in u per table temperature, linear in theta, clamped;
 *   torque  = n_surfaces * mu * R_eq * F  (mu: parameter, or friction.csv mu(theta_cm, |omega_slip|)).
 *
 * Value references follow cushion_clutch.fmu_src.clutch_model.VARIABLES; CC_VR_DER_THETA_CS is the
 * state derivative (both FMI versions), CC_VR_TIME the independent variable (FMI 3 only).
 * No global state: any number of instances, in any number of threads (one instance per thread).
 */
#ifndef CLUTCH_CORE_H
#define CLUTCH_CORE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "resource_uri.h"

enum {
    VR_X_TO, VR_THETA_CM, VR_TORQUE, VR_FORCE, VR_THETA_CS, VR_U_F, VR_X_KISS,
    VR_N_SURFACES, VR_MU, VR_R_EQ, VR_U, VR_H, VR_C, VR_THETA_A, VR_THETA_CS_START,
    VR_X_KISS_REF, VR_LEVER_RATIO, VR_OMEGA_SLIP, CC_VR_DER_THETA_CS, CC_NVARS
};
#define CC_VR_TIME CC_NVARS

/* statuses: the same numbers as fmi2Status and fmi3Status */
enum { CC_OK = 0, CC_WARNING = 1, CC_DISCARD = 2, CC_ERROR = 3, CC_FATAL = 4 };

/* phases of the FMI state machines (bit mask, so a call can list where it is allowed) */
enum {
    PH_INSTANTIATED = 1, PH_INIT = 2, PH_STEP = 4, PH_EVENT = 8, PH_CONT = 16,
    PH_TERMINATED = 32, PH_ERROR = 64
};
#define PH_ANY (PH_INSTANTIATED | PH_INIT | PH_STEP | PH_EVENT | PH_CONT | PH_TERMINATED | PH_ERROR)

typedef struct {
    int n;
    double *x, *y, *d;
} Curve;

typedef struct {
    int nt;
    double *theta; /* degC, increasing */
    double *delta; /* m */
    Curve *curves;
    /* optional friction table mu(theta_cm degC, |omega_slip| rad/s), row-major [ntf][nw] */
    int ntf, nw;
    double *f_theta, *f_omega, *f_mu;
} Table;

/* cover parameters, in the order of cover.CoverParameters' fields (cushion_clutch/model/cover.py) */
enum {
    CV_A, CV_B, CV_T, CV_H, CV_E, CV_KE, CV_NU, CV_RPP, CV_RF, CV_SINST, CV_C, CV_TF, CV_AF, CV_TPP, CV_APP,
    CV_LFW, CV_AFW, CV_TREF, CV_NPAR
};

/* the cover's force balance, prepared once per parameter set (clutch_cover.c) */
typedef struct {
    double p[CV_NPAR];
    double e, L_pp, L_b, kb, kp, fal; /* arms (m), bearing/pp travel per unit s, F_AL factor without E */
    double u_full_ref;                /* cushion full compression at the reference temperature, m */
    double xc;                        /* bearing-system constant X_c, m */
    double s_last, x_last;            /* warm start of the Newton iteration: last s and x_to, m (NaN: none) */
    int hint[2], hint_k[2];           /* last table intervals (Newton; kiss and solid points) */
    /* the frame of the last (theta_cs K, theta_cm K, wear m): bracket, E, positions and forces */
    double f_theta_cs, f_theta_cm, f_wear, f_e, f_w;
    const Curve *f_c0, *f_c1;
    double s_kiss, s_solid, fc_solid, m_solid, fto_solid, fto_kiss, x_solid, x_kiss;
} CcCover;

typedef struct {
    double clamp, bearing, cushion; /* F_pp, F_to, F_c, N */
    double u, s;                    /* cushion compression from its kiss point, diaphragm deflection, m */
    double x_kiss, x_solid, x_lift; /* bearing positions, m */
} CcCoverState;

/* message sink of a front end: status, category, the finished message (never a format) */
typedef void (*CcLogger)(void *ctx, int status, const char *category, const char *message);

typedef struct {
    double r[CC_NVARS];
    double time;
    int phase;
    int me;           /* 1: Model Exchange instance, 0: Co-Simulation */
    int dirty;        /* outputs and derivative need recomputing */
    int range_warned;
    int terminated;   /* CS: the last step was refused (fmi2Terminated / terminateSimulation) */
    int logging_on;
    Table table;
    CcCover cover;
    int cover_ok;     /* cover prepared from the current parameters */
    int table_ok;
    char table_error[600];
    CcLogger logger;
    void *log_ctx;
} CcModel;

/* the serialized (and saved) FMU state: versioned, checksummed, validated before use */
#define CC_STATE_MAGIC 0x43434653u /* "CCFS" */
#define CC_STATE_VERSION 2u
typedef struct {
    uint32_t magic, version, size;
    int32_t phase, me, range_warned, terminated, reserved;
    double time;
    double r[CC_NVARS];
    uint64_t checksum; /* FNV-1a 64 of every byte before it */
} CcState;

/* ---- tables and resources (clutch_tables.c) */
int cc_table_load(Table *tb, const char *dir, char *err, size_t errlen);
void cc_table_free(Table *tb);
double cc_table_force(const Table *tb, double u, double theta_degC);
double cc_table_delta(const Table *tb, double theta_degC);
double cc_table_mu(const Table *tb, double theta_degC, double omega);
double cc_table_full(const Table *tb, double theta_degC);
/* table temperatures i and i+1 around theta with weight w of i+1 (clamped: w = 0 or 1) */
void cc_table_bracket(const Table *tb, double theta_degC, int *i, double *w);

/* ---- cover (clutch_cover.c) */
void cc_cover_prepare(CcCover *cv, const double *par, double lever_ratio, double x_kiss_ref, const Table *tb);
double cc_cover_slope_bound(const CcCover *cv);
/* 0, or -1 if the diaphragm cannot hold the cushion (bearing force < 0); out is filled either way */
int cc_cover_state(CcCover *cv, const Table *tb, double x_to, double theta_cs, double theta_cm, double wear,
                   CcCoverState *out);

/* ---- model (clutch_core.c) */
int cc_instantiate(CcModel *m, const char *resource_dir, int me, CcLogger logger, void *ctx, int logging_on);
void cc_free(CcModel *m);
void cc_reset(CcModel *m);
void cc_log(CcModel *m, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
int cc_allowed(CcModel *m, int mask, const char *fn);
int cc_set_real(CcModel *m, const unsigned int vr[], size_t n, const double v[], const char *fn);
int cc_get_real(CcModel *m, const unsigned int vr[], size_t n, double v[], const char *fn);
int cc_enter_init(CcModel *m, double start_time, const char *fn);
int cc_exit_init(CcModel *m, const char *fn);
int cc_do_step(CcModel *m, double t, double h, const char *fn);
int cc_derivative(CcModel *m, double *der, const char *fn);
/* ME SetTime: refuses a non-finite time */
int cc_set_time(CcModel *m, double t, const char *fn);
int cc_set_state_value(CcModel *m, double theta_cs, const char *fn);
/* the continuous state theta_cs, K (its start value during initialisation) */
int cc_get_state_value(CcModel *m, double *theta_cs, const char *fn);
void cc_state_save(const CcModel *m, CcState *s);
int cc_state_check(CcModel *m, const void *bytes, size_t size, const char *fn);
void cc_state_load(CcModel *m, const CcState *s);

#endif
