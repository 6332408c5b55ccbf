"""The native step's caches are exact: the branch-free interval search, the table-interval hint, the Newton hints and the
frame memo of the cover (fmu_src/core/clutch_tables.c, clutch_cover.c) give the same bits as the plain searches and
a freshly prepared cover, over random sequences (a C driver over the shipped default tables).

Their speed is measured by ``python -m cushion_clutch.benchmarks.fmu`` (the C host's time per step) and with
callgrind (docs/reference/fmu.md); the C host's ``checksum`` mode compares two builds bit for bit."""
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description

from cushion_clutch.data import DEFAULT_TABLES, fmu_source
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.fmu.native import fmi2_header_dir, stage_sources
from cushion_clutch.model.table_format import table_set_x_kiss_ref

pytestmark = pytest.mark.fmu

DRIVER = r"""
#define CC_DEFINE_VARIABLE_TABLE
#include "clutch_core.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static unsigned long long rng = 88172645463325252ULL;
static double urand(void) { /* xorshift64, [0, 1) */
    rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static int bsearch_interval(const Curve *c, double u) { /* the plain search */
    int lo = 0, hi = c->n - 1;
    while (hi - lo > 1) { int mid = (lo + hi) / 2; if (c->x[mid] <= u) lo = mid; else hi = mid; }
    return lo;
}

static int same(const void *a, const void *b, size_t n) { return memcmp(a, b, n) == 0; }

static int same_bracket(const TBracket *a, const TBracket *b) { /* field by field: the struct has padding; the
                                                                   cover's bracket leaves r0, r1 out */
    return a->c0 == b->c0 && a->c1 == b->c1 && a->i == b->i && same(&a->w, &b->w, 8) &&
           same(&a->first, &b->first, 8) && same(&a->full, &b->full, 8) && a->pr == b->pr &&
           same(&a->inv_span, &b->inv_span, 8);
}

int main(int argc, char **argv) {
    Table tb;
    char err[600];
    double r[CC_NVARS];
    CcCover warm, cold;
    long k, bad = 0, checked = 0;
    int t, j, hint = 0;
    double worst_rel = 0.0;
    if (argc != 2 || cc_table_load(&tb, argv[1], err, sizeof err) != 0) { printf("load failed %s\n", err); return 2; }
    for (k = 0; k < CC_NVARS; ++k) r[k] = CC_VARIABLES[k].start;
    /* 1: the locator finds the binary search's interval: at every knot, its neighbours, and random points */
    for (t = 0; t < tb.nt; ++t) {
        const Curve *c = &tb.curves[t];
        for (j = 0; j < c->n; ++j) {
            double pts[3] = {c->x[j], nextafter(c->x[j], -INFINITY), nextafter(c->x[j], INFINITY)};
            int q;
            for (q = 0; q < 3; ++q) {
                double u = pts[q];
                if (!(u > c->x[0] && u < c->x[c->n - 1])) continue;
                ++checked;
                if (cc_curve_locate(c, u) != bsearch_interval(c, u)) { ++bad; printf("locate mismatch t %d u %.17g\n", t, u); }
            }
        }
        for (k = 0; k < 20000; ++k) {
            double u = c->x[0] + (c->x[c->n - 1] - c->x[0]) * urand();
            if (!(u > c->x[0])) continue;
            ++checked;
            if (cc_curve_locate(c, u) != bsearch_interval(c, u)) { ++bad; printf("locate mismatch t %d u %.17g\n", t, u); }
        }
    }
    /* 2: the bracket with the interval hint equals the one without (table temperatures, beyond both ends) */
    for (k = 0; k < 20000; ++k) {
        TBracket a, b;
        double th = k % 7 == 0 ? tb.theta[k % tb.nt] : -80.0 + 500.0 * urand();
        if (k % 11 == 0) th = nextafter(tb.theta[k % tb.nt], k % 2 ? INFINITY : -INFINITY);
        double delta;
        cc_table_bracket(&tb, th, &a);
        delta = cc_table_bracket_hint(&tb, th, &b, &hint);
        ++checked;
        if (!same_bracket(&a, &b) || !same(&delta, &(double){cc_table_delta(&tb, th)}, 8)) {
            ++bad; printf("bracket mismatch theta %.17g\n", th);
        }
    }
    /* 2b: the cell search of every curve alone and every adjacent pair finds the one cell holding phi (at every
          cell edge, its neighbours, random points, far beyond both ends) */
    for (t = 0; t < 2 * tb.nt - 1; ++t) {
        const CurvePair *p = &tb.pairs[t];
        for (k = 0; k < 3 * (p->m + 2) + 20000; ++k) {
            double phi;
            int i, q = (int)(k / 3);
            if (q <= p->m) {
                double e = q == 0 ? -1e300 : p->cell[q].lo;
                phi = k % 3 == 0 ? e : nextafter(e, k % 3 == 1 ? -INFINITY : INFINITY);
            } else phi = -0.5 + 2.0 * urand();
            if (k % 997 == 0) phi = k % 2 ? 1e30 : -1e30;
            i = cc_pair_locate(p, phi);
            ++checked;
            if (!(i >= 0 && i <= p->m && p->cell[i].lo <= phi && phi < p->cell[i + 1].lo)) {
                ++bad; printf("pair locate mismatch t %d phi %.17g\n", t, phi);
            }
        }
    }
    /* 2c: a bracket's cubic (cc_bracket_force, the cover's) is its curves' Hermite forms blended (cc_table_force,
          spring_table's operations) to 4e-13 relative + 1e-12 N (measured: 1.5e-13): temperatures on, between and beyond the tables, u from
          before first contact to past full compression */
    for (k = 0; k < 200000; ++k) {
        TBracket b;
        CellPt pt;
        double th = k % 7 == 0 ? tb.theta[k % tb.nt] : -80.0 + 500.0 * urand(), u = -0.0006 + 0.003 * urand();
        double f, g;
        int h = 0;
        cc_table_bracket(&tb, th, &b);
        f = cc_bracket_force(&b, u, &h, &pt);
        g = cc_table_force(&tb, u, th);
        ++checked;
        if (!(fabs(f - g) <= 4e-13 * fabs(g) + 1e-12)) { ++bad; printf("bracket force %.17g vs %.17g at theta %.17g u %.17g\n", f, g, th, u); }
        if (fabs(f - g) / (fabs(g) + 1e-300) > worst_rel) worst_rel = fabs(f - g) / (fabs(g) + 1e-300);
    }
    /* 3: a warm cover (hints and frame memo from every call before) answers as a freshly prepared one:
          random bearing positions over the stroke, temperatures that repeat, sit on the tables or beyond */
    cc_cover_prepare(&warm, r + VR_DIAPHRAGM_OUTER_RADIUS_M, r[VR_LEVER_RATIO], r[VR_X_KISS_REF], &tb);
    {
        double th_cs = 350.0, th_cm = 360.0, wear = 0.0;
        for (k = 0; k < 30000; ++k) {
            CcCoverState a, b;
            int ra, rb;
            double x_to = -0.002 + 0.014 * urand();
            if (k % 3 == 0) th_cs = 250.0 + 400.0 * urand();      /* else: the same frame, a new x_to */
            if (k % 17 == 0) th_cs = tb.theta[k % tb.nt] + 273.15;  /* a table temperature (w = 0) */
            if (k % 5 == 0) th_cm = 250.0 + 400.0 * urand();
            if (k % 101 == 0) wear = 0.001 * urand();
            ra = cc_cover_state(&warm, &tb, x_to, th_cs, th_cm, wear, &a);
            cc_cover_prepare(&cold, r + VR_DIAPHRAGM_OUTER_RADIUS_M, r[VR_LEVER_RATIO], r[VR_X_KISS_REF], &tb);
            rb = cc_cover_state(&cold, &tb, x_to, th_cs, th_cm, wear, &b);
            ++checked;
            if (ra != rb || !same(&a, &b, sizeof a)) {
                ++bad;
                if (bad < 10) printf("cover mismatch x_to %.17g theta_cs %.17g theta_cm %.17g\n", x_to, th_cs, th_cm);
            }
        }
    }
    cc_table_free(&tb);
    printf("bracket cubic vs Hermite: worst relative difference %.3g\n", worst_rel);
    printf("checked %ld mismatches %ld\n", checked, bad);
    return bad != 0;
}
"""


def _cover_driver(tmp: Path, driver_c: str, flags: tuple[str, ...] = ()) -> tuple[Path, Path]:
    """A gcc -O2 build of ``driver_c`` with the C tables and cover (no FMI), and a resource folder with the
    default tables: (executable, resource folder); ``flags``: more compiler flags. Skips without gcc."""
    cc = shutil.which("gcc")
    if cc is None:
        pytest.skip("gcc not installed")
    src = tmp / "src"
    stage_sources(src, "{00000000-0000-0000-0000-000000000000}", 2, table_set_x_kiss_ref(DEFAULT_TABLES))
    (src / "driver.c").write_text(driver_c)
    res_dir = tmp / "res"
    res_dir.mkdir()
    (res_dir / "tables").symlink_to(DEFAULT_TABLES)
    exe = tmp / "driver"
    subprocess.run([cc, "-std=c99", "-O2", "-Wall", *flags, f"-I{src}", *(str(src / f) for f in
                    ("driver.c", "clutch_tables.c", "clutch_cover.c", "resource_uri.c")), "-o", str(exe), "-lm"],
                   check=True)
    return exe, res_dir


def test_caches_give_the_bits_of_the_plain_searches_and_a_cold_cover(tmp_path):
    exe, res_dir = _cover_driver(tmp_path, DRIVER)
    res = subprocess.run([str(exe), str(res_dir)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    checked = int(res.stdout.split()[-3])
    assert checked > 100_000 and res.stdout.strip().endswith("mismatches 0")
    print(res.stdout.strip().splitlines()[-2])


def test_c_host_checksum_is_deterministic_and_independent_of_the_compiler(tmp_path):
    """The host's checksum mode: the FMU's own (zig-built) binary and a gcc -O2 build of its sources give the
    same bits for every output of every step (no contraction into FMA, no x87: the arithmetic is IEEE double)."""
    cc = shutil.which("gcc")
    if cc is None:
        pytest.skip("gcc not installed")
    fmu = build_fmu(DEFAULT_TABLES, tmp_path / "native.fmu", backend="native")
    unzip = tmp_path / "fmu"
    zipfile.ZipFile(fmu).extractall(unzip)
    host = tmp_path / "host"
    subprocess.run([cc, "-std=c99", "-D_POSIX_C_SOURCE=199309L", "-O2", f"-I{fmi2_header_dir()}",
                    str(fmu_source("fmi2_host.c")), "-o", str(host), "-ldl"], check=True)
    gcc_lib = tmp_path / "gcc.so"
    files = [str(p) for p in sorted((unzip / "sources").glob("*.c"))]
    subprocess.run([cc, "-std=c99", "-O2", "-fPIC", "-shared", "-fvisibility=hidden", f"-I{unzip / 'sources'}",
                    *files, "-o", str(gcc_lib), "-lm"], check=True)
    guid = read_model_description(str(fmu)).guid
    sums = []
    for lib in (unzip / "binaries/linux64/CushionClutch.so", gcc_lib, gcc_lib):
        out = subprocess.run([str(host), str(lib), (unzip / "resources").as_uri(), guid, "20000", "0.001",
                              "checksum"], capture_output=True, text=True, check=True).stdout
        sums.append(next(ln.split()[1] for ln in out.splitlines() if ln.startswith("checksum")))
    assert len(sums[0]) == 16 and sums[0] == sums[1] == sums[2]


SCAN_DRIVER = r"""
#define CC_DEFINE_VARIABLE_TABLE
#include "clutch_core.h"
#include <stdlib.h>
#include <string.h>

/* stdin: lines "x_to theta_cs theta_cm wear" (C99 hex floats); stdout: one line per input, in input order,
   of the cover's answer (hex floats: bit for bit) from one warm cover called in the order of argv[2] (a
   permutation file: one input index per line), or a freshly prepared cover per call ("cold") */
int main(int argc, char **argv) {
    Table tb;
    char err[600];
    double r[CC_NVARS], (*in)[4];
    int n = 0, cap = 1 << 16, k, *order, (*stat);
    CcCoverState *res;
    CcCover cv;
    FILE *f;
    if (argc != 3 || cc_table_load(&tb, argv[1], err, sizeof err) != 0) { printf("load failed %s\n", err); return 2; }
    for (k = 0; k < CC_NVARS; ++k) r[k] = CC_VARIABLES[k].start;
    in = malloc(sizeof *in * cap); order = malloc(sizeof *order * cap); res = malloc(sizeof *res * cap);
    stat = malloc(sizeof *stat * cap);
    while (n < cap && scanf("%la %la %la %la", &in[n][0], &in[n][1], &in[n][2], &in[n][3]) == 4) ++n;
    if (strcmp(argv[2], "cold") != 0) {
        f = fopen(argv[2], "r");
        for (k = 0; k < n; ++k) if (fscanf(f, "%d", &order[k]) != 1) return 3;
        fclose(f);
    }
    cc_cover_prepare(&cv, r + VR_DIAPHRAGM_OUTER_RADIUS_M, r[VR_LEVER_RATIO], r[VR_X_KISS_REF], &tb);
    for (k = 0; k < n; ++k) {
        int j = strcmp(argv[2], "cold") ? order[k] : k;
        if (!strcmp(argv[2], "cold"))
            cc_cover_prepare(&cv, r + VR_DIAPHRAGM_OUTER_RADIUS_M, r[VR_LEVER_RATIO], r[VR_X_KISS_REF], &tb);
        memset(&res[j], 0, sizeof res[j]);
        stat[j] = cc_cover_state(&cv, &tb, in[j][0], in[j][1], in[j][2], in[j][3], &res[j]);
    }
    printf("x_kiss_ref %a\n", r[VR_X_KISS_REF]);
    for (k = 0; k < n; ++k)
        printf("%d %a %a %a %a %a %a\n", stat[k], res[k].clamp, res[k].bearing, res[k].cushion, res[k].u, res[k].s,
               res[k].x_kiss);
    cc_table_free(&tb);
    return 0;
}
"""


@pytest.fixture(scope="module")
def scan_driver(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("scan")
    exe, res_dir = _cover_driver(tmp, SCAN_DRIVER)

    def run(inputs, order):
        text = "".join(" ".join(float(v).hex() for v in row) + "\n" for row in inputs)
        arg = "cold"
        if order is not None:
            arg = str(tmp / "order.txt")
            (tmp / "order.txt").write_text("".join(f"{j}\n" for j in order))
        out = subprocess.run([str(exe), str(res_dir), arg], input=text, capture_output=True, text=True,
                             check=True, timeout=120).stdout.splitlines()
        return float.fromhex(out[0].split()[1]), out[1:]
    return run


def _scan_inputs(wear_limit_m: float):
    """The whole input domain: x_to -2...25 mm (every 0.5 mm, and around the kiss point), theta_cs and theta_cm
    200...800 K (the table temperatures, between and beyond them), facing wear 0...its limit (and 1.5 times it, where
    some temperatures cannot be held); plus random points."""
    import numpy as np
    rng = np.random.default_rng(28)
    xs = [*np.arange(-0.002, 0.02501, 0.0005), *np.linspace(0.0030, 0.0046, 17)]
    thetas = [200.0, 293.15, 320.0, 353.15, 410.0, 468.15, 500.0, 523.15, 573.15, 640.0, 800.0]
    rows = [(x, tcs, tcm, w) for w in (0.0, 0.5 * wear_limit_m, 0.999 * wear_limit_m, 1.5 * wear_limit_m)
            for tcs in thetas for tcm in (200.0, 353.15, 600.0, 800.0) for x in xs]
    for _ in range(3000):
        rows.append((rng.uniform(-0.002, 0.025), rng.uniform(200.0, 800.0), rng.uniform(200.0, 800.0),
                     rng.uniform(0.0, wear_limit_m)))
    return rows


def test_native_cover_matches_the_python_model_over_the_domain(scan_driver):
    """The C cover (Halley steps, per-interval cubics, bucket search) against cushion_clutch.model.cover (Newton,
    Hermite form): both converge to |x(s) - x_to| <= 1e-15 (1 + |x_to|) m, so forces agree to round-off of that
    residual: 1e-11 relative or 1e-9 N, positions to 4e-15 m (two residuals of 1e-15 m apart through
    |dx_to/ds| >= L_b/e), the same refusals (bearing force < 0)."""
    from dataclasses import replace

    from cushion_clutch.model import ClutchParameters, load_table
    from cushion_clutch.model.clutch_model import THETA_MAX_K, THETA_MIN_K, cover_frame
    from cushion_clutch.model.cover import wear_limit

    table, p = load_table(), ClutchParameters()
    limit = wear_limit(p.cover, p.lever_ratio, table, p.x_kiss_ref, THETA_MIN_K, THETA_MAX_K)
    assert limit > 1e-3
    rows = _scan_inputs(limit)
    x_kiss_ref, lines = scan_driver(rows, None)
    p = replace(p, x_kiss_ref=x_kiss_ref)
    worst = {f"{q} {ph}": 0.0 for q in ("force", "position") for ph in ("open", "cushion", "solid")}
    phases = {"open": 0, "cushion": 0, "solid": 0, "refused": 0}
    for (x, tcs, tcm, w), line in zip(rows, lines, strict=True):
        stat, *vals = line.split()
        clamp, bearing, cushion, u, s, x_kiss = (float.fromhex(v) for v in vals)
        try:
            fr = cover_frame(table, replace(p, facing_wear=w), tcs, tcm)
            st = fr.state(x)
        except ValueError:
            assert stat == "-1", (x, tcs, tcm, w)
            phases["refused"] += 1
            continue
        assert stat == "0", (x, tcs, tcm, w)
        phase = "open" if x < fr.x_kiss else "solid" if x >= fr.x_solid else "cushion"
        phases[phase] += 1
        for got, ref in ((clamp, st.clamp_force), (bearing, st.bearing_force), (cushion, st.cushion_force)):
            err = abs(got - ref) / max(abs(ref) * 1e-11, 1e-9)
            worst[f"force {phase}"] = max(worst[f"force {phase}"], err)
            assert err <= 1.0, (x, tcs, tcm, w, got, ref)
        for got, ref in ((u, st.u), (s, st.s), (x_kiss, st.x_kiss)):
            worst[f"position {phase}"] = max(worst[f"position {phase}"], abs(got - ref) / 4e-15)
            assert abs(got - ref) <= 4e-15, (x, tcs, tcm, w, got, ref)
    assert min(phases.values()) > 50, phases          # every phase and refusals are covered
    print(phases, "worst error / tolerance:", worst)


def test_native_cover_answer_is_independent_of_the_call_history(scan_driver):
    """One warm cover (frame cache, interval hints, kept exp) answers each input with the same bits whatever came
    before: forward, reversed and shuffled orders and a freshly prepared cover per call agree bit for bit."""
    import numpy as np

    rows = _scan_inputs(1.5e-3)
    n = len(rows)
    runs = [scan_driver(rows, order)[1] for order in
            (None, list(range(n)), list(range(n))[::-1], list(np.random.default_rng(5).permutation(n)))]
    assert all(r == runs[0] for r in runs[1:])


WARM_DRIVER = r"""
#define CC_DEFINE_VARIABLE_TABLE
#include "clutch_core.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

extern long cc_count_evals, cc_count_open; /* clutch_cover.c built with -DCC_COUNT_EVALS */

/* the inputs of step k: pattern 0 a launch's (1 ms steps: the bearing closes over 0.8 s, holds, opens; theta_cs
   drifts over and beyond the tables, theta_cm is held for 10 ms, facing wear 0 or 0.8 mm per engagement);
   pattern 1 the C host's (fmu_src/bench/fmi2_host.c: jumps of 0.4 mm and more every step); pattern 2 a braked
   standstill's (the bearing opening from 4.5 mm and decaying exponentially, 2 ms, through subnormal numbers to 0, as
   the launch loop's actuator lag does; theta_cs cooling every step, 3 K above theta_cm with a time constant of
   600 s, about 5 uK per step as in the recorded launch's standstill; theta_cm held for 50 ms) */
static void inputs(int pattern, long k, double *x, double *tcs, double *tcm, double *wear) {
    if (pattern == 0) {
        double t = (k % 1500) * 1e-3, q;
        if (t < 0.8) { q = t / 0.8; *x = -0.001 + 0.013 * q * q * (3.0 - 2.0 * q); }
        else if (t < 1.2) *x = 0.012;
        else *x = 0.012 - 0.013 * (t - 1.2) / 0.3;
        *tcs = 230.0 + 0.09 * (k % 6000);
        *tcm = *tcs + 30.0 + 0.5 * ((k / 10) % 7);
        *wear = (k / 1500) % 2 ? 0.0008 : 0.0;
    } else if (pattern == 2) {
        double t = (k % 3000) * 1e-3;
        *x = 0.0045 * exp(-t / 0.002);
        *tcm = 300.0 + 0.002 * ((k / 50) % 5);
        *tcs = 300.0 + 3.0 * exp(-t / 600.0);
        *wear = (k / 3000) % 2 ? 0.0008 : 0.0;
    } else {
        *x = 0.003 + 0.005 * (double)((k * 7919) % 1000) / 1000.0;
        *tcm = 300.0 + 300.0 * (double)((k * 104729) % 1000) / 1000.0;
        *tcs = 400.0 + 0.01 * (k % 1000);
        *wear = 0.0;
    }
}

/* argv: resource dir, steps, pattern[, "all"]; stdout: per step (patterns 0 and 2, all with "all") the inputs, the
   warm answer and the cold answer's bearing force and s (hex floats), then the evaluations per step warm
   (cc_cover_solve, one CcWarm) and cold (cc_cover_state), the steps whose warm answer equals the cold one bit for
   bit, the steps where a second warm cover over the same sequence differs (replay), the warm evaluations per step
   that took the open solve's shortcut (clutch_cover.c) */
int main(int argc, char **argv) {
    Table tb;
    char err[600];
    double r[CC_NVARS];
    CcCover warm, cold, again;
    CcWarm w = {NAN, 0.0, 0.0}, w2 = {NAN, 0.0, 0.0};
    long n = atol(argv[2]), k, ew = 0, ec = 0, same = 0, replay = 0, eo = 0;
    int pattern = atoi(argv[3]);
    if (cc_table_load(&tb, argv[1], err, sizeof err) != 0) { printf("load failed %s\n", err); return 2; }
    for (k = 0; k < CC_NVARS; ++k) r[k] = CC_VARIABLES[k].start;
    cc_cover_prepare(&warm, r + VR_DIAPHRAGM_OUTER_RADIUS_M, r[VR_LEVER_RATIO], r[VR_X_KISS_REF], &tb);
    cc_cover_prepare(&cold, r + VR_DIAPHRAGM_OUTER_RADIUS_M, r[VR_LEVER_RATIO], r[VR_X_KISS_REF], &tb);
    cc_cover_prepare(&again, r + VR_DIAPHRAGM_OUTER_RADIUS_M, r[VR_LEVER_RATIO], r[VR_X_KISS_REF], &tb);
    printf("x_kiss_ref %a\n", r[VR_X_KISS_REF]);
    for (k = 0; k < n; ++k) {
        double x, tcs, tcm, wear;
        CcCoverState a, b, c;
        int ra, rb, rc;
        memset(&a, 0, sizeof a); memset(&b, 0, sizeof b); memset(&c, 0, sizeof c);
        inputs(pattern, k, &x, &tcs, &tcm, &wear);
        cc_count_evals = cc_count_open = 0;
        ra = cc_cover_solve(&warm, &tb, x, tcs, tcm, wear, &w, &a);
        ew += cc_count_evals;
        eo += cc_count_open;
        cc_count_evals = 0;
        rb = cc_cover_state(&cold, &tb, x, tcs, tcm, wear, &b);
        ec += cc_count_evals;
        rc = cc_cover_solve(&again, &tb, x, tcs, tcm, wear, &w2, &c);
        same += ra == rb && !memcmp(&a, &b, sizeof a);
        replay += rc != ra || memcmp(&a, &c, sizeof a) != 0;
        if (pattern != 1 || argc > 4)
            printf("%a %a %a %a %d %a %a %a %a %a %a %a %a\n", x, tcs, tcm, wear, ra, a.clamp, a.bearing, a.cushion,
                   a.u, a.s, a.x_kiss, b.bearing, b.s);
    }
    printf("evals %.4f %.4f same %ld replay %ld open %.4f\n", (double)ew / n, (double)ec / n, same, replay,
           (double)eo / n);
    cc_table_free(&tb);
    return 0;
}
"""


def _warm_exe(tmp: Path, flags: tuple[str, ...] = ()):
    """WARM_DRIVER built with -DCC_COUNT_EVALS (and ``flags``): run(steps, pattern, every_step=False) ->
    (x_kiss_ref, per-step lines, (warm evals, cold evals, same, replay, open evals))."""
    exe, res_dir = _cover_driver(tmp, WARM_DRIVER, ("-DCC_COUNT_EVALS", *flags))

    def run(steps: int, pattern: int, every_step: bool = False):
        out = subprocess.run([str(exe), str(res_dir), str(steps), str(pattern), *(["all"] if every_step else [])],
                             capture_output=True, text=True, check=True, timeout=120).stdout.splitlines()
        *_, ew, ec, _, same, _, replay, _, eo = out[-1].split()
        return (float.fromhex(out[0].split()[1]), out[1:-1],
                (float(ew), float(ec), int(same), int(replay), float(eo)))
    return run


@pytest.fixture(scope="module")
def warm_driver(tmp_path_factory):
    """run(steps, pattern) -> (x_kiss_ref, per-step lines, (warm evals, cold evals, same, replay, open evals))."""
    run = _warm_exe(tmp_path_factory.mktemp("warm"))
    return lambda steps, pattern: run(steps, pattern)


def test_warm_start_matches_the_python_model_in_a_launch_and_saves_evaluations(warm_driver):
    """The cover's warm start (cc_cover_solve: the last answer moved along its tangent, or in the open phase the
    parabola through the last three; the FMU's update_outputs)
    over a launch's 1 ms inputs (bearing closing, held, opening; temperatures over and beyond the tables, theta_cm
    held 10 ms; two wear values): every answer within the Python model's tolerances of the cold scan test (forces
    1e-11 relative or 1e-9 N, positions 4e-15 m, measured: 0.14 and 0.11 of them), fewer evaluations than the
    chord start (1.94 -> 1.30 per step measured, a third of the steps in the solid phase needing none), and a second warm cover over the same sequence gives the same bits (no hidden state)."""
    x_kiss_ref, lines, (ew, ec, same, replay, _) = warm_driver(6000, 0)
    print(f"launch pattern: {ew:.3f} evaluations per step warm, {ec:.3f} cold; {same} of 6000 identical to cold")
    assert replay == 0
    assert ew < 0.75 * ec, (ew, ec)                 # the warm start is used (1.29 against 1.94 measured)
    phases, worst = _against_python(x_kiss_ref, lines[::3])   # every third step: the Python cover's ~30 us each
    assert min(phases["open"], phases["cushion"], phases["solid"]) > 50, phases
    print(phases, "worst error / tolerance: forces %.3g, positions %.3g" % tuple(worst))


def test_warm_start_in_a_braked_standstill_matches_the_python_model_with_one_evaluation(warm_driver):
    """The open clutch's warm start (cc_cover_solve: the parabola through the last three answers, refined) over a
    braked standstill's 1 ms steps (the bearing decaying through subnormal numbers to 0, theta_cs cooling by about
    5 uK every step, theta_cm held 50 ms, two wear values): every answer within the Python model's tolerances of the
    cold scan test, about one evaluation per step (measured 1.02; the tangent start needed 2.0), and a second warm
    cover over the same sequence gives the same bits."""
    x_kiss_ref, lines, (ew, ec, same, replay, _) = warm_driver(6000, 2)
    print(f"standstill: {ew:.3f} evaluations per step warm, {ec:.3f} cold")
    assert replay == 0
    assert ew < 1.3 and ew < 0.7 * ec, (ew, ec)
    phases, worst = _against_python(x_kiss_ref, lines[::4])
    assert phases["open"] > 1000 and phases["refused"] == 0, phases
    print(phases, "worst error / tolerance: forces %.3g, positions %.3g" % tuple(worst))


def _against_python(x_kiss_ref: float, lines: list[str]):
    """The warm driver's answers (``lines``) against cushion_clutch.model.cover's at the same inputs: forces within
    1e-11 relative or 1e-9 N, positions within 4e-15 m, the same refusals. Returns (steps per phase, worst error /
    tolerance of forces and positions)."""
    from dataclasses import replace

    from cushion_clutch.model import ClutchParameters, load_table
    from cushion_clutch.model.clutch_model import cover_frame

    table, p = load_table(), replace(ClutchParameters(), x_kiss_ref=x_kiss_ref)
    frames, phases, worst = {}, {"open": 0, "cushion": 0, "solid": 0, "refused": 0}, [0.0, 0.0]
    for line in lines:
        x, tcs, tcm, w, stat, *vals = line.split()
        x, tcs, tcm, w = (float.fromhex(v) for v in (x, tcs, tcm, w))
        clamp, bearing, cushion, u, s, x_kiss = (float.fromhex(v) for v in vals[:6])
        key = (tcs, tcm, w)
        if key not in frames:
            try:
                frames[key] = cover_frame(table, replace(p, facing_wear=w), tcs, tcm)
            except ValueError:
                frames[key] = None
        fr = frames[key]
        if fr is None:
            assert stat == "-1", (x, tcs, tcm, w)
            phases["refused"] += 1
            continue
        st = fr.state(x)
        assert stat == "0", (x, tcs, tcm, w)
        phases["open" if x < fr.x_kiss else "solid" if x >= fr.x_solid else "cushion"] += 1
        for got, ref in ((clamp, st.clamp_force), (bearing, st.bearing_force), (cushion, st.cushion_force)):
            worst[0] = max(worst[0], abs(got - ref) / max(abs(ref) * 1e-11, 1e-9))
            assert abs(got - ref) <= max(abs(ref) * 1e-11, 1e-9), (x, tcs, tcm, w, got, ref)
        for got, ref in ((u, st.u), (s, st.s), (x_kiss, st.x_kiss)):
            worst[1] = max(worst[1], abs(got - ref) / 4e-15)
            assert abs(got - ref) <= 4e-15, (x, tcs, tcm, w, got, ref)
    return phases, worst


def test_warm_start_is_not_used_for_the_c_hosts_jumps(warm_driver):
    """The C host's inputs jump by 0.4 mm or more every step (more than CC_WARM_DX): the warm cover starts from
    the chord every time, so its answers are the cold ones bit for bit (the benchmark's checksum is main's)."""
    _, _, (ew, ec, same, replay, _) = warm_driver(20000, 1)
    assert replay == 0 and same == 20000 and ew == ec, (ew, ec, same)


def test_open_solve_shortcut_gives_the_bits_of_the_table(tmp_path_factory):
    """The open solve's shortcut (clutch_cover.c: while the cushion's normalised compression lies below its first
    knot, where the table's force is a clamped constant, the solver iterates on the cubic alone, without the table)
    gives every answer bit for bit as the table does: the cover built with and without it (-DCC_NO_OPEN_SHORTCUT),
    warm over a launch, a braked standstill (the bearing decaying through subnormal numbers to 0, theta_cs cooling
    every step) and the C host's jumps, and cold over the whole input domain (every phase and refusals); the same
    evaluations, most of the standstill's taken by the shortcut."""
    import numpy as np

    on = _warm_exe(tmp_path_factory.mktemp("open_on"))
    off = _warm_exe(tmp_path_factory.mktemp("open_off"), ("-DCC_NO_OPEN_SHORTCUT",))
    share = {}
    for steps, pattern in ((6000, 0), (6000, 2), (20000, 1)):
        _, lines_on, st_on = on(steps, pattern, True)
        _, lines_off, st_off = off(steps, pattern, True)
        assert len(lines_on) == steps and lines_on == lines_off, pattern
        assert st_on[:4] == st_off[:4] and st_off[4] == 0.0, (pattern, st_on, st_off)
        share[pattern] = st_on[4] / st_on[0]
        if pattern == 2:      # the standstill reaches subnormal bearing positions and 0
            xs = [float.fromhex(ln.split()[0]) for ln in lines_on]
            assert any(0.0 < x < 2.2250738585072014e-308 for x in xs) and 0.0 in xs
    print("evaluations taken by the shortcut (launch, standstill, jumps):", share)
    assert share[2] > 0.9 and share[0] > 0.2, share
    rows = _scan_inputs(2.5e-3)      # facing wear up to 3.75 mm: beyond the default cover's limit, refusals
    text = "".join(" ".join(float(v).hex() for v in row) + "\n" for row in rows)
    outs = []
    for name, flags in (("scan_on", ()), ("scan_off", ("-DCC_NO_OPEN_SHORTCUT",))):
        exe, res_dir = _cover_driver(tmp_path_factory.mktemp(name), SCAN_DRIVER, flags)
        outs.append(subprocess.run([str(exe), str(res_dir), "cold"], input=text, capture_output=True, text=True,
                                   check=True, timeout=120).stdout)
    assert len(outs[0].splitlines()) == len(rows) + 1 and outs[0] == outs[1]
    assert np.mean([ln.split()[0] == "-1" for ln in outs[0].splitlines()[1:]]) > 0.0   # refusals covered


def test_fmu_warm_start_is_in_the_saved_state_and_reset_starts_cold():
    """The FMU's outputs depend on its inputs and its state, which holds the warm start: a launch-like run replayed
    from a saved state (serialized and restored) continues with the same bits, and fmi2Reset starts the same
    sequence again with the same bits (the warm start cold after reset and initialisation)."""
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave
    from native_builds import native_fmus

    fmu = native_fmus()[2]
    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu)), modelIdentifier="CushionClutch", instanceName="w")
    vin = [vr["x_to"], vr["theta_cm"], vr["omega_slip"]]
    vout = [vr[k] for k in ("torque", "force", "theta_cs", "u_f", "x_kiss", "clamp_force", "bearing_force")]

    def start():
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()

    def run(k0, k1):
        out = []
        for k in range(k0, k1):     # closing over 0.8 s in 1 ms steps, theta_cm held 10 ms
            q = min(k * 1e-3 / 0.8, 1.0)
            s.setReal(vin, [0.012 * q * q * (3.0 - 2.0 * q), 330.0 + 0.5 * (k // 10), 100.0 * (1.0 - q)])
            s.doStep(k * 1e-3, 1e-3)
            out.append(s.getReal(vout))
        return out

    s.instantiate()
    start()
    first = run(0, 400)
    saved = s.serializeFMUstate(s.getFMUstate())
    rest = run(400, 900)
    s.setFMUstate(s.deSerializeFMUstate(saved))
    assert run(400, 900) == rest                    # the restored warm start continues with the same bits
    s.reset()
    start()
    assert run(0, 900) == first + rest              # reset: cold again, the same bits
    s.terminate()
    s.freeInstance()


def _fnv1a(data: bytes) -> str:
    """The C host's checksum (FNV-1a 64) of ``data``."""
    h = 14695981039346656037
    for b in data:
        h = ((h ^ b) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


def test_c_host_replays_a_launch_as_the_launch_client_does(tmp_path):
    """The C host's launch pattern (``--replay``, benchmarks/fmu.py): one launch of the default scenario recorded
    at the clutch FMU's step (``record_launch``), replayed in the C host with the client's set-only-what-changed
    calls, gives every output of every step bit for bit as in the launch (the checksum of torque, theta_cs and
    x_kiss, the same binary), with as many fmi2SetReal calls as inputs changed; at sampled steps (slipping,
    held, open) the outputs equal the Python model's within the tolerances of the scans above."""
    import numpy as np

    from cushion_clutch.benchmarks.fmu import check_replay_vrs, compile_host, record_launch, write_pattern
    from cushion_clutch.fmu.crossbuild import HOST
    from cushion_clutch.fmu.native import build_native_fmu
    from cushion_clutch.model import ClutchParameters, load_table, outputs, thermal_step

    if shutil.which("gcc") is None:
        pytest.skip("gcc not installed")
    fmu = build_native_fmu(DEFAULT_TABLES, tmp_path / "native.fmu", 2, platforms=(HOST[2],))
    check_replay_vrs(fmu)
    rec = record_launch(fmu, launches=1)
    x, tcm, w = rec["inputs"].T
    torque, tcs, x_kiss = rec["outputs"].T
    n = len(x)
    changed = np.r_[True, (np.diff(rec["inputs"], axis=0) != 0).any(axis=1)]
    slipping = (torque > 0) & (np.abs(w) > 1.0)
    assert rec["h"] == 1e-3 and n == 60_000 and 0.1 < changed.mean() < 0.9 and slipping.sum() > 500, (
        n, changed.mean(), slipping.sum())
    unzip = tmp_path / "fmu"
    zipfile.ZipFile(fmu).extractall(unzip)
    host = compile_host(tmp_path / "host")
    pattern = write_pattern(tmp_path / "launch.f64", rec["inputs"])
    out = subprocess.run([str(host), str(unzip / "binaries/linux64/CushionClutch.so"), (unzip / "resources").as_uri(),
                          read_model_description(str(fmu)).guid, "0", "0.001", "checksum", "--replay", str(pattern)],
                         capture_output=True, text=True, check=True, timeout=60).stdout
    got = {ln.split()[0]: ln.split()[1:] for ln in out.splitlines()}
    assert got["replay"] == [str(n), "sets", str(int(changed.sum()))], got["replay"]
    assert [float(v) for v in got["outputs"]] == [torque[-1], tcs[-1], x_kiss[-1]]
    assert got["checksum"] == [_fnv1a(np.ascontiguousarray(rec["outputs"], dtype="<f8").tobytes())]
    # against the Python model: the same step of theta_cs, the cover at the step's inputs and new theta_cs
    table, p = load_table(), ClutchParameters()
    rng = np.random.default_rng(5)
    picks = np.r_[rng.choice(np.flatnonzero(slipping), 15, replace=False),
                  rng.choice(np.flatnonzero(~changed), 5, replace=False),
                  rng.choice(np.flatnonzero(torque == 0), 5, replace=False)]
    for k in picks:
        assert tcs[k] == pytest.approx(thermal_step(tcs[k - 1], tcm[k], rec["h"], p), rel=1e-12), k
        o = outputs(x[k], tcs[k], table, p, theta_cm=tcm[k])
        assert torque[k] == pytest.approx(o.torque, rel=1e-11, abs=1e-10), k
        assert abs(x_kiss[k] - o.x_kiss) <= 4e-15, k
