/* Nonlinear modes through the C interface (frirom.h frirom_run_set_nonlinear_mode, _start_
 * mode, _advance_mode): a single-DoF Jenkins oscillator (m = 1, k = 1e4, kt = 1e4, slip
 * force 1 N) at H = 1, on all DoFs and condensed by its one mode, against the describing
 * function's frequency and damping (1e-6 relative with N = 4096 samples: the AFT's
 * sampled transitions err by ~10 N^-2), and bad input naming the argument. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "frirom.h"

static const double K0 = 1e4, KT = 1e4, FS = 1.0;

/* omega, xi of m x'' + k x + f_J(x) = xi x' at displacement amplitude A (H = 1) */
static void describing(double A, double *w, double *xi) {
    const double pi = acos(-1.0);
    double a1 = KT * A, b1 = 0.0;
    if (A > FS / KT) {
        double ts = acos(1.0 - 2.0 * FS / (KT * A));
        a1 = 2 / pi * ((2 * FS - KT * A) * sin(ts) + KT * A * (ts / 2 + sin(2 * ts) / 4));
        b1 = 2 / pi * ((FS - KT * A) * (1 - cos(ts)) + KT * A * sin(ts) * sin(ts) / 2
                       - FS * (1 + cos(ts)));
    }
    *w = sqrt(K0 + a1 / A);
    *xi = -b1 / (A * *w);
}

static int backbone(int nmodes) {
    const int kr[] = {0}, ginfo[] = {FRIROM_LAW_JENKINS, 1, 1}, gr[] = {0}, out[] = {0};
    const double kv[] = {K0}, mv[] = {1.0}, gv[] = {1.0}, params[] = {KT, 0.5, 2.0};
    const double fe[3] = {0, 1, 0}, phi[] = {1.0}, wm[] = {100.0}, zm[] = {0.0};
    double amp[41], om[41], xi[41], xo[3 * 41];
    int npts = 0, status = 0, total = 0;
    char msg[512];
    frirom_run *run = NULL;
    struct frirom_settings s;
    frirom_settings_default(&s);
    s.harmonics = 1;
    s.samples = 4096;
    s.formulation = 2;
    if (frirom_run_open(&run, 1, 1, kr, kr, kv, 1, kr, kr, mv, 0, NULL, NULL, NULL, 0.0, 0.0,
                        0, NULL, 1, ginfo, 1, gr, gr, gv, 3, params, 0, NULL, fe, 1, out, &s,
                        0, msg, sizeof msg)) {
        fprintf(stderr, "open: %s\n", msg); return 1;
    }
    if (frirom_run_set_nonlinear_mode(run, phi, sqrt(K0 + KT), nmodes, phi, wm, zm, msg,
                                      sizeof msg)) {
        fprintf(stderr, "set_nonlinear_mode: %s\n", msg); return 1;
    }
    if (frirom_run_start_mode(run, 1e-5, 1e-2, msg, sizeof msg)) {
        fprintf(stderr, "start_mode: %s\n", msg); return 1;
    }
    double worst = 0.0;
    while (status == 0) {
        if (frirom_run_advance_mode(run, 40, &npts, amp, om, xi, xo, &status, msg,
                                    sizeof msg)) {
            fprintf(stderr, "advance_mode: %s\n", msg); return 1;
        }
        for (int j = 0; j < npts; ++j) {
            double w, x;
            describing(amp[j], &w, &x);
            double e = fabs(om[j] / w - 1) + fabs(xi[j] - x) / 30.0;
            if (e > worst) worst = e;
        }
        total += npts;
    }
    frirom_run_close(&run);
    printf("nmodes %d: %d points, status %d, worst %.2e\n", nmodes, total, status, worst);
    if (status != 1 || fabs(amp[npts - 1] / 1e-2 - 1) > 1e-12 || worst > 1e-6) return 1;
    return 0;
}

int main(void) {
    char msg[256];
    if (backbone(0) || backbone(1)) return 1;
    if (frirom_run_start_mode(NULL, 1e-5, 1e-2, msg, sizeof msg) == 0) return 1;
    int st = 0, n = 0;
    double d[3];
    if (frirom_run_advance_mode(NULL, 1, &n, d, d, d, d, &st, msg, sizeof msg) == 0) return 1;
    return 0;
}
