/* The joint case through frirom_frf: 0-based indices, column-major arrays; prints the
 * same table as frf_joint.f90. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "frirom.h"

int main(void) {
    enum { N = 5, H = 5, NC = 2 * H + 1, NOUT = 3, MAXPTS = 1000 };
    /* K (N/m): every entry of the symmetric matrix; M (kg) diagonal. DoFs: platform:x,
     * platform:y, blade_low:x, blade_mid:x, tip:x */
    const int kr[] = {0, 1, 2, 0, 2, 3, 2, 3, 4, 3, 4}, kc[] = {0, 1, 0, 2, 2, 2, 3, 3, 3, 4, 4};
    const double kv[] = {5.5e6, 8e6, -1.5e6, -1.5e6, 2.5e6, -1e6, -1e6, 1.6e6, -6e5, -6e5, 6e5};
    const int md[] = {0, 1, 2, 3, 4};
    const double mv[] = {0.08, 0.08, 0.03, 0.03, 0.02};
    const double zeta[] = {0.003, 0.003, 0.003, 0.003, 0.003};  /* modal, every mode */
    /* one Jenkins element (kt N/m, mu, fn0 N): u = cos 30 x + sin 30 y of the platform */
    const int ginfo[] = {FRIROM_LAW_JENKINS, 1, 1}, gr[] = {0, 0}, gc[] = {0, 1};
    const double gv[] = {0.8660254037844386, 0.5}, params[] = {1e7, 0.5, 100.0};
    const int outdofs[] = {4, 0, 1};
    const double pi = acos(-1.0);
    double fe[N * NC] = {0};
    fe[4 + N * 1] = 2.0;   /* 2 N cos(omega t) at the tip: fe(tip, a1) */

    struct frirom_settings s;
    frirom_settings_default(&s);
    s.harmonics = H;
    s.samples = 64;
    s.formulation = FRIROM_CONDENSED;
    s.ds = 0.02;
    s.ds_max = 0.1;
    s.max_points = MAXPTS;

    double *omega = malloc(sizeof(double) * MAXPTS);
    double *xo = malloc(sizeof(double) * NOUT * NC * MAXPTS);
    double *amp = malloc(sizeof(double) * NOUT * MAXPTS);
    int npts, complete, ny;
    char msg[512];
    int info = frirom_frf(N, 11, kr, kc, kv, 5, md, md, mv, 0, NULL, NULL, NULL, 0.0, 0.0,
                          5, zeta, 1, ginfo, 2, gr, gc, gv, 3, params, 0, NULL, fe,
                          2 * pi * 400.0, 2 * pi * 520.0, NOUT, outdofs, &s, MAXPTS, &npts,
                          &complete, omega, xo, amp, 0, &ny, NULL, msg, sizeof msg);
    if (info != 0 && npts == 0) {
        fprintf(stderr, "frirom_frf: %s\n", msg);
        return 1;
    }
    for (int k = 0; k < npts; ++k)
        printf("%.16e %.16e %.16e %.16e\n", omega[k], amp[NOUT * k], amp[NOUT * k + 1],
               amp[NOUT * k + 2]);
    printf("complete %d %d\n", complete, npts);
    if (!complete) printf("%s\n", msg);
    free(omega); free(xo); free(amp);
    return 0;
}
