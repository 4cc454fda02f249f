/* The C interface: a Jenkins element stuck all cycle is the spring kt (f = kt x, exact),
 * one that slips dissipates 4 mu N (A - mu N / kt) per cycle (to 10/N^2), and bad input
 * returns a status code with a message. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "frirom.h"

int main(void) {
    enum { H = 3, NC = 2 * H + 1, N = 1024 };
    double x[NC] = {0}, f[NC], jac[NC * NC], params[3] = {1e5, 0.3, 100.0};
    int periods = 0;
    char msg[256];
    const double pi = acos(-1.0), kt = 1e5, fs = 30.0;

    x[1] = 1e-4; x[4] = 0.5e-4;  /* stuck: |kt x| < 30 N */
    if (frirom_aft_eval(FRIROM_LAW_JENKINS, H, N, 1, x, params, NULL, f, jac, &periods, msg, 256)) {
        fprintf(stderr, "stick call failed: %s\n", msg); return 1;
    }
    for (int i = 0; i < NC; ++i)
        if (fabs(f[i] - kt * x[i]) > 1e-12 * kt * 1e-4) { fprintf(stderr, "stick f\n"); return 1; }
    for (int i = 0; i < NC; ++i)
        if (fabs(jac[i * NC + i] - kt) > 1e-9 * kt) { fprintf(stderr, "stick jac\n"); return 1; }

    double a = 1e-3;
    memset(x, 0, sizeof x); x[1] = a;
    if (frirom_aft_eval(FRIROM_LAW_JENKINS, H, N, 1, x, params, NULL, f, NULL, NULL, msg, 256)) {
        fprintf(stderr, "slip call failed: %s\n", msg); return 1;
    }
    double energy = -pi * a * f[2], ref = 4 * fs * (a - fs / kt);
    if (fabs(energy / ref - 1) > 10.0 / ((double)N * N)) {
        fprintf(stderr, "energy %g vs %g\n", energy, ref); return 1;
    }

    params[0] = -1.0;
    int info = frirom_aft_eval(FRIROM_LAW_JENKINS, H, N, 1, x, params, NULL, f, NULL, NULL, msg, 256);
    if (info != 2 || strstr(msg, "kt must be > 0") == NULL) {
        fprintf(stderr, "bad kt: info %d msg %s\n", info, msg); return 1;
    }
    info = frirom_aft_eval(9, H, N, 1, x, params, NULL, f, NULL, NULL, msg, 256);
    if (info != 11 || strstr(msg, "law 9 (expected 1 jenkins, 2 normal1d") == NULL) {
        fprintf(stderr, "bad law: info %d msg %s\n", info, msg); return 1;
    }
    puts("test_capi: ok");
    return 0;
}
