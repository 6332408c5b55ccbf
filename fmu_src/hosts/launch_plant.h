/* The launch simulation's plant steps between two TCU cycles, compiled (cushion_clutch/launch/plant_block.py).
 * This header is also the cffi declaration (plain C declarations, no macros; cushion_clutch.fmu.hostlib inlines
 * its one include, the network's node, and drops the include and guard lines).
 * Units SI: rad/s, m/s, N.m, J, W, K, m, s. */

typedef int (*lp_set_real)(void *c, const unsigned int vr[], size_t nvr, const double value[]);
typedef int (*lp_get_real)(void *c, const unsigned int vr[], size_t nvr, double value[]);
typedef int (*lp_do_step)(void *c, double t, double h, int no_set_prior);

#include "thermal_step.h" /* TnNode: one node of the plant's thermal network for one clamp state */

/* constants of a run */
typedef struct {
    /* the clutch FMU (FMI 2 co-simulation, loaded by fmpy): component, functions, value references */
    void *comp;
    lp_set_real set_real;
    lp_do_step do_step;
    lp_get_real get_real;
    unsigned int vr_in[3];          /* x_to, theta_cm, omega_slip */
    unsigned int vr_out[4];         /* torque, theta_cs, x_kiss, clamp_force */
    /* engine (engine.EngineGovernor) */
    int n_curve;
    double curve_w[32];
    double curve_t[32];
    double drag, kp, ki, w_idle, w_stall, w_max;
    /* driveline (driveline.Driveline) */
    double i_tot, r, eta, f_grade, f_roll, j_v, j_e, j_disc, k, c, kappa, air, brake_torque;
    /* loop (simulate.simulate_launches) and metrics (metrics.LaunchRecord.step) */
    double h, act, w_lift, prefill, alpha_jerk, creep_nm;
    int tcu_every, net_every;
    /* the plant's thermal network (model.thermal_network.ThermalNetwork), nodes per clamp state (0 open, 1 clamped) */
    int net_n_nodes;
    int net_cm[2];                  /* the two facing nodes: theta_cm is their mean */
    int net_surface[2];             /* the two metal friction surfaces: the series' theta_surface is the hotter */
    double net_h0, net_hr, net_wr, net_ta; /* still air, rotating W/(m2 K), its reference speed rad/s, air K */
    double net_dt[2];               /* the step the fixed nodes' decay factors are for, per clamp state, s */
    TnNode net[2][16];              /* the nodes per clamp state (decay: at the step net_dt of its clamp state) */
    /* mu at the friction surface (simulate.py, issue 37): with mu_surface != 0 the torque is
     * n_surfaces mu(theta_fs, |omega_slip|) r_eq clamp_force, mu from this table (model.friction.FrictionTable:
     * bilinear, clamped; f_mu row-major, f_nt temperatures degC x f_nw slip speeds rad/s) */
    int mu_surface, f_nt, f_nw;
    double n_surfaces, r_eq;
    double f_theta[16], f_omega[16], f_mu[256];
} lp_consts;

/* The state carried across calls, doubles only (flags 0/1, counts exact), so that it is also a double[] the
 * caller fills and reads at once. It lives in C over a run: the caller reads the head after every call and
 * the rest at a launch slot's end and the run's end. */
typedef struct {
    /* the head: after the last call's last step */
    double steps;                   /* the last call's steps */
    double n_events;                /* its lock/unlock events (0: the steps' event fields are all 0) */
    double w_e, w_d, v, phi, locked, t_e, x_act, theta_cm, t_cap, theta_cs, x_kiss, stalled, has_lock, lock_time;
    double throttle, theta_cm_step; /* the engine's throttle, the facing temperature the FMU saw in the step */
    double theta_surface, theta_last; /* the network: the hotter friction surface, the last node (quiet periods) */
    /* driveline */
    double engine_work, potential, slip, damping, resistance, brake;
    double t_c, slip_J, slip_W;
    /* engine */
    double integral;
    /* loop */
    double held0, held1, held2;     /* the FMU inputs last set: x_to, theta_cm, omega_slip */
    double lifted, net_n, net_e;
    /* the launch record */
    double rec_stall, rec_slip_J, a_filt, jerk, sq_err, max_err, sum_creep, n_err, n_creep;
    /* the thermal network's node temperatures, K */
    double theta[16];
    double theta_fs;                /* the friction-surface temperature, K: the two metal surfaces' mean */
    double clamp;                   /* the clutch FMU's clamp_force of the last step, N */
} lp_state;

/* held over a block: set by the TCU cycle before it */
typedef struct {
    double k0, n_steps;             /* the first step's index, the run's steps */
    double next_switch, slot_start, slot_end;
    double countdown;               /* steps to the next TCU cycle, as the loop counts (0: the block's first step is one) */
    double x_cmd, pedal_level, t_dem, t_rate;
    double engaged, braking, launching;
} lp_block;

/* one step's figures (the series' row, the metrics' inputs) */
typedef struct {
    double w_e, w_d, v, accel, x_act, t_dem, t_cap, t_c, theta_cm_step, theta_cs, x_kiss, throttle, locked, t_shaft;
    double theta_surface, theta_last; /* the network after the step: the hotter friction surface, the last node */
    double event;                   /* 1 locked (at t + h), -1 unlocked in the step (at t), -2 unlocked as the TCU let go (at t + h) */
} lp_step_out;

/* Run steps from blk->k0 until (exclusive) the next TCU cycle, the slot switch or the run's end; at most
 * max_steps. The thermal network steps every net_every steps. out: the steps' figures, accel: their
 * accelerations (m/s2) once more, contiguous. Returns the number of steps done (>= 1 unless an error), or -1,
 * -2, -3 if fmi2SetReal, fmi2DoStep, fmi2GetReal failed (its status in *fmi_status). */
int lp_run_block(lp_consts *c, lp_state *s, const lp_block *blk, lp_step_out *out, double *accel, int max_steps,
                 int *fmi_status);
/* One quiet TCU period (simulate.py: the car stands braked, the clutch open and retracted) of tcu_every steps
 * as one step of h_quiet = tcu_every h from t: the actuator's decay act_quiet, the clutch FMU, the idle engine,
 * the network; the period's figures are in the state's head. Returns 0, -1..-3 as lp_run_block, or -4 if the
 * FMU returned a torque (s->t_cap) with the bearing retracted. */
int lp_run_quiet(lp_consts *c, lp_state *s, double t, double h_quiet, double act_quiet, int *fmi_status);
