/* The joint case (a blade with a platform friction damper, cases/joint) through the run
 * object of frirom.h: a run opened once, advanced a batch of points at a time, stopped
 * after 30 points, checkpointed, closed, and a second run restored from the checkpoint
 * that finishes the curve; the restored curve equals the uninterrupted one bit for bit.
 * The same curve by every receptance route (banded LU, sparse LU, modes) and by the
 * banded formulation, and one solve at a fixed frequency.
 *
 * Build (an installed frirom): cc run_checkpoint.c $(pkg-config --cflags --libs frirom)
 * -lgfortran -lm. Prints "omega amp(tip:x) amp(platform:x) amp(platform:y)" per point of
 * the uninterrupted curve, then one line per check; exits 1 if a check fails. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "frirom.h"

enum { N = 5, H = 5, NC = 2 * H + 1, NOUT = 3, BATCH = 10, MAXPTS = 1000 };

/* LAPACK (linked with frirom): the generalised symmetric eigenproblem K phi = w^2 M phi */
void dsygv_(const int *itype, const char *jobz, const char *uplo, const int *n, double *a,
            const int *lda, double *b, const int *ldb, double *w, double *work,
            const int *lwork, int *info);

/* K (N/m): every entry of the symmetric matrix; M (kg) diagonal. DoFs: platform:x,
 * platform:y, blade_low:x, blade_mid:x, tip:x */
static const int kr[] = {0, 1, 2, 0, 2, 3, 2, 3, 4, 3, 4};
static const int kc[] = {0, 1, 0, 2, 2, 2, 3, 3, 3, 4, 4};
static const double kv[] = {5.5e6, 8e6, -1.5e6, -1.5e6, 2.5e6, -1e6, -1e6, 1.6e6, -6e5, -6e5,
                            6e5};
static const int md[] = {0, 1, 2, 3, 4};
static const double mv[] = {0.08, 0.08, 0.03, 0.03, 0.02};
static const double zeta[] = {0.003, 0.003, 0.003, 0.003, 0.003};  /* modal, every mode */
/* one Jenkins element (kt N/m, mu, fn0 N): u = cos 30 x + sin 30 y of the platform */
static const int ginfo[] = {FRIROM_LAW_JENKINS, 1, 1}, gr[] = {0, 0}, gc[] = {0, 1};
static const double gv[] = {0.8660254037844386, 0.5}, params[] = {1e7, 0.5, 100.0};
static const int outdofs[] = {4, 0, 1};

struct curve { int npts, status; double omega[MAXPTS], amp[NOUT * MAXPTS]; };

static frirom_run *open_run(const struct frirom_settings *s, int sparse) {
    double fe[N * NC] = {0};
    fe[4 + N * 1] = 2.0;   /* 2 N cos(omega t) at the tip: fe(tip, a1) */
    frirom_run *run = NULL;
    char msg[512];
    if (frirom_run_open(&run, N, 11, kr, kc, kv, 5, md, md, mv, 0, NULL, NULL, NULL, 0.0, 0.0,
                        5, zeta, 1, ginfo, 2, gr, gc, gv, 3, params, 0, NULL, fe, NOUT,
                        outdofs, s, sparse, msg, sizeof msg) != 0) {
        fprintf(stderr, "frirom_run_open: %s\n", msg);
        exit(2);
    }
    return run;
}

/* Advance until the run stops, or until it has made `stop` points (0: no stop). */
static void advance(frirom_run *run, struct curve *c, int stop) {
    double xo[NOUT * NC * (BATCH + 1)];
    char msg[512];
    while (c->status == 0 && (stop == 0 || c->npts < stop)) {
        int n = 0;
        int info = frirom_run_advance(run, BATCH, &n, c->omega + c->npts, xo,
                                      c->amp + NOUT * c->npts, NULL, &c->status, msg,
                                      sizeof msg);
        c->npts += n;
        if (info != 0 && c->status != 4) {
            fprintf(stderr, "frirom_run_advance: %s\n", msg);
            exit(2);
        }
    }
}

/* Receptances from all modes of (K, M), mass-normalised, with the modal ratios. */
static void set_modes(frirom_run *run) {
    double k[N * N] = {0}, m[N * N] = {0}, w[N], work[64];
    int one = 1, n = N, lwork = 64, info;
    char msg[512];
    for (int i = 0; i < 11; ++i) k[kr[i] + N * kc[i]] += kv[i];
    for (int i = 0; i < N; ++i) m[i + N * i] = mv[i];
    dsygv_(&one, "V", "U", &n, k, &n, m, &n, w, work, &lwork, &info);
    for (int i = 0; i < N; ++i) w[i] = sqrt(w[i]);
    if (info != 0 || frirom_run_set_modes(run, N, k, w, zeta, msg, sizeof msg) != 0) {
        fprintf(stderr, "modes: %s\n", msg);
        exit(2);
    }
}

static void solve_curve(const struct frirom_settings *s, int sparse, int modes,
                        struct curve *c) {
    char msg[512];
    frirom_run *run = open_run(s, sparse);
    if (modes) set_modes(run);
    c->npts = c->status = 0;
    if (frirom_run_start(run, 2 * M_PI * 400.0, 2 * M_PI * 520.0, msg, sizeof msg) != 0) {
        fprintf(stderr, "frirom_run_start: %s\n", msg);
        exit(2);
    }
    advance(run, c, 0);
    frirom_run_close(&run);
}

int main(void) {
    static struct curve full, cut, other;
    struct frirom_settings s;
    char msg[512];
    int bad = 0;
    frirom_settings_default(&s);
    s.harmonics = H;
    s.samples = 64;
    s.max_points = MAXPTS;

    /* the uninterrupted curve */
    solve_curve(&s, 0, 0, &full);
    for (int k = 0; k < full.npts; ++k)
        printf("%.16e %.16e %.16e %.16e\n", full.omega[k], full.amp[NOUT * k],
               full.amp[NOUT * k + 1], full.amp[NOUT * k + 2]);
    printf("complete %d %d\n", full.status == 1, full.npts);

    /* stopped after 30 points, checkpointed, restored in a new run */
    frirom_run *run = open_run(&s, 0);
    int ny, nw, ne, nck;
    frirom_run_sizes(run, &ny, &nw, &ne, &nck);
    double *ck = malloc(sizeof(double) * nck);
    cut.npts = cut.status = 0;
    frirom_run_start(run, 2 * M_PI * 400.0, 2 * M_PI * 520.0, msg, sizeof msg);
    advance(run, &cut, 30);
    int at = cut.npts;
    if (frirom_run_checkpoint(run, nck, ck, msg, sizeof msg) != 0) {
        fprintf(stderr, "frirom_run_checkpoint: %s\n", msg);
        return 2;
    }
    frirom_run_close(&run);
    run = open_run(&s, 0);
    if (frirom_run_restore(run, nck, ck, msg, sizeof msg) != 0) {
        fprintf(stderr, "frirom_run_restore: %s\n", msg);
        return 2;
    }
    advance(run, &cut, 0);
    int same = cut.npts == full.npts && cut.status == full.status &&
               memcmp(cut.omega, full.omega, sizeof(double) * full.npts) == 0 &&
               memcmp(cut.amp, full.amp, sizeof(double) * NOUT * full.npts) == 0;
    printf("restored after %d points: %d points, %s\n", at, cut.npts,
           same ? "equal to the uninterrupted run" : "DIFFERENT");
    bad += !same;

    /* one solve at a fixed frequency, from the linear solution, on the same run */
    double xo[NOUT * NC], amp[NOUT];
    double *y = malloc(sizeof(double) * ny);
    int info = frirom_run_solve_at(run, 2 * M_PI * 466.0, NULL, y, xo, amp, msg, sizeof msg);
    printf("solve at 466 Hz: info %d, amp(tip:x) %.6e\n", info, amp[0]);
    bad += info != 0;
    frirom_run_close(&run);
    free(y);
    free(ck);

    /* every receptance route and the banded formulation: the curve completes, and the
     * solve at 466 Hz equals the banded LU's to the solver's tolerance (1e-8) */
    const char *names[] = {"sparse LU", "modes", "banded"};
    for (int r = 0; r < 3; ++r) {
        struct frirom_settings t = s;
        double xr[NOUT * NC], ar[NOUT];
        if (r == 2) t.formulation = FRIROM_BANDED;
        solve_curve(&t, r == 0, r == 1, &other);
        run = open_run(&t, r == 0);
        if (r == 1) set_modes(run);
        info = frirom_run_solve_at(run, 2 * M_PI * 466.0, NULL, NULL, xr, ar, msg, sizeof msg);
        frirom_run_close(&run);
        double d = 0;
        for (int o = 0; o < NOUT; ++o) d = fmax(d, fabs(ar[o] - amp[o]) / amp[0]);
        int ok = info == 0 && other.status == 1 && d < 1e-8;
        printf("%s: %d points, complete %d; at 466 Hz amp(tip:x) %.10e, relative "
               "difference %.1e%s\n", names[r], other.npts, other.status == 1, ar[0], d,
               ok ? "" : " FAILED");
        bad += !ok;
    }
    return bad ? 1 : 0;
}
