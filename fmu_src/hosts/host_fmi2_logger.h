/* The FMI 2.0 logger of our benchmark hosts (fmi2_host.c, fmi2_duty_host.c): every message to stderr as
 * "[instance status category] message", the message used as the printf format as FMI 2.0 specifies.
 * (fault_host.c has its own logger: it reports messages on stdout for the fault catalogue.) */
#ifndef HOST_FMI2_LOGGER_H
#define HOST_FMI2_LOGGER_H

#include <stdarg.h>
#include <stdio.h>

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list ap;
    (void)env;
    va_start(ap, message);
    fprintf(stderr, "[%s %d %s] ", name, (int)status, category);
    vfprintf(stderr, message, ap);
    fprintf(stderr, "\n");
    va_end(ap);
}

#endif
