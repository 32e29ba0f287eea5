/* The profile: the time and calls of each stage of the step, and its
 * text (m:profile(), the executable's --profile). */
#include "joints.h"
#include "laws/law.h"
#include "model_internal.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdarg.h>

/* ------------------------------------------------------------- profile */

sx_profile sx_model_profile(const sx_model *m) { return m->prof; }

void sx_model_profile_reset(sx_model *m) { memset(&m->prof, 0, sizeof m->prof); }

void sx_model_profile_add(sx_model *m, sx_stage stage, double seconds)
{
    if ((unsigned)stage >= SX_STAGE_COUNT || !(seconds >= 0)) return;
    m->prof.seconds[stage] += seconds;
    m->prof.calls[stage]++;
}

const char *sx_stage_name(sx_stage stage)
{
    static const char *const names[SX_STAGE_COUNT] = {"broad phase", "ball contacts", "wall contacts",
                                                      "integration", "callbacks",     "other"};
    return (unsigned)stage < SX_STAGE_COUNT ? names[stage] : NULL;
}

/* snprintf at offset *used of buf[len], counting what it needed in *need. */
static void appendf(char *buf, size_t len, int *need, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static void appendf(char *buf, size_t len, int *need, const char *fmt, ...)
{
    char none[1];
    const size_t used = (size_t)*need;
    va_list ap;
    va_start(ap, fmt);
    const int w = buf && used < len ? vsnprintf(buf + used, len - used, fmt, ap) : vsnprintf(none, sizeof none, fmt, ap);
    va_end(ap);
    if (w > 0) *need += w;
}

int sx_profile_format(const sx_profile *p, int64_t balls, char *buf, size_t len)
{
    double total = 0;
    for (int s = 0; s < SX_STAGE_COUNT; s++) total += p->seconds[s];
    int need = 0;
#define OUT(...) appendf(buf, len, &need, __VA_ARGS__)
    OUT("%-14s %10s %7s %10s %12s\n", "stage", "seconds", "share", "calls", "us/call");
    for (int s = 0; s < SX_STAGE_COUNT; s++) {
        const double sec = p->seconds[s];
        OUT("%-14s %10.4f %6.1f%% %10lld %12.2f\n", sx_stage_name((sx_stage)s), sec, total > 0 ? 100 * sec / total : 0.0,
            (long long)p->calls[s], p->calls[s] ? 1e6 * sec / (double)p->calls[s] : 0.0);
    }
    OUT("%-14s %10.4f %6.1f%% %10lld steps in %lld cycles (%.4f s inside cycles)\n", "total", total, 100.0,
        (long long)p->steps, (long long)p->cycles, p->cycle_seconds);
    if (balls > 0 && p->cycle_seconds > 0 && p->steps > 0)
        OUT("%lld balls: %.3g particle-steps per second inside cycles\n", (long long)balls,
            (double)balls * (double)p->steps / p->cycle_seconds);
    if (p->resumed > 0)
        OUT("%lld of the cycles went on from the last one's scattered state, without a gather\n",
            (long long)p->resumed);
    if (p->gathers > 0) OUT("%lld exchanges of the whole state between the ranks (gathers)\n", (long long)p->gathers);
    if (p->received > 0 && p->steps > 0)
        OUT("%.4g bytes received from the other ranks, %.4g a step\n", (double)p->received,
            (double)p->received / (double)p->steps);
#undef OUT
    return need;
}
