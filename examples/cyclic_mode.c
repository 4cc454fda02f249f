/* A cyclic sector's nonlinear mode (one nodal diameter, a travelling wave) through
 * frirom.h: a run opened on the rows the solver reads (contact DoFs of sector 0 and of
 * the next sector, outputs; K, M, C unused), made a cyclic mode run by
 * frirom_run_set_nonlinear_mode_cyclic with each harmonic's modes and the linear
 * travelling wave it starts from, then the backbone by frirom_run_start_mode and
 * frirom_run_advance_mode, a batch of points at a time; then the same backbone stopped
 * after its first batch, checkpointed, and restored in a new run, which must make the
 * uninterrupted run's points bit for bit. The sector's data come from a
 * text file that Python writes (tests/capi_cyclic.py write_case: frirom.reduction.cyclic
 * makes the modes of each nodal diameter from the sector's matrices).
 *
 * Build (an installed frirom): cc cyclic_mode.c $(pkg-config --cflags --libs frirom)
 * -lgfortran -lm. Run: cyclic_mode SECTOR.txt. Prints "amplitude omega xi xo..." per point
 * (xo: the outputs' harmonics, column-major (nout, 2H+1)), then "status S NPTS" and the
 * restore's line; exits 1 on a failure, with the library's message, or when the restored
 * run differs. */
#include <stdio.h>
#include <stdlib.h>
#include "frirom.h"

enum { BATCH = 20 };

static FILE *in;
/* the sector's data (read by main) */
static int n, h, ngroup, ng, npar, nsl, nout, nmodes;   /* nsl: sliders */
static int *ginfo, *gr, *gc, *outdofs;
static double *gv, *params, *w0, *fe, *q0, *psi, *omega, *zeta, omega0;

static int read_ints(int n, int *v) {
    for (int i = 0; i < n; ++i)
        if (fscanf(in, "%d", &v[i]) != 1) return 1;
    return 0;
}

static int read_doubles(int n, double *v) {
    for (int i = 0; i < n; ++i)
        if (fscanf(in, "%lf", &v[i]) != 1) return 1;
    return 0;
}

static void *room(size_t n, size_t size) {
    void *p = calloc(n ? n : 1, size);
    if (!p) { fprintf(stderr, "cyclic_mode: out of memory\n"); exit(1); }
    return p;
}

/* A run on the sector made a cyclic mode run (K, M, C: none; the modes give every
 * receptance). */
static int open_mode(frirom_run **run, const struct frirom_settings *s, char *msg,
                     int msglen) {
    if (frirom_run_open(run, n, 0, NULL, NULL, NULL, 0, NULL, NULL, NULL, 0, NULL, NULL, NULL,
                        0.0, 0.0, 0, NULL, ngroup, ginfo, ng, gr, gc, gv, npar, params, nsl,
                        nsl ? w0 : NULL, fe, nout, outdofs, s, 0, msg, msglen))
        return 1;
    return frirom_run_set_nonlinear_mode_cyclic(*run, nmodes, q0, omega0, psi, omega, zeta,
                                                msg, msglen) != 0;
}

int main(int argc, char **argv) {
    int sz[9], iset[5];
    double rset[6], range[3];
    char msg[512];
    if (argc != 2 || !(in = fopen(argv[1], "r"))) {
        fprintf(stderr, "usage: cyclic_mode SECTOR.txt (tests/capi_cyclic.py)\n");
        return 1;
    }
    if (read_ints(9, sz) || read_ints(5, iset) || read_doubles(6, rset) ||
        read_doubles(3, range)) {
        fprintf(stderr, "cyclic_mode: %s: bad header\n", argv[1]); return 1;
    }
    n = sz[0];
    h = sz[1];
    ngroup = sz[3];
    ng = sz[4];
    npar = sz[5];
    nsl = sz[6];
    nout = sz[7];
    nmodes = sz[8];
    omega0 = range[0];
    const int nc = 2 * h + 1;
    ginfo = room(3 * ngroup, sizeof(int));
    gr = room(ng, sizeof(int));
    gc = room(ng, sizeof(int));
    outdofs = room(nout, sizeof(int));
    gv = room(ng, sizeof(double));
    params = room(npar, sizeof(double));
    w0 = room(nsl, sizeof(double));
    fe = room((size_t)n * nc, sizeof(double));
    q0 = room(2 * nmodes, sizeof(double));
    psi = room(2 * (size_t)n * nmodes * (h + 1), sizeof(double));
    omega = room((size_t)nmodes * (h + 1), sizeof(double));
    zeta = room((size_t)nmodes * (h + 1), sizeof(double));
    if (read_ints(3 * ngroup, ginfo) || read_ints(ng, gr) || read_ints(ng, gc) ||
        read_doubles(ng, gv) || read_doubles(npar, params) || read_doubles(nsl, w0) ||
        read_doubles(n * nc, fe) || read_ints(nout, outdofs) ||
        read_doubles(2 * nmodes, q0) || read_doubles(2 * n * nmodes * (h + 1), psi) ||
        read_doubles(nmodes * (h + 1), omega) || read_doubles(nmodes * (h + 1), zeta)) {
        fprintf(stderr, "cyclic_mode: %s: too few numbers\n", argv[1]); return 1;
    }
    fclose(in);

    struct frirom_settings s;
    frirom_settings_default(&s);
    s.harmonics = h;
    s.samples = sz[2];
    s.formulation = FRIROM_CONDENSED;
    s.max_points = iset[0];
    s.max_iter = iset[1];
    s.batch = iset[2];
    s.reuse_jacobian = iset[3];
    s.history = iset[4];
    s.tol_residual = rset[0];
    s.tol_update = rset[1];
    s.tol_stall = rset[2];
    s.ds = rset[3];
    s.ds_min = rset[4];
    s.ds_max = rset[5];

    /* the backbone uninterrupted (printed), then stopped after its first batch,
     * checkpointed, and restored in a new run that must make the same points */
    const size_t cap = (size_t)s.max_points + BATCH + 1;
    double *amp = room(cap, sizeof(double)), *om = room(cap, sizeof(double)),
           *xi = room(cap, sizeof(double)),
           *xo = room((size_t)nout * nc * (BATCH + 1), sizeof(double));
    int npts = 0, status = 0, total = 0;
    frirom_run *run = NULL;
    if (open_mode(&run, &s, msg, sizeof msg) ||
        frirom_run_start_mode(run, range[1], range[2], msg, sizeof msg)) {
        fprintf(stderr, "%s\n", msg); return 1;
    }
    while (status == 0) {
        if (frirom_run_advance_mode(run, BATCH, &npts, amp + total, om + total, xi + total,
                                    xo, &status, msg, sizeof msg)) {
            fprintf(stderr, "frirom_run_advance_mode: %s\n", msg); return 1;
        }
        for (int j = 0; j < npts; ++j) {
            printf("%.17g %.17g %.17g", amp[total + j], om[total + j], xi[total + j]);
            for (int k = 0; k < nout * nc; ++k) printf(" %.17g", xo[(size_t)j * nout * nc + k]);
            printf("\n");
        }
        total += npts;
    }
    frirom_run_close(&run);
    printf("status %d %d\n", status, total);

    int ny, nw, ne, nck, cut = 0, st2 = 0, same = 1;
    double a2[BATCH + 1], o2[BATCH + 1], x2[BATCH + 1];
    if (open_mode(&run, &s, msg, sizeof msg) ||
        frirom_run_start_mode(run, range[1], range[2], msg, sizeof msg) ||
        frirom_run_advance_mode(run, BATCH, &cut, a2, o2, x2, xo, &st2, msg, sizeof msg) ||
        frirom_run_sizes(run, &ny, &nw, &ne, &nck)) {
        fprintf(stderr, "first batch: %s\n", msg); return 1;
    }
    double *ck = room((size_t)nck, sizeof(double));
    if (frirom_run_checkpoint(run, nck, ck, msg, sizeof msg)) {
        fprintf(stderr, "frirom_run_checkpoint: %s\n", msg); return 1;
    }
    frirom_run_close(&run);
    if (open_mode(&run, &s, msg, sizeof msg) ||
        frirom_run_restore(run, nck, ck, msg, sizeof msg)) {
        fprintf(stderr, "restore: %s\n", msg); return 1;
    }
    int at = cut;
    st2 = 0;
    while (st2 == 0) {
        if (frirom_run_advance_mode(run, BATCH, &npts, a2, o2, x2, xo, &st2, msg,
                                    sizeof msg)) {
            fprintf(stderr, "restored advance: %s\n", msg); return 1;
        }
        for (int j = 0; j < npts; ++j, ++at)
            same = same && at < total && a2[j] == amp[at] && o2[j] == om[at] && x2[j] == xi[at];
    }
    frirom_run_close(&run);
    same = same && at == total && st2 == status;
    printf("restored after %d points: %d points in all, %s\n", cut, at,
           same ? "equal to the uninterrupted run" : "DIFFERENT");
    free(amp); free(om); free(xi); free(ck);
    free(ginfo); free(gr); free(gc); free(outdofs); free(gv); free(params); free(w0);
    free(fe); free(q0); free(psi); free(omega); free(zeta); free(xo);
    return status == 1 && same ? 0 : 1;
}
