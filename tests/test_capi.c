/* The C interface: a Jenkins element stuck all cycle is the spring kt (f = kt x, exact),
 * one that slips dissipates 4 mu N (A - mu N / kt) per cycle (to 10/N^2), and bad input
 * returns a status code with a message (frirom_frf: naming the argument). The whole solve
 * is checked against Python by the frf_joint test (tests/capi_compare.py). */
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
    params[0] = kt;
    {   /* frirom_frf: an output DoF out of range, no point computed */
        const int kr[] = {0}, md[] = {0}, ginfo[] = {FRIROM_LAW_JENKINS, 1, 1}, gr[] = {0};
        const int out[] = {3};
        const double kv[] = {1e4}, mv[] = {1.0}, gv[] = {1.0}, fe[3] = {0, 1, 0};
        double om[1], xo[3], amp[1];
        int npts = -1, complete = -1, ny = -1;
        struct frirom_settings s;
        frirom_settings_default(&s);
        s.harmonics = 1;
        s.max_points = 1;
        info = frirom_frf(1, 1, kr, kr, kv, 1, md, md, mv, 0, NULL, NULL, NULL, 0.0, 0.0, 0,
                          NULL, 1, ginfo, 1, gr, gr, gv, 3, params, 0, NULL, fe, 50.0, 150.0,
                          1, out, &s, 1, &npts, &complete, om, xo, amp, 0, &ny, NULL, msg, 256);
        if (info != 2 || npts != 0 || complete != 0 || strstr(msg, "outdofs") == NULL) {
            fprintf(stderr, "frirom_frf bad output: info %d npts %d msg %s\n", info, npts, msg);
            return 1;
        }
    }
    {   /* the run object: bad calls return a code and a message naming the argument or
         * the call, never stop the process (a NULL or closed run, a negative count, a NaN
         * contact parameter, a checkpoint of another length, an advance before start) */
        const int kr[] = {0}, md[] = {0}, ginfo[] = {FRIROM_LAW_JENKINS, 1, 1}, gr[] = {0};
        const int out[] = {0};
        const double kv[] = {1e4}, mv[] = {1.0}, gv[] = {1.0}, fe[3] = {0, 1, 0};
        double p[3] = {1e5, 0.3, 100.0}, om[2], xo[6], amp[2], ck[64];
        int npts, status, ny, nw, ne, nck;
        struct frirom_settings s;
        frirom_run *run = NULL;
        frirom_settings_default(&s);
        s.harmonics = 1;
#define REFUSED(what, call, expect)                                                       \
        if ((call) == 0 || strstr(msg, expect) == NULL) {                                   \
            fprintf(stderr, "%s: accepted or unnamed: %s\n", what, msg);                    \
            return 1;                                                                       \
        }
        REFUSED("NULL run", frirom_run_start(NULL, 50.0, 150.0, msg, 256), "not an open run")
        REFUSED("negative nk", frirom_run_open(&run, 1, -1, kr, kr, kv, 1, md, md, mv, 0, NULL,
                NULL, NULL, 0.0, 0.0, 0, NULL, 1, ginfo, 1, gr, gr, gv, 3, p, 0, NULL, fe, 1,
                out, &s, 0, msg, 256), "nk")
        p[1] = NAN;
        REFUSED("NaN mu", frirom_run_open(&run, 1, 1, kr, kr, kv, 1, md, md, mv, 0, NULL, NULL,
                NULL, 0.0, 0.0, 0, NULL, 1, ginfo, 1, gr, gr, gv, 3, p, 0, NULL, fe, 1, out, &s,
                0, msg, 256), "params")
        p[1] = 0.3;
        if (run != NULL || frirom_run_open(&run, 1, 1, kr, kr, kv, 1, md, md, mv, 0, NULL,
                                           NULL, NULL, 0.0, 0.0, 0, NULL, 1, ginfo, 1, gr, gr,
                                           gv, 3, p, 0, NULL, fe, 1, out, &s, 0, msg, 256)) {
            fprintf(stderr, "run_open: %s\n", msg);
            return 1;
        }
        frirom_run_sizes(run, &ny, &nw, &ne, &nck);
        REFUSED("advance before start", frirom_run_advance(run, 1, &npts, om, xo, amp, NULL,
                &status, msg, 256), "run_start first")
        REFUSED("negative start", frirom_run_start(run, -50.0, 150.0, msg, 256),
                "positive frequencies")
        REFUSED("restore of another length", frirom_run_restore(run, nck + 1, ck, msg, 256),
                "nck")
        REFUSED("no modes", frirom_run_set_modes(run, 0, NULL, NULL, NULL, msg, 256), "nmodes")
        frirom_run_close(&run);
        if (run != NULL || frirom_run_close(&run) != 0) {
            fprintf(stderr, "close did not clear the run\n");
            return 1;
        }
    }
    {   /* a body held only by its contacts (issue 29): a blade (m 1 on k 1, forced 0.01)
         * and a damper (m 0.3, no stiffness) tied by one Jenkins element that never slips
         * (kt 2, mu fn0 100): K is singular and the solve fails until
         * frirom_run_set_free_bodies; then the stuck 2-DoF closed form to 1e-9 */
        const int kr[] = {0}, mr[] = {0, 1}, ginfo[] = {FRIROM_LAW_JENKINS, 1, 1};
        const int gr[] = {0, 0}, gc[] = {0, 1}, out[] = {0, 1};
        const double kv[] = {1.0}, mv[] = {1.0, 0.3}, gv[] = {1.0, -1.0};
        const double p[3] = {2.0, 1.0, 100.0}, fe[6] = {0, 0, 0.01, 0, 0, 0};
        const double w = 1.0, al = 0.02;
        double xo[6], amp[2];
        struct frirom_settings s;
        frirom_run *run = NULL;
        frirom_settings_default(&s);
        s.harmonics = 1;
        if (frirom_run_open(&run, 2, 1, kr, kr, kv, 2, mr, mr, mv, 0, NULL, NULL, NULL, al,
                            0.0, 0, NULL, 1, ginfo, 2, gr, gc, gv, 3, p, 0, NULL, fe, 2, out,
                            &s, 0, msg, 256)) {
            fprintf(stderr, "free body open: %s\n", msg);
            return 1;
        }
        if (frirom_run_solve_at(run, w, NULL, NULL, xo, amp, msg, 256) == 0) {
            fprintf(stderr, "free body solved without frirom_run_set_free_bodies\n");
            return 1;
        }
        REFUSED("free bodies on = 2", frirom_run_set_free_bodies(run, 2, msg, 256),
                "expected 0 or 1")
        if (frirom_run_set_free_bodies(run, 1, msg, 256) ||
            frirom_run_solve_at(run, w, NULL, NULL, xo, amp, msg, 256)) {
            fprintf(stderr, "free body: %s\n", msg);
            return 1;
        }
        /* D x = [F, 0]: x0 = F D22 / det, with D11 = 1 + 2 - w^2 + i w al, D22 = 2 -
         * 0.3 w^2 + 0.3 i w al, D12 = -2 */
        double d11r = 3.0 - w * w, d11i = w * al, d22r = 2.0 - 0.3 * w * w, d22i = 0.3 * w * al;
        double detr = d11r * d22r - d11i * d22i - 4.0, deti = d11r * d22i + d11i * d22r;
        double ref = 0.01 * hypot(d22r, d22i) / hypot(detr, deti);
        double got = hypot(xo[2], xo[4]);     /* xo (nout = 2, 3): a1 of DoF 0 at [2] */
        if (fabs(got / ref - 1.0) > 1e-9) {
            fprintf(stderr, "free body: amplitude %.15g, closed form %.15g\n", got, ref);
            return 1;
        }
        frirom_run_close(&run);
    }
    puts("test_capi: ok");
    return 0;
}
