/* What the ranks of a decomposed step agree on (decompose.h): to stop on
 * an interrupt, at the same step on every rank, and the error one of them
 * met. */
#include "decompose.h"

#include <stdlib.h>
#include <string.h>

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

/* An error one rank met in its own part of a step (its pairs' contacts,
 * its wall blocks, its balls' or clumps' motion) does not stop it there:
 * the other ranks would wait in the step's next exchange. The rank moves
 * nothing more and keeps to the step's exchanges to the last, the largest
 * displacement (infinite from a failing rank), where every rank learns of
 * it; or the ranks stop together where they all decide alike (a
 * cylinder's radius, the cell's rates, the energy guard). There each rank
 * shares its error, if any, with the part of the step it came from, and
 * the serial run's, the earliest part's on the lowest rank (the ranks'
 * pairs, wall blocks and balls follow one another in the serial order; a
 * clump's error carries its index, as the clumps' owners do not), becomes
 * every rank's. The cycle then ends as any cycle does (sx_model_error_agreed):
 * a script can catch the error on every rank alike. */
/* Whether rank a's error comes before rank b's (a < b) in the serial step. */
static bool before(const sx_step_error *a, const sx_step_error *b)
{
    return a->part < b->part || (a->part == b->part && a->order < b->order);
}

/* An error in a rank's own part of the step: the other ranks' balls and
 * clumps may have moved on through it. */
static bool one_ranks(sx_fail_part part)
{
    return part == SX_FAIL_CONTACTS || part == SX_FAIL_WALLS || part == SX_FAIL_MOTION || part == SX_FAIL_CLUMPS;
}

sx_status sx__dd_agree_failure(sx_model *m, const sx_step_error *mine)
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks;
    sx_step_error *all = calloc((size_t)R, sizeof *all);
    if (!all) return sx__fail(m, SX_ENOMEM, "cycle: out of memory to share the ranks' errors");
    all[d->x.rank] = *mine;
    if (!sx__dd_share_by_rank(d, all, sizeof *all)) {
        free(all);
        return sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange their errors");
    }
    int pick = -1;
    for (int r = 0; r < R; r++)
        if (all[r].st && (pick < 0 || before(&all[r], &all[pick]))) pick = r;
    /* an instability's critical estimate: the ranks' least, the serial
     * one, as every rank now meets here (the failing rank's own, made where
     * it failed, was up to twice it, and turned an overlap's cause about:
     * "within the critical one" for "too large") */
    double crit;
    if (pick >= 0 && all[pick].unstable.kind != SX_UNSTABLE_NONE && sx__critical(m, &crit)) {
        sx__unstable_fail(m, &all[pick].unstable, crit);
        memcpy(all[pick].err, m->err, sizeof all[pick].err);
    }
    sx_status agreed;
    if (pick < 0) /* a displacement no rank's error explains */
        agreed = sx__fail(m, SX_EUNSTABLE, "unstable at step %lld: a ball's displacement is not finite",
                          (long long)m->step);
    else if (R > 1 && one_ranks(all[pick].part))
        agreed = sx__fail(m, all[pick].st,
                          "%s (under mpirun the state is as this step found it on the failing rank only: the "
                          "other ranks' balls may have gone on through the step; load a save to go on)",
                          all[pick].err);
    else
        agreed = sx__fail(m, all[pick].st, "%s", all[pick].err);
    /* the balls that moved are not known to the rebuild's criterion (a
     * failing rank gives an infinite displacement): the next step builds */
    if (pick < 0 || one_ranks(all[pick].part)) m->build_needed = true;
    free(all);
    d->agreed = true;
    return agreed;
}

sx_status sx__dd_agree_alike(sx_model *m, sx_status st)
{
    sx_dd *d = m->dd;
    if (!d || !st || st == SX_ENOMEM || d->agreed) return st; /* agreed already: by every rank, alike */
    uint64_t v = sx__fnv(1469598103934665603ULL, &st, sizeof st);
    v = sx__fnv(v, m->err, strnlen(m->err, sizeof m->err));
    if (d->x.agree(d->x.ud, v)) d->agreed = true;
    return st;
}
