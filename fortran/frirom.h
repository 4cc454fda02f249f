/* frirom C interface (bind(c) entry points of libfrirom, module frirom_capi).
 *
 * Arrays are column-major (Fortran order). Harmonic ordering of a length-(2H+1) axis:
 * [a0, a1, b1, ..., aH, bH], x(tau) = a0 + sum_h a_h cos(h tau) + b_h sin(h tau).
 * Every function returns a frirom status code (0 = success) and writes a NUL-terminated
 * message into msg (msglen bytes) when msg is not NULL.
 *
 * Link: $(pkg-config --cflags --libs frirom) -lgfortran
 */
#ifndef FRIROM_H
#define FRIROM_H

#ifdef __cplusplus
extern "C" {
#endif

enum frirom_law {
    FRIROM_LAW_JENKINS = 1,   /* u;         kt, mu, fn0 */
    FRIROM_LAW_NORMAL1D = 2,  /* u, v;      kt, kn, mu, n0 */
    FRIROM_LAW_NORMAL2D = 3,  /* u1, u2, v; kt, kn, mu, n0 */
    FRIROM_LAW_CUBIC = 4      /* u;         k1, k3 */
};

/* frirom_settings.formulation: unknowns are the contact DoFs' harmonics (Eq. 5-9) or all
 * DoFs' harmonics (banded LU). */
enum frirom_formulation { FRIROM_CONDENSED = 1, FRIROM_BANDED = 2 };

/* Solver settings of frirom_frf; frirom_settings_default fills the defaults of
 * frirom.solver.SolverOptions. Steps are dimensionless (unknowns / |first point|,
 * frequency / range). */
struct frirom_settings {
    int harmonics;        /* H: harmonics 0..H (default 3) */
    int samples;          /* AFT samples per period; 0: the default for H (512 up to H 15) */
    int formulation;      /* FRIROM_CONDENSED (default) or FRIROM_BANDED */
    int max_points;       /* points of the curve at most (2000) */
    int max_iter;         /* Newton iterations per corrector (25) */
    int batch;            /* points per internal call; the points do not depend on it (10) */
    int reuse_jacobian;   /* 1: keep a factorisation while Newton contracts (1) */
    int history;          /* 1: carry the contact sliders along the curve (1) */
    double tol_residual;  /* 1e-8 */
    double tol_update;    /* 1e-8 */
    double tol_stall;     /* 0 */
    double ds, ds_min, ds_max;  /* first, smallest, largest arc-length step (0.02, 1e-6, 0.1) */
};

/* Text of a status code. */
int frirom_status_message(int info, char *msg, int msglen);

/* AFT forces (and Jacobian) of ne elements of one law at nharm harmonics, nsamp samples.
 * x, f: (2H+1, ndir, ne); params: (npar, ne); w0: (nslider, ne) or NULL for zeros;
 * jac: (ndir(2H+1), ndir(2H+1), ne) or NULL; periods: (ne) or NULL. */
int frirom_aft_eval(int law, int nharm, int nsamp, int ne, const double *x,
                    const double *params, const double *w0, double *f, double *jac,
                    int *periods, char *msg, int msglen);

void frirom_settings_default(struct frirom_settings *s);

/* The forced response of a model from omega_start to omega_end (rad/s) by harmonic balance
 * and arc-length continuation through turning points (module frirom_solve, frf_solve; the
 * same steps as frirom.solver.frf with receptances 'factorization').
 * Indices are 0-based. Matrices as triplets (row, column, value) listing every entry (both
 * triangles of a symmetric matrix; duplicates add): K (nk entries, N/m), M (nm, kg), C (ncd,
 * N s/m; 0 and NULLs for none). Damping is C + alpha M + beta K + modal: zeta (nzeta) ratios
 * of the lowest nzeta modes. Contacts: ginfo (3, ngroup) = law (enum frirom_law), elements,
 * directions per group; group g owns the next elements*directions rows of G, element by
 * element; G as ng triplets (gr, gc, gv) over all groups; params (npar) each group's
 * (npar_law, elements) parameters, concatenated; w0 (nw) initial sliders or nw = 0, NULL.
 * fe (n, 2H+1): excitation harmonics [a0, a1, b1, ...], N. outdofs (nout): DoFs kept.
 * Out (maxpts >= s->max_points points of room): npts points, omega (npts) rad/s, xo (nout,
 * 2H+1, npts) output harmonics, amp (nout, npts) max over a period of |x(t)|, y (nycap,
 * npts) unknowns when y is not NULL and nycap >= ny (ny: unknowns per point); complete = 1
 * when the curve reached omega_end. Returns 0 when every solve converged (complete = 0
 * then means max_points was reached or the curve turned back out of the range; msg says
 * which); non-zero with npts > 0: the curve stopped there, msg says why; non-zero with
 * npts = 0: bad input (msg names the argument) or no first point. */
int frirom_frf(int n, int nk, const int *kr, const int *kc, const double *kv,
               int nm, const int *mr, const int *mc, const double *mv,
               int ncd, const int *cr, const int *cc, const double *cv,
               double alpha, double beta, int nzeta, const double *zeta,
               int ngroup, const int *ginfo, int ng, const int *gr, const int *gc,
               const double *gv, int npar, const double *params, int nw, const double *w0,
               const double *fe, double omega_start, double omega_end,
               int nout, const int *outdofs, const struct frirom_settings *s,
               int maxpts, int *npts, int *complete, double *omega, double *xo, double *amp,
               int nycap, int *ny, double *y, char *msg, int msglen);

#ifdef __cplusplus
}
#endif
#endif
