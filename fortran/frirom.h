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

/* Text of a status code. */
int frirom_status_message(int info, char *msg, int msglen);

/* AFT forces (and Jacobian) of ne elements of one law at nharm harmonics, nsamp samples.
 * x, f: (2H+1, ndir, ne); params: (npar, ne); w0: (nslider, ne) or NULL for zeros;
 * jac: (ndir(2H+1), ndir(2H+1), ne) or NULL; periods: (ne) or NULL. */
int frirom_aft_eval(int law, int nharm, int nsamp, int ne, const double *x,
                    const double *params, const double *w0, double *f, double *jac,
                    int *periods, char *msg, int msglen);

#ifdef __cplusplus
}
#endif
#endif
