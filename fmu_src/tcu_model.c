/* The production TCU's clutch model: see tcu_model.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "clutch_cover.h"
#include "clutch_tables.h"
#include "tcu_model.h"

#if defined(_WIN32)
#define TM_EXPORT __declspec(dllexport)
#else
#define TM_EXPORT __attribute__((visibility("default")))
#endif

struct TcuModel {
    Table table;
    CcCover cover; /* this instance's: its frame memo and search hints follow this model's calls alone */
    double wear, gain;
};

TM_EXPORT TcuModel *tm_open(const char *dir, const double *cover, int n_cover, double lever_ratio, double x_kiss_ref,
                  double wear, double gain, char *err, size_t errlen) {
    TcuModel *m;
    if (n_cover != CV_NPAR) {
        snprintf(err, errlen, "tcu_model: %d cover parameters given, the cover takes %d", n_cover, CV_NPAR);
        return NULL;
    }
    m = (TcuModel *)calloc(1, sizeof *m);
    if (!m) { snprintf(err, errlen, "tcu_model: out of memory"); return NULL; }
    if (cc_table_load(&m->table, dir, err, errlen) != 0) { free(m); return NULL; }
    cc_cover_prepare(&m->cover, cover, lever_ratio, x_kiss_ref, &m->table);
    m->wear = wear;
    m->gain = gain;
    return m;
}

TM_EXPORT void tm_close(TcuModel *m) {
    if (!m) return;
    cc_table_free(&m->table);
    free(m);
}

TM_EXPORT double tm_torque(TcuModel *m, double x_to, double theta_cs, double theta_cm) {
    CcCoverState st;
    if (cc_cover_state(&m->cover, &m->table, x_to, theta_cs, theta_cm, m->wear, &st) != 0) return NAN;
    return m->gain * st.clamp;
}
