/*
 * A chain of lumped thermal nodes (the clutch's thermal network in the CushionClutchThermal FMU).
 *
 * Nodes 0 .. n-1 in a chain, temperatures theta_i (K), heat capacities C_i (J/K):
 *   link i -- i+1:   conductance g_always[i], plus g_clamped[i] while the clutch is clamped (W/K);
 *   sink of node i:  convection G_c = area[i] (h_still + h_rot (|w_i| / w_ref)^0.8) to the air at theta_a,
 *                    with w_i the engine or the disc speed (speed[i]), plus g_engine[i] to the engine
 *                    block at theta_engine (W/K);
 *   heat input:      q_i = share[i] * P  (P the slip power, W).
 * Co-Simulation: tn_step advances node by node (0 first) with the exact exponential solution for the node's
 * neighbours held: the one step of the launch plant's network too (thermal_step.c, the operations of the Python
 * plant's cushion_clutch.model.thermal_network.ThermalNetwork.step in its order); Model Exchange: tn_derivative.
 * The structure (n, speed sources, mean weights) and the parameters' value references are generated from
 * Python into cushion_variables.h (cushion_clutch.fmu.thermal_chain); this file knows no node by name.
 */
#ifndef THERMAL_NETWORK_H
#define THERMAL_NETWORK_H

#include "thermal_step.h" /* TnNode, tn_chain_step */

#define TN_MAX 32
enum { TN_ENGINE = 0, TN_DISC = 1 };

typedef struct {
    int n;
    double cap[TN_MAX], share[TN_MAX], area[TN_MAX], g_engine[TN_MAX]; /* J/K, 1, m2, W/K */
    int speed[TN_MAX];                          /* TN_ENGINE or TN_DISC */
    double g_always[TN_MAX], g_clamped[TN_MAX]; /* link i -- i+1, W/K */
    double theta_engine, theta_a, h_still, h_rot, w_ref; /* K, K, W/(m2 K), W/(m2 K), rad/s */
} TnParams;

/* the network at one operating point: links (n-1), the nodes' sink conductances and temperatures, and the
   convection coefficient h_still + h_rot (|w| / w_ref)^0.8 at the engine's and the disc's speed (TN_ENGINE, TN_DISC) */
typedef struct {
    double link[TN_MAX], sink_g[TN_MAX], sink_t[TN_MAX]; /* W/K, W/K, K */
    double h[2];                                         /* W/(m2 K) */
} TnOperating;

/* the last arguments of the network's transcendental calls and their values, kept by the caller between steps:
   a call with the same argument (compared exactly) takes the kept value, the same bits exp/pow would give, so the
   results do not depend on the call history; ready = 0 (a zeroed memo) computes everything */
typedef struct {
    int ready;
    double pow_in[2], pow_out[2]; /* |w| / w_ref of the engine and the disc, and its power 0.8 */
    double exp_in[TN_MAX], exp_out[TN_MAX]; /* -dt gfix_i / C_i of each node without convection, and its exponential */
} TnMemo;

/* the operating point at the given speeds (rad/s) and clamp state (memo: NULL or the caller's TnMemo) */
void tn_operating(const TnParams *p, double w_engine, double w_disc, int clamped, TnOperating *op, TnMemo *memo);
/* the links alone for another clamp state (the sinks depend on the speeds only) */
void tn_links(const TnParams *p, int clamped, TnOperating *op);
/* advance theta (K) by dt (s) with the slip power (W) and the operating point held (memo: NULL or the caller's) */
void tn_step(const TnParams *p, const TnOperating *op, double *theta, double dt, double power, TnMemo *memo);
/* dtheta/dt (K/s) */
void tn_derivative(const TnParams *p, const TnOperating *op, const double *theta, double power, double *der);

#endif
