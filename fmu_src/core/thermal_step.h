/*
 * The one step of a chain of lumped thermal nodes (Co-Simulation): the launch plant's network
 * (hosts/launch_plant.c) and the thermal FMU's (thermal_network.c, tn_step) both advance it here. Node by node,
 * 0 first, each node takes the exact exponential solution with its neighbours held (Gauss-Seidel splitting),
 * left neighbour already advanced, in the operation order of the Python reference
 * cushion_clutch.model.thermal_network.ThermalNetwork.step, so that the three give the same bits (built without
 * fused multiply-adds: tests/test_thermal_step.py). Units SI: K, W, W/K, J/K, m2, s.
 * This header is part of the launch plant's cffi declaration too (plain declarations; cushion_clutch.fmu.hostlib
 * drops its guard lines there).
 */
#ifndef THERMAL_STEP_H
#define THERMAL_STEP_H

/* one node for one clamp state and step: the per-node constants of ThermalNetwork.step (ThermalNetwork._prepare),
 * flags as 0/1 */
typedef struct {
    double cap, gl, gr, area, on_disc, ge_te, gfix, share; /* J/K, W/K, W/K, m2, 1, W, W/K, 1 */
    double fixed;                   /* 1: no convection and gfix > 0, the decay factor is a constant of the step */
    double decay;                   /* exp(-dt gfix / cap) at the step (fixed nodes) */
} TnNode;

/* advance the n nodes' temperatures th (K) by dt (s) with the slip power p_slip (W) into the nodes by their shares,
 * the convection coefficients h_engine and h_disc (W/(m2 K)) of the nodes cooled at the engine's and at the disc's
 * speed (on_disc), and the air at theta_a (K) */
void tn_chain_step(const TnNode *nodes, int n, double *th, double dt, double p_slip, double h_engine, double h_disc,
                   double theta_a);

#endif
