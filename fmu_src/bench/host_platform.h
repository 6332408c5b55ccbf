/* The platform layer of our FMI hosts (fmi2_host.c, fmi2_duty_host.c, fmi3_host.c): load a shared library and read a
 * monotonic clock, with dlopen/clock_gettime on POSIX and LoadLibrary/QueryPerformanceCounter on
 * Windows (the hosts are cross-compiled with zig and run under Wine). */
#ifndef HOST_PLATFORM_H
#define HOST_PLATFORM_H

#include <stdio.h>

#ifdef _WIN32
#include <windows.h>
#define LIB HMODULE
#define OPEN(path) LoadLibraryA(path)
#define SYM(lib, name) ((void *)GetProcAddress(lib, name))
#define CLOSE(lib) FreeLibrary(lib)
static double now_s(void) {
    LARGE_INTEGER f, t;
    QueryPerformanceFrequency(&f);
    QueryPerformanceCounter(&t);
    return (double)t.QuadPart / (double)f.QuadPart;
}
#else
#include <dlfcn.h>
#include <time.h>
#define LIB void *
#define OPEN(path) dlopen(path, RTLD_NOW | RTLD_LOCAL)
#define SYM(lib, name) dlsym(lib, name)
#define CLOSE(lib) dlclose(lib)
static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}
#endif

/* LOAD(fmi2DoStep) declares a pointer of the FMI type named after the function, read from `lib`;
 * a missing symbol ends main() with exit code 2. */
#define LOAD(name) \
    name##TYPE *name = (name##TYPE *)SYM(lib, #name); \
    if (!name) { fprintf(stderr, "missing symbol %s\n", #name); return 2; }

#endif
