/* The solver's user-law callback (frirom.h frirom_user_law_fn) over the period marches
 * of userlaw.c: Jenkins for a group of one direction, normal1d for two. The run passes
 * the context back untouched; this law needs none. */
#include <stddef.h>

int user_jenkins(int ne, int nd, int n, int np, int ns, const double *u, const double *p,
                 double *w, double *f);
int user_normal1d(int ne, int nd, int n, int np, int ns, const double *u, const double *p,
                  double *w, double *f);

int solver_law(void *ctx, int group, int ne, int nd, int n, int np, int ns, const double *u,
               const double *p, double *w, double *f)
{
    (void)ctx;
    (void)group;
    if (nd == 1) return user_jenkins(ne, nd, n, np, ns, u, p, w, f);
    if (nd == 2) return user_normal1d(ne, nd, n, np, ns, u, p, w, f);
    return 1;
}
