/*
 * Fault-catalogue host (issue 12): runs one misuse case against an FMI 2.0
 * co-simulation library, as a C master would, and reports what it saw.
 *
 *   fault_host LIBRARY RESOURCE_URI GUID CASE
 *
 * RESOURCE_URI "NULL" passes a NULL resourceLocation. The logger is a real
 * printf-style logger (the message is the format, as in most C masters), so a
 * message that carries unescaped format characters crashes here.
 * Output, one line each: "status N" (the probed call's status), "check NAME 0|1"
 * (case-specific facts), "log S MESSAGE" (every logged message), and finally
 * "survived" after the instance was freed. Exit 0 unless a call failed to load.
 */
#include <dlfcn.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

static pthread_mutex_t log_lock = PTHREAD_MUTEX_INITIALIZER;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    char buf[2048];
    va_list ap;
    (void)env; (void)name; (void)category;
    va_start(ap, message);
    vsnprintf(buf, sizeof buf, message, ap);       /* the message is the format, as in most hosts */
    va_end(ap);
    for (char *p = buf; *p; ++p) if (*p == '\n') *p = ' ';
    pthread_mutex_lock(&log_lock);
    printf("log %d %s\n", (int)status, buf);
    pthread_mutex_unlock(&log_lock);
}

static fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};

#define F(name) static name##TYPE *p_##name;
F(fmi2Instantiate) F(fmi2FreeInstance) F(fmi2SetupExperiment) F(fmi2EnterInitializationMode)
F(fmi2ExitInitializationMode) F(fmi2Terminate) F(fmi2Reset) F(fmi2SetReal) F(fmi2GetReal) F(fmi2DoStep)
F(fmi2GetFMUstate) F(fmi2SetFMUstate) F(fmi2FreeFMUstate) F(fmi2SerializedFMUstateSize)
F(fmi2SerializeFMUstate) F(fmi2DeSerializeFMUstate) F(fmi2GetBooleanStatus) F(fmi2GetRealStatus)
#undef F

static const char *uri, *guid;

static fmi2Component inst(const char *name) {
    return p_fmi2Instantiate(name, fmi2CoSimulation, guid, uri, &cb, fmi2False, fmi2True);
}

static fmi2Status ready(fmi2Component c) {
    fmi2Status s = p_fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
    fmi2Status a = p_fmi2EnterInitializationMode(c), b = p_fmi2ExitInitializationMode(c);
    return s > a ? (s > b ? s : b) : (a > b ? a : b);
}

static fmi2Status set1(fmi2Component c, fmi2ValueReference vr, double v) { return p_fmi2SetReal(c, &vr, 1, &v); }

static double get1(fmi2Component c, fmi2ValueReference vr) {
    double v = NAN;
    p_fmi2GetReal(c, &vr, 1, &v);
    return v;
}

static double run(fmi2Component c, long n, double t) {
    const fmi2ValueReference vin[2] = {0, 1};
    for (long k = 0; k < n; ++k) {
        double in[2] = {0.003 + 0.005 * (double)((k * 7919) % 1000) / 1000.0,
                        300.0 + 300.0 * (double)((k * 104729) % 1000) / 1000.0};
        p_fmi2SetReal(c, vin, 2, in);
        p_fmi2DoStep(c, t, 0.01, fmi2True);
        t += 0.01;
    }
    return t;
}

static void outs(fmi2Component c, double *o) {
    const fmi2ValueReference vr[5] = {2, 3, 4, 5, 6};
    p_fmi2GetReal(c, vr, 5, o);
}

static int same5(const double *a, const double *b) { return memcmp(a, b, 5 * sizeof(double)) == 0; }

static void check(const char *name, int ok) { printf("check %s %d\n", name, ok ? 1 : 0); }

static double rss_mb(void) {
    long pages = 0, rss = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) { if (fscanf(f, "%ld %ld", &pages, &rss) != 2) rss = 0; fclose(f); }
    return rss * 4096.0 / 1e6;
}

static size_t serialize(fmi2Component c, fmi2FMUstate st, char **bytes) {
    size_t n = 0;
    p_fmi2SerializedFMUstateSize(c, st, &n);
    *bytes = malloc(n ? n : 1);
    p_fmi2SerializeFMUstate(c, st, (fmi2Byte *)*bytes, n);
    return n;
}

static void *thread_run(void *arg) {
    double *o = arg;
    fmi2Component c = inst("thread");
    if (!c) { o[0] = NAN; return NULL; }
    ready(c);
    run(c, 2000, 0.0);
    outs(c, o);
    p_fmi2FreeInstance(c);
    return NULL;
}

static int run_case(const char *name) {
    fmi2Component c = NULL;
    fmi2Status s = fmi2OK;
    double a[5], b[5];
    if (!strcmp(name, "resources_null") || !strcmp(name, "resources_missing") || !strcmp(name, "wrong_guid")
        || !strcmp(name, "table_format_chars")) {
        c = inst("c");
        s = c ? ready(c) : fmi2Error;
        if (c && s <= fmi2Warning) s = p_fmi2DoStep(c, 0.0, 0.01, fmi2True);
    } else if (!strcmp(name, "step_before_init")) {
        c = inst("c");
        s = p_fmi2DoStep(c, 0.0, 0.1, fmi2True);
    } else if (!strcmp(name, "step_after_terminate")) {
        c = inst("c"); ready(c); run(c, 10, 0.0); p_fmi2Terminate(c);
        s = p_fmi2DoStep(c, 0.1, 0.1, fmi2True);
    } else if (!strcmp(name, "exit_init_after_steps")) {
        c = inst("c"); ready(c); set1(c, 1, 700.0);
        for (int k = 0; k < 200; ++k) p_fmi2DoStep(c, k, 1.0, fmi2True);
        outs(c, a);
        s = p_fmi2ExitInitializationMode(c);
        outs(c, b);
        check("unchanged", same5(a, b));
    } else if (!strcmp(name, "set_output")) {
        c = inst("c"); ready(c); run(c, 10, 0.0); outs(c, a);
        s = set1(c, 2, 123.0);
        outs(c, b);
        check("unchanged", same5(a, b));
    } else if (!strcmp(name, "set_fixed_param_after_init")) {
        c = inst("c"); ready(c);
        s = set1(c, 8, 0.56);
        check("mu_unchanged", get1(c, 8) == 0.28);
    } else if (!strcmp(name, "set_partially_bad")) {
        const fmi2ValueReference vr[2] = {0, 2};
        const double v[2] = {0.0055, 1.0};
        c = inst("c"); ready(c); run(c, 5, 0.0);
        double before = get1(c, 0);
        s = p_fmi2SetReal(c, vr, 2, v);
        check("unchanged", get1(c, 0) == before);
    } else if (!strcmp(name, "set_unknown_vr")) {
        c = inst("c"); ready(c);
        s = set1(c, 999, 1.0);
    } else if (!strcmp(name, "negative_step")) {
        c = inst("c"); ready(c);
        s = p_fmi2DoStep(c, 0.0, -0.1, fmi2True);
    } else if (!strcmp(name, "nan_input")) {
        c = inst("c"); ready(c); set1(c, 0, NAN);
        s = p_fmi2DoStep(c, 0.0, 0.01, fmi2True);
    } else if (!strcmp(name, "time_backwards")) {
        c = inst("c"); ready(c); p_fmi2DoStep(c, 0.0, 0.1, fmi2True);
        s = p_fmi2DoStep(c, 0.05, 0.1, fmi2True);
    } else if (!strcmp(name, "discard_status")) {
        fmi2Boolean term = fmi2False;
        double last = NAN;
        c = inst("c"); ready(c); p_fmi2DoStep(c, 0.0, 0.01, fmi2True); set1(c, 0, NAN);
        s = p_fmi2DoStep(c, 0.01, 0.01, fmi2True);
        check("bool_status_ok", p_fmi2GetBooleanStatus(c, fmi2Terminated, &term) == fmi2OK);
        check("real_status_ok", p_fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &last) == fmi2OK && last == 0.01);
    } else if (!strcmp(name, "state_roundtrip") || !strcmp(name, "state_truncated")
               || !strcmp(name, "state_corrupted")) {
        fmi2FMUstate st = NULL, st2 = NULL;
        char *bytes = NULL;
        size_t n;
        c = inst("c"); ready(c);
        double t = run(c, 2000, 0.0);
        p_fmi2GetFMUstate(c, &st);
        n = serialize(c, st, &bytes);
        if (!strcmp(name, "state_roundtrip")) {
            run(c, 500, t); outs(c, a);
            s = p_fmi2DeSerializeFMUstate(c, (fmi2Byte *)bytes, n, &st2);
            if (s <= fmi2Warning) s = p_fmi2SetFMUstate(c, st2);
            run(c, 500, t); outs(c, b);
            check("identical", same5(a, b));
        } else {
            outs(c, a);
            if (!strcmp(name, "state_corrupted")) bytes[n / 2] ^= 0x5A;
            s = p_fmi2DeSerializeFMUstate(c, (fmi2Byte *)bytes, strcmp(name, "state_truncated") ? n : n / 2, &st2);
            if (s <= fmi2Warning) s = p_fmi2SetFMUstate(c, st2);
            outs(c, b);
            check("unchanged", same5(a, b));
        }
        p_fmi2FreeFMUstate(c, &st);
        if (st2) p_fmi2FreeFMUstate(c, &st2);
        free(bytes);
    } else if (!strcmp(name, "fifty_instances")) {
        fmi2Component cs[50];
        int ok = 1;
        for (int i = 0; i < 50; ++i) { cs[i] = inst("i"); ok = ok && cs[i]; }
        for (int i = 0; ok && i < 50; ++i) { ready(cs[i]); run(cs[i], 20, 0.0); }
        if (ok) outs(cs[0], a);
        for (int i = 0; ok && i < 50; ++i) { outs(cs[i], b); ok = same5(a, b); }
        for (int i = 0; i < 50; ++i) if (cs[i]) p_fmi2FreeInstance(cs[i]);
        check("identical", ok);
    } else if (!strcmp(name, "cycles_1000")) {
        double r0 = 0.0;
        for (int i = 0; i < 1050; ++i) {
            fmi2Component x = inst("cycle");
            if (!x) { s = fmi2Error; break; }
            ready(x); p_fmi2DoStep(x, 0.0, 0.01, fmi2True); p_fmi2Terminate(x); p_fmi2FreeInstance(x);
            if (i == 49) r0 = rss_mb();
        }
        check("rss_bound", rss_mb() - r0 < 2.0);
    } else if (!strcmp(name, "threads_8")) {
        pthread_t th[8];
        double o[8][5];
        int ok = 1;
        c = inst("serial"); ready(c); run(c, 2000, 0.0); outs(c, a);
        for (int i = 0; i < 8; ++i) pthread_create(&th[i], NULL, thread_run, o[i]);
        for (int i = 0; i < 8; ++i) { pthread_join(th[i], NULL); ok = ok && same5(a, o[i]); }
        check("identical", ok);
    } else {
        fprintf(stderr, "unknown case %s\n", name);
        return 2;
    }
    printf("status %d\n", (int)s);
    if (c) p_fmi2FreeInstance(c);
    printf("survived\n");
    return 0;
}

int main(int argc, char **argv) {
    void *lib;
    if (argc != 5) {
        fprintf(stderr, "usage: %s LIBRARY RESOURCE_URI|NULL GUID CASE\n", argv[0]);
        return 2;
    }
    uri = strcmp(argv[2], "NULL") ? argv[2] : NULL;
    guid = argv[3];
    lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
#define L(name) p_##name = (name##TYPE *)dlsym(lib, #name); \
    if (!p_##name) { fprintf(stderr, "missing symbol %s\n", #name); return 2; }
    L(fmi2Instantiate) L(fmi2FreeInstance) L(fmi2SetupExperiment) L(fmi2EnterInitializationMode)
    L(fmi2ExitInitializationMode) L(fmi2Terminate) L(fmi2Reset) L(fmi2SetReal) L(fmi2GetReal) L(fmi2DoStep)
    L(fmi2GetFMUstate) L(fmi2SetFMUstate) L(fmi2FreeFMUstate) L(fmi2SerializedFMUstateSize)
    L(fmi2SerializeFMUstate) L(fmi2DeSerializeFMUstate) L(fmi2GetBooleanStatus) L(fmi2GetRealStatus)
#undef L
    setvbuf(stdout, NULL, _IOLBF, 0);
    int rc = run_case(argv[4]);
    dlclose(lib);
    return rc;
}
