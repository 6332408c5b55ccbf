/* What our FMI 2.0 benchmark hosts (fmi2_host.c, fmi2_duty_host.c) share: the logger (every message to stderr
 * as "[instance status category] message", the message used as the printf format as FMI 2.0 specifies), the
 * Co-Simulation functions they load, and the instance's start. (fault_host.c has its own logger: it reports
 * messages on stdout for the fault catalogue.) Include after host_platform.h and fmi2Functions.h. */
#ifndef HOST_FMI2_H
#define HOST_FMI2_H

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

static void host_logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                        fmi2String category, fmi2String message, ...) {
    va_list ap;
    (void)env;
    va_start(ap, message);
    fprintf(stderr, "[%s %d %s] ", name, (int)status, category);
    vfprintf(stderr, message, ap);
    fprintf(stderr, "\n");
    va_end(ap);
}

/* in main(), with `lib` open: the Co-Simulation functions as local pointers named after them (LOAD) */
#define LOAD_FMI2_CS                                                                                     \
    LOAD(fmi2Instantiate) LOAD(fmi2SetupExperiment) LOAD(fmi2EnterInitializationMode)                   \
    LOAD(fmi2ExitInitializationMode) LOAD(fmi2SetReal) LOAD(fmi2GetReal) LOAD(fmi2DoStep)                \
    LOAD(fmi2Terminate) LOAD(fmi2FreeInstance)

/* a Co-Simulation instance "host" of guid at the resource URI, set up and initialised at t = 0 with the
   stderr logger; NULL (the reason on stderr) if a call failed */
static fmi2Component host_fmi2_start(fmi2InstantiateTYPE *instantiate, fmi2SetupExperimentTYPE *setup,
                                     fmi2EnterInitializationModeTYPE *enter, fmi2ExitInitializationModeTYPE *exit_,
                                     const char *guid, const char *uri) {
    static const fmi2CallbackFunctions cb = {host_logger, calloc, free, NULL, NULL};
    fmi2Component c = instantiate("host", fmi2CoSimulation, guid, uri, &cb, fmi2False, fmi2False);
    if (!c) {
        fprintf(stderr, "fmi2Instantiate failed\n");
        return NULL;
    }
    if (setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) > fmi2Warning || enter(c) > fmi2Warning ||
        exit_(c) > fmi2Warning) {
        fprintf(stderr, "initialization failed\n");
        return NULL;
    }
    return c;
}

#endif
