/* Test driver of cc_uri_to_path: uri_driver WINDOWS URI... prints one line per URI:
   "ok <path>" or "error <reason>". Built with gcc against fmu_src/core/resource_uri.c. */
#include <stdio.h>
#include <stdlib.h>

#include "resource_uri.h"

int main(int argc, char **argv) {
    char out[4096], err[600];
    int k, windows;
    if (argc < 2) return 2;
    windows = atoi(argv[1]);
    for (k = 2; k < argc; ++k) {
        if (cc_uri_to_path(argv[k], windows, out, sizeof out, err, sizeof err) == 0)
            printf("ok %s\n", out);
        else
            printf("error %s\n", err);
    }
    return 0;
}
