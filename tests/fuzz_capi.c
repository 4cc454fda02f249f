/* A fuzzer of the C interface (frirom.h): every entry point called with malformed
 * arguments (NULL pointers, negative and zero counts, NaN and Inf, sizes that do not match,
 * a closed or forged run, lifecycle calls out of order), each call in a child process so
 * that a crash, a hang or a stopped process is counted, not fatal.
 *
 * Named cases: each must return a non-zero status whose message names the argument (or
 * the call). Random cases (seeded): a valid 2-DoF Jenkins model whose counts, indices,
 * values and pointers are mutated, then driven through open, sizes, start, advance,
 * solve_at, checkpoint, restore and close with mutated arguments: no crash, no hang, no
 * stopped process, and every refusal carries a message.
 *
 *   fuzz_capi [random cases, default 400] [seed, default 25]
 *   fuzz_capi one SEED      (one random case in this process, to debug a failure;
 *                            FUZZ_CAPI_VERBOSE=1 prints the mutated model and the calls)
 * Exit code 0 when every case passed; prints one line per failure and a summary. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "frirom.h"

enum { BUF = 8192, MSG = 512, OK_EXIT = 0, ACCEPTED = 41, UNNAMED = 42, HANG_S = 30 };

static char msg[MSG];
static int tried, failed, crashed, hung, stopped;

/* The parent's side of one case: wait for the child and count what happened. */
static void report(const char *what, pid_t pid) {
    int ws = 0;
    ++tried;
    if (pid < 0 || waitpid(pid, &ws, 0) < 0) {
        printf("FAIL %s: fork/wait failed\n", what);
        ++failed;
        return;
    }
    if (WIFSIGNALED(ws)) {
        if (WTERMSIG(ws) == SIGALRM) {
            printf("FAIL %s: hung (> %d s)\n", what, HANG_S);
            ++hung;
        } else {
            printf("FAIL %s: crashed (signal %d)\n", what, WTERMSIG(ws));
            ++crashed;
        }
        ++failed;
    } else if (WEXITSTATUS(ws) == ACCEPTED) {
        printf("FAIL %s: accepted\n", what);
        ++failed;
    } else if (WEXITSTATUS(ws) == UNNAMED) {
        ++failed;   /* the child printed the message */
    } else if (WEXITSTATUS(ws) != OK_EXIT) {
        printf("FAIL %s: stopped the process (exit %d)\n", what, WEXITSTATUS(ws));
        ++stopped;
        ++failed;
    }
}

/* A call that must be refused with a message containing `name` ("" : any message). */
#define REFUSED(what, name, expr)                                                         \
    do {                                                                                  \
        fflush(stdout);                                                                   \
        pid_t pid_ = fork();                                                              \
        if (pid_ == 0) {                                                                  \
            alarm(HANG_S);                                                                \
            msg[0] = '\0';                                                                \
            int rc_ = (expr);                                                             \
            if (rc_ == 0) _exit(ACCEPTED);                                                \
            if (strstr(msg, name) == NULL) {                                              \
                printf("FAIL %s: status %d, message does not name '%s': %s\n", what, rc_,  \
                       name, msg);                                                        \
                fflush(stdout);                                                           \
                _exit(UNNAMED);                                                           \
            }                                                                             \
            _exit(OK_EXIT);                                                               \
        }                                                                                 \
        report(what, pid_);                                                               \
    } while (0)

/* Statements that must neither crash, hang nor stop the process. */
#define SURVIVES(what, ...)                                                              \
    do {                                                                                  \
        fflush(stdout);                                                                   \
        pid_t pid_ = fork();                                                              \
        if (pid_ == 0) {                                                                  \
            alarm(HANG_S);                                                                \
            __VA_ARGS__;                                                                  \
            fflush(stdout);                                                               \
            _exit(OK_EXIT);                                                               \
        }                                                                                 \
        report(what, pid_);                                                               \
    } while (0)

/* The valid model: 2 DoFs (springs 1e4 to ground and 1e4 between, unit masses), one
 * Jenkins element on DoF 1, force on DoF 0, both DoFs out; H = 1. Buffers are BUF long
 * so that mutated counts stay inside them (a count larger than the caller's array cannot
 * be detected by any C API: the fuzzer does not try that). */
struct model {
    int n, nk, nm, ncd, nzeta, ngroup, ng, npar, nw, nout, sparse;
    int kr[BUF], kc[BUF], mr[BUF], mc[BUF], cr[BUF], cc[BUF], ginfo[BUF], gr[BUF], gc[BUF];
    int outdofs[BUF];
    double kv[BUF], mv[BUF], cv[BUF], zeta[BUF], gv[BUF], params[BUF], w0[BUF], fe[BUF];
    double alpha, beta;
    struct frirom_settings s;
};

static void model_init(struct model *m) {
    memset(m, 0, sizeof *m);
    m->n = 2;
    const int kr[] = {0, 0, 1, 1}, kc[] = {0, 1, 0, 1};
    const double kv[] = {2e4, -1e4, -1e4, 1e4};
    m->nk = 4;
    for (int i = 0; i < 4; ++i) {
        m->kr[i] = kr[i];
        m->kc[i] = kc[i];
        m->kv[i] = kv[i];
    }
    m->nm = 2;
    m->mr[0] = m->mc[0] = 0;
    m->mr[1] = m->mc[1] = 1;
    m->mv[0] = m->mv[1] = 1.0;
    m->ncd = 0;
    m->nzeta = 1;
    m->zeta[0] = 0.01;
    m->ngroup = 1;
    m->ginfo[0] = FRIROM_LAW_JENKINS;
    m->ginfo[1] = 1;
    m->ginfo[2] = 1;
    m->ng = 1;
    m->gr[0] = 0;
    m->gc[0] = 1;
    m->gv[0] = 1.0;
    m->npar = 3;
    m->params[0] = 1e5;
    m->params[1] = 0.3;
    m->params[2] = 10.0;
    m->nw = 0;
    m->fe[2] = 1.0;  /* (n, 2H+1) column-major: a1 of DoF 0 */
    m->nout = 2;
    m->outdofs[0] = 0;
    m->outdofs[1] = 1;
    frirom_settings_default(&m->s);
    m->s.harmonics = 1;
    m->s.max_points = 40;
}

static int model_open(struct model *m, frirom_run **run, char *mp, int ml) {
    return frirom_run_open(run, m->n, m->nk, m->kr, m->kc, m->kv, m->nm, m->mr, m->mc, m->mv,
                           m->ncd, m->cr, m->cc, m->cv, m->alpha, m->beta, m->nzeta, m->zeta,
                           m->ngroup, m->ginfo, m->ng, m->gr, m->gc, m->gv, m->npar,
                           m->params, m->nw, m->w0, m->fe, m->nout, m->outdofs, &m->s,
                           m->sparse, mp, ml);
}

/* Result buffers: CAP doubles each; the fuzzer only passes counts that fit them (room
 * claimed that the caller does not have is the caller's error, not the API's). */
enum { CAP = 1 << 21 };
static double out_omega[CAP], out_xo[CAP], out_amp[CAP], out_y[CAP], ck[CAP];

/* Points of room that the output buffers have for this model (>= 1). */
static int room(const struct model *m, long per_point) {
    long nc = m->s.harmonics >= 0 && m->s.harmonics < 1000 ? 2L * m->s.harmonics + 1 : 1;
    long per = (m->nout > 0 ? m->nout : 1) * nc;
    if (per_point > per) per = per_point;
    long r = CAP / per - 1;
    return (int)(r < 1 ? 1 : (r > 100000 ? 100000 : r));
}

static int model_frf(struct model *m, double w0, double w1, int maxpts) {
    int npts, complete, ny;
    if (maxpts > room(m, 0)) maxpts = room(m, 0);
    return frirom_frf(m->n, m->nk, m->kr, m->kc, m->kv, m->nm, m->mr, m->mc, m->mv, m->ncd,
                      m->cr, m->cc, m->cv, m->alpha, m->beta, m->nzeta, m->zeta, m->ngroup,
                      m->ginfo, m->ng, m->gr, m->gc, m->gv, m->npar, m->params, m->nw, m->w0,
                      m->fe, w0, w1, m->nout, m->outdofs, &m->s, maxpts, &npts, &complete,
                      out_omega, out_xo, out_amp, 0, &ny, NULL, msg, MSG);
}

/* An open, started run (exits the child with "stopped" when that fails). */
static frirom_run *started(struct model *m) {
    frirom_run *run = NULL;
    if (model_open(m, &run, msg, MSG) || frirom_run_start(run, 60.0, 200.0, msg, MSG)) {
        printf("valid model refused: %s\n", msg);
        fflush(stdout);
        _exit(3);
    }
    return run;
}

static unsigned long long rng_state;
static unsigned rnd(unsigned n) {
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (unsigned)(rng_state >> 33) % n;
}

static double bad_double(double v) {
    switch (rnd(7)) {
    case 0: return NAN;
    case 1: return INFINITY;
    case 2: return -INFINITY;
    case 3: return -v;
    case 4: return 0.0;
    case 5: return v * 1e300;
    default: return 1e-300;
    }
}

static int bad_count(int v) {
    const int c[] = {-1, 0, 1, 2, 3, v + 1, v - 1, 63, -2147483647 - 1};
    return c[rnd(9)];
}

static int bad_index(void) {
    const int c[] = {-1, 2, 3, 63, 1 << 30, -2147483647 - 1, 0, 1};
    return c[rnd(8)];
}

/* One random mutation of the model. */
static void mutate(struct model *m) {
    int *counts[] = {&m->n, &m->nk, &m->nm, &m->ncd, &m->nzeta, &m->ngroup, &m->ng,
                     &m->npar, &m->nw, &m->nout, &m->s.harmonics, &m->s.samples,
                     &m->s.formulation, &m->s.max_points, &m->s.max_iter, &m->s.batch,
                     &m->s.reuse_jacobian, &m->s.history, &m->s.stability, &m->sparse};
    int *idx[] = {m->kr, m->kc, m->mr, m->mc, m->cr, m->cc, m->ginfo, m->gr, m->gc,
                  m->outdofs};
    double *vals[] = {m->kv, m->mv, m->cv, m->zeta, m->gv, m->params, m->w0, m->fe};
    double *scal[] = {&m->alpha, &m->beta, &m->s.tol_residual, &m->s.tol_update,
                      &m->s.tol_stall, &m->s.ds, &m->s.ds_min, &m->s.ds_max};
    switch (rnd(4)) {
    case 0: {
        int k = rnd(20);
        *counts[k] = bad_count(*counts[k]);
        if (k == 8 && *counts[k] > 0) m->w0[rnd(4)] = bad_double(1.0);
        break;
    }
    case 1: idx[rnd(10)][rnd(4)] = bad_index(); break;
    case 2: vals[rnd(8)][rnd(4)] = bad_double(1e4); break;
    default: *scal[rnd(8)] = bad_double(1e-3); break;
    }
}

static void named_cases(void) {
    struct model m;
    frirom_run *run = NULL;
    int ny, nw, ne, nck, npts, status;
    double x[64] = {0}, f[64], p[3] = {1e5, 0.3, 10.0};

    /* frirom_status_message and frirom_settings_default */
    SURVIVES("status_message NULL msg", frirom_status_message(2, NULL, 100));
    SURVIVES("status_message msglen 0 and -5", frirom_status_message(2, msg, 0);
             frirom_status_message(-77, msg, -5); frirom_status_message(1 << 30, msg, 1));
    SURVIVES("settings_default NULL", frirom_settings_default(NULL));

    /* frirom_aft_eval */
    REFUSED("aft law 0", "law", frirom_aft_eval(0, 1, 16, 1, x, p, NULL, f, NULL, NULL, msg,
                                                MSG));
    REFUSED("aft nharm -1", "nharm", frirom_aft_eval(1, -1, 16, 1, x, p, NULL, f, NULL, NULL,
                                                     msg, MSG));
    REFUSED("aft ne -3", "ne", frirom_aft_eval(1, 1, 16, -3, x, p, NULL, f, NULL, NULL, msg,
                                               MSG));
    REFUSED("aft nsamp 0", "nsamp", frirom_aft_eval(1, 1, 0, 1, x, p, NULL, f, NULL, NULL,
                                                    msg, MSG));
    REFUSED("aft nsamp -16", "nsamp", frirom_aft_eval(1, 1, -16, 1, x, p, NULL, f, NULL, NULL,
                                                      msg, MSG));
    REFUSED("aft x NULL", "x", frirom_aft_eval(1, 1, 16, 1, NULL, p, NULL, f, NULL, NULL, msg,
                                               MSG));
    REFUSED("aft params NULL", "params", frirom_aft_eval(1, 1, 16, 1, x, NULL, NULL, f, NULL,
                                                         NULL, msg, MSG));
    REFUSED("aft f NULL", "f", frirom_aft_eval(1, 1, 16, 1, x, p, NULL, NULL, NULL, NULL, msg,
                                               MSG));
    p[1] = NAN;
    REFUSED("aft NaN mu", "params", frirom_aft_eval(1, 1, 16, 1, x, p, NULL, f, NULL, NULL, msg,
                                                MSG));
    p[1] = 0.3;
    p[0] = INFINITY;
    REFUSED("aft Inf kt", "params", frirom_aft_eval(1, 1, 16, 1, x, p, NULL, f, NULL, NULL, msg,
                                                MSG));
    p[0] = 1e5;
    x[1] = NAN;
    REFUSED("aft NaN x", "x", frirom_aft_eval(1, 1, 16, 1, x, p, NULL, f, NULL, NULL, msg,
                                              MSG));
    x[1] = 0.0;
    SURVIVES("aft msg NULL", frirom_aft_eval(0, 1, 16, 1, x, p, NULL, f, NULL, NULL, NULL,
                                             MSG));

    /* frirom_frf and frirom_run_open: the model's arguments */
#define BOTH(what, name, edit)                                                            \
    model_init(&m);                                                                       \
    edit;                                                                                 \
    REFUSED("frf " what, name, model_frf(&m, 60.0, 200.0, BUF / 8));                      \
    model_init(&m);                                                                       \
    edit;                                                                                 \
    REFUSED("run_open " what, name, model_open(&m, &run, msg, MSG))
    BOTH("n 0", "n", m.n = 0);
    BOTH("n -1", "n", m.n = -1);
    BOTH("nk -1", "nk", m.nk = -1);
    BOTH("nm -4", "nm", m.nm = -4);
    BOTH("nout -1", "nout", m.nout = -1);
    BOTH("ngroup -1", "ngroup", m.ngroup = -1);
    BOTH("harmonics -1", "harmonics", m.s.harmonics = -1);
    BOTH("K row out of range", "kr", m.kr[1] = 7);
    BOTH("K column negative", "kc", m.kc[1] = -1);
    BOTH("M row out of range", "mr", m.mr[0] = 2);
    BOTH("K value NaN", "kv", m.kv[0] = NAN);
    BOTH("M value Inf", "mv", m.mv[1] = INFINITY);
    BOTH("damping alpha NaN", "alpha", m.alpha = NAN);
    BOTH("zeta negative", "zeta", m.zeta[0] = -0.5);
    BOTH("zeta more than n", "nzeta", m.nzeta = 3);
    BOTH("G row count mismatch", "npar", m.ginfo[1] = 3);
    BOTH("G column out of range", "gc", m.gc[0] = 5);
    BOTH("G value NaN", "gv", m.gv[0] = NAN);
    BOTH("unknown law", "law", m.ginfo[0] = 42);
    BOTH("npar mismatch", "npar", m.npar = 2);
    BOTH("NaN mu", "params", m.params[1] = NAN);
    BOTH("negative kt", "kt", m.params[0] = -1e5);
        BOTH("nw mismatch", "nw", m.nw = 5);
    BOTH("w0 NaN", "w0", m.nw = 1; m.w0[0] = NAN);
    BOTH("fe NaN", "fe", m.fe[2] = NAN);
    BOTH("output DoF out of range", "outdofs", m.outdofs[1] = 2);
    BOTH("formulation 7", "formulation", m.s.formulation = 7);
    BOTH("max_points 0", "max_points", m.s.max_points = 0);
    BOTH("tol_residual NaN", "tol_residual", m.s.tol_residual = NAN);
    BOTH("ds negative", "ds", m.s.ds = -0.1);
    BOTH("samples -8", "samples", m.s.samples = -8);
#undef BOTH
    model_init(&m);
    REFUSED("frf omega NaN", "omega_start", model_frf(&m, NAN, 200.0, BUF / 8));
    REFUSED("frf omega_end Inf", "omega_end", model_frf(&m, 60.0, INFINITY, BUF / 8));
    REFUSED("frf omega negative", "omega_start", model_frf(&m, -60.0, 200.0, BUF / 8));
    REFUSED("frf maxpts small", "maxpts", model_frf(&m, 60.0, 200.0, 3));
    REFUSED("frf settings NULL", "settings",
            frirom_frf(m.n, m.nk, m.kr, m.kc, m.kv, m.nm, m.mr, m.mc, m.mv, 0, NULL, NULL,
                       NULL, 0, 0, 0, NULL, m.ngroup, m.ginfo, m.ng, m.gr, m.gc, m.gv, m.npar,
                       m.params, 0, NULL, m.fe, 60, 200, m.nout, m.outdofs, NULL, 40, &npts,
                       &status, out_omega, out_xo, out_amp, 0, &ny, NULL, msg, MSG));
    REFUSED("frf K NULL", "kr",
            frirom_frf(m.n, m.nk, NULL, NULL, NULL, m.nm, m.mr, m.mc, m.mv, 0, NULL, NULL,
                       NULL, 0, 0, 0, NULL, m.ngroup, m.ginfo, m.ng, m.gr, m.gc, m.gv, m.npar,
                       m.params, 0, NULL, m.fe, 60, 200, m.nout, m.outdofs, &m.s, 40, &npts,
                       &status, out_omega, out_xo, out_amp, 0, &ny, NULL, msg, MSG));
    REFUSED("frf fe NULL", "fe",
            frirom_frf(m.n, m.nk, m.kr, m.kc, m.kv, m.nm, m.mr, m.mc, m.mv, 0, NULL, NULL,
                       NULL, 0, 0, 0, NULL, m.ngroup, m.ginfo, m.ng, m.gr, m.gc, m.gv, m.npar,
                       m.params, 0, NULL, NULL, 60, 200, m.nout, m.outdofs, &m.s, 40, &npts,
                       &status, out_omega, out_xo, out_amp, 0, &ny, NULL, msg, MSG));
    REFUSED("frf npts NULL", "npts",
            frirom_frf(m.n, m.nk, m.kr, m.kc, m.kv, m.nm, m.mr, m.mc, m.mv, 0, NULL, NULL,
                       NULL, 0, 0, 0, NULL, m.ngroup, m.ginfo, m.ng, m.gr, m.gc, m.gv, m.npar,
                       m.params, 0, NULL, m.fe, 60, 200, m.nout, m.outdofs, &m.s, 40, NULL,
                       &status, out_omega, out_xo, out_amp, 0, &ny, NULL, msg, MSG));
    REFUSED("frf omega out NULL", "omega",
            frirom_frf(m.n, m.nk, m.kr, m.kc, m.kv, m.nm, m.mr, m.mc, m.mv, 0, NULL, NULL,
                       NULL, 0, 0, 0, NULL, m.ngroup, m.ginfo, m.ng, m.gr, m.gc, m.gv, m.npar,
                       m.params, 0, NULL, m.fe, 60, 200, m.nout, m.outdofs, &m.s, 40, &npts,
                       &status, NULL, out_xo, out_amp, 0, &ny, NULL, msg, MSG));
    REFUSED("run_open run NULL", "run",
            frirom_run_open(NULL, m.n, m.nk, m.kr, m.kc, m.kv, m.nm, m.mr, m.mc, m.mv, 0,
                            NULL, NULL, NULL, 0, 0, 0, NULL, m.ngroup, m.ginfo, m.ng, m.gr,
                            m.gc, m.gv, m.npar, m.params, 0, NULL, m.fe, m.nout, m.outdofs,
                            &m.s, 0, msg, MSG));
    REFUSED("run_open settings NULL", "settings",
            frirom_run_open(&run, m.n, m.nk, m.kr, m.kc, m.kv, m.nm, m.mr, m.mc, m.mv, 0,
                            NULL, NULL, NULL, 0, 0, 0, NULL, m.ngroup, m.ginfo, m.ng, m.gr,
                            m.gc, m.gv, m.npar, m.params, 0, NULL, m.fe, m.nout, m.outdofs,
                            NULL, 0, msg, MSG));
    REFUSED("run_open params NULL", "params",
            frirom_run_open(&run, m.n, m.nk, m.kr, m.kc, m.kv, m.nm, m.mr, m.mc, m.mv, 0,
                            NULL, NULL, NULL, 0, 0, 0, NULL, m.ngroup, m.ginfo, m.ng, m.gr,
                            m.gc, m.gv, m.npar, NULL, 0, NULL, m.fe, m.nout, m.outdofs,
                            &m.s, 0, msg, MSG));

    /* a NULL, closed or forged run given to every call that takes one */
    static double forged_zero[BUF], forged_junk[BUF];
    memset(forged_junk, 0xA5, sizeof forged_junk);
    frirom_run *closed = NULL;
    model_init(&m);
    if (model_open(&m, &closed, msg, MSG)) {
        printf("FAIL valid model refused: %s\n", msg);
        ++failed;
    }
    frirom_run *keep = closed;
    frirom_run_close(&closed);
    frirom_run *bad[] = {NULL, keep, (frirom_run *)forged_zero, (frirom_run *)forged_junk,
                         (frirom_run *)((char *)forged_zero + 3)};
    const char *bad_name[] = {"NULL run", "closed run", "forged run (zeros)",
                              "forged run (junk)", "misaligned run"};
    for (int b = 0; b < 5; ++b) {
        char what[128];
        frirom_run *r = bad[b];
#define ON(call, expr)                                                                    \
        snprintf(what, sizeof what, "%s: %s", call, bad_name[b]);                         \
        REFUSED(what, "open run", expr)
        ON("run_start", frirom_run_start(r, 60, 200, msg, MSG));
        ON("run_advance", frirom_run_advance(r, 5, &npts, out_omega, out_xo, out_amp, NULL,
                                             &status, msg, MSG));
        ON("run_solve_at", frirom_run_solve_at(r, 80, NULL, NULL, out_xo, out_amp, msg, MSG));
        ON("run_set_modes", frirom_run_set_modes(r, 1, x, x, x, msg, MSG));
        ON("run_set_modes_harmonic", frirom_run_set_modes_harmonic(r, 1, x, x, x, msg, MSG));
        ON("run_set_nonlinear_mode_cyclic", frirom_run_set_nonlinear_mode_cyclic(
               r, 1, x, 100, x, x, x, msg, MSG));
        ON("run_set_selection", frirom_run_set_selection(r, 1, (int *)x, NULL, 0, msg, MSG));
        ON("run_checkpoint", frirom_run_checkpoint(r, 4, ck, msg, MSG));
        ON("run_restore", frirom_run_restore(r, 4, ck, msg, MSG));
#undef ON
        snprintf(what, sizeof what, "run_sizes: %s", bad_name[b]);
        REFUSED(what, "", frirom_run_sizes(r, &ny, &nw, &ne, &nck));
        if (b > 0) {
            snprintf(what, sizeof what, "run_close: %s", bad_name[b]);
            REFUSED(what, "", frirom_run_close(&r));
        }
    }
    SURVIVES("run_close NULL pointer and pointer to NULL", frirom_run_close(NULL);
             frirom_run *z = NULL; frirom_run_close(&z));

    /* an open run: lifecycle out of order and bad arguments */
    model_init(&m);
#define OPENED(what, name, expr)                                                          \
    REFUSED(what, name, (model_open(&m, &run, msg, MSG) ? -1000 : (expr)))
    OPENED("sizes NULL out", "", frirom_run_sizes(run, NULL, NULL, NULL, NULL));
    OPENED("advance before start", "run_start", frirom_run_advance(run, 3, &npts, out_omega,
           out_xo, out_amp, NULL, &status, msg, MSG));
    OPENED("checkpoint before start", "checkpoint",
           (frirom_run_sizes(run, &ny, &nw, &ne, &nck),
            frirom_run_checkpoint(run, nck, ck, msg, MSG)));
    OPENED("start NaN", "omega_start", frirom_run_start(run, NAN, 200, msg, MSG));
    OPENED("start end Inf", "omega_end", frirom_run_start(run, 60, INFINITY, msg, MSG));
    OPENED("start negative", "positive", frirom_run_start(run, -60, 200, msg, MSG));
    OPENED("start huge", "omega_start", frirom_run_start(run, 6e301, 200, msg, MSG));
    OPENED("solve_at huge", "omega", frirom_run_solve_at(run, 1e200, NULL, NULL, out_xo,
           out_amp, msg, MSG));
    OPENED("start equal ends", "omega", frirom_run_start(run, 60, 60, msg, MSG));
    OPENED("set_modes nmodes 0", "nmodes", frirom_run_set_modes(run, 0, x, x, x, msg, MSG));
    OPENED("set_modes phi NULL", "phi", frirom_run_set_modes(run, 1, NULL, x, x, msg, MSG));
    OPENED("set_modes omega NaN", "omega",
           (x[10] = NAN, frirom_run_set_modes(run, 1, x, x + 10, x, msg, MSG)));
    OPENED("set_modes nmodes > n", "phi", frirom_run_set_modes(run, 5, x, x, x, msg, MSG));
    {   /* cyclic: n = 2 DoFs, H = 1, one mode (complex arrays interleaved re, im) */
        double cq[2] = {1, 0}, cp[8] = {1, 0, 0.5, 0, 1, 0, 0.5, 0}, cw[2] = {100, 100},
               cz[2] = {0, 0};
        OPENED("set_modes_harmonic nmodes 0", "nmodes",
               frirom_run_set_modes_harmonic(run, 0, cp, cw, cz, msg, MSG));
        OPENED("set_modes_harmonic psi NULL", "psi",
               frirom_run_set_modes_harmonic(run, 1, NULL, cw, cz, msg, MSG));
        OPENED("set_modes_harmonic omega 0", "omega",
               frirom_run_set_modes_harmonic(run, 1, cp, x, cz, msg, MSG));
        OPENED("set_modes_harmonic zeta NaN", "zeta",
               (cz[1] = NAN, frirom_run_set_modes_harmonic(run, 1, cp, cw, cz, msg, MSG)));
        cz[1] = 0;
        OPENED("set_nonlinear_mode_cyclic nmodes -1", "nmodes",
               frirom_run_set_nonlinear_mode_cyclic(run, -1, cq, 100, cp, cw, cz, msg, MSG));
        OPENED("set_nonlinear_mode_cyclic q0 NULL", "q0",
               frirom_run_set_nonlinear_mode_cyclic(run, 1, NULL, 100, cp, cw, cz, msg, MSG));
        OPENED("set_nonlinear_mode_cyclic q0 zero", "q0",
               frirom_run_set_nonlinear_mode_cyclic(run, 1, x, 100, cp, cw, cz, msg, MSG));
        OPENED("set_nonlinear_mode_cyclic omega0 NaN", "omega0",
               frirom_run_set_nonlinear_mode_cyclic(run, 1, cq, NAN, cp, cw, cz, msg, MSG));
        OPENED("set_nonlinear_mode_cyclic psi Inf", "psi",
               (cp[3] = INFINITY, frirom_run_set_nonlinear_mode_cyclic(run, 1, cq, 100, cp, cw,
                                                                       cz, msg, MSG)));
        cp[3] = 0;
        OPENED("set_nonlinear_mode_cyclic zeta NULL", "zeta",
               frirom_run_set_nonlinear_mode_cyclic(run, 1, cq, 100, cp, cw, NULL, msg, MSG));
        OPENED("start_mode before set_nonlinear_mode_cyclic", "mode run",
               frirom_run_start_mode(run, 1e-6, 1e-3, msg, MSG));
    }
    OPENED("set_selection nnl -1", "nnl", frirom_run_set_selection(run, -1, (int *)x, NULL,
           0, msg, MSG));
    OPENED("set_selection nnl mismatch", "keep", frirom_run_set_selection(run, 3, (int *)x,
           NULL, 0, msg, MSG));
    OPENED("set_selection keep NULL", "keep", frirom_run_set_selection(run, 1, NULL, NULL, 0,
           msg, MSG));
    OPENED("solve_at NaN", "omega", frirom_run_solve_at(run, NAN, NULL, NULL, out_xo, out_amp,
           msg, MSG));
    OPENED("solve_at negative", "omega", frirom_run_solve_at(run, -5, NULL, NULL, out_xo,
           out_amp, msg, MSG));
    OPENED("solve_at y0 NaN", "y0", (out_y[0] = NAN, frirom_run_solve_at(run, 80, out_y, NULL,
           out_xo, out_amp, msg, MSG)));
    OPENED("solve_at xo NULL", "xo", frirom_run_solve_at(run, 80, NULL, NULL, NULL, out_amp,
           msg, MSG));
    OPENED("restore NaN checkpoint", "ck",
           (frirom_run_sizes(run, &ny, &nw, &ne, &nck), memset(ck, 0xFF, sizeof ck),
            frirom_run_restore(run, nck, ck, msg, MSG)));
    OPENED("restore zero checkpoint", "ck",
           (frirom_run_sizes(run, &ny, &nw, &ne, &nck), memset(ck, 0, sizeof ck),
            frirom_run_restore(run, nck, ck, msg, MSG)));
#undef OPENED
    /* a started run */
#define STARTED(what, name, expr) REFUSED(what, name, (run = started(&m), (expr)))
    STARTED("advance k 0", "k", frirom_run_advance(run, 0, &npts, out_omega, out_xo, out_amp,
            NULL, &status, msg, MSG));
    STARTED("advance k -3", "k", frirom_run_advance(run, -3, &npts, out_omega, out_xo,
            out_amp, NULL, &status, msg, MSG));
    STARTED("advance npts NULL", "npts", frirom_run_advance(run, 3, NULL, out_omega, out_xo,
            out_amp, NULL, &status, msg, MSG));
    STARTED("advance omega NULL", "omega", frirom_run_advance(run, 3, &npts, NULL, out_xo,
            out_amp, NULL, &status, msg, MSG));
    STARTED("advance status NULL", "status", frirom_run_advance(run, 3, &npts, out_omega,
            out_xo, out_amp, NULL, NULL, msg, MSG));
#undef STARTED
}

#define CHECK(call, expr)                                                                 \
    msg[0] = '\0';                                                                        \
    if (getenv("FUZZ_CAPI_VERBOSE")) printf("%s\n", #expr), fflush(stdout);              \
    rc = (expr);                                                                          \
    if (rc != 0 && msg[0] == '\0') {                                                      \
        printf("FAIL %s: %s returned %d without a message\n", what, call, rc);            \
        fflush(stdout);                                                                   \
        _exit(UNNAMED);                                                                   \
    }

/* One random case (in the child): a mutated model through the lifecycle, mutated calls. */
static void random_case(const char *what) {
    struct model m;
    frirom_run *run = NULL;
    int ny = 0, nw = 0, ne = 0, nck = 0, npts = 0, status = 0, rc;
    model_init(&m);
    int nmut = 1 + (int)rnd(3);
    for (int k = 0; k < nmut; ++k) mutate(&m);
    if (getenv("FUZZ_CAPI_VERBOSE")) {  /* what was mutated, for a failing seed */
        printf("n %d nk %d nm %d ncd %d nzeta %d ngroup %d ng %d npar %d nw %d nout %d sparse %d"
               "\nH %d samples %d formulation %d max_points %d max_iter %d batch %d reuse %d "
               "history %d stability %d\ntol %g %g %g ds %g %g %g alpha %g beta %g\n", m.n,
               m.nk, m.nm, m.ncd, m.nzeta, m.ngroup, m.ng, m.npar, m.nw, m.nout, m.sparse,
               m.s.harmonics, m.s.samples, m.s.formulation, m.s.max_points, m.s.max_iter,
               m.s.batch, m.s.reuse_jacobian, m.s.history, m.s.stability, m.s.tol_residual,
               m.s.tol_update, m.s.tol_stall, m.s.ds, m.s.ds_min, m.s.ds_max, m.alpha, m.beta);
        for (int i = 0; i < 4; ++i)
            printf("k %d %d %g  m %d %d %g  g %d %d %g  p %g  fe %g  out %d  ginfo %d\n",
                   m.kr[i], m.kc[i], m.kv[i], m.mr[i], m.mc[i], m.mv[i], m.gr[i], m.gc[i],
                   m.gv[i], m.params[i], m.fe[i], m.outdofs[i], m.ginfo[i]);
        fflush(stdout);
    }
    if (rnd(4) == 0) {
        int maxpts = m.s.max_points > 0 ? m.s.max_points : 1;
        if (maxpts > room(&m, 0)) return;  /* the caller would not have the room */
        CHECK("frirom_frf", model_frf(&m, rnd(5) ? 60.0 : bad_double(60.0), 200.0, maxpts));
        return;
    }
    CHECK("frirom_run_open", model_open(&m, &run, msg, MSG));
    if (rc != 0) return;
    frirom_run_sizes(run, &ny, &nw, &ne, &nck);
    CHECK("frirom_run_start",
          frirom_run_start(run, rnd(6) ? 60.0 : bad_double(60.0), 200.0, msg, MSG));
    if (ny > CAP / 2) return;  /* more unknowns than the caller's buffers hold */
    for (int s = 0; s < 3; ++s) {
        int call = (int)rnd(5), k = rnd(6) ? 1 + (int)rnd(20) : bad_count(3);
        if (call == 0) {
            CHECK("frirom_run_solve_at",
                  frirom_run_solve_at(run, rnd(4) ? 90.0 : bad_double(90.0), NULL, out_y,
                                      out_xo, out_amp, msg, MSG));
        } else if (k > 0 && k > room(&m, ny)) {
            continue;  /* more unknowns or points than the caller's buffers hold */
        } else if (call == 1 && nck > 0 && nck < CAP) {
            CHECK("frirom_run_checkpoint",
                  frirom_run_checkpoint(run, rnd(3) ? nck : bad_count(nck), ck, msg, MSG));
            if (rnd(2)) {
                unsigned at = rnd((unsigned)nck);
                ck[at] = bad_double(1.0);
                if (getenv("FUZZ_CAPI_VERBOSE")) printf("ck[%u] = %g\n", at, ck[at]);
            }
            CHECK("frirom_run_restore", frirom_run_restore(run, nck, ck, msg, MSG));
        } else {
            CHECK("frirom_run_advance", frirom_run_advance(run, k, &npts, out_omega, out_xo,
                                                           out_amp, out_y, &status, msg, MSG));
            if (k < 1 && rc == 0) {
                printf("FAIL %s: advance accepted k = %d\n", what, k);
                fflush(stdout);
                _exit(ACCEPTED);
            }
        }
    }
    frirom_run_close(&run);
    if (run != NULL) {
        printf("FAIL %s: close left the run\n", what);
        fflush(stdout);
        _exit(ACCEPTED);
    }
}
#undef CHECK

static void random_cases(int count) {
    for (int i = 0; i < count; ++i) {
        char what[64];
        snprintf(what, sizeof what, "random case %d (seed %llu)", i, rng_state);
        unsigned long long seed = rng_state;
        SURVIVES(what, random_case(what));
        rng_state = seed * 2862933555777941757ULL + 3037000493ULL;
    }
}

int main(int argc, char **argv) {
    if (argc > 2 && strcmp(argv[1], "one") == 0) {  /* one random case, in this process */
        rng_state = strtoull(argv[2], NULL, 10);
        random_case("random case");
        puts("survived");
        return 0;
    }
    int count = argc > 1 ? atoi(argv[1]) : 400;
    rng_state = argc > 2 ? strtoull(argv[2], NULL, 10) : 25;
    named_cases();
    int named = tried, named_failed = failed;
    random_cases(count);
    printf("fuzz_capi: %d named cases (%d failed), %d random cases (%d failed): %d crashed, "
           "%d hung, %d stopped the process\n", named, named_failed, tried - named,
           failed - named_failed, crashed, hung, stopped);
    return failed ? 1 : 0;
}
