/* Jenkins and normal1d written as frirom user laws in C (tests/test_user_laws.py and
 * cases/bench/laws.py). Signature: frirom.laws.C_LAW; arrays column-major, element
 * fastest: u (ne, ndir, N), params (ne, npar), w (ne, nslider) start in / end out,
 * f (ne, ndir, N). Written from the law's rules in docs/deck.md, not from the Fortran. */
#include <math.h>

int user_jenkins(int ne, int nd, int n, int np, int ns, const double *u, const double *p,
                 double *w, double *f)
{
    if (nd != 1 || np != 3 || ns != 1) return 1;
    for (int k = 0; k < n; ++k) {
        for (int e = 0; e < ne; ++e) {
            double kt = p[e], mu = p[e + ne], fn0 = p[e + 2 * ne];
            double lim = mu * (fn0 > 0.0 ? fn0 : 0.0);
            double x = u[e + (long)ne * k];
            double t = kt * (x - w[e]);
            if (fabs(t) > lim) {
                double fs = copysign(lim, t);
                w[e] = x - fs / kt;
                t = fs;
            }
            f[e + (long)ne * k] = t;
        }
    }
    return 0;
}

/* 1-D friction with normal load variation: f_n = max(n0 + kn v, 0); an open element's
 * slider follows u, and at the last open sample before the contact recloses it sits at
 * the re-contact point (linear interpolation of the gap). */
int user_normal1d(int ne, int nd, int n, int np, int ns, const double *u, const double *p,
                  double *w, double *f)
{
    if (nd != 2 || np != 4 || ns != 1) return 1;
    for (int k = 0; k < n; ++k) {
        int k1 = (k + 1) % n;
        for (int e = 0; e < ne; ++e) {
            double kt = p[e], kn = p[e + ne], mu = p[e + 2 * ne], n0 = p[e + 3 * ne];
            double x = u[e + (long)ne * (2 * k)], v = u[e + (long)ne * (2 * k + 1)];
            double x1 = u[e + (long)ne * (2 * k1)], v1 = u[e + (long)ne * (2 * k1 + 1)];
            double g = n0 + kn * v, g1 = n0 + kn * v1;
            if (g <= 0.0 && g1 > 0.0) x = x + g / (g - g1) * (x1 - x);
            double nf = g > 0.0 ? g : 0.0;
            double lim = mu * nf;
            double t = kt * (x - w[e]);
            if (fabs(t) > lim) {
                double fs = copysign(lim, t);
                w[e] = x - fs / kt;
                t = fs;
            }
            f[e + (long)ne * (2 * k)] = t;
            f[e + (long)ne * (2 * k + 1)] = nf;
        }
    }
    return 0;
}
