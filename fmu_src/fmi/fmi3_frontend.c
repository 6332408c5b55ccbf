/*
 * CushionClutch: FMI 3.0 front end (Co-Simulation and Model Exchange) over the model core
 * (clutch_core.h). Only the FMI 3.0 API is exported. cushion_guid.h is written by the FMU build
 * (the instantiationToken). Value reference CC_VR_TIME is the independent variable time.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "clutch_core.h"
#include "cushion_guid.h"
#include "fmi3Functions.h"

#ifdef _WIN32
#define CC_WINDOWS 1
#else
#define CC_WINDOWS 0
#endif

typedef struct {
    CcModel m;
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log_message;
    int event_mode_used;
} Inst;

static void log_sink(void *ctx, int status, const char *category, const char *message) {
    Inst *c = (Inst *)ctx;
    if (c->log_message) c->log_message(c->env, (fmi3Status)status, category, message);
}

#define INST(ret)               \
    Inst *c = (Inst *)instance; \
    if (!c) return ret;         \
    CcModel *m = &c->m;         \
    (void)m;

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t n, const fmi3String cats[]) {
    INST(fmi3Error)
    (void)n; (void)cats;
    m->logging_on = loggingOn != fmi3False;
    return fmi3OK;
}

static Inst *instantiate(fmi3String token, fmi3String resourcePath, int me, fmi3Boolean loggingOn,
                         fmi3InstanceEnvironment env, fmi3LogMessageCallback logMessage, const char *fn) {
    Inst *c = (Inst *)calloc(1, sizeof(Inst));
    char dir[4096], err[600];
    if (!c) return NULL;
    c->env = env;
    c->log_message = logMessage;
    c->m.logger = log_sink;
    c->m.log_ctx = c;
    if (!token || strcmp(token, CC_GUID) != 0) {
        cc_log(&c->m, CC_ERROR, "%s: instantiationToken %s does not match this binary's %s (modelDescription.xml "
               "and binary are from different builds)", fn, token ? token : "(null)", CC_GUID);
    } else if (!resourcePath) {
        cc_log(&c->m, CC_ERROR, "%s: no resourcePath given: the tables cannot be found", fn);
    } else if (cc_uri_to_path(resourcePath, CC_WINDOWS, dir, sizeof dir, err, sizeof err) != 0) {
        cc_log(&c->m, CC_ERROR, "%s: %s", fn, err);
    } else if (cc_instantiate(&c->m, dir, me, log_sink, c, loggingOn != fmi3False) == 0) {
        return c;
    }
    cc_free(&c->m);
    free(c);
    return NULL;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resourcePath,
                                          fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment env,
                                          fmi3LogMessageCallback logMessage) {
    (void)name; (void)visible;
    return instantiate(token, resourcePath, 1, loggingOn, env, logMessage, "fmi3InstantiateModelExchange");
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resourcePath,
                                         fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
                                         fmi3Boolean earlyReturnAllowed, const fmi3ValueReference required[],
                                         size_t nRequired, fmi3InstanceEnvironment env,
                                         fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback update) {
    Inst *c;
    (void)name; (void)visible; (void)earlyReturnAllowed; (void)required; (void)nRequired; (void)update;
    c = instantiate(token, resourcePath, 0, loggingOn, env, logMessage, "fmi3InstantiateCoSimulation");
    if (c) c->event_mode_used = eventModeUsed != fmi3False;
    return c;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resourcePath,
                                               fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment env, fmi3LogMessageCallback logMessage,
                                               fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock) {
    (void)name; (void)token; (void)resourcePath; (void)visible; (void)loggingOn; (void)clockUpdate; (void)lock;
    (void)unlock;
    if (logMessage) logMessage(env, fmi3Error, "logStatusError", "Scheduled Execution is not supported");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) {
    Inst *c = (Inst *)instance;
    if (!c) return;
    cc_free(&c->m);
    free(c);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean tolDef, fmi3Float64 tol,
                                       fmi3Float64 startTime, fmi3Boolean stopDef, fmi3Float64 stopTime) {
    INST(fmi3Error)
    (void)tolDef; (void)tol; (void)stopDef; (void)stopTime;
    if (!isfinite(startTime)) {
        cc_log(m, CC_ERROR, "fmi3EnterInitializationMode: startTime = %g is not finite", startTime);
        return fmi3Error;
    }
    return (fmi3Status)cc_enter_init(m, startTime, "fmi3EnterInitializationMode");
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    int status;
    INST(fmi3Error)
    status = cc_exit_init(m, "fmi3ExitInitializationMode");
    if (status == CC_OK && !m->me && c->event_mode_used) m->phase = PH_EVENT;
    return (fmi3Status)status;
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    INST(fmi3Error)
    if (!cc_allowed(m, m->me ? (PH_EVENT | PH_CONT) : (c->event_mode_used ? PH_STEP : 0), "fmi3EnterEventMode"))
        return fmi3Error;
    m->phase = PH_EVENT;
    return fmi3OK;
}

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    INST(fmi3Error)
    if (m->me || !cc_allowed(m, PH_EVENT, "fmi3EnterStepMode")) {
        if (m->me) cc_log(m, CC_ERROR, "fmi3EnterStepMode: this is a Model Exchange instance");
        return fmi3Error;
    }
    m->phase = PH_STEP;
    return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
    INST(fmi3Error)
    if (!cc_allowed(m, PH_STEP | PH_EVENT | PH_CONT, "fmi3Terminate")) return fmi3Error;
    m->phase = PH_TERMINATED;
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance instance) {
    INST(fmi3Error)
    cc_reset(m);
    return fmi3OK;
}

/* ------------------------------------------------------------------ Float64 */
fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Float64 v[],
                          size_t nValues) {
    size_t k;
    int status;
    INST(fmi3Error)
    if (nValues != n) {
        cc_log(m, CC_ERROR, "fmi3GetFloat64: nValues = %lu differs from nValueReferences = %lu (scalars only)",
               (unsigned long)nValues, (unsigned long)n);
        return fmi3Error;
    }
    for (k = 0; k < n; ++k)
        if (vr[k] == CC_VR_TIME) break;
    if (k == n) return (fmi3Status)cc_get_real(m, vr, n, v, "fmi3GetFloat64");
    for (k = 0; k < n; ++k) { /* with the independent variable: one by one */
        if (vr[k] == CC_VR_TIME) {
            if (!cc_allowed(m, PH_ANY & ~PH_INSTANTIATED, "fmi3GetFloat64")) return fmi3Error;
            v[k] = m->time;
        } else if ((status = cc_get_real(m, &vr[k], 1, &v[k], "fmi3GetFloat64")) != CC_OK) {
            return (fmi3Status)status;
        }
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, const fmi3Float64 v[],
                          size_t nValues) {
    INST(fmi3Error)
    if (nValues != n) {
        cc_log(m, CC_ERROR, "fmi3SetFloat64: nValues = %lu differs from nValueReferences = %lu (scalars only)",
               (unsigned long)nValues, (unsigned long)n);
        return fmi3Error;
    }
    return (fmi3Status)cc_set_real(m, vr, n, v, "fmi3SetFloat64");
}

/* the model has Float64 variables only: other types have no value references */
static fmi3Status no_such(fmi3Instance instance, size_t n, const char *fn) {
    INST(fmi3Error)
    if (n == 0) return fmi3OK;
    cc_log(m, CC_ERROR, "%s: unknown value reference (the model has Float64 variables only)", fn);
    return fmi3Error;
}

#define NO_GET(T, NAME)                                                                                 \
    fmi3Status NAME(fmi3Instance i, const fmi3ValueReference vr[], size_t n, T v[], size_t nv) {        \
        (void)vr; (void)v; (void)nv; return no_such(i, n, #NAME);                                       \
    }
#define NO_SET(T, NAME)                                                                                 \
    fmi3Status NAME(fmi3Instance i, const fmi3ValueReference vr[], size_t n, const T v[], size_t nv) {  \
        (void)vr; (void)v; (void)nv; return no_such(i, n, #NAME);                                       \
    }
NO_GET(fmi3Float32, fmi3GetFloat32) NO_GET(fmi3Int8, fmi3GetInt8) NO_GET(fmi3UInt8, fmi3GetUInt8)
NO_GET(fmi3Int16, fmi3GetInt16) NO_GET(fmi3UInt16, fmi3GetUInt16) NO_GET(fmi3Int32, fmi3GetInt32)
NO_GET(fmi3UInt32, fmi3GetUInt32) NO_GET(fmi3UInt64, fmi3GetUInt64)
NO_GET(fmi3Boolean, fmi3GetBoolean) NO_GET(fmi3String, fmi3GetString)
NO_SET(fmi3Float32, fmi3SetFloat32) NO_SET(fmi3Int8, fmi3SetInt8) NO_SET(fmi3UInt8, fmi3SetUInt8)
NO_SET(fmi3Int16, fmi3SetInt16) NO_SET(fmi3UInt16, fmi3SetUInt16) NO_SET(fmi3Int32, fmi3SetInt32)
NO_SET(fmi3UInt32, fmi3SetUInt32) NO_SET(fmi3UInt64, fmi3SetUInt64)
NO_SET(fmi3Boolean, fmi3SetBoolean) NO_SET(fmi3String, fmi3SetString)

/* Int64 (the type of FMI 3 enumerations): the table set's enumeration spring (clutch_core.c; more than one set) */
fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Int64 v[], size_t nv) {
    size_t k;
    INST(fmi3Error)
    if (nv != n) {
        cc_log(m, CC_ERROR, "fmi3GetInt64: nValues = %lu differs from nValueReferences = %lu (scalars only)",
               (unsigned long)nv, (unsigned long)n);
        return fmi3Error;
    }
    for (k = 0; k < n; ++k) {
        long long x;
        int status = cc_get_integer(m, vr ? &vr[k] : NULL, 1, v ? &x : NULL, "fmi3GetInt64");
        if (status != CC_OK) return (fmi3Status)status;
        v[k] = (fmi3Int64)x;
    }
    return fmi3OK;
}
fmi3Status fmi3SetInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, const fmi3Int64 v[],
                        size_t nv) {
    size_t k;
    INST(fmi3Error)
    if (nv != n) {
        cc_log(m, CC_ERROR, "fmi3SetInt64: nValues = %lu differs from nValueReferences = %lu (scalars only)",
               (unsigned long)nv, (unsigned long)n);
        return fmi3Error;
    }
    for (k = 0; k < n; ++k) {
        long long x = v ? (long long)v[k] : 0;
        int status = cc_set_integer(m, vr ? &vr[k] : NULL, 1, v ? &x : NULL, "fmi3SetInt64");
        if (status != CC_OK) return (fmi3Status)status;
    }
    return fmi3OK;
}

fmi3Status fmi3GetBinary(fmi3Instance i, const fmi3ValueReference vr[], size_t n, size_t sizes[], fmi3Binary v[],
                         size_t nv) {
    (void)vr; (void)sizes; (void)v; (void)nv; return no_such(i, n, "fmi3GetBinary");
}
fmi3Status fmi3SetBinary(fmi3Instance i, const fmi3ValueReference vr[], size_t n, const size_t sizes[],
                         const fmi3Binary v[], size_t nv) {
    (void)vr; (void)sizes; (void)v; (void)nv; return no_such(i, n, "fmi3SetBinary");
}
fmi3Status fmi3GetClock(fmi3Instance i, const fmi3ValueReference vr[], size_t n, fmi3Clock v[]) {
    (void)vr; (void)v; return no_such(i, n, "fmi3GetClock");
}
fmi3Status fmi3SetClock(fmi3Instance i, const fmi3ValueReference vr[], size_t n, const fmi3Clock v[]) {
    (void)vr; (void)v; return no_such(i, n, "fmi3SetClock");
}
fmi3Status fmi3GetIntervalDecimal(fmi3Instance i, const fmi3ValueReference vr[], size_t n, fmi3Float64 iv[],
                                  fmi3IntervalQualifier q[]) {
    (void)vr; (void)iv; (void)q; return no_such(i, n, "fmi3GetIntervalDecimal");
}
fmi3Status fmi3GetIntervalFraction(fmi3Instance i, const fmi3ValueReference vr[], size_t n, fmi3UInt64 c[],
                                   fmi3UInt64 r[], fmi3IntervalQualifier q[]) {
    (void)vr; (void)c; (void)r; (void)q; return no_such(i, n, "fmi3GetIntervalFraction");
}
fmi3Status fmi3GetShiftDecimal(fmi3Instance i, const fmi3ValueReference vr[], size_t n, fmi3Float64 s[]) {
    (void)vr; (void)s; return no_such(i, n, "fmi3GetShiftDecimal");
}
fmi3Status fmi3GetShiftFraction(fmi3Instance i, const fmi3ValueReference vr[], size_t n, fmi3UInt64 c[],
                                fmi3UInt64 r[]) {
    (void)vr; (void)c; (void)r; return no_such(i, n, "fmi3GetShiftFraction");
}
fmi3Status fmi3SetIntervalDecimal(fmi3Instance i, const fmi3ValueReference vr[], size_t n, const fmi3Float64 iv[]) {
    (void)vr; (void)iv; return no_such(i, n, "fmi3SetIntervalDecimal");
}
fmi3Status fmi3SetIntervalFraction(fmi3Instance i, const fmi3ValueReference vr[], size_t n, const fmi3UInt64 c[],
                                   const fmi3UInt64 r[]) {
    (void)vr; (void)c; (void)r; return no_such(i, n, "fmi3SetIntervalFraction");
}
fmi3Status fmi3SetShiftDecimal(fmi3Instance i, const fmi3ValueReference vr[], size_t n, const fmi3Float64 s[]) {
    (void)vr; (void)s; return no_such(i, n, "fmi3SetShiftDecimal");
}
fmi3Status fmi3SetShiftFraction(fmi3Instance i, const fmi3ValueReference vr[], size_t n, const fmi3UInt64 c[],
                                const fmi3UInt64 r[]) {
    (void)vr; (void)c; (void)r; return no_such(i, n, "fmi3SetShiftFraction");
}

/* ------------------------------------------------------------- not supported */
static fmi3Status unsupported(fmi3Instance instance, const char *what) {
    INST(fmi3Error)
    cc_log(m, CC_ERROR, "%s is not supported", what);
    return fmi3Error;
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance i, fmi3ValueReference vr, size_t *n) {
    (void)vr; (void)n; return unsupported(i, "fmi3GetNumberOfVariableDependencies");
}
fmi3Status fmi3GetVariableDependencies(fmi3Instance i, fmi3ValueReference d, size_t e[], fmi3ValueReference ind[],
                                       size_t ei[], fmi3DependencyKind k[], size_t n) {
    (void)d; (void)e; (void)ind; (void)ei; (void)k; (void)n;
    return unsupported(i, "fmi3GetVariableDependencies");
}
fmi3Status fmi3GetDirectionalDerivative(fmi3Instance i, const fmi3ValueReference u[], size_t nu,
                                        const fmi3ValueReference k[], size_t nk, const fmi3Float64 s[], size_t ns,
                                        fmi3Float64 o[], size_t no) {
    (void)u; (void)nu; (void)k; (void)nk; (void)s; (void)ns; (void)o; (void)no;
    return unsupported(i, "fmi3GetDirectionalDerivative");
}
fmi3Status fmi3GetAdjointDerivative(fmi3Instance i, const fmi3ValueReference u[], size_t nu,
                                    const fmi3ValueReference k[], size_t nk, const fmi3Float64 s[], size_t ns,
                                    fmi3Float64 o[], size_t no) {
    (void)u; (void)nu; (void)k; (void)nk; (void)s; (void)ns; (void)o; (void)no;
    return unsupported(i, "fmi3GetAdjointDerivative");
}
fmi3Status fmi3EnterConfigurationMode(fmi3Instance i) { return unsupported(i, "fmi3EnterConfigurationMode"); }
fmi3Status fmi3ExitConfigurationMode(fmi3Instance i) { return unsupported(i, "fmi3ExitConfigurationMode"); }
fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance i) { return unsupported(i, "fmi3EvaluateDiscreteStates"); }
fmi3Status fmi3GetOutputDerivatives(fmi3Instance i, const fmi3ValueReference vr[], size_t n, const fmi3Int32 o[],
                                    fmi3Float64 v[], size_t nv) {
    (void)vr; (void)n; (void)o; (void)v; (void)nv; return unsupported(i, "fmi3GetOutputDerivatives");
}
fmi3Status fmi3ActivateModelPartition(fmi3Instance i, fmi3ValueReference c, fmi3Float64 t) {
    (void)c; (void)t; return unsupported(i, "fmi3ActivateModelPartition");
}

/* ------------------------------------------------------------ events, ME, CS */
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *needUpdate, fmi3Boolean *terminate,
                                    fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged,
                                    fmi3Boolean *nextEventTimeDefined, fmi3Float64 *nextEventTime) {
    INST(fmi3Error)
    if (!cc_allowed(m, PH_EVENT, "fmi3UpdateDiscreteStates")) return fmi3Error;
    if (needUpdate) *needUpdate = fmi3False;
    if (terminate) *terminate = fmi3False;
    if (nominalsChanged) *nominalsChanged = fmi3False;
    if (valuesChanged) *valuesChanged = fmi3False;
    if (nextEventTimeDefined) *nextEventTimeDefined = fmi3False;
    if (nextEventTime) *nextEventTime = 0.0;
    return fmi3OK;
}

#define ME_ONLY(fn)                                                                          \
    if (!m->me) { cc_log(m, CC_ERROR, "%s: this is a Co-Simulation instance", fn); return fmi3Error; }

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    INST(fmi3Error)
    ME_ONLY("fmi3EnterContinuousTimeMode")
    if (!cc_allowed(m, PH_EVENT, "fmi3EnterContinuousTimeMode")) return fmi3Error;
    m->phase = PH_CONT;
    return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetPrior, fmi3Boolean *enterEventMode,
                                       fmi3Boolean *terminateSimulation) {
    INST(fmi3Error)
    (void)noSetPrior;
    ME_ONLY("fmi3CompletedIntegratorStep")
    if (!cc_allowed(m, PH_CONT, "fmi3CompletedIntegratorStep")) return fmi3Error;
    if (enterEventMode) *enterEventMode = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    INST(fmi3Error)
    ME_ONLY("fmi3SetTime")
    if (cc_set_time(m, time, "fmi3SetTime") != CC_OK) return fmi3Error;
    return fmi3OK;
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t nx) {
    INST(fmi3Error)
    ME_ONLY("fmi3SetContinuousStates")
    if (nx != CC_NSTATES || !x) { cc_log(m, CC_ERROR, "fmi3SetContinuousStates: nx = %lu, expected %d", (unsigned long)nx, CC_NSTATES); return fmi3Error; }
    return (fmi3Status)cc_set_states(m, x, "fmi3SetContinuousStates");
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 der[], size_t nx) {
    INST(fmi3Error)
    ME_ONLY("fmi3GetContinuousStateDerivatives")
    if (nx != CC_NSTATES || !der) { cc_log(m, CC_ERROR, "fmi3GetContinuousStateDerivatives: nx = %lu, expected %d", (unsigned long)nx, CC_NSTATES); return fmi3Error; }
    return (fmi3Status)cc_derivative(m, der, "fmi3GetContinuousStateDerivatives");
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 ind[], size_t ni) {
    INST(fmi3Error)
    (void)ind;
    if (ni != 0) { cc_log(m, CC_ERROR, "fmi3GetEventIndicators: the model has no event indicators"); return fmi3Error; }
    return fmi3OK;
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t nx) {
    INST(fmi3Error)
    ME_ONLY("fmi3GetContinuousStates")
    if (nx != CC_NSTATES || !x) { cc_log(m, CC_ERROR, "fmi3GetContinuousStates: nx = %lu, expected %d", (unsigned long)nx, CC_NSTATES); return fmi3Error; }
    return (fmi3Status)cc_get_states(m, x, "fmi3GetContinuousStates");
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nx) {
    INST(fmi3Error)
    ME_ONLY("fmi3GetNominalsOfContinuousStates")
    if (nx != CC_NSTATES || !nominals) return fmi3Error;
    for (nx = 0; nx < CC_NSTATES; ++nx) nominals[nx] = 300.0; /* K */
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *n) {
    INST(fmi3Error)
    *n = 0;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *n) {
    INST(fmi3Error)
    *n = m->me ? CC_NSTATES : 0;
    return fmi3OK;
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
                      fmi3Float64 *lastSuccessfulTime) {
    int status;
    INST(fmi3Error)
    (void)noSetPrior;
    if (m->me) { cc_log(m, CC_ERROR, "fmi3DoStep: this is a Model Exchange instance"); return fmi3Error; }
    status = cc_do_step(m, t, h, "fmi3DoStep");
    if (eventHandlingNeeded) *eventHandlingNeeded = fmi3False;
    if (terminateSimulation) *terminateSimulation = m->terminated ? fmi3True : fmi3False;
    if (earlyReturn) *earlyReturn = fmi3False;
    if (lastSuccessfulTime) *lastSuccessfulTime = m->time;
    return (fmi3Status)status;
}

/* ------------------------------------------------------------------ FMU state */
fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *state) {
    CcState *s;
    INST(fmi3Error)
    if (!state) return fmi3Error;
    s = *state ? (CcState *)*state : (CcState *)malloc(sizeof(CcState));
    if (!s) { cc_log(m, CC_ERROR, "fmi3GetFMUState: out of memory"); return fmi3Error; }
    cc_state_save(m, s);
    *state = s;
    return fmi3OK;
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState state) {
    INST(fmi3Error)
    if (!cc_state_check(m, state, state ? sizeof(CcState) : 0, "fmi3SetFMUState")) return fmi3Error;
    cc_state_load(m, (const CcState *)state);
    return fmi3OK;
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *state) {
    (void)instance;
    if (state && *state) { free(*state); *state = NULL; }
    return fmi3OK;
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState state, size_t *size) {
    (void)instance; (void)state;
    *size = sizeof(CcState);
    return fmi3OK;
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState state, fmi3Byte bytes[], size_t size) {
    INST(fmi3Error)
    if (!state || !bytes || size < sizeof(CcState)) {
        cc_log(m, CC_ERROR, "fmi3SerializeFMUState: no state or buffer too small");
        return fmi3Error;
    }
    memcpy(bytes, state, sizeof(CcState));
    return fmi3OK;
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte bytes[], size_t size, fmi3FMUState *state) {
    CcState *s;
    INST(fmi3Error)
    if (!state || !cc_state_check(m, bytes, size, "fmi3DeserializeFMUState")) return fmi3Error;
    s = (CcState *)malloc(sizeof(CcState));
    if (!s) { cc_log(m, CC_ERROR, "fmi3DeserializeFMUState: out of memory"); return fmi3Error; }
    memcpy(s, bytes, sizeof(CcState));
    *state = s;
    return fmi3OK;
}
