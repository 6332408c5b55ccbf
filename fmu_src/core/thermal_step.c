/*
 * The one step of a chain of lumped thermal nodes (thermal_step.h): the operations of
 * cushion_clutch.model.thermal_network.ThermalNetwork.step, in its order.
 */
#include "thermal_step.h"

#include <math.h>

void tn_chain_step(const TnNode *nodes, int n, double *th, double dt, double p_slip, double h_engine, double h_disc,
                   double theta_a) {
    double left = 0.0; /* the left neighbour's temperature, advanced already */
    int i;
    for (i = 0; i < n; i++) {
        const TnNode *q = nodes + i;
        double flow = q->share * p_slip + q->ge_te;
        double gs, decay = q->decay;
        if (q->gl != 0.0)
            flow += q->gl * left;
        if (q->gr != 0.0)
            flow += q->gr * th[i + 1];
        if (q->fixed == 0.0) {
            double conv = q->area * (q->on_disc != 0.0 ? h_disc : h_engine);
            gs = q->gfix + conv;
            flow += conv * theta_a;
            if (gs > 0.0)
                decay = exp(-dt * gs / q->cap);
        } else {
            gs = q->gfix;
        }
        if (gs > 0.0) {
            double inf = flow / gs;
            left = th[i] = inf + (th[i] - inf) * decay;
        } else {
            left = th[i] = th[i] + flow * dt / q->cap;
        }
    }
}
