/* A C driver's own contact law through frirom.h: the Jenkins law of tests/data/userlaw.c
 * (written from docs/deck.md's rules, not from the Fortran) wrapped as a
 * frirom_user_law_fn, registered with a run whose contact group carries
 * frirom_law_user_code(1, 3, 1), gives the built-in Jenkins run's unknowns to 1e-10 at
 * frequencies below, at and above the stuck resonance; the context pointer comes back
 * untouched; a user-law run without a registered law fails with a message, and a law
 * that returns nonzero stops the solve with its code named. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "frirom.h"

int user_jenkins(int ne, int nd, int n, int np, int ns, const double *u, const double *p,
                 double *w, double *f);

struct counter { long calls; int fail; };

static int jenkins(void *ctx, int group, int ne, int nd, int n, int np, int ns,
                   const double *u, const double *p, double *w, double *f)
{
    struct counter *c = ctx;
    c->calls++;
    if (c->fail || group != 1) return 7;
    return user_jenkins(ne, nd, n, np, ns, u, p, w, f) ? 7 : 0;
}

static int open_run(frirom_run **run, int law, char *msg)
{
    /* 1 DoF: m = 1, k = 1, c = 0.02 (Rayleigh beta), Jenkins kt 2, mu 0.2, fn0 1 */
    static const int kr[] = {0}, md[] = {0}, gr[] = {0}, out[] = {0};
    static const double kv[] = {1.0}, mv[] = {1.0}, gv[] = {1.0}, p[] = {2.0, 0.2, 1.0};
    static const double fe[11] = {0, 0, 0.3};
    int ginfo[] = {law, 1, 1};
    struct frirom_settings s;
    frirom_settings_default(&s);
    s.harmonics = 5;
    s.tol_residual = 1e-12;
    s.tol_update = 1e-12;
    return frirom_run_open(run, 1, 1, kr, kr, kv, 1, md, md, mv, 0, NULL, NULL, NULL, 0.0,
                           0.02, 0, NULL, 1, ginfo, 1, gr, gr, gv, 3, p, 0, NULL, fe, 1, out,
                           &s, 0, msg, 256);
}

int main(void)
{
    char msg[256];
    frirom_run *ref = NULL, *user = NULL;
    struct counter c = {0, 0};
    int code = frirom_law_user_code(1, 3, 1), ny, nw, ne, nck;
    double y0[64], y1[64], xo[11], amp[1];
    if (code >= 0 || frirom_law_user_code(0, 3, 1) != 0) {
        fprintf(stderr, "user code %d\n", code); return 1;
    }
    if (open_run(&ref, FRIROM_LAW_JENKINS, msg) || open_run(&user, code, msg)) {
        fprintf(stderr, "open: %s\n", msg); return 1;
    }
    if (frirom_run_solve_at(user, 1.2, NULL, y1, xo, amp, msg, 256) == 0 ||
        strstr(msg, "run_set_user_law") == NULL) {
        fprintf(stderr, "no law registered: accepted or unnamed: %s\n", msg); return 1;
    }
    if (frirom_run_set_user_law(user, jenkins, &c, msg, 256)) {
        fprintf(stderr, "set_user_law: %s\n", msg); return 1;
    }
    frirom_run_sizes(ref, &ny, &nw, &ne, &nck);
    const double omegas[] = {0.9, 1.2, 1.45, 1.7};
    for (int i = 0; i < 4; ++i) {
        double err = 0.0, big = 0.0;
        if (frirom_run_solve_at(ref, omegas[i], NULL, y0, xo, amp, msg, 256) ||
            frirom_run_solve_at(user, omegas[i], NULL, y1, xo, amp, msg, 256)) {
            fprintf(stderr, "solve at %g: %s\n", omegas[i], msg); return 1;
        }
        for (int j = 0; j < ny; ++j) {
            err = fmax(err, fabs(y0[j] - y1[j]));
            big = fmax(big, fabs(y0[j]));
        }
        if (!(err <= 1e-10 * big)) {
            fprintf(stderr, "omega %g: |y_user - y_builtin| %g of %g\n", omegas[i], err, big);
            return 1;
        }
    }
    if (c.calls == 0) { fprintf(stderr, "the law was never called\n"); return 1; }
    c.fail = 1;
    if (frirom_run_solve_at(user, 1.2, NULL, y1, xo, amp, msg, 256) == 0 ||
        strstr(msg, "returned 7") == NULL) {
        fprintf(stderr, "failing law: accepted or unnamed: %s\n", msg); return 1;
    }
    frirom_run_close(&ref);
    frirom_run_close(&user);
    printf("test_capi_user_law: ok (%ld law calls)\n", c.calls);
    return 0;
}
