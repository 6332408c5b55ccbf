/*
 * The pythonfmu FMU's front door: a thin FMI 2.0 Co-Simulation library in front of pythonfmu's
 * wrapper (shipped next to it as CushionClutch_pythonfmu.<so|dll>), which it loads on the first
 * fmi2Instantiate and to which it forwards every call unchanged.
 *
 * It exists for what pythonfmu's wrapper (0.7) does before any slave code runs and that kills the
 * host: a NULL resource location (std::string from NULL: abort), a resource folder without the
 * slave (NULL dereference: SIGSEGV), and percent-encoded characters other than %20 in the
 * location (the wrapper decodes only %20, then cannot find the slave: SIGSEGV). Here:
 *   - the GUID is checked against the one this FMU was built with (pythonfmu does not check it);
 *   - the location is decoded (resource_uri.c) and the folder must hold the slave module;
 *   - the wrapper gets the location in the only form it decodes correctly ("file://" + the path
 *     with spaces as %20), or the call is refused if the path itself holds "%20";
 *   - every refusal is logged through the host's logger (as a "%s" argument, never as the format)
 *     and fmi2Instantiate returns NULL, as FMI 2.0 asks.
 * The wrapper library is never unloaded (pythonfmu's interpreter must outlive its last instance).
 *
 * It also gives the slave the statuses the wrapper cannot return (fmi2Warning, fmi2Error: the wrapper
 * answers every call fmi2OK, or fmi2Discard from a doStep that returned False). Each instance is a
 * Guard holding the wrapper's instance; the wrapper gets the guard's logger, through which the slave
 * sends a message of category CC_STATUS_CATEGORY with the status the call returns (cushion_slave.py,
 * STATUS_CATEGORY). Such a message is not passed on; the call returns the worst of the wrapper's
 * status and the slave's. The wrapper runs with loggingOn = true (it would drop every message,
 * these too, otherwise); the guard passes on what the native FMU would: Warning and worse always (the
 * validity warnings of issue 28 reach every host's log), OK messages only with loggingOn.
 *
 * The host never aborts at exit (issue 28; Linux). pythonfmu 0.7's wrapper keeps its interpreter state in a
 * static std::shared_ptr and resets it again in a library destructor (finalizePythonInterpreter). At process
 * exit the static's destructor (an atexit entry) runs first and frees the state; the library destructor
 * (run later by the dynamic linker) then releases the freed block again: a use-after-free and double free
 * that valgrind shows and that aborts the host after a complete, correct run (free(): corrupted ... chunks,
 * exit -6; how often depends on the heap layout). Two things here:
 *   - right after loading the wrapper the guard registers an exit handler that calls the wrapper's own
 *     release (finalizePythonInterpreter, exported). Exit handlers run last-registered first, so it runs
 *     before the wrapper's static destructor, while the state is alive; the static destructor and the library
 *     destructor then find an empty pointer. (Unloading the wrapper instead does not work: as a C++ library
 *     with unique symbols it is never unmapped.) The guard pins itself in memory (RTLD_NODELETE) so that the
 *     handler's code is still there at exit after a host's dlclose;
 *   - where the host has not started Python itself, the guard starts it (Py_InitializeEx(0): no signal
 *     handlers, then releases the GIL) before the wrapper's first instance. The wrapper then sees a running
 *     interpreter, which it never finalizes (its finalizer is the other code that ran at exit), and neither
 *     does the guard. A Python host (fmpy) is left as it is.
 * On Windows the wrapper behaves as shipped (its Python DLL is not reachable from here).
 */
#ifndef _WIN32
#define _GNU_SOURCE /* dladdr */
#endif
#include "cushion_guid.h" /* CC_GUID, generated when the FMU is built */
#include "fmi2Functions.h"
#include "resource_uri.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _WIN32
#include <windows.h>
#define WRAPPER_NAME "CushionClutch_pythonfmu.dll"
#define IS_WINDOWS 1
#else
#include <dlfcn.h>
#define WRAPPER_NAME "CushionClutch_pythonfmu.so"
#define IS_WINDOWS 0
#endif

#define PATH_MAX_LEN 4096
/* category of the slave's status messages: cushion_slave.STATUS_CATEGORY */
#define CC_STATUS_CATEGORY "cushionReturnStatus"

static void *wrapper = NULL;

/* one instance: the wrapper's instance, the host's callbacks and the ones given to the wrapper */
typedef struct {
    fmi2Component inner;
    fmi2CallbackFunctions host, mine;
    int logging_on;
    int status; /* the slave's status for the call under way */
} Guard;

/* the wrapper's logger: status messages are kept, the others passed on as the wrapper sends them
   (the message is the format, '%' doubled by the slave) */
static void guard_logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                         fmi2String message, ...) {
    Guard *g = (Guard *)env;
    if (category && strcmp(category, CC_STATUS_CATEGORY) == 0) {
        if ((int)status > g->status) g->status = (int)status;
        return;
    }
    if (!g->logging_on && status < fmi2Warning) return;
    g->host.logger(g->host.componentEnvironment, name, status, category, message ? message : "");
}

#ifndef _WIN32
/* at process exit, before the wrapper's static destructors: the wrapper's own release of its interpreter
   state (its library destructor's job, which would otherwise run after the state was freed; see the top) */
static void unload_wrapper_at_exit(void) {
    void (*fin)(void) = wrapper ? (void (*)(void))dlsym(wrapper, "finalizePythonInterpreter") : NULL;
    if (fin) fin(); /* releases the interpreter state while it is alive; later releases find it empty */
}
#endif

static void refuse(const fmi2CallbackFunctions *functions, fmi2String name, const char *fmt, const char *arg) {
    char msg[PATH_MAX_LEN + 512];
    snprintf(msg, sizeof msg, fmt, arg ? arg : "(null)");
    if (functions && functions->logger)
        functions->logger(functions->componentEnvironment, name ? name : "CushionClutch", fmi2Error, "error", "%s",
                          msg);
}

/* load the wrapper next to this library; 0 on success, else a reason in err */
static int load_wrapper(char *err, size_t errlen) {
    char path[PATH_MAX_LEN];
    char *slash;
    if (wrapper) return 0;
#ifdef _WIN32
    {
        HMODULE self = NULL;
        wchar_t wpath[PATH_MAX_LEN], *wslash;
        if (!GetModuleHandleExW(GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS | GET_MODULE_HANDLE_EX_FLAG_UNCHANGED_REFCOUNT,
                                (LPCWSTR)(void *)&load_wrapper, &self) ||
            !GetModuleFileNameW(self, wpath, PATH_MAX_LEN)) {
            snprintf(err, errlen, "cannot locate the FMU's library (error %lu)", (unsigned long)GetLastError());
            return -1;
        }
        wslash = wcsrchr(wpath, L'\\');
        if (!wslash) wslash = wcsrchr(wpath, L'/');
        if (!wslash || (size_t)(wslash - wpath) + 40 > PATH_MAX_LEN) {
            snprintf(err, errlen, "unexpected library path");
            return -1;
        }
        wcscpy(wslash + 1, L"" WRAPPER_NAME);
        wrapper = (void *)LoadLibraryW(wpath);
        if (!wrapper) {
            snprintf(err, errlen, "cannot load %s next to the FMU's library (error %lu; is Python on the PATH?)",
                     WRAPPER_NAME, (unsigned long)GetLastError());
            return -1;
        }
    }
    (void)path;
    (void)slash;
#else
    {
        Dl_info info;
        if (!dladdr((void *)&load_wrapper, &info) || !info.dli_fname) {
            snprintf(err, errlen, "cannot locate the FMU's library");
            return -1;
        }
        if (strlen(info.dli_fname) + 40 > sizeof path) {
            snprintf(err, errlen, "library path too long");
            return -1;
        }
        strcpy(path, info.dli_fname);
        slash = strrchr(path, '/');
        if (slash) strcpy(slash + 1, WRAPPER_NAME);
        else strcpy(path, WRAPPER_NAME);
        wrapper = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!wrapper) {
            snprintf(err, errlen, "cannot load %s: %s", path, dlerror());
            return -1;
        }
        /* after the wrapper's own exit entries, so it runs before them. The handler's code must still be there at
           exit: this library pins itself (RTLD_NODELETE), so a host's dlclose leaves it, and the wrapper, loaded */
        (void)dlopen(info.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        atexit(unload_wrapper_at_exit);
    }
#endif
    return 0;
}

static void *sym(const char *name) {
    if (!wrapper) return NULL;
#ifdef _WIN32
    return (void *)GetProcAddress((HMODULE)wrapper, name);
#else
    return dlsym(wrapper, name);
#endif
}

#ifndef _WIN32
/* libpython's entry points, from the wrapper's dependencies or (a preloaded libpython) the global scope */
static void *py_sym(const char *name) {
    void *f = sym(name);
    return f ? f : dlsym(RTLD_DEFAULT, name);
}
#endif

/* start the interpreter once, before the wrapper's first instance, unless it runs (see the top) */
static void keep_interpreter(void) {
#ifndef _WIN32
    static int done = 0;
    typedef int (*IsInitTYPE)(void);
    typedef void (*InitExTYPE)(int);
    typedef void *(*SaveThreadTYPE)(void);
    IsInitTYPE is_init;
    InitExTYPE init_ex;
    SaveThreadTYPE save_thread;
    if (done) return;
    done = 1;
    is_init = (IsInitTYPE)py_sym("Py_IsInitialized");
    init_ex = (InitExTYPE)py_sym("Py_InitializeEx");
    save_thread = (SaveThreadTYPE)py_sym("PyEval_SaveThread");
    if (is_init) { /* keep libpython loaded for good, whoever loaded it: the interpreter outlives the wrapper */
        Dl_info info;
        if (dladdr((void *)is_init, &info) && info.dli_fname) (void)dlopen(info.dli_fname, RTLD_NOW | RTLD_NOLOAD);
    }
    if (is_init && init_ex && save_thread && !is_init()) {
        init_ex(0);
        (void)save_thread(); /* the wrapper takes the GIL with PyGILState_Ensure in every call */
    }
#endif
}

/* the location in the form pythonfmu's wrapper decodes: it strips "file://" ("file:///" on Windows)
   and replaces "%20" by a space, nothing else */
static int wrapper_uri(const char *dir, char *out, size_t len) {
    size_t o;
    const char *p;
    if (strstr(dir, "%20")) return -1;
    o = (size_t)snprintf(out, len, IS_WINDOWS ? "file:///" : "file://");
    for (p = dir; *p; ++p) {
        if (o + 4 >= len) return -1;
        if (*p == ' ') { memcpy(out + o, "%20", 3); o += 3; }
        else out[o++] = *p;
    }
    out[o] = 0;
    return 0;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    char dir[PATH_MAX_LEN], file[PATH_MAX_LEN + 32], uri[3 * PATH_MAX_LEN + 16], err[PATH_MAX_LEN + 256];
    FILE *probe;
    fmi2InstantiateTYPE *real;
    if (!functions || !functions->logger) return NULL;
    if (!instanceName || !*instanceName) {
        refuse(functions, instanceName, "fmi2Instantiate: instanceName is %s; FMI 2.0 requires a non-empty name",
               instanceName ? "empty" : "NULL");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        refuse(functions, instanceName, "fmi2Instantiate: %s", "the pythonfmu FMU supports Co-Simulation only");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, CC_GUID) != 0) {
        refuse(functions, instanceName, "fmi2Instantiate: GUID %s does not match this FMU's " CC_GUID
               " (a modelDescription.xml from another build?)", fmuGUID);
        return NULL;
    }
    if (!fmuResourceLocation || !*fmuResourceLocation) {
        refuse(functions, instanceName, "fmi2Instantiate: fmuResourceLocation is %s; the pythonfmu FMU needs its "
               "resources folder (slave module and tables)", fmuResourceLocation ? "empty" : "NULL");
        return NULL;
    }
    if (cc_uri_to_path(fmuResourceLocation, IS_WINDOWS, dir, sizeof dir, err, sizeof err) != 0) {
        refuse(functions, instanceName, "fmi2Instantiate: resource location: %s", err);
        return NULL;
    }
    snprintf(file, sizeof file, IS_WINDOWS ? "%s\\slavemodule.txt" : "%s/slavemodule.txt", dir);
    probe = cc_fopen(file, "r");
    if (!probe) {
        refuse(functions, instanceName, "fmi2Instantiate: the resource folder has no slave module "
               "(slavemodule.txt): %s", dir);
        return NULL;
    }
    fclose(probe);
    if (wrapper_uri(dir, uri, sizeof uri) != 0) {
        refuse(functions, instanceName, "fmi2Instantiate: resource folder %s: pythonfmu cannot open a path "
               "holding \"%%20\" or this long; unpack the FMU elsewhere", dir);
        return NULL;
    }
    if (load_wrapper(err, sizeof err) != 0) {
        refuse(functions, instanceName, "fmi2Instantiate: %s", err);
        return NULL;
    }
    keep_interpreter();
    real = (fmi2InstantiateTYPE *)sym("fmi2Instantiate");
    if (!real) {
        refuse(functions, instanceName, "fmi2Instantiate: %s", "the pythonfmu wrapper exports no fmi2Instantiate");
        return NULL;
    }
    {
        Guard *g = (Guard *)calloc(1, sizeof(Guard));
        if (!g) {
            refuse(functions, instanceName, "fmi2Instantiate: %s", "out of memory");
            return NULL;
        }
        g->host = g->mine = *functions;
        g->mine.logger = guard_logger;
        g->mine.componentEnvironment = g;
        g->logging_on = loggingOn != fmi2False;
        g->inner = real(instanceName, fmuType, fmuGUID, uri, &g->mine, visible, fmi2True);
        if (!g->inner) {
            free(g);
            return NULL;
        }
        return g;
    }
}

/* ---- every other call: forwarded to the wrapper's instance (in); the worse of its status and the slave's */
#define FORWARD_C(name, params, args)                                      \
    fmi2Status name params {                                               \
        name##TYPE *f = (name##TYPE *)sym(#name);                          \
        Guard *g = (Guard *)c;                                             \
        fmi2Component in;                                                  \
        fmi2Status r;                                                      \
        if (!g || !f) return fmi2Error;                                    \
        in = g->inner;                                                     \
        g->status = fmi2OK;                                                \
        r = f args;                                                        \
        return (int)r >= g->status ? r : (fmi2Status)g->status;            \
    }

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

void fmi2FreeInstance(fmi2Component c) {
    fmi2FreeInstanceTYPE *f = (fmi2FreeInstanceTYPE *)sym("fmi2FreeInstance");
    Guard *g = (Guard *)c;
    if (!g) return;
    if (f) f(g->inner);
    free(g);
}

/* the wrapper keeps loggingOn = true; the guard filters (categories are not used, as in the native FMU) */
fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) {
    Guard *g = (Guard *)c;
    (void)n;
    (void)cat;
    if (!g) return fmi2Error;
    g->logging_on = on != fmi2False;
    return fmi2OK;
}
FORWARD_C(fmi2SetupExperiment, (fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0, fmi2Boolean stopDef,
                                fmi2Real t1), (in, tolDef, tol, t0, stopDef, t1))
FORWARD_C(fmi2EnterInitializationMode, (fmi2Component c), (in))
FORWARD_C(fmi2ExitInitializationMode, (fmi2Component c), (in))
FORWARD_C(fmi2Terminate, (fmi2Component c), (in))
FORWARD_C(fmi2Reset, (fmi2Component c), (in))
FORWARD_C(fmi2GetReal, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]), (in, vr, n, v))
FORWARD_C(fmi2GetInteger, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]), (in, vr, n, v))
FORWARD_C(fmi2GetBoolean, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]), (in, vr, n, v))
FORWARD_C(fmi2GetString, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]), (in, vr, n, v))
FORWARD_C(fmi2SetReal, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]), (in, vr, n, v))
FORWARD_C(fmi2SetInteger, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]),
          (in, vr, n, v))
FORWARD_C(fmi2SetBoolean, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]),
          (in, vr, n, v))
FORWARD_C(fmi2SetString, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]),
          (in, vr, n, v))
FORWARD_C(fmi2GetFMUstate, (fmi2Component c, fmi2FMUstate *s), (in, s))
FORWARD_C(fmi2SetFMUstate, (fmi2Component c, fmi2FMUstate s), (in, s))
FORWARD_C(fmi2FreeFMUstate, (fmi2Component c, fmi2FMUstate *s), (in, s))
FORWARD_C(fmi2SerializedFMUstateSize, (fmi2Component c, fmi2FMUstate s, size_t *size), (in, s, size))
FORWARD_C(fmi2SerializeFMUstate, (fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t size), (in, s, b, size))
FORWARD_C(fmi2DeSerializeFMUstate, (fmi2Component c, const fmi2Byte b[], size_t size, fmi2FMUstate *s),
          (in, b, size, s))
FORWARD_C(fmi2GetDirectionalDerivative, (fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                         const fmi2ValueReference z[], size_t nz, const fmi2Real dv[], fmi2Real d[]),
          (in, u, nu, z, nz, dv, d))
FORWARD_C(fmi2SetRealInputDerivatives, (fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], const fmi2Real v[]), (in, vr, n, order, v))
FORWARD_C(fmi2GetRealOutputDerivatives, (fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                         const fmi2Integer order[], fmi2Real v[]), (in, vr, n, order, v))
FORWARD_C(fmi2DoStep, (fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior), (in, t, h, noSetPrior))
FORWARD_C(fmi2CancelStep, (fmi2Component c), (in))
FORWARD_C(fmi2GetStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Status *v), (in, k, v))
FORWARD_C(fmi2GetRealStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Real *v), (in, k, v))
FORWARD_C(fmi2GetIntegerStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Integer *v), (in, k, v))
/* fmi2Terminated: false. pythonfmu's wrapper answers true after any doStep that returned fmi2Discard, but every
   Discard of the slave is recoverable (a refused step changes nothing; the next valid step proceeds), as in the
   native FMU (issue 39); fmpy's simulate_fmu would otherwise end the run quietly at the first refused step */
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v) {
    if (c && k == fmi2Terminated && v) {
        *v = fmi2False;
        return fmi2OK;
    }
    {
        fmi2GetBooleanStatusTYPE *f = (fmi2GetBooleanStatusTYPE *)sym("fmi2GetBooleanStatus");
        Guard *g = (Guard *)c;
        if (!g || !f) return fmi2Error;
        return f(g->inner, k, v);
    }
}
FORWARD_C(fmi2GetStringStatus, (fmi2Component c, const fmi2StatusKind k, fmi2String *v), (in, k, v))
