/*
 * Minimal FMI 2.0 co-simulation host: load an FMU's shared library (dlopen on POSIX,
 * LoadLibrary on Windows: the same source is cross-compiled with zig and run under Wine),
 * run a deterministic input sequence, print the final outputs and the time per step.
 *
 *   fmi2_host LIBRARY RESOURCE_URI GUID STEPS STEP_SIZE [checksum]
 *
 * With "checksum", also prints an FNV-1a 64 hash of the bytes of every step's outputs (a bit-for-bit
 * comparison of two builds over the whole sequence; benchmarks/fmu.py, tests/test_native_speed.py).
 *
 * Inputs at step k: x_to = 0.003 + 0.005 * ((k * 7919) % 1000) / 1000 m,
 *                   theta_cm = 300 + 300 * ((k * 104729) % 1000) / 1000 K.
 * Value references: x_to 0, theta_cm 1, torque 2, force 3, theta_cs 4, u_f 5, x_kiss 6.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "host_platform.h" /* LIB, OPEN, SYM, CLOSE, LOAD, now_s() */

#include "fmi2Functions.h"
#include "host_fmi2.h"          /* logger, LOAD_FMI2_CS, host_fmi2_start() */

int main(int argc, char **argv) {
    LIB lib;
    long steps, k;
    double h, in[2], out[5], t = 0.0;
    const fmi2ValueReference vin[2] = {0, 1}, vout[5] = {2, 3, 4, 5, 6};
    fmi2Component c;
    double t0, t1;
    unsigned long long hash = 14695981039346656037ULL;
    int checksum = argc == 7 && !strcmp(argv[6], "checksum");
    if (argc != 6 && !checksum) {
        fprintf(stderr, "usage: %s LIBRARY RESOURCE_URI GUID STEPS STEP_SIZE [checksum]\n", argv[0]);
        return 2;
    }
    steps = atol(argv[4]);
    h = atof(argv[5]);
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
            in[1] = 300.0 + 300.0 * (double)((k * 104729) % 1000) / 1000.0;
            if (fmi2SetReal(c, vin, 2, in) > fmi2Warning || fmi2DoStep(c, t, h, fmi2True) > fmi2Warning ||
                fmi2GetReal(c, vout, 5, out) > fmi2Warning) {
                fprintf(stderr, "step %ld failed\n", k);
                return 1;
            }
            t += h;
            if (checksum) {
                const unsigned char *b = (const unsigned char *)out;
                size_t j;
                for (j = 0; j < sizeof out; ++j) hash = (hash ^ b[j]) * 1099511628211ULL;
            }
        }
        t1 = now_s();
        printf("outputs %.17g %.17g %.17g %.17g %.17g\n", out[0], out[1], out[2], out[3], out[4]);
        printf("us_per_step %.4f\n", (t1 - t0) * 1e6 / steps);
        if (checksum) printf("checksum %016llx\n", hash);
        fmi2Terminate(c);
        fmi2FreeInstance(c);
    }
    CLOSE(lib);
    return 0;
}
