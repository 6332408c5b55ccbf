/*
 * The production TCU's clutch model (tcu_model.c): the torque of the TCU's own characteristic (its table set,
 * cover and wear; the nominal, constant mu) through the clutch model's public table and cover functions, the
 * same code the FMU runs (clutch_tables.c, clutch_cover.c). One instance per model: the cover keeps its frame
 * memo and search hints per instance. Loaded with cffi by cushion_clutch/launch/tcu_model.py (this header is
 * its cdef: declarations only, no preprocessor lines).
 */
typedef struct TcuModel TcuModel;

/* the tables of <dir>/tables (force_deflection.csv, kiss_point.csv), the cover parameters (CV_NPAR values in the
   order of cover.CoverParameters' fields), lever ratio (1), kiss point at reference (m), facing wear (m) and the
   torque gain n_surfaces mu R_eq (m); NULL on failure with the reason in err */
TcuModel *tm_open(const char *dir, const double *cover, int n_cover, double lever_ratio, double x_kiss_ref,
                  double wear, double gain, char *err, size_t errlen);
void tm_close(TcuModel *m);
/* torque (N.m) at bearing position x_to (m), theta_cs and theta_cm (K): gain times the cover's clamp force;
   NaN if the diaphragm cannot hold the cushion there (the caller asks the Python model) */
double tm_torque(TcuModel *m, double x_to, double theta_cs, double theta_cm);
/* the inverse (clutch_model.x_to_for_torque, cover.py _Frame.x_for_clamp): the smallest bearing position (m) whose
   torque reaches torque (N.m) at theta_cs and theta_cm (K), the cushion's compression found to tol_m / lever ratio
   (tol_m in m); at or below the cushion's first force its first-contact position, above the closed capacity the
   lift-off position; NaN if the diaphragm cannot hold the cushion (the caller asks the Python model) */
double tm_x_for_torque(TcuModel *m, double torque, double theta_cs, double theta_cm, double tol_m);
