/* The launch simulation's plant steps between two TCU cycles, compiled (cushion_clutch/launch/plant_block.py).
 * This header is also the cffi declaration (plain C declarations only: no macros, no includes).
 * Units SI: rad/s, m/s, N.m, J, W, K, m, s. */

typedef int (*lp_set_real)(void *c, const unsigned int vr[], size_t nvr, const double value[]);
typedef int (*lp_get_real)(void *c, const unsigned int vr[], size_t nvr, double value[]);
typedef int (*lp_do_step)(void *c, double t, double h, int no_set_prior);

/* constants of a run */
typedef struct {
    /* the clutch FMU (FMI 2 co-simulation, loaded by fmpy): component, functions, value references */
    void *comp;
    lp_set_real set_real;
    lp_do_step do_step;
    lp_get_real get_real;
    unsigned int vr_in[3];          /* x_to, theta_cm, omega_slip */
    unsigned int vr_out[3];         /* torque, theta_cs, x_kiss */
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
} lp_consts;

/* The state carried across steps (copied in and out around a block), the block's inputs and a step's figures:
 * doubles only (flags 0/1, counts exact), so that each is also a double[] the caller fills and reads at once. */
typedef struct {
    /* driveline */
    double w_e, w_d, v, phi, locked;
    double engine_work, potential, slip, damping, resistance, brake;
    double t_c, slip_J, slip_W;
    /* engine */
    double integral, throttle, t_e;
    /* loop */
    double x_act, theta_cm, t_cap, theta_cs, x_kiss;
    double held0, held1, held2;     /* the FMU inputs last set: x_to, theta_cm, omega_slip */
    double lifted, stalled, net_n, net_e;
    /* the launch record */
    double has_lock, rec_stall, lock_time, rec_slip_J, a_filt, jerk, sq_err, max_err, sum_creep, n_err, n_creep;
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
    double event;                   /* 1 locked (at t + h), -1 unlocked in the step (at t), -2 unlocked as the TCU let go (at t + h) */
    double net_due;                 /* the thermal network steps after this step, with net_w_e, net_w_d */
    double net_w_e, net_w_d;
} lp_step_out;

/* Run steps from blk->k0 until (exclusive) the next TCU cycle, the slot switch, the run's end or after the
 * step that makes the thermal network due; at most max_steps. Returns the number of steps done (>= 1 unless
 * an error), or -1, -2, -3 if fmi2SetReal, fmi2DoStep, fmi2GetReal failed (its status in *fmi_status). */
int lp_run_block(const lp_consts *c, lp_state *s, const lp_block *blk, lp_step_out *out, int max_steps,
                 int *fmi_status);
