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
    FRIROM_LAW_CUBIC = 4,     /* u;         k1, k3 */
    FRIROM_LAW_IWAN4 = 5,     /* u;         fs, kt, chi, beta (31 sliders) */
    FRIROM_LAW_IWAN = 6       /* u;         k1, fs1, ..., k10, fs10 (10 sliders) */
};

/* frirom_settings.formulation: unknowns are the contact DoFs' harmonics (Eq. 5-9) or all
 * DoFs' harmonics (banded LU). */
enum frirom_formulation { FRIROM_CONDENSED = 1, FRIROM_BANDED = 2 };

/* Solver settings (Fortran frirom_run run_settings, the one place their defaults are
 * written; frirom.solver.SolverOptions reads the same): call frirom_settings_default
 * first. Steps are dimensionless (unknowns / |first point|, frequency / range). */
struct frirom_settings {
    int harmonics;        /* H: harmonics 0..H */
    int samples;          /* AFT samples per period; 0: the default for H (512 up to H 15) */
    int formulation;      /* FRIROM_CONDENSED (default) or FRIROM_BANDED */
    int max_points;       /* points of the curve at most */
    int max_iter;         /* Newton iterations per corrector */
    int batch;            /* points per segment of frirom_frf (a checkpoint after each) */
    int reuse_jacobian;   /* 1: keep a factorisation while Newton contracts */
    int history;          /* 1: carry the contact sliders along the curve */
    int stability;        /* 1: Hill's method at every point; 2: the same,
                             whole strip on reduced models (else nearest 0) */
    double tol_residual;  /* Newton's relative residual test */
    double tol_update;    /* ... and update test */
    double tol_stall;     /* a corrector stalled below this after max_iter is accepted */
    double ds, ds_min, ds_max;  /* first, smallest, largest arc-length step */
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

/* The run object: the one continuation driver of frirom (module frirom_run), which Python
 * and Fortran callers drive through the same calls. A run lives across calls and owns
 * its system (set up once), its continuation state and its held factorisation:
 *
 *   frirom_run_open      the model, as frirom_frf takes it (without the range and the
 *                        results); sparse = 1: condensed receptances by sparse LU (MUMPS)
 *   frirom_run_set_modes receptances by nmodes real mass-normalised modes phi (n, nmodes),
 *                        omega (rad/s), zeta: instead of factorisations (optional)
 *   frirom_run_set_selection  a travelling-wave selection keep (nnl, H+1) of the contact
 *                        DoFs' harmonics (1 = kept), its direction pair (nnl, H+1) or
 *                        NULL, orbits = 1: AFT on one element per orbit (optional)
 *   frirom_run_set_free_bodies  on = 1: a body held only by its contacts (K singular):
 *                        the contacts' stuck stiffness moved into the linear part and a
 *                        pin of FREE_PIN = 1e-2 of it on each contact's mean (the Python
 *                        Model.free_bodies() case; docs/cases/upd.md) (optional)
 *   frirom_run_start     from omega_start to omega_end (rad/s): solves the first point
 *   frirom_run_advance   up to k more points into omega (k+1), xo (nout, 2H+1, k+1), amp
 *                        (nout, k+1) and y (ny, k+1) or NULL; status: 0 going, 1 done
 *                        (reached omega_end), 2 max_points made, 3 the curve turned back
 *                        and left the range, 4 a corrector failed (the return value is its
 *                        code, msg says why; the points made are kept), 5 stalled: no
 *                        progress in frequency over 200 points (msg gives the diagnosis:
 *                        a family of solutions, a singular direction, a tolerance floor)
 *   frirom_run_solve_at  one solve at omega from y0 (ny) or from the linear solution
 *                        (y0 NULL), the continuation state untouched
 *   frirom_run_checkpoint  after an advance, everything exact resume needs: nck doubles
 *   frirom_run_restore   on a run opened on the same model (instead of start): its next
 *                        advances make the points the checkpointed run made after it
 *   frirom_run_close     frees the run, *run = NULL
 *
 * frirom_run_sizes gives the unknowns per point ny, sliders nw, contact elements ne and
 * the checkpoint length nck. frirom_frf is a loop over these calls. */
typedef struct frirom_run frirom_run;

int frirom_run_open(frirom_run **run, int n, int nk, const int *kr, const int *kc,
                    const double *kv, int nm, const int *mr, const int *mc, const double *mv,
                    int ncd, const int *cr, const int *cc, const double *cv,
                    double alpha, double beta, int nzeta, const double *zeta,
                    int ngroup, const int *ginfo, int ng, const int *gr, const int *gc,
                    const double *gv, int npar, const double *params, int nw,
                    const double *w0, const double *fe, int nout, const int *outdofs,
                    const struct frirom_settings *s, int sparse, char *msg, int msglen);
int frirom_run_sizes(const frirom_run *run, int *ny, int *nw, int *ne, int *nck);
int frirom_run_set_modes(frirom_run *run, int nmodes, const double *phi,
                         const double *omega, const double *zeta, char *msg, int msglen);
int frirom_run_set_selection(frirom_run *run, int nnl, const int *keep, const int *pair,
                             int orbits, char *msg, int msglen);
int frirom_run_set_free_bodies(frirom_run *run, int on, char *msg, int msglen);
int frirom_run_start(frirom_run *run, double omega_start, double omega_end, char *msg,
                     int msglen);
int frirom_run_advance(frirom_run *run, int k, int *npts, double *omega, double *xo,
                       double *amp, double *y, int *status, char *msg, int msglen);
int frirom_run_solve_at(frirom_run *run, double omega, const double *y0, double *y,
                        double *xo, double *amp, char *msg, int msglen);
int frirom_run_checkpoint(const frirom_run *run, int nck, double *ck, char *msg, int msglen);
int frirom_run_restore(frirom_run *run, int nck, const double *ck, char *msg, int msglen);
int frirom_run_close(frirom_run **run);

/* Nonlinear modes by the extended periodic motion concept (EPMC, Krack 2015) on the same
 * run object: the backbone of one mode, its frequency and damping against its amplitude.
 *
 *   frirom_run_set_nonlinear_mode  makes an open run a mode run starting from the linear
 *                        mode phi (n) at omega0 (rad/s; mass-normalised here): on all
 *                        DoFs (nmodes = 0), or condensed to the contact DoFs by nmodes
 *                        real modes (n, nmodes) of the free structure with omega (rad/s)
 *                        and zeta (the artificial damping changes their damping term)
 *   frirom_run_start_mode  from modal amplitude a_start to a_end (> 0, log steps; harmonic
 *                        1 mass-normalised): solves the first point
 *   frirom_run_advance_mode  up to k more points into amplitude, omega (rad/s), xi (the
 *                        artificial damping, 1/s; damping ratio xi / (2 omega)) (k+1 each)
 *                        and xo (nout, 2H+1, k+1) the output harmonics; status as
 *                        frirom_run_advance
 *
 * frirom_run_checkpoint, _restore, _sizes and _close work on a mode run as on any run. */
int frirom_run_set_nonlinear_mode(frirom_run *run, const double *phi, double omega0,
                                  int nmodes, const double *modes, const double *omega,
                                  const double *zeta, char *msg, int msglen);
int frirom_run_start_mode(frirom_run *run, double a_start, double a_end, char *msg,
                          int msglen);
int frirom_run_advance_mode(frirom_run *run, int k, int *npts, double *amplitude,
                            double *omega, double *xi, double *xo, int *status, char *msg,
                            int msglen);

/* Cyclic sectors (a tuned rotor's sector 0 under a travelling wave; frirom.reduction.cyclic
 * makes the data from a sector's matrices, docs/nonlinear_modes.md). The run is opened on
 * the DoFs the solver reads: sector 0's contact DoFs, the next sector's contact DoFs as
 * DoFs of their own (G's columns for them), the outputs and loaded DoFs; K, M, C are not
 * used (nk = nm = ncd = 0). Complex arrays are interleaved (re, im) doubles, the layout of
 * double _Complex and std::complex<double>; H is the run's harmonics.
 *
 *   frirom_run_set_modes_harmonic  receptances from modes of their own per harmonic h:
 *                        psi (n, nmodes, H+1) complex mass-normalised shapes of h's nodal
 *                        diameter over the sector (the next sector's rows times
 *                        exp(i k_h 2 pi / N)), omega, zeta (nmodes, H+1) rad/s and ratios
 *                        (unused modes of a harmonic with fewer: omega 1, zeta 0, psi 0);
 *                        a forced response under an engine order then uses them
 *   frirom_run_set_nonlinear_mode_cyclic  makes an open run a condensed mode run of one
 *                        nodal diameter as a travelling wave, with the modes as above and
 *                        the linear mode it starts from: its modal coordinates q0 (nmodes,
 *                        complex) in harmonic 1's modes and frequency omega0 (rad/s); then
 *                        frirom_run_start_mode / frirom_run_advance_mode (amplitude: the
 *                        sector's modal amplitude, the rotor's is sqrt(N) times it). */
int frirom_run_set_modes_harmonic(frirom_run *run, int nmodes, const double *psi,
                                  const double *omega, const double *zeta, char *msg,
                                  int msglen);
int frirom_run_set_nonlinear_mode_cyclic(frirom_run *run, int nmodes, const double *q0,
                                         double omega0, const double *psi,
                                         const double *omega, const double *zeta,
                                         char *msg, int msglen);

/* Contact laws written by the user (docs/tutorials/user_laws.md). A contact group whose
 * ginfo law code is frirom_law_user_code(ndir, npar, nslider) (negative; 0 when a size is
 * out of range: 1 <= ndir <= 7, 0 <= npar <= 255, 0 <= nslider <= 1e6) is evaluated by the
 * function registered with frirom_run_set_user_law, in every formulation. The function
 * marches one period of the group's ne elements: u (ne, ndir, nsamp) relative
 * displacements, params (ne, npar), w (ne, nslider) the state at the period's start in
 * and at its end out, f (ne, ndir, nsamp) the forces against u; column-major, element
 * fastest. It returns 0, or a nonzero code the run reports as a law error. ctx is
 * passed back untouched; group is the contact group, 1-based. frirom closes the cycle
 * (repeats the period until w returns to its start), takes the force harmonics, and builds
 * the Jacobian by central differences (2 ndir (2H+1) closed periods). The run keeps the
 * pointers only: keep ctx alive until frirom_run_close. */
typedef int (*frirom_user_law_fn)(void *ctx, int group, int ne, int ndir, int nsamp,
                                  int npar, int nslider, const double *u,
                                  const double *params, double *w, double *f);
int frirom_law_user_code(int ndir, int npar, int nslider);
int frirom_run_set_user_law(frirom_run *run, frirom_user_law_fn fn, void *ctx, char *msg,
                            int msglen);

#ifdef __cplusplus
}
#endif
#endif
