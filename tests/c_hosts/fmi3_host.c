/*
 * Minimal FMI 3.0 co-simulation host (the FMI 3.0 twin of fmi2_host.c): load an FMU's shared library (dlopen on POSIX,
 * LoadLibrary on Windows: the same source is cross-compiled with zig and run under Wine),
 * run a deterministic input sequence, print the final outputs and the time per step.
 *
 *   fmi3_host LIBRARY RESOURCE_PATH INSTANTIATION_TOKEN STEPS STEP_SIZE
 *
 * Inputs at step k: x_to = 0.003 + 0.005 * ((k * 7919) % 1000) / 1000 m,
 *                   theta_cm = 300 + 300 * ((k * 104729) % 1000) / 1000 K.
 * Value references: x_to 0, theta_cm 1, torque 2, force 3, theta_cs 4, u_f 5, x_kiss 6.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include "host_platform.h" /* LIB, OPEN, SYM, CLOSE, LOAD, now_s() */

#include "fmi3Functions.h"

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    fprintf(stderr, "[%d %s] %s\n", (int)status, category, message);
}

int main(int argc, char **argv) {
    LIB lib;
    long steps, k;
    double h, in[2], out[5], t = 0.0, last;
    const fmi3ValueReference vin[2] = {0, 1}, vout[5] = {2, 3, 4, 5, 6};
    fmi3Instance c;
    fmi3Boolean event, terminate, early;
    double t0, t1;
    if (argc != 6) {
        fprintf(stderr, "usage: %s LIBRARY RESOURCE_PATH INSTANTIATION_TOKEN STEPS STEP_SIZE\n", argv[0]);
        return 2;
    }
    steps = atol(argv[4]);
    h = atof(argv[5]);
    lib = OPEN(argv[1]);
    if (!lib) { fprintf(stderr, "cannot load %s\n", argv[1]); return 2; }
    {
        LOAD(fmi3InstantiateCoSimulation) LOAD(fmi3EnterInitializationMode) LOAD(fmi3ExitInitializationMode)
        LOAD(fmi3SetFloat64) LOAD(fmi3GetFloat64) LOAD(fmi3DoStep) LOAD(fmi3Terminate) LOAD(fmi3FreeInstance)
        c = fmi3InstantiateCoSimulation("host", argv[3], argv[2], fmi3False, fmi3False, fmi3False, fmi3False,
                                        NULL, 0, NULL, logger, NULL);
        if (!c) { fprintf(stderr, "fmi3InstantiateCoSimulation failed\n"); return 1; }
        if (fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) > fmi3Warning ||
            fmi3ExitInitializationMode(c) > fmi3Warning) {
            fprintf(stderr, "initialization failed\n");
            return 1;
        }
        t0 = now_s();
        for (k = 0; k < steps; ++k) {
            in[0] = 0.003 + 0.005 * (double)((k * 7919) % 1000) / 1000.0;
            in[1] = 300.0 + 300.0 * (double)((k * 104729) % 1000) / 1000.0;
            if (fmi3SetFloat64(c, vin, 2, in, 2) > fmi3Warning ||
                fmi3DoStep(c, t, h, fmi3True, &event, &terminate, &early, &last) > fmi3Warning ||
                fmi3GetFloat64(c, vout, 5, out, 5) > fmi3Warning) {
                fprintf(stderr, "step %ld failed\n", k);
                return 1;
            }
            t += h;
        }
        t1 = now_s();
        printf("outputs %.17g %.17g %.17g %.17g %.17g\n", out[0], out[1], out[2], out[3], out[4]);
        printf("us_per_step %.4f\n", (t1 - t0) * 1e6 / steps);
        fmi3Terminate(c);
        fmi3FreeInstance(c);
    }
    CLOSE(lib);
    return 0;
}
