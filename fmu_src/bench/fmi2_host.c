/*
 * Minimal FMI 2.0 co-simulation host: load an FMU's shared library (dlopen on POSIX,
 * LoadLibrary on Windows: the same source is cross-compiled with zig and run under Wine),
 * run an input sequence, print the final outputs and the time per step.
 *
 *   fmi2_host LIBRARY RESOURCE_URI GUID STEPS STEP_SIZE [checksum] [--replay FILE]
 *
 * With "checksum", also prints an FNV-1a 64 hash of the bytes of every step's outputs (a bit-for-bit
 * comparison of two builds over the whole sequence; benchmarks/fmu.py, tests/test_native_speed.py).
 *
 * The jump pattern (the default; every step a cold solve of the cover): inputs at step k
 *   x_to = 0.003 + 0.005 * ((k * 7919) % 1000) / 1000 m,
 *   theta_cm = 300 + 300 * ((k * 104729) % 1000) / 1000 K,
 * both set every step; torque, force, theta_cs, u_f and x_kiss read every step.
 *
 * The replay pattern (--replay FILE): FILE holds 3 doubles per step in this machine's byte order (little-endian
 * on every platform we build for): x_to [m], theta_cm [K], omega_slip [rad/s], as the launch simulation's FMU
 * client (cushion_clutch/launch/fmu_client.py) gives them (benchmarks/fmu.py writes it from a launch). As that
 * client does, the three inputs are set (one fmi2SetReal) only when one of them differs from those last set, and
 * torque, theta_cs and x_kiss are read every step (the checksum hashes these three). STEPS steps are run, the file
 * replayed from its start again when it ends; STEPS 0 runs the file once. Also printed: "replay N sets M", the
 * file's steps and the fmi2SetReal calls made.
 *
 * Value references: x_to 0, theta_cm 1, torque 2, force 3, theta_cs 4, u_f 5, x_kiss 6, omega_slip 17.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "host_platform.h" /* LIB, OPEN, SYM, CLOSE, LOAD, now_s() */

#include "fmi2Functions.h"
#include "host_fmi2.h"          /* host_logger, LOAD_FMI2_CS, host_fmi2_start() */

/* FNV-1a 64 of n doubles' bytes, continuing from hash */
static unsigned long long fnv1a(unsigned long long hash, const double *v, size_t n) {
    const unsigned char *b = (const unsigned char *)v;
    size_t i;
    for (i = 0; i < n * sizeof(double); ++i) hash = (hash ^ b[i]) * 1099511628211ULL;
    return hash;
}

/* the replay file's steps (3 doubles each) in a malloc'd array, their number in *n; NULL (reason on stderr) */
static double *read_replay(const char *path, long *n) {
    FILE *f = fopen(path, "rb");
    double *v = NULL;
    long size;
    if (!f) { fprintf(stderr, "cannot open %s\n", path); return NULL; }
    if (fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fprintf(stderr, "cannot read %s\n", path);
        fclose(f);
        return NULL;
    }
    *n = size / (long)(3 * sizeof(double));
    if (*n < 1 || size % (long)(3 * sizeof(double)) != 0) {
        fprintf(stderr, "%s: %ld bytes, not a positive multiple of 24 (3 doubles per step)\n", path, size);
        fclose(f);
        return NULL;
    }
    v = (double *)malloc((size_t)size);
    if (!v || fread(v, 1, (size_t)size, f) != (size_t)size) {
        fprintf(stderr, "cannot read %s\n", path);
        free(v);
        v = NULL;
    }
    fclose(f);
    return v;
}

int main(int argc, char **argv) {
    LIB lib;
    long steps, k, nrec = 0, sets = 0;
    double h, in[3], out[5], t = 0.0, *rec = NULL;
    const fmi2ValueReference vin[2] = {0, 1}, vout[5] = {2, 3, 4, 5, 6};
    const fmi2ValueReference rin[3] = {0, 1, 17}, rout[3] = {2, 4, 6};
    fmi2Component c;
    double t0, t1;
    unsigned long long hash = 14695981039346656037ULL;
    int checksum = 0, a, bad = argc < 6;
    const char *replay = NULL;
    for (a = 6; a < argc && !bad; ++a) {
        if (!strcmp(argv[a], "checksum")) checksum = 1;
        else if (!strcmp(argv[a], "--replay") && a + 1 < argc) replay = argv[++a];
        else bad = 1;
    }
    if (bad) {
        fprintf(stderr, "usage: %s LIBRARY RESOURCE_URI GUID STEPS STEP_SIZE [checksum] [--replay FILE]\n", argv[0]);
        return 2;
    }
    steps = atol(argv[4]);
    h = atof(argv[5]);
    if (replay) {
        rec = read_replay(replay, &nrec);
        if (!rec) return 2;
        if (steps == 0) steps = nrec;
    }
    lib = OPEN(argv[1]);
    if (!lib) { fprintf(stderr, "cannot load %s\n", argv[1]); return 2; }
    {
        LOAD_FMI2_CS
        c = host_fmi2_start(fmi2Instantiate, fmi2SetupExperiment, fmi2EnterInitializationMode,
                            fmi2ExitInitializationMode, argv[3], argv[2]);
        if (!c) return 1;
        if (replay) {      /* the launch client's pattern: set what changed (all three), read three */
            const double *r = rec;
            double held[3];
            long j = 0;
            held[0] = held[1] = held[2] = 0.0 / 0.0;    /* NaN: the first step sets */
            t0 = now_s();
            for (k = 0; k < steps; ++k) {
                if (r[0] != held[0] || r[1] != held[1] || r[2] != held[2]) {
                    held[0] = r[0];
                    held[1] = r[1];
                    held[2] = r[2];
                    ++sets;
                    if (fmi2SetReal(c, rin, 3, held) > fmi2Warning) {
                        fprintf(stderr, "step %ld: fmi2SetReal failed\n", k);
                        return 1;
                    }
                }
                if (fmi2DoStep(c, t, h, fmi2True) > fmi2Warning || fmi2GetReal(c, rout, 3, out) > fmi2Warning) {
                    fprintf(stderr, "step %ld failed\n", k);
                    return 1;
                }
                t += h;
                if (checksum) hash = fnv1a(hash, out, 3);
                if (++j == nrec) { j = 0; r = rec; } else r += 3;
            }
            t1 = now_s();
            printf("outputs %.17g %.17g %.17g\n", out[0], out[1], out[2]);
            printf("replay %ld sets %ld\n", nrec, sets);
        } else {           /* the jump pattern */
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
                if (checksum) hash = fnv1a(hash, out, 5);
            }
            t1 = now_s();
            printf("outputs %.17g %.17g %.17g %.17g %.17g\n", out[0], out[1], out[2], out[3], out[4]);
        }
        printf("us_per_step %.4f\n", (t1 - t0) * 1e6 / steps);
        if (checksum) printf("checksum %016llx\n", hash);
        fmi2Terminate(c);
        fmi2FreeInstance(c);
    }
    free(rec);
    CLOSE(lib);
    return 0;
}
