/*
 * Resource locations: the FMI resource URI -> file-system path conversion (RFC 8089 forms, Windows
 * drive letters and UNC shares) and fopen of a UTF-8 path. Shared by the model core (clutch_tables.c)
 * and the pythonfmu guard (pythonfmu_guard.c); no model code here.
 */
#include "resource_uri.h"

#include <stdio.h>
#include <string.h>
#ifdef _WIN32
#include <windows.h>
#endif

FILE *cc_fopen(const char *path, const char *mode) {
#ifdef _WIN32
    wchar_t wpath[4096], wmode[8];
    if (!MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, path, -1, wpath, 4096) ||
        !MultiByteToWideChar(CP_UTF8, 0, mode, -1, wmode, 8))
        return NULL;
    return _wfopen(wpath, wmode);
#else
    return fopen(path, mode);
#endif
}

/* --------------------------------------------------------------- URI -> path */
static int hexval(char ch) {
    if (ch >= '0' && ch <= '9') return ch - '0';
    if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
    if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
    return -1;
}

static int is_drive(const char *p) {
    return ((p[0] >= 'A' && p[0] <= 'Z') || (p[0] >= 'a' && p[0] <= 'z')) && (p[1] == ':' || p[1] == '|') &&
           (p[2] == '/' || p[2] == '\\' || p[2] == 0);
}

/* file:///C:/a%20b -> C:\a b (windows) ; file:///a/b -> /a/b ; file://localhost/a -> /a ;
   file:/C:/a, file://C:/a -> C:\a ; file://server/share/x -> \\server\share\x (windows; refused on POSIX).
   A string without the file: scheme is taken as a path as it is. Trailing separators are dropped. */
int cc_uri_to_path(const char *uri, int windows, char *out, size_t len, char *err, size_t errlen) {
    const char *p = uri, *host = NULL;
    size_t o = 0, hostlen = 0;
    if (!uri || !*uri) { snprintf(err, errlen, "empty resource location"); return -1; }
    if (strncmp(p, "file:", 5) != 0) {
        if (strlen(p) + 1 > len) { snprintf(err, errlen, "resource path too long"); return -1; }
        strcpy(out, p);
        o = strlen(out);
        goto trim;
    }
    p += 5;
    if (p[0] == '/' && p[1] == '/') { /* authority */
        const char *a = p + 2, *slash = a;
        while (*slash && *slash != '/') ++slash;
        if (windows && is_drive(a)) { /* file://C:/x (non-standard, seen in the wild) */
            p = a;
        } else {
            host = a;
            hostlen = (size_t)(slash - a);
            p = slash;
            if (hostlen == 0 || (hostlen == 9 && strncmp(host, "localhost", 9) == 0)) host = NULL;
        }
    }
    if (host) {
        if (!windows) {
            snprintf(err, errlen, "file URI names the host '%.*s': only local files can be read", (int)hostlen,
                     host);
            return -1;
        }
        if (hostlen + 3 > len) { snprintf(err, errlen, "resource path too long"); return -1; }
        out[o++] = '/'; out[o++] = '/';
        memcpy(out + o, host, hostlen);
        o += hostlen;
    } else if (windows && p[0] == '/' && is_drive(p + 1)) {
        ++p; /* /C:/x -> C:/x */
    }
    for (; *p; ++p) {
        char ch = *p;
        if (ch == '?' || ch == '#') break;
        if (ch == '%') {
            int hi = hexval(p[1]), lo = hi < 0 ? -1 : hexval(p[2]);
            if (hi < 0 || lo < 0) {
                snprintf(err, errlen, "bad percent-encoding in resource location %s", uri);
                return -1;
            }
            ch = (char)(hi * 16 + lo);
            if (ch == 0) { snprintf(err, errlen, "%%00 in resource location %s", uri); return -1; }
            p += 2;
        }
        if (o + 2 > len) { snprintf(err, errlen, "resource path too long"); return -1; }
        out[o++] = ch;
    }
    if (windows && o >= 2 && out[1] == '|') out[1] = ':';
trim:
    while (o > 1 && (out[o - 1] == '/' || (windows && out[o - 1] == '\\'))) {
        if (windows && o == 3 && out[1] == ':') break; /* keep C:/ */
        --o;
    }
    out[o] = 0;
    if (windows) {
        size_t k;
        for (k = 0; k < o; ++k)
            if (out[k] == '/') out[k] = '\\';
    }
    return 0;
}
