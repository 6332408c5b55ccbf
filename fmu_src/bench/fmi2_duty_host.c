/*
 * FMI 2.0 co-simulation host timing one step of the plain (CushionClutch) and the thermal
 * (CushionClutchThermal) clutch FMU on the same duty (cushion_clutch.benchmarks.fmu):
 *
 *   fmi2_duty_host LIBRARY RESOURCE_URI GUID STEPS STEP_SIZE VR_X_TO VR_B VR_C MODE
 *
 * Inputs at step k: x_to (VR_X_TO) = 0.003 + 0.005 * ((k * 7919) % 1000) / 1000 m, then
 *   MODE 0 (plain):   VR_B theta_cm = 300 + 300 * ((k * 104729) % 1000) / 1000 K, VR_C omega_slip = 100 rad/s;
 *   MODE 1 (thermal): VR_B omega_slip = 100 rad/s, VR_C omega_engine = 150 rad/s.
 * Outputs read every step: torque 2, theta_cs 4, x_kiss 6 (the clutch model's value references in both).
 */
#include <stdio.h>
#include <stdlib.h>

#include "host_platform.h" /* LIB, OPEN, SYM, CLOSE, LOAD, now_s() */
#include "fmi2Functions.h"
#include "host_fmi2.h"          /* host_logger, LOAD_FMI2_CS, host_fmi2_start() */

int main(int argc, char **argv) {
    LIB lib;
    long steps, k;
    int mode;
    double h, in[3], out[3], t = 0.0;
    fmi2ValueReference vin[3];
    const fmi2ValueReference vout[3] = {2, 4, 6};
    fmi2Component c;
    double t0, t1;
    if (argc != 10) {
        fprintf(stderr, "usage: %s LIBRARY RESOURCE_URI GUID STEPS STEP_SIZE VR_X_TO VR_B VR_C MODE\n", argv[0]);
        return 2;
    }
    steps = atol(argv[4]);
    h = atof(argv[5]);
    vin[0] = (fmi2ValueReference)atol(argv[6]);
    vin[1] = (fmi2ValueReference)atol(argv[7]);
    vin[2] = (fmi2ValueReference)atol(argv[8]);
    mode = atoi(argv[9]);
    lib = OPEN(argv[1]);
    if (!lib) { fprintf(stderr, "cannot load %s\n", argv[1]); return 2; }
    {
        LOAD_FMI2_CS
        c = host_fmi2_start(fmi2Instantiate, fmi2SetupExperiment, fmi2EnterInitializationMode,
                            fmi2ExitInitializationMode, argv[3], argv[2]);
        if (!c) return 1;
        t0 = now_s();
        for (k = 0; k < steps; ++k) {
            in[0] = 0.003 + 0.005 * (double)((k * 7919) % 1000) / 1000.0;
            in[1] = mode ? 100.0 : 300.0 + 300.0 * (double)((k * 104729) % 1000) / 1000.0;
            in[2] = mode ? 150.0 : 100.0;
            if (fmi2SetReal(c, vin, 3, in) > fmi2Warning || fmi2DoStep(c, t, h, fmi2True) > fmi2Warning ||
                fmi2GetReal(c, vout, 3, out) > fmi2Warning) {
                fprintf(stderr, "step %ld failed\n", k);
                return 1;
            }
            t += h;
        }
        t1 = now_s();
        printf("outputs %.17g %.17g %.17g\n", out[0], out[1], out[2]);
        printf("us_per_step %.4f\n", (t1 - t0) * 1e6 / steps);
        fmi2Terminate(c);
        fmi2FreeInstance(c);
    }
    CLOSE(lib);
    return 0;
}
