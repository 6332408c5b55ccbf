/* The launch simulation's plant steps between two TCU cycles, compiled: the same step as the Python loop of
 * cushion_clutch/launch/simulate.py (the reference; tests/test_launch_plant_block.py checks that both give the
 * same series and metrics), written out for speed. Every expression keeps the Python one's order of
 * operations (built with -ffp-contract=off -fno-builtin: no fused multiply-adds, pow stays pow), so the two
 * agree to the last bit where the FMU and libm are the same.
 *
 * Per step: first-order actuator, the clutch FMU (inputs held over the step; fmi2SetReal only when they
 * change), the engine with its idle governor (engine.EngineGovernor.torque), the compliant driveline with
 * slip/lock and its energy books (driveline.Driveline.step), the slip energy into the thermal network, the
 * network's step every net_every steps (model.thermal_network.ThermalNetwork.step: libm's exp and pow, as
 * Python's math.exp and **), and the launch record's per-step metrics (metrics.LaunchRecord.step). A quiet TCU
 * period (the car braked at rest, the clutch open) is one step of a TCU period (lp_run_quiet). The state
 * (lp_state) stays here over a run; the caller reads its head after each call. */
#include <math.h>
#include <stddef.h>
#include "launch_plant.h"

#include "host_export.h"

/* engine.EngineGovernor.torque */
static double engine_torque(const lp_consts *c, lp_state *s, double w_e, double pedal, int stalled, double h)
{
    const double *w = c->curve_w, *t = c->curve_t;
    int n = c->n_curve;
    double t_max;
    if (w_e <= w[0]) {
        t_max = t[0];
    } else if (w_e >= w[n - 1]) {
        t_max = t[n - 1];
    } else {
        int i = 0;                                  /* bisect_right(w, w_e) - 1 */
        while (i + 1 < n && w[i + 1] <= w_e)
            i++;
        t_max = t[i] + (t[i + 1] - t[i]) * (w_e - w[i]) / (w[i + 1] - w[i]);
    }
    double err = c->w_idle - w_e;
    double gov = (c->kp * err + c->ki * s->integral + c->drag * w_e) / t_max;
    gov = gov > 1.0 ? 1.0 : (gov < 0.0 ? 0.0 : gov);
    if (pedal < gov && (gov < 1.0 || err < 0.0) && (gov > 0.0 || err > 0.0))
        s->integral += err * h;
    double thr = pedal > gov ? pedal : gov;
    if (w_e > c->w_max || w_e <= c->w_stall || stalled)
        thr = 0.0;
    s->throttle = thr;
    return thr * t_max - c->drag * w_e;
}

/* driveline.Driveline._shaft */
static double shaft(const lp_consts *c, const lp_state *s, double j1, double t1, double w_v, double t_veh,
                    int held, double h)
{
    double kappa = c->kappa;
    if (held)
        return (c->k * s->phi + kappa * (s->w_d - 0.5 * w_v + 0.5 * h * t1 / j1)) / (1.0 + 0.5 * kappa * h / j1);
    return (c->k * s->phi + kappa * (s->w_d - w_v + 0.5 * h * (t1 / j1 + t_veh / c->j_v))) /
           (1.0 + 0.5 * kappa * h * (1.0 / j1 + c->eta / c->j_v));
}

/* driveline.Driveline.step */
static int driveline_step(const lp_consts *c, lp_state *s, double t_e, double t_cap, int engaged, int braking,
                          double h)
{
    double w_e = s->w_e, w_d = s->w_d, v = s->v;
    if (v == 0.0 && t_cap == 0.0 && w_d == 0.0 && s->phi == 0.0 && !s->locked) {
        double w_e_new = w_e + t_e / c->j_e * h;
        if (w_e_new < 0.0)
            w_e_new = 0.0;
        s->engine_work += t_e * 0.5 * (w_e + w_e_new) * h;
        s->w_e = w_e_new;
        s->t_c = s->slip_J = s->slip_W = 0.0;
        return 0;
    }
    double i_tot = c->i_tot, r = c->r, eta = c->eta, j_e = c->j_e, j_v = c->j_v;
    double w_v = v * i_tot / r;
    double f_res = (v > 0.0 ? c->f_roll : 0.0) + c->air * v * v + c->f_grade;
    double t_res = f_res * r / i_tot;
    int locked = s->locked != 0.0, event = 0;
    double j_lock = j_e + c->j_disc;
    double t_brake = braking && v > 0.0 ? c->brake_torque : 0.0;
    double t_s, t_c = 0.0, j1, t1;
    if (locked) {
        t_s = shaft(c, s, j_lock, t_e, w_v, t_res + t_brake, 0, h);
        t_c = (c->j_disc * t_e + j_e * t_s) / j_lock;
        if (fabs(t_c) > t_cap) {
            locked = 0;
            event = -1;
        }
    }
    if (!locked) {
        t_c = w_e != w_d ? copysign(t_cap, w_e - w_d) : 0.0;
        j1 = c->j_disc;
        t1 = t_c;
    } else {
        j1 = j_lock;
        t1 = t_e;
    }
    t_s = shaft(c, s, j1, t1, w_v, t_res + t_brake, 0, h);
    double w_v_new = w_v + h / j_v * (eta * t_s - t_res - t_brake);
    if (w_v_new < 0.0) {
        t_s = shaft(c, s, j1, t1, w_v, 0.0, 1, h);
        w_v_new = 0.0;
        t_brake = eta * t_s - t_res + j_v * w_v / h;
    }
    double w_d_new = w_d + h / j1 * (t1 - t_s);
    double w_e_new;
    if (locked) {
        w_e_new = w_d_new;
    } else {
        w_e_new = w_e + (t_e - t_c) / j_e * h;
        if (w_e_new < 0.0)
            w_e_new = 0.0;
    }
    double d_m = 0.5 * (w_d + w_d_new) - 0.5 * (w_v + w_v_new);
    s->phi += h * d_m;
    double wm_e = 0.5 * (w_e + w_e_new), wm_d = 0.5 * (w_d + w_d_new), wm_v = 0.5 * (w_v + w_v_new);
    s->engine_work += t_e * wm_e * h;
    double slip_w = !locked ? t_c * (wm_e - wm_d) : 0.0;
    double slip = slip_w * h;
    s->damping += c->c * d_m * d_m * h;
    s->resistance += ((f_res - c->f_grade) * r / i_tot + (1.0 - eta) * t_s) * wm_v * h;
    s->potential += c->f_grade * r / i_tot * wm_v * h;
    s->brake += t_brake * wm_v * h;
    if (!locked && t_cap > 0.0 && engaged && (w_e - w_d) * (w_e_new - w_d_new) <= 0.0) {
        double t_s_new = c->k * s->phi + c->c * (w_d_new - w_v_new);
        if (fabs((c->j_disc * t_e + j_e * t_s_new) / j_lock) <= t_cap) {
            double ke_before = 0.5 * (j_e * pow(w_e_new, 2.0) + c->j_disc * pow(w_d_new, 2.0));
            w_e_new = w_d_new = (j_e * w_e_new + c->j_disc * w_d_new) / j_lock;
            slip += ke_before - 0.5 * j_lock * pow(w_e_new, 2.0);
            locked = 1;
            event = 1;
        }
    }
    s->slip += slip;
    s->w_e = w_e_new;
    s->w_d = w_d_new;
    s->v = w_v_new * r / i_tot;
    s->locked = locked;
    s->t_c = t_c;
    s->slip_J = slip;
    s->slip_W = fabs(slip_w);
    if (!locked && t_cap == 0.0 && w_v_new == 0.0 && fabs(w_d_new) < 1e-6 && fabs(s->phi) < 1e-9) {
        s->damping += 0.5 * c->j_disc * pow(w_d_new, 2.0) + 0.5 * c->k * pow(s->phi, 2.0);
        s->w_d = s->phi = 0.0;
    }
    return event;
}

/* metrics.LaunchRecord.step (the acceleration itself is kept by the caller, out->accel) */
static void record_step(const lp_consts *c, lp_state *s, double accel, double t_dem, double t_cap, int launching)
{
    double a_prev = s->a_filt;
    s->a_filt += c->alpha_jerk * (accel - a_prev);
    double jerk = fabs(s->a_filt - a_prev) / c->h;
    if (jerk > s->jerk)
        s->jerk = jerk;
    if (launching && !s->has_lock && t_dem > 0.0) {
        double e = t_cap - t_dem;
        s->n_err += 1;
        s->sq_err += e * e;
        if (fabs(e) > s->max_err)
            s->max_err = fabs(e);
        if (t_dem <= c->creep_nm) {
            s->n_creep += 1;
            s->sum_creep += e;
        }
    }
}

/* model.friction._bracket: index i and weight w with v between g[i] and g[i + 1] (clamped; w = 0 for one point) */
static void bracket(const double *g, int n, double v, int *i, double *w)
{
    if (n == 1 || v <= g[0]) {
        *i = 0;
        *w = 0.0;
        return;
    }
    if (v >= g[n - 1]) {
        *i = n - 2;
        *w = 1.0;
        return;
    }
    int k = 0;                                      /* bisect_right(g, v) - 1 */
    while (k + 1 < n && g[k + 1] <= v)
        k++;
    *i = k;
    *w = (v - g[k]) / (g[k + 1] - g[k]);
}

/* model.friction.FrictionTable.__call__: mu at theta (degC) and |omega| (rad/s), bilinear, clamped */
static double friction_mu(const lp_consts *c, double theta_degC, double omega)
{
    int i, j, nw = c->f_nw;
    double wi, wj;
    bracket(c->f_theta, c->f_nt, theta_degC, &i, &wi);
    bracket(c->f_omega, nw, fabs(omega), &j, &wj);
    const double *m = c->f_mu;
    int i1 = i + 1 < c->f_nt - 1 ? i + 1 : c->f_nt - 1;
    int j1 = j + 1 < nw - 1 ? j + 1 : nw - 1;
    double lo = (1.0 - wj) * m[i * nw + j] + wj * m[i * nw + j1];
    double hi = (1.0 - wj) * m[i1 * nw + j] + wj * m[i1 * nw + j1];
    return (1.0 - wi) * lo + wi * hi;
}

/* model.thermal_network.ThermalNetwork.step: advance the nodes th by dt with the slip power p_slip (W), the
 * speeds (rad/s) and the clamp state held, node by node with the exact exponential for the neighbours held
 * (the fixed nodes' decay factors are those of the step net_dt, recomputed as ThermalNetwork._prepare does
 * for another step) */
static void net_step(lp_consts *c, double *th, double dt, double p_slip, double w_engine, double w_disc,
                     int clamped)
{
    TnNode *nodes = c->net[clamped];
    int i, n = c->net_n_nodes;
    if (dt != c->net_dt[clamped]) {
        for (i = 0; i < n; i++)
            if (nodes[i].fixed != 0.0)
                nodes[i].decay = exp(-dt * nodes[i].gfix / nodes[i].cap);
        c->net_dt[clamped] = dt;
    }
    double h_engine = c->net_h0 + c->net_hr * pow(fabs(w_engine) / c->net_wr, 0.8);
    double h_disc = c->net_h0 + c->net_hr * pow(fabs(w_disc) / c->net_wr, 0.8);
    tn_chain_step(nodes, n, th, dt, p_slip, h_engine, h_disc, c->net_ta); /* the one step (core/thermal_step.c) */
}

/* the network is due after a step (simulate.py: after the driveline, with its speeds): step it with the slip
 * energy gathered since its last step, theta_cm the facings' mean */
static void net_due(lp_consts *c, lp_state *s, double w_engine, double w_disc, int clamped)
{
    double dt = s->net_n * c->h;
    net_step(c, s->theta, dt, s->net_e / (s->net_n * c->h), w_engine, w_disc, clamped);
    s->theta_cm = 0.5 * (s->theta[c->net_cm[0]] + s->theta[c->net_cm[1]]);
    s->theta_fs = 0.5 * (s->theta[c->net_surface[0]] + s->theta[c->net_surface[1]]);
    s->net_n = 0.0;
    s->net_e = 0.0;
}

/* the network's figures in a row: the hotter metal friction surface (Python's max), the last node */
static void net_figures(const lp_consts *c, const lp_state *s, double *surface, double *last)
{
    double a = s->theta[c->net_surface[0]], b = s->theta[c->net_surface[1]];
    *surface = b > a ? b : a;
    *last = s->theta[c->net_n_nodes - 1];
}

/* the clutch FMU over one step of h from t, inputs held (fmu_client.ClutchFmu.step: fmi2SetReal only when they
 * changed); 0 or the failed function's code (lp_run_block) */
static int clutch_step(const lp_consts *c, lp_state *s, double t, double h, double omega_slip, int *fmi_status)
{
    if (omega_slip != s->held2 || s->x_act != s->held0 || s->theta_cm != s->held1) {
        double v_in[3] = {s->x_act, s->theta_cm, omega_slip};
        s->held0 = s->x_act;
        s->held1 = s->theta_cm;
        s->held2 = omega_slip;
        int st = c->set_real(c->comp, c->vr_in, 3, v_in);
        if (st > 1) {
            s->held0 = NAN;
            *fmi_status = st;
            return -1;
        }
    }
    int st = c->do_step(c->comp, t, h, 1);
    if (st > 1) {
        *fmi_status = st;
        return -2;
    }
    double v_out[4];
    st = c->get_real(c->comp, c->vr_out, 4, v_out);
    if (st > 1) {
        *fmi_status = st;
        return -3;
    }
    s->t_cap = v_out[0];
    s->theta_cs = v_out[1];
    s->x_kiss = v_out[2];
    s->clamp = v_out[3];
    return 0;
}

HOST_EXPORT int lp_run_block(lp_consts *c, lp_state *s, const lp_block *blk, lp_step_out *out, double *accel_out,
                           int max_steps, int *fmi_status)
{
    double h = c->h;
    int countdown = (int)blk->countdown;
    int engaged = blk->engaged != 0.0, braking = blk->braking != 0.0, launching = blk->launching != 0.0;
    int j = 0;
    long n_steps = (long)blk->n_steps;
    s->n_events = 0.0;
    for (long k = (long)blk->k0; k < n_steps && j < max_steps; k++, j++) {
        double t = (double)k * h;
        if (j > 0 && (countdown == 0 || t >= blk->next_switch))
            break;                                   /* the next TCU cycle or launch slot: the caller's */
        lp_step_out *o = out + j;
        double tl = t - blk->slot_start;
        countdown -= 1;
        double x_cmd = blk->x_cmd;
        s->x_act = x_cmd + (s->x_act - x_cmd) * c->act;
        double w_e = s->w_e;
        double omega_slip = w_e - s->w_d;
        int st = clutch_step(c, s, t, h, omega_slip, fmi_status);
        if (st < 0)
            return st;
        if (c->mu_surface)
            s->t_cap = c->n_surfaces * friction_mu(c, s->theta_fs - 273.15, omega_slip) * c->r_eq * s->clamp;
        double t_cap = s->t_cap;
        if (engaged && !s->lifted && s->has_lock && w_e > c->w_lift)
            s->lifted = 1;
        double t_e = s->t_e = engine_torque(c, s, w_e, engaged && !s->lifted ? blk->pedal_level : 0.0,
                                            s->stalled != 0.0, h);
        double v = s->v;
        int ev = driveline_step(c, s, t_e, t_cap, engaged, braking, h);
        o->event = ev;
        if (ev > 0 && !s->has_lock) {
            s->has_lock = 1;
            s->lock_time = tl + h - c->prefill;
        }
        double theta_cm_step = s->theta_cm;
        s->rec_slip_J += s->slip_J;
        s->net_e += s->slip_J;
        s->net_n += 1;
        if (s->net_n == (double)c->net_every)
            net_due(c, s, s->w_e, s->w_d, engaged);
        double accel = (s->v - v) / h;
        double t_dem = blk->t_dem + blk->t_rate * (double)(c->tcu_every - countdown) * h;
        if (engaged) {
            record_step(c, s, accel, t_dem, t_cap, launching);
            if (s->w_e <= c->w_stall)
                s->rec_stall = s->stalled = 1;
        } else if (s->locked) {
            s->locked = 0;
            o->event = -2;
        }
        if (o->event != 0.0)
            s->n_events += 1;
        if (s->stalled && tl + h >= blk->slot_end - blk->slot_start - h) {    /* driveline.restart_engine */
            s->engine_work += 0.5 * c->j_e * (pow(c->w_idle, 2.0) - pow(s->w_e, 2.0));
            s->w_e = c->w_idle;
        }
        o->t_cap = t_cap;
        o->theta_cs = s->theta_cs;
        o->x_kiss = s->x_kiss;
        o->x_act = s->x_act;
        o->w_e = s->w_e;
        o->w_d = s->w_d;
        o->v = s->v;
        o->accel = accel_out[j] = accel;
        o->t_c = s->t_c;
        o->theta_cm_step = theta_cm_step;
        o->throttle = s->throttle;
        o->locked = s->locked;
        o->t_shaft = c->k * s->phi + c->c * (s->w_d - s->v * c->i_tot / c->r);
        o->t_dem = t_dem;
        net_figures(c, s, &o->theta_surface, &o->theta_last);
    }
    if (j > 0)
        s->theta_cm_step = out[j - 1].theta_cm_step;
    s->steps = j;
    return j;
}

HOST_EXPORT int lp_run_quiet(lp_consts *c, lp_state *s, double t, double h_quiet, double act_quiet, int *fmi_status)
{
    s->x_act *= act_quiet;
    int st = clutch_step(c, s, t, h_quiet, s->w_e, fmi_status);
    if (st < 0)
        return st;
    if (s->t_cap != 0.0)
        return -4;
    s->steps = 1.0;
    s->n_events = 0.0;
    s->theta_cm_step = s->theta_cm;
    double t_e = s->t_e = engine_torque(c, s, s->w_e, 0.0, 0, h_quiet);
    driveline_step(c, s, t_e, 0.0, 0, 1, h_quiet);
    s->net_n += c->tcu_every;
    if (s->net_n >= c->net_every)
        net_due(c, s, s->w_e, 0.0, 0);
    net_figures(c, s, &s->theta_surface, &s->theta_last);
    return 0;
}
