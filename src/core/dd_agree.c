/* What the ranks of a decomposed step agree on (decompose.h): to stop on
 * an interrupt, at the same step on every rank. */
#include "decompose.h"

/* An interrupt stops every rank at the same step. Every STOP_EVERY steps
 * the ranks share the number of their process's last unanswered interrupt
 * request and of the last one a stop answered (a Ctrl-C or a SIGUSR1 that
 * mpirun forwards to each rank reaches each at its own step; a rank's run
 * that is not decomposed may have answered its own), and a request above
 * every rank's answered level stops the cycle on every rank there, in
 * step: the cycle ends as any cycle does, and the interruption can be
 * reported, and caught, alike on every rank. The decision is made from
 * the shared numbers alone, so ranks that are threads of one process
 * (tests/test_decompose.c) decide alike too. A rank's late copy of a
 * signal a stop answered is not a new request. One small exchange every
 * STOP_EVERY steps: a running cycle stops within that many steps of the
 * signal. */
enum { STOP_EVERY = 16 };

bool sx__dd_stop(sx_model *m, bool *stop)
{
    sx_dd *d = m->dd;
    *stop = false;
    if (m->step % STOP_EVERY) return true;
    const int R = d->x.ranks, me = d->x.rank;
    double *s = d->stopping;
    s[2 * me] = (double)sx__interrupts_unanswered(), s[2 * me + 1] = (double)sx__interrupts_level();
    if (!sx__dd_share_by_rank(d, s, 2 * sizeof *s)) return false;
    double request = 0, level = 0;
    for (int r = 0; r < R; r++) request = s[2 * r] > request ? s[2 * r] : request, level = s[2 * r + 1] > level ? s[2 * r + 1] : level;
    if (request > level) sx__interrupts_stopped((unsigned)request), *stop = true;
    return true;
}

