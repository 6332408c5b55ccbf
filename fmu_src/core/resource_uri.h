/* Resource locations (resource_uri.c): shared by the model core and the pythonfmu guard. */
#ifndef RESOURCE_URI_H
#define RESOURCE_URI_H

#include <stddef.h>
#include <stdio.h>

/* file URI (RFC 8089 forms) to a file-system path; windows selects drive-letter / UNC rules.
   Returns 0, or -1 with a reason in err. */
int cc_uri_to_path(const char *uri, int windows, char *out, size_t len, char *err, size_t errlen);
/* fopen of a UTF-8 path (wide-character API on Windows) */
FILE *cc_fopen(const char *path, const char *mode);

#endif
