/* A cyclic sector's nonlinear mode (one nodal diameter, a travelling wave) through
 * frirom.h: a run opened on the rows the solver reads (contact DoFs of sector 0 and of
 * the next sector, outputs; K, M, C unused), made a cyclic mode run by
 * frirom_run_set_nonlinear_mode_cyclic with each harmonic's modes and the linear
 * travelling wave it starts from, then the backbone by frirom_run_start_mode and
 * frirom_run_advance_mode, a batch of points at a time. The sector's data come from a
 * text file that Python writes (tests/capi_cyclic.py write_case: frirom.reduction.cyclic
 * makes the modes of each nodal diameter from the sector's matrices).
 *
 * Build (an installed frirom): cc cyclic_mode.c $(pkg-config --cflags --libs frirom)
 * -lgfortran -lm. Run: cyclic_mode SECTOR.txt. Prints "amplitude omega xi xo..." per point
 * (xo: the outputs' harmonics, column-major (nout, 2H+1)), then "status S NPTS"; exits 1
 * on a failure, with the library's message. */
#include <stdio.h>
#include <stdlib.h>
#include "frirom.h"

enum { BATCH = 20 };

static FILE *in;

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
    const int n = sz[0], h = sz[1], ngroup = sz[3], ng = sz[4], npar = sz[5], nw = sz[6],
              nout = sz[7], nmodes = sz[8], nc = 2 * h + 1;
    int *ginfo = room(3 * ngroup, sizeof(int)), *gr = room(ng, sizeof(int)),
        *gc = room(ng, sizeof(int)), *outdofs = room(nout, sizeof(int));
    double *gv = room(ng, sizeof(double)), *params = room(npar, sizeof(double)),
           *w0 = room(nw, sizeof(double)), *fe = room((size_t)n * nc, sizeof(double)),
           *q0 = room(2 * nmodes, sizeof(double)),
           *psi = room(2 * (size_t)n * nmodes * (h + 1), sizeof(double)),
           *omega = room((size_t)nmodes * (h + 1), sizeof(double)),
           *zeta = room((size_t)nmodes * (h + 1), sizeof(double));
    if (read_ints(3 * ngroup, ginfo) || read_ints(ng, gr) || read_ints(ng, gc) ||
        read_doubles(ng, gv) || read_doubles(npar, params) || read_doubles(nw, w0) ||
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

    frirom_run *run = NULL;
    /* K, M, C: none (the modes give every receptance) */
    if (frirom_run_open(&run, n, 0, NULL, NULL, NULL, 0, NULL, NULL, NULL, 0, NULL, NULL,
                        NULL, 0.0, 0.0, 0, NULL, ngroup, ginfo, ng, gr, gc, gv, npar, params,
                        nw, nw ? w0 : NULL, fe, nout, outdofs, &s, 0, msg, sizeof msg)) {
        fprintf(stderr, "frirom_run_open: %s\n", msg); return 1;
    }
    if (frirom_run_set_nonlinear_mode_cyclic(run, nmodes, q0, range[0], psi, omega, zeta,
                                             msg, sizeof msg)) {
        fprintf(stderr, "frirom_run_set_nonlinear_mode_cyclic: %s\n", msg); return 1;
    }
    if (frirom_run_start_mode(run, range[1], range[2], msg, sizeof msg)) {
        fprintf(stderr, "frirom_run_start_mode: %s\n", msg); return 1;
    }
    double amp[BATCH + 1], om[BATCH + 1], xi[BATCH + 1];
    double *xo = room((size_t)nout * nc * (BATCH + 1), sizeof(double));
    int npts = 0, status = 0, total = 0;
    while (status == 0) {
        if (frirom_run_advance_mode(run, BATCH, &npts, amp, om, xi, xo, &status, msg,
                                    sizeof msg)) {
            fprintf(stderr, "frirom_run_advance_mode: %s\n", msg); return 1;
        }
        for (int j = 0; j < npts; ++j) {
            printf("%.17g %.17g %.17g", amp[j], om[j], xi[j]);
            for (int k = 0; k < nout * nc; ++k) printf(" %.17g", xo[(size_t)j * nout * nc + k]);
            printf("\n");
        }
        total += npts;
    }
    frirom_run_close(&run);
    printf("status %d %d\n", status, total);
    free(ginfo); free(gr); free(gc); free(outdofs); free(gv); free(params); free(w0);
    free(fe); free(q0); free(psi); free(omega); free(zeta); free(xo);
    return status == 1 ? 0 : 1;
}
