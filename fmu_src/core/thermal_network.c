/*
 * The chain of lumped thermal nodes (thermal_network.h): conductances, the exact-exponential
 * Gauss-Seidel step (Co-Simulation: the nodes' constants for thermal_step.c) and the derivative (Model Exchange).
 */
#include "thermal_network.h"

#include <math.h>

void tn_links(const TnParams *p, int clamped, TnOperating *op) {
    int i;
    for (i = 0; i + 1 < p->n; ++i) op->link[i] = clamped ? p->g_always[i] + p->g_clamped[i] : p->g_always[i];
}

/* a ** 0.8, or the memo's value for the same a */
static double pow08(double a, int k, TnMemo *memo) {
    if (memo && memo->ready & 1 && a == memo->pow_in[k]) return memo->pow_out[k];
    if (!memo) return pow(a, 0.8);
    memo->pow_in[k] = a;
    return memo->pow_out[k] = pow(a, 0.8);
}

void tn_operating(const TnParams *p, double w_engine, double w_disc, int clamped, TnOperating *op, TnMemo *memo) {
    int i;
    /* (|w| / w_ref)^0.8 per speed source (turbulent forced convection, Nu ~ Re^0.8) */
    double x[2];
    x[TN_ENGINE] = pow08(fabs(w_engine) / p->w_ref, TN_ENGINE, memo);
    x[TN_DISC] = pow08(fabs(w_disc) / p->w_ref, TN_DISC, memo);
    if (memo && !(memo->ready & 1)) {
        /* the first call filled both entries: they are valid from now on */
        memo->ready |= 1;
    }
    op->h[TN_ENGINE] = p->h_still + p->h_rot * x[TN_ENGINE];
    op->h[TN_DISC] = p->h_still + p->h_rot * x[TN_DISC];
    tn_links(p, clamped, op);
    for (i = 0; i < p->n; ++i) {
        double conv = p->area[i] > 0.0 ? p->area[i] * op->h[p->speed[i]] : 0.0;
        double g = conv + p->g_engine[i];
        op->sink_g[i] = g;
        op->sink_t[i] = g > 0.0 ? (p->g_engine[i] * p->theta_engine + conv * p->theta_a) / g : p->theta_a;
    }
}

/* exp(a) of node i, or the memo's value for the same a */
static double exp_node(double a, int i, TnMemo *memo) {
    if (!memo) return exp(a);
    if (memo->ready & 2 && a == memo->exp_in[i]) return memo->exp_out[i];
    memo->exp_in[i] = a;
    return memo->exp_out[i] = exp(a);
}

/* the nodes' constants of the step (ThermalNetwork._prepare's, in its order) and the one step (thermal_step.c) */
void tn_step(const TnParams *p, const TnOperating *op, double *th, double dt, double power, TnMemo *memo) {
    TnNode nodes[TN_MAX];
    int i, n = p->n;
    for (i = 0; i < n; ++i) {
        TnNode *q = nodes + i;
        q->cap = p->cap[i];
        q->gl = i > 0 ? op->link[i - 1] : 0.0;
        q->gr = i < n - 1 ? op->link[i] : 0.0;
        q->area = p->area[i];
        q->on_disc = p->speed[i] == TN_DISC ? 1.0 : 0.0;
        q->ge_te = p->g_engine[i] * p->theta_engine;
        q->gfix = q->gl + q->gr + p->g_engine[i];
        q->share = p->share[i];
        q->fixed = q->area == 0.0 && q->gfix > 0.0 ? 1.0 : 0.0;
        if (q->fixed != 0.0) {
            q->decay = exp_node(-dt * q->gfix / q->cap, i, memo);
        } else {
            q->decay = 0.0;
            if (memo) memo->exp_in[i] = NAN; /* no entry for this node: the next call computes it */
        }
    }
    if (memo) memo->ready |= 2;
    tn_chain_step(nodes, n, th, dt, power, op->h[TN_ENGINE], op->h[TN_DISC], p->theta_a);
}

void tn_derivative(const TnParams *p, const TnOperating *op, const double *th, double power, double *der) {
    const double *link = op->link, *sg = op->sink_g, *st = op->sink_t;
    int i, n = p->n;
    for (i = 0; i < n; ++i) {
        double q = p->share[i] * power + sg[i] * (st[i] - th[i]);
        if (i > 0) q += link[i - 1] * (th[i - 1] - th[i]);
        if (i < n - 1) q += link[i] * (th[i + 1] - th[i]);
        der[i] = q / p->cap[i];
    }
}
