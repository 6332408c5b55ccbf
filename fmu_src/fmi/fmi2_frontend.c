/*
 * CushionClutch: FMI 2.0 front end (Co-Simulation and Model Exchange) over the model core
 * (clutch_core.h). Only the FMI 2.0 API is exported. cushion_guid.h is written by the FMU build.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "clutch_core.h"
#include "cushion_guid.h"
#include "fmi2Functions.h"

#ifdef _WIN32
#define CC_WINDOWS 1
#else
#define CC_WINDOWS 0
#endif

typedef struct {
    CcModel m; /* first: the core's log context is the Comp */
    fmi2CallbackFunctions cb;
    char name[256];
} Comp;

static void log_sink(void *ctx, int status, const char *category, const char *message) {
    Comp *c = (Comp *)ctx;
    /* the message is data, never a format */
    c->cb.logger(c->cb.componentEnvironment, c->name, (fmi2Status)status, category, "%s", message);
}

#define COMP(ret)                          \
    Comp *c = (Comp *)comp;                \
    if (!c) return ret;                    \
    CcModel *m = &c->m;                    \
    (void)m;

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean loggingOn, size_t n, const fmi2String cats[]) {
    COMP(fmi2Error)
    (void)n; (void)cats;
    m->logging_on = loggingOn != fmi2False;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible, fmi2Boolean loggingOn) {
    Comp *c;
    char dir[4096], err[600];
    (void)visible;
    if (!functions || !functions->logger) return NULL;
    c = (Comp *)calloc(1, sizeof(Comp));
    if (!c) return NULL;
    c->cb = *functions;
    snprintf(c->name, sizeof c->name, "%s", name ? name : "CushionClutch");
    c->m.logger = log_sink;
    c->m.log_ctx = c;
    if (type != fmi2CoSimulation && type != fmi2ModelExchange) {
        cc_log(&c->m, CC_ERROR, "fmi2Instantiate: unknown fmi2Type %d", (int)type);
    } else if (!guid || strcmp(guid, CC_GUID) != 0) {
        cc_log(&c->m, CC_ERROR, "fmi2Instantiate: GUID %s does not match this binary's %s (modelDescription.xml "
               "and binary are from different builds)", guid ? guid : "(null)", CC_GUID);
    } else if (!resources) {
        cc_log(&c->m, CC_ERROR, "fmi2Instantiate: no fmuResourceLocation given: the tables cannot be found");
    } else if (cc_uri_to_path(resources, CC_WINDOWS, dir, sizeof dir, err, sizeof err) != 0) {
        cc_log(&c->m, CC_ERROR, "fmi2Instantiate: %s", err);
    } else if (cc_instantiate(&c->m, dir, type == fmi2ModelExchange, log_sink, c, loggingOn != fmi2False) == 0) {
        return c;
    }
    cc_free(&c->m);
    free(c);
    return NULL;
}

void fmi2FreeInstance(fmi2Component comp) {
    Comp *c = (Comp *)comp;
    if (!c) return;
    cc_free(&c->m);
    free(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean tolDef, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stopDef, fmi2Real stop) {
    COMP(fmi2Error)
    (void)tolDef; (void)tol; (void)stopDef; (void)stop;
    if (!cc_allowed(m, PH_INSTANTIATED, "fmi2SetupExperiment")) return fmi2Error;
    if (!isfinite(start)) {
        cc_log(m, CC_ERROR, "fmi2SetupExperiment: startTime = %g is not finite", start);
        return fmi2Error;
    }
    m->time = start;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component comp) {
    COMP(fmi2Error)
    return (fmi2Status)cc_enter_init(m, m->time, "fmi2EnterInitializationMode");
}

fmi2Status fmi2ExitInitializationMode(fmi2Component comp) {
    COMP(fmi2Error)
    return (fmi2Status)cc_exit_init(m, "fmi2ExitInitializationMode");
}

fmi2Status fmi2Terminate(fmi2Component comp) {
    COMP(fmi2Error)
    if (!cc_allowed(m, PH_STEP | PH_EVENT | PH_CONT, "fmi2Terminate")) return fmi2Error;
    m->phase = PH_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component comp) {
    COMP(fmi2Error)
    cc_reset(m);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    COMP(fmi2Error)
    return (fmi2Status)cc_get_real(m, vr, n, value, "fmi2GetReal");
}

fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    COMP(fmi2Error)
    return (fmi2Status)cc_set_real(m, vr, n, value, "fmi2SetReal");
}

/* ------------------------------------------------------------- Co-Simulation */
fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    COMP(fmi2Error)
    (void)noSetPrior;
    if (m->me) { cc_log(m, CC_ERROR, "fmi2DoStep: this is a Model Exchange instance"); return fmi2Error; }
    return (fmi2Status)cc_do_step(m, t, h, "fmi2DoStep");
}

fmi2Status fmi2CancelStep(fmi2Component comp) {
    COMP(fmi2Error)
    cc_log(m, CC_ERROR, "fmi2CancelStep: steps are never asynchronous here");
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Status *v) {
    COMP(fmi2Error)
    (void)s; (void)v;
    cc_log(m, CC_ERROR, "fmi2GetStatus: no asynchronous step is pending");
    return fmi2Discard;
}

fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Real *v) {
    COMP(fmi2Error)
    if (s == fmi2LastSuccessfulTime && v) { *v = m->time; return fmi2OK; }
    cc_log(m, CC_ERROR, "fmi2GetRealStatus: only fmi2LastSuccessfulTime is available");
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Boolean *v) {
    COMP(fmi2Error)
    if (s == fmi2Terminated && v) { *v = m->terminated ? fmi2True : fmi2False; return fmi2OK; }
    cc_log(m, CC_ERROR, "fmi2GetBooleanStatus: only fmi2Terminated is available");
    return fmi2Discard;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Integer *v) {
    COMP(fmi2Error)
    (void)s; (void)v;
    cc_log(m, CC_ERROR, "fmi2GetIntegerStatus: no integer status is defined");
    return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component comp, const fmi2StatusKind s, fmi2String *v) {
    COMP(fmi2Error)
    (void)s; (void)v;
    cc_log(m, CC_ERROR, "fmi2GetStringStatus: no string status is defined");
    return fmi2Discard;
}

/* ------------------------------------------------------------ Model Exchange */
#define ME_ONLY(fn)                                                                          \
    if (!m->me) { cc_log(m, CC_ERROR, "%s: this is a Co-Simulation instance", fn); return fmi2Error; }

fmi2Status fmi2EnterEventMode(fmi2Component comp) {
    COMP(fmi2Error)
    ME_ONLY("fmi2EnterEventMode")
    if (!cc_allowed(m, PH_EVENT | PH_CONT, "fmi2EnterEventMode")) return fmi2Error;
    m->phase = PH_EVENT;
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component comp, fmi2EventInfo *info) {
    COMP(fmi2Error)
    ME_ONLY("fmi2NewDiscreteStates")
    if (!cc_allowed(m, PH_EVENT, "fmi2NewDiscreteStates")) return fmi2Error;
    info->newDiscreteStatesNeeded = fmi2False;
    info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = fmi2False;
    info->nextEventTimeDefined = fmi2False;
    info->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component comp) {
    COMP(fmi2Error)
    ME_ONLY("fmi2EnterContinuousTimeMode")
    if (!cc_allowed(m, PH_EVENT, "fmi2EnterContinuousTimeMode")) return fmi2Error;
    m->phase = PH_CONT;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component comp, fmi2Boolean noSetPrior, fmi2Boolean *enterEventMode,
                                       fmi2Boolean *terminateSimulation) {
    COMP(fmi2Error)
    (void)noSetPrior;
    ME_ONLY("fmi2CompletedIntegratorStep")
    if (!cc_allowed(m, PH_CONT, "fmi2CompletedIntegratorStep")) return fmi2Error;
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component comp, fmi2Real time) {
    COMP(fmi2Error)
    ME_ONLY("fmi2SetTime")
    if (cc_set_time(m, time, "fmi2SetTime") != CC_OK) return fmi2Error;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component comp, const fmi2Real x[], size_t nx) {
    COMP(fmi2Error)
    ME_ONLY("fmi2SetContinuousStates")
    if (nx != CC_NSTATES || !x) { cc_log(m, CC_ERROR, "fmi2SetContinuousStates: nx = %lu, expected %d", (unsigned long)nx, CC_NSTATES); return fmi2Error; }
    return (fmi2Status)cc_set_states(m, x, "fmi2SetContinuousStates");
}

fmi2Status fmi2GetDerivatives(fmi2Component comp, fmi2Real der[], size_t nx) {
    COMP(fmi2Error)
    ME_ONLY("fmi2GetDerivatives")
    if (nx != CC_NSTATES || !der) { cc_log(m, CC_ERROR, "fmi2GetDerivatives: nx = %lu, expected %d", (unsigned long)nx, CC_NSTATES); return fmi2Error; }
    return (fmi2Status)cc_derivative(m, der, "fmi2GetDerivatives");
}

fmi2Status fmi2GetEventIndicators(fmi2Component comp, fmi2Real ind[], size_t ni) {
    COMP(fmi2Error)
    (void)ind;
    if (ni != 0) { cc_log(m, CC_ERROR, "fmi2GetEventIndicators: the model has no event indicators"); return fmi2Error; }
    return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component comp, fmi2Real x[], size_t nx) {
    COMP(fmi2Error)
    ME_ONLY("fmi2GetContinuousStates")
    if (nx != CC_NSTATES || !x) { cc_log(m, CC_ERROR, "fmi2GetContinuousStates: nx = %lu, expected %d", (unsigned long)nx, CC_NSTATES); return fmi2Error; }
    return (fmi2Status)cc_get_states(m, x, "fmi2GetContinuousStates");
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component comp, fmi2Real nominal[], size_t nx) {
    COMP(fmi2Error)
    ME_ONLY("fmi2GetNominalsOfContinuousStates")
    if (nx != CC_NSTATES || !nominal) return fmi2Error;
    for (nx = 0; nx < CC_NSTATES; ++nx) nominal[nx] = 300.0; /* K */
    return fmi2OK;
}

/* ------------------------------------------------------------------ FMU state */
fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    COMP(fmi2Error)
    CcState *s;
    if (!state) return fmi2Error;
    s = *state ? (CcState *)*state : (CcState *)malloc(sizeof(CcState));
    if (!s) { cc_log(m, CC_ERROR, "fmi2GetFMUstate: out of memory"); return fmi2Error; }
    cc_state_save(m, s);
    *state = s;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state) {
    COMP(fmi2Error)
    if (!cc_state_check(m, state, state ? sizeof(CcState) : 0, "fmi2SetFMUstate")) return fmi2Error;
    cc_state_load(m, (const CcState *)state);
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    (void)comp;
    if (state && *state) { free(*state); *state = NULL; }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state, size_t *size) {
    (void)comp; (void)state;
    *size = sizeof(CcState);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    COMP(fmi2Error)
    if (!state || !bytes || size < sizeof(CcState)) {
        cc_log(m, CC_ERROR, "fmi2SerializeFMUstate: no state or buffer too small");
        return fmi2Error;
    }
    memcpy(bytes, state, sizeof(CcState));
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) {
    COMP(fmi2Error)
    CcState *s;
    if (!state || !cc_state_check(m, bytes, size, "fmi2DeSerializeFMUstate")) return fmi2Error;
    s = (CcState *)malloc(sizeof(CcState));
    if (!s) { cc_log(m, CC_ERROR, "fmi2DeSerializeFMUstate: out of memory"); return fmi2Error; }
    memcpy(s, bytes, sizeof(CcState));
    *state = s;
    return fmi2OK;
}

/* ------------------------------------------------------------- not supported */
static fmi2Status unsupported(fmi2Component comp, const char *what) {
    COMP(fmi2Error)
    cc_log(m, CC_ERROR, "%s is not supported", what);
    return fmi2Error;
}

static fmi2Status no_such_variables(fmi2Component comp, const char *fn, size_t n) {
    COMP(fmi2Error)
    if (n == 0) return fmi2OK;
    cc_log(m, CC_ERROR, "%s: unknown value reference (the model has Real variables only)", fn);
    return fmi2Error;
}

/* the one integer variable: the table set's enumeration spring (clutch_core.c; more than one set carried) */
fmi2Status fmi2GetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    size_t k;
    COMP(fmi2Error)
    for (k = 0; k < n; ++k) {
        long long x;
        int status = cc_get_integer(m, vr ? &vr[k] : NULL, 1, v ? &x : NULL, "fmi2GetInteger");
        if (status != CC_OK) return (fmi2Status)status;
        v[k] = (fmi2Integer)x;
    }
    return fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
    (void)vr; (void)v; return no_such_variables(c, "fmi2GetBoolean", n);
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    (void)vr; (void)v; return no_such_variables(c, "fmi2GetString", n);
}
fmi2Status fmi2SetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    size_t k;
    COMP(fmi2Error)
    for (k = 0; k < n; ++k) {
        long long x = v ? v[k] : 0;
        int status = cc_set_integer(m, vr ? &vr[k] : NULL, 1, v ? &x : NULL, "fmi2SetInteger");
        if (status != CC_OK) return (fmi2Status)status;
    }
    return fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
    (void)vr; (void)v; return no_such_variables(c, "fmi2SetBoolean", n);
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    (void)vr; (void)v; return no_such_variables(c, "fmi2SetString", n);
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real du[], fmi2Real dz[]) {
    (void)u; (void)nu; (void)z; (void)nz; (void)du; (void)dz;
    return unsupported(c, "fmi2GetDirectionalDerivative");
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)n; (void)order; (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives");
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)n; (void)order; (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives");
}
