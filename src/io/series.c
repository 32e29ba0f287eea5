/* Output series: snapshots for viewing, appended to one HDF5 file, with
 * an XDMF file beside it that ParaView (or VisIt) opens as a time series.
 *
 * Each snapshot is a group /snapshots/NNNNNN holding the balls as points
 * (always 3 components per vector, z = 0 in 2D, so viewers need no
 * special case), ball-ball contacts and bonds as line cells between ball
 * centres (connectivity into the balls' points), ball-wall contacts as
 * lines from the centre to the contact point, and walls as quadrilaterals
 * (3D) or segments (2D); an infinite wall is drawn across the balls'
 * bounding box; the crack log so far (with the bonds) as points, so a
 * viewer draws the crack map of each snapshot. Every block is named in the
 * XDMF (balls, contacts, wall_contacts, bonds, cracks, walls).
 *
 * Histories grow beside the snapshots: /histories/<name> holds extendable
 * datasets (history.c) to which each write appends the samples of steps
 * after the last one the file holds.
 *
 * Nothing is lost on a crash: the file is created under a temporary name
 * and renamed; each snapshot and the history rows are written, flushed and
 * synced before the `count`s of complete snapshots and rows are raised
 * (readers ignore what lies beyond them). HDF5 rewrites metadata in place
 * (a group's header when a link is added, a growing dataset's chunk
 * index) and writes a flush's pieces in address order, a parent before
 * its new child, so the file is written through a journal (journal.c)
 * that makes each flush atomic: a kill leaves the file as the last
 * completed flush left it. A snapshot is written as an unlinked group and
 * linked once it is complete, so a failed write leaves no link behind.
 * The XDMF is never patched in place: the new one (kept in memory, so no
 * snapshot is read back) is written and synced under a temporary name
 * before the counts are raised, and renamed over the old one right after,
 * so it is always a complete document and lists the snapshots the counts
 * say are complete; only a kill in the microseconds between the counts'
 * write and the rename leaves it one snapshot behind (seixo.xdmf and
 * append mode rebuild it). The 1.8 file format keeps a file whose writer
 * was killed openable.
 *
 * This file keeps the series file (open, append, recovery of what a killed
 * write left, close); series_frame.c writes one snapshot's groups and
 * series_xdmf.c the XDMF. */
#include "series_internal.h"
#include "state.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* A history the file holds: its complete rows and their last step. */
typedef struct held {
    char *name;
    int64_t rows, last;
} held;

struct sx_series {
    char *path;       /* the .h5 */
    char *xmf;        /* the .xmf beside it */
    char *base;       /* the .h5's name as the .xmf refers to it */
    hid_t file;
    int dim;
    unsigned fields;
    int compression;
    int64_t count;    /* complete snapshots */
    int64_t opened_at; /* appending: the last snapshot's step when opened (-1: none) */
    xdoc x;           /* the XDMF: a grid per block and complete snapshot */
    held *held;       /* histories met so far */
    int nheld, capheld;
    dev_t dev;        /* the .h5's file, however its path is spelt */
    ino_t ino;
    dev_t xdev;       /* the .xmf's folder (the file is renamed over at each write) */
    ino_t xino;
    sx_series *next;  /* the process's open series */
};

/* The series open in this process, so that no other writer takes one's
 * file (a robustness tester's finding: a second m:output, or an m:save, to
 * an open series' path replaced its file while the first went on writing
 * into the unnamed old one, counting snapshots that were lost). */
static sx_series *open_series;

/* The folder of path (its identity) and its last component. */
static bool folder_of(const char *path, struct stat *st, const char **base)
{
    const char *slash = strrchr(path, '/');
    *base = slash ? slash + 1 : path;
    char dir[4096];
    if (!slash) snprintf(dir, sizeof dir, ".");
    else if (slash == path) snprintf(dir, sizeof dir, "/");
    else if (snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path) >= (int)sizeof dir) return false;
    return stat(dir, st) == 0;
}

/* An open series whose .xmf path names: its folder's identity and name. */
static const sx_series *xmf_owner(const char *path)
{
    struct stat st;
    const char *base;
    if (!path || !folder_of(path, &st, &base)) return NULL;
    for (const sx_series *s = open_series; s; s = s->next) {
        const char *slash = strrchr(s->xmf, '/');
        if (s->xdev == st.st_dev && s->xino == st.st_ino && strcmp(slash ? slash + 1 : s->xmf, base) == 0) return s;
    }
    return NULL;
}

bool sx_io_series_open_at(const char *path)
{
    struct stat st;
    if (xmf_owner(path)) return true; /* its .xmf, rewritten at each write */
    if (!path || stat(path, &st) != 0) return false;
    for (const sx_series *s = open_series; s; s = s->next)
        if (s->dev == st.st_dev && s->ino == st.st_ino) return true;
    return false;
}

static void remember_open(sx_series *s)
{
    struct stat st, xst;
    const char *base;
    if (stat(s->path, &st) != 0 || !folder_of(s->xmf, &xst, &base)) return;
    s->dev = st.st_dev;
    s->ino = st.st_ino;
    s->xdev = xst.st_dev;
    s->xino = xst.st_ino;
    s->next = open_series;
    open_series = s;
}

static void forget_open(sx_series *s)
{
    for (sx_series **p = &open_series; *p; p = &(*p)->next)
        if (*p == s) {
            *p = s->next;
            return;
        }
}

static const struct {
    unsigned bit;
    const char *name;
} field_names[] = {
    {SX_OUT_ID, "id"},           {SX_OUT_RADIUS, "radius"},     {SX_OUT_VELOCITY, "velocity"},
    {SX_OUT_SPIN, "spin"},       {SX_OUT_FORCE, "force"},       {SX_OUT_MOMENT, "moment"},
    {SX_OUT_GROUP, "group"},     {SX_OUT_MATERIAL, "material"}, {SX_OUT_MASS, "mass"},
    {SX_OUT_CONTACTS, "contacts"}, {SX_OUT_BONDS, "bonds"},     {SX_OUT_WALLS, "walls"},
};
enum { NFIELDS = sizeof field_names / sizeof *field_names };

const char *sx_series_field_name(unsigned bit)
{
    for (int k = 0; k < NFIELDS; k++)
        if (field_names[k].bit == bit) return field_names[k].name;
    return NULL;
}

unsigned sx_series_field_bit(const char *name)
{
    for (int k = 0; k < NFIELDS; k++)
        if (strcmp(field_names[k].name, name) == 0) return field_names[k].bit;
    return 0;
}

int64_t sx_series_count(const sx_series *s) { return s->count; }

int64_t sx_series_opened_at(const sx_series *s) { return s->opened_at; }
const char *sx_series_path(const sx_series *s) { return s->path; }

/* -------------------------------------------------------- the series */

static char *dup_str(const char *s)
{
    const size_t n = strlen(s) + 1;
    char *p = malloc(n);
    if (p) memcpy(p, s, n);
    return p;
}

/* The file flushed as far as a killed writer keeps it (microseconds), or
 * synced to the disk too (journal.c makes either atomic). */
static bool flush_file(hid_t file) { return sx_h5_flush(file, false); }
static bool sync_file(hid_t file) { return sx_h5_flush(file, true); }

/* The system's cause of a failed flush, when it is the disk's ("No space
 * left on device"; HDF5's own says "driver flush request failed"), else "". */
static const char *disk_cause(int e)
{
    return e == ENOSPC || e == EDQUOT || e == EIO || e == EFBIG ? strerror(e) : "";
}

static void fields_text(unsigned f, char *out, size_t len)
{
    out[0] = 0;
    size_t n = 0;
    for (int k = 0; k < NFIELDS; k++)
        if (f & field_names[k].bit) {
            const int w = snprintf(out + n, len - n, "%s%s", n ? " " : "", field_names[k].name);
            if (w < 0 || (size_t)w >= len - n) break;
            n += (size_t)w;
        }
}

/* A new, empty series file: written under a temporary name, then renamed. */
static bool create_file(sx_h5 *h, const char *path, int dim, const sx_series_opts *o, unsigned fields)
{
    char tmp[4096];
    if (!sx_h5_temp_for(h, path, tmp, sizeof tmp)) return false;
    hid_t f = sx_h5_create_temp(h, tmp, false);
    if (f < 0) return false;
    char text[256];
    fields_text(fields, text, sizeof text);
    sx_io_write_provenance(h, f, "series", dim, o ? &o->provenance : NULL);
    sx_h5_attr_str(h, f, "fields", text);
    sx_h5_attr_int(h, f, "count", 0);
    sx_h5_close(sx_h5_group(h, f, "snapshots"));
    if (H5Fclose(f) < 0) sx_h5_fail_h5(h, "cannot complete the file");
    if (!h->failed) sx_h5_commit(h, tmp, path);
    if (h->failed) remove(tmp);
    return !h->failed;
}

/* ---------------------------------------------------------- its end */

typedef struct tails {
    int64_t last;
    const char *path;
} tails;

/* Raises t->last to history `name`'s last step (a damaged history is the
 * writer's to recover, not this check's: skipped). */
static herr_t history_end(hid_t g, const char *name, const H5L_info_t *info, void *ud)
{
    (void)info;
    tails *t = ud;
    char err[16];
    sx_h5 probe;
    sx_h5_begin(&probe, t->path, err, sizeof err);
    hid_t hg = H5Gopen2(g, name, H5P_DEFAULT);
    int64_t count = 0, last = INT64_MIN;
    if (hg >= 0 && sx_io_history_tail(&probe, hg, name, &count, &last) && count > 0 && last > t->last) t->last = last;
    sx_h5_close(hg);
    sx_h5_end(&probe);
    H5Eclear2(H5E_DEFAULT);
    return 0;
}

/* The last step a series holds: its last complete snapshot's or, if
 * later, a history's (written at close, past the last snapshot); -1 for
 * none. *what says which. What cannot be read is skipped. */
static int64_t series_end(hid_t file, const char *path, int64_t count, const char **what, int64_t *snapshot)
{
    char err[16], name[48];
    sx_h5 probe;
    int64_t step = -1;
    *what = "snapshots";
    sx_h5_begin(&probe, path, err, sizeof err);
    snprintf(name, sizeof name, "/snapshots/%06lld", (long long)count - 1);
    hid_t g = count > 0 && H5Lexists(file, name, H5P_DEFAULT) > 0 ? H5Gopen2(file, name, H5P_DEFAULT) : -1;
    if (g < 0 || !sx_h5_get_i64(&probe, g, name, "step", &step, 1, true)) step = -1;
    sx_h5_close(g);
    sx_h5_end(&probe);
    *snapshot = step;
    tails t = {step, path};
    hid_t hs = H5Lexists(file, "/histories", H5P_DEFAULT) > 0 ? H5Gopen2(file, "/histories", H5P_DEFAULT) : -1;
    if (hs >= 0) H5Literate(hs, H5_INDEX_NAME, H5_ITER_INC, NULL, history_end, &t);
    sx_h5_close(hs);
    H5Eclear2(H5E_DEFAULT);
    if (t.last > step) *what = "histories";
    return t.last;
}

sx_series *sx_series_open(const char *path, int dim, const sx_series_opts *o, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, path ? path : "", err, errlen);
    sx_series *s = calloc(1, sizeof *s);
    if (s) s->file = -1, s->opened_at = -1;
    const unsigned fields = o && o->fields ? o->fields : SX_OUT_DEFAULT;
    if (!s) {
        sx_h5_fail(&h, "out of memory");
    } else if (!path || !*path) {
        sx_h5_fail(&h, "an empty path");
    } else if (dim != 2 && dim != 3) {
        sx_h5_fail(&h, "dim must be 2 or 3");
    } else if (sx_io_series_open_at(path)) {
        sx_h5_fail(&h, "an output series open in this session writes this file: close it first (o:close())");
    } else if (strlen(path) >= 4 && strcmp(path + strlen(path) - 4, ".xmf") == 0) {
        /* the HDF5 data went into a.xmf and its XDMF into a.xmf.xmf */
        sx_h5_fail(&h, "give the series' .h5 path: its .xmf is written beside it");
    } else if (!(s->path = dup_str(path)) || !(s->xmf = sx_io_xmf_path(path))) {
        sx_h5_fail(&h, "out of memory");
    } else if (xmf_owner(s->xmf)) { /* run.h5 and run.hdf5 share run.xmf */
        sx_h5_fail(&h, "its .xmf, '%s', is another open output series': close that one first", s->xmf);
    } else {
        const char *slash = strrchr(path, '/');
        s->base = dup_str(slash ? slash + 1 : path);
        s->dim = dim;
        s->fields = fields;
        s->compression = o && o->compression > 0 ? (o->compression > 9 ? 9 : o->compression) : 0;
        const bool append = o && o->append && access(path, F_OK) == 0;
        if (!s->base) {
            sx_h5_fail(&h, "out of memory");
        } else if (append) {
            int d = 0, version = 0;
            s->file = sx_io_open(&h, path, true, "series", dim, &d, &version);
            if (s->file >= 0) sx_h5_get_i64(&h, s->file, "/", "count", &s->count, 1, true);
            const char *ends = "snapshots";
            const int64_t last = s->file >= 0 && !h.failed && o->check_step
                                     ? series_end(s->file, path, s->count, &ends, &s->opened_at)
                                     : -1;
            if (o->check_step && o->step < last)
                /* a model loaded from a save older than the series' end:
                 * its snapshots and samples would follow later ones, their
                 * times going back; refused before anything is written */
                sx_h5_fail(&h, "the series holds %s up to step %lld, later than this model's step %lld (a model "
                               "loaded from an earlier save?): what it adds would go back in time; write a new series",
                           ends, (long long)last, (long long)o->step);
            /* what is appended now follows this format: an older reader must refuse the file */
            if (s->file >= 0 && version < SX_IO_FORMAT_VERSION &&
                sx_h5_attr_int(&h, s->file, "format_version", SX_IO_FORMAT_VERSION) && !sync_file(s->file))
                sx_h5_fail_h5(&h, "cannot flush the series");
        } else if (create_file(&h, path, dim, o, fields)) {
            hid_t fapl = sx_h5_fapl(false);
            s->file = fapl >= 0 ? H5Fopen(path, H5F_ACC_RDWR, fapl) : -1;
            if (s->file < 0) sx_h5_fail_h5(&h, "cannot reopen the new series");
            sx_h5_close(fapl);
        }
        if (!h.failed && s->count < 0) sx_h5_fail(&h, "damaged: negative snapshot count");
        /* the XDMF of what the file holds now, kept in memory from here on */
        if (!h.failed && sx_io_xmf_body(&h, &s->x, s->base, s->file, s->dim, s->count)) sx_io_xmf_write(&h, s->xmf, &s->x);
    }
    const bool failed = h.failed;
    sx_h5_end(&h);
    if (failed) {
        sx_series_close(s, NULL, 0);
        return NULL;
    }
    remember_open(s);
    return s;
}

/* ------------------------------------------------------------ recovery */

/* Links every link of a group but one into another group. */
typedef struct relink {
    hid_t to;
    const char *skip;
} relink;

static herr_t relink_one(hid_t g, const char *name, const H5L_info_t *info, void *ud)
{
    (void)info;
    const relink *r = ud;
    /* an object that cannot be read cannot be linked again: it stays
     * behind, with the group set aside */
    if (strcmp(name, r->skip) != 0) H5Lcreate_hard(g, name, r->to, name, H5P_DEFAULT, H5P_DEFAULT);
    return 0;
}

/* Removes the link `name` of the group `parent` (an absolute path of the
 * root), left by a write that failed or was killed. HDF5 deletes a link
 * only by reading its object (to lower the object's link count), which a
 * killed write may have left unreadable: its link reached the disk, its
 * header did not (the cache evicts a group's header, with its new link,
 * whenever it likes). Then the group is rebuilt without that link: a new
 * group links every other object (each readable, so nothing complete is
 * lost), is flushed, and takes the group's name; the old group is set
 * aside as <parent>-damaged-<n>, which no reader looks at. */
static bool drop_link(sx_h5 *h, hid_t file, const char *parent, const char *name)
{
    if (h->failed) return false;
    hid_t pg = H5Gopen2(file, parent, H5P_DEFAULT);
    if (pg < 0) return sx_h5_fail_h5(h, "damaged: cannot open the group %s", parent);
    bool ok = H5Lexists(pg, name, H5P_DEFAULT) <= 0 || H5Ldelete(pg, name, H5P_DEFAULT) >= 0;
    H5Eclear2(H5E_DEFAULT);
    if (!ok) {
        char aside[128];
        for (int n = 1; n < 1000 && (snprintf(aside, sizeof aside, "%s-damaged-%d", parent, n), true); n++)
            if (H5Lexists(file, aside, H5P_DEFAULT) <= 0) break;
        hid_t ng = H5Gcreate_anon(file, H5P_DEFAULT, H5P_DEFAULT);
        relink r = {ng, name};
        /* the new group on disk before any link to it */
        ok = ng >= 0 && H5Literate(pg, H5_INDEX_NAME, H5_ITER_INC, NULL, relink_one, &r) >= 0 && sync_file(file);
        H5Eclear2(H5E_DEFAULT);
        ok = ok && H5Lexists(file, aside, H5P_DEFAULT) <= 0 &&
             H5Lmove(file, parent, file, aside, H5P_DEFAULT, H5P_DEFAULT) >= 0;
        if (ok && H5Olink(ng, file, parent, H5P_DEFAULT, H5P_DEFAULT) < 0) {
            H5Lmove(file, aside, file, parent, H5P_DEFAULT, H5P_DEFAULT);
            ok = false;
        }
        if (!ok) sx_h5_fail_h5(h, "damaged: cannot remove %s/%s, left by an incomplete write", parent, name);
        sx_h5_close(ng);
    }
    sx_h5_close(pg);
    return ok;
}

/* ------------------------------------------------------ history rows */

/* A history being appended: its group, its entry in s->held and the rows
 * written beyond the file's count. */
typedef struct pending {
    hid_t g;
    int held;
    int64_t rows, last;
} pending;

/* The entry of s->held for the history group g named `name` (read from the
 * file the first time it is met); -1 on failure. */
static int held_of(sx_h5 *h, sx_series *s, hid_t g, const char *name, bool fresh)
{
    for (int i = 0; i < s->nheld; i++)
        if (strcmp(s->held[i].name, name) == 0) return i;
    if (s->nheld == s->capheld) {
        const int cap = s->capheld ? 2 * s->capheld : 8;
        held *q = realloc(s->held, (size_t)cap * sizeof *q);
        if (!q) return sx_h5_fail(h, "out of memory"), -1;
        s->held = q;
        s->capheld = cap;
    }
    held *e = &s->held[s->nheld];
    e->rows = 0;
    e->last = INT64_MIN;
    if (!(e->name = dup_str(name))) return sx_h5_fail(h, "out of memory"), -1;
    if (!fresh) {
        char where[320];
        snprintf(where, sizeof where, "/histories/%.300s", name);
        if (!sx_io_history_tail(h, g, where, &e->rows, &e->last)) {
            free(e->name);
            return -1;
        }
    }
    return s->nheld++;
}

/* Writes, beyond each history's complete rows, its samples of steps after
 * the last one the file holds; nothing is counted yet. */
static void hist_stage(sx_h5 *h, sx_series *s, const sx_io_history *x, int nh, pending *p)
{
    for (int i = 0; i < nh; i++) p[i].g = -1;
    if (nh <= 0 || h->failed) return;
    for (int i = 0; i < nh; i++) {
        if (!sx_io_history_valid(h, &x[i])) return;
        for (int j = 0; j < i; j++)
            if (strcmp(x[i].name, x[j].name) == 0) {
                sx_h5_fail(h, "two histories named '%s'", x[i].name);
                return;
            }
    }
    hid_t hg = sx_h5_group(h, s->file, "histories");
    /* a history whose group a killed write left unreadable (its link
     * reached the disk, its header did not) starts again: its rows went
     * with the header, and the model holds them all */
    for (int i = 0; i < nh && !h->failed; i++) {
        H5O_info_t oi;
        if (H5Lexists(hg, x[i].name, H5P_DEFAULT) > 0 && H5Oget_info_by_name(hg, x[i].name, &oi, H5P_DEFAULT) < 0) {
            sx_h5_close(hg);
            hg = drop_link(h, s->file, "/histories", x[i].name) ? sx_h5_group(h, s->file, "histories") : -1;
        }
    }
    for (int i = 0; i < nh && !h->failed; i++) {
        const sx_io_history *q = &x[i];
        const bool fresh = H5Lexists(hg, q->name, H5P_DEFAULT) <= 0;
        if (fresh) {
            H5G_info_t gi;
            /* rows are appended a few at a time: 8 KiB chunks */
            p[i].g = H5Gget_info(hg, &gi) < 0 ? (sx_h5_fail_h5(h, "damaged: cannot list /histories"), -1)
                                              : sx_io_history_create(h, hg, q, (int64_t)gi.nlinks, 1024);
        } else {
            p[i].g = sx_h5_open_group(h, hg, q->name, true);
        }
        if (p[i].g < 0) break;
        p[i].held = held_of(h, s, p[i].g, q->name, fresh);
        if (p[i].held < 0) break;
        const held *e = &s->held[p[i].held];
        /* the first sample after the file's last step (steps increase) */
        int64_t lo = 0, hi = q->n;
        while (lo < hi) {
            const int64_t mid = lo + (hi - lo) / 2;
            if (q->steps[mid] > e->last) hi = mid;
            else lo = mid + 1;
        }
        sx_io_history_put(h, p[i].g, q, lo, e->rows);
        p[i].rows = e->rows + (q->n - lo);
        p[i].last = q->n > lo ? q->steps[q->n - 1] : e->last;
    }
    sx_h5_close(hg);
}

static void hist_raise(sx_h5 *h, const pending *p, int nh)
{
    for (int i = 0; i < nh && !h->failed; i++) sx_h5_attr_int(h, p[i].g, "count", p[i].rows);
}

static void hist_commit(sx_series *s, const pending *p, int nh)
{
    for (int i = 0; i < nh; i++) s->held[p[i].held].rows = p[i].rows, s->held[p[i].held].last = p[i].last;
}

/* ---------------------------------------------------------- writing */

/* One write: a snapshot of m (none when NULL) and the histories' new
 * rows, in the order that keeps every reader consistent (see the top). */
static sx_status append(sx_series *s, const sx_model *m, const sx_io_history *x, int nh, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, s->path, err, errlen);
    h.compression = s->compression;
    pending *p = calloc((size_t)(nh > 0 ? nh : 0) + 1, sizeof *p);
    snap sn;
    char tmp[4096];
    bool have_tmp = false;
    size_t xat[NKINDS]; /* the blocks' lengths, to drop a failed snapshot's grids */
    for (int k = 0; k < NKINDS; k++) xat[k] = s->x.kind[k].n;
    if (!p) {
        sx_h5_fail(&h, "out of memory");
    } else if (m && m->dim != s->dim) {
        sx_h5_fail(&h, "the series holds %dD models, this one is %dD", s->dim, m->dim);
    } else if (s->file < 0) {
        sx_h5_fail(&h, "the series is closed");
    } else {
        if (m) {
            char name[48];
            snprintf(name, sizeof name, "/snapshots/%06lld", (long long)s->count);
            /* 1. the snapshot written unlinked, then linked (in place of a
             * group left by a write that failed or was killed), so that a
             * failed write leaves no link behind */
            hid_t g = H5Gcreate_anon(s->file, H5P_DEFAULT, H5P_DEFAULT);
            if (g < 0) sx_h5_fail_h5(&h, "cannot add a snapshot");
            else sx_io_frame_write(&h, g, m, s->fields, &sn);
            if (!h.failed && drop_link(&h, s->file, "/snapshots", name + strlen("/snapshots/")) &&
                H5Olink(g, s->file, name, H5P_DEFAULT, H5P_DEFAULT) < 0)
                sx_h5_fail_h5(&h, "cannot add a snapshot");
            sx_h5_close(g);
        }
        hist_stage(&h, s, x, nh, p);
        /* 2. the snapshot and the rows on disk before anything says they
         * are complete */
        errno = 0;
        if (!h.failed && !sync_file(s->file)) {
            const int e = errno;
            sx_h5_fail_h5(&h, "cannot flush the snapshot%s%s", *disk_cause(e) ? ": " : "", disk_cause(e));
        }
        /* 3. the XDMF that lists it, on disk under a temporary name */
        if (m && !h.failed) {
            sx_io_xmf_step(&s->x, s->base, s->count, &sn);
            if (!sx_io_xmf_compose(&s->x)) sx_h5_fail(&h, "out of memory");
            else have_tmp = sx_h5_write_temp(&h, s->xmf, s->x.out.p, s->x.out.n, tmp, sizeof tmp);
        }
        /* 4. the counts, and at once 5. the XDMF renamed into place */
        if (!h.failed) {
            if (m) sx_h5_attr_int(&h, s->file, "count", s->count + 1);
            hist_raise(&h, p, nh);
            if (!h.failed && !flush_file(s->file)) sx_h5_fail_h5(&h, "cannot flush the counts");
        }
        if (!h.failed) {
            s->count += m ? 1 : 0;
            hist_commit(s, p, nh);
            if (have_tmp && sx_h5_rename(&h, tmp, s->xmf)) have_tmp = false;
            /* 6. the counts durable too */
            if (!sync_file(s->file)) sx_h5_fail_h5(&h, "cannot flush the counts");
        } else {
            for (int k = 0; k < NKINDS; k++) s->x.kind[k].n = xat[k];
        }
    }
    if (have_tmp) remove(tmp);
    for (int i = 0; p && i < nh; i++) sx_h5_close(p[i].g);
    free(p);
    const bool failed = h.failed;
    sx_h5_end(&h);
    return failed ? SX_EINVAL : SX_OK;
}

sx_status sx_series_write(sx_series *s, const sx_model *m, const sx_io_history *h, int nh, char *err,
                          size_t errlen)
{
    return append(s, m, h, nh, err, errlen);
}

sx_status sx_series_write_histories(sx_series *s, const sx_io_history *h, int nh, char *err, size_t errlen)
{
    return append(s, NULL, h, nh, err, errlen);
}

sx_status sx_series_close(sx_series *s, char *err, size_t errlen)
{
    if (!s) return SX_OK;
    forget_open(s);
    sx_h5 h;
    sx_h5_begin(&h, s->path ? s->path : "", err, errlen);
    if (s->file >= 0 && H5Fclose(s->file) < 0) sx_h5_fail_h5(&h, "cannot close the series");
    const bool failed = h.failed;
    sx_h5_end(&h);
    for (int i = 0; i < s->nheld; i++) free(s->held[i].name);
    free(s->held);
    sx_io_xdoc_free(&s->x);
    free(s->path);
    free(s->xmf);
    free(s->base);
    free(s);
    return failed ? SX_EINVAL : SX_OK;
}
int64_t sx_series_read_count(const char *path, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, path ? path : "", err, errlen);
    int dim = 0, version = 0;
    int64_t count = -1;
    hid_t f = path && *path ? sx_io_open(&h, path, false, "series", 0, &dim, &version) : -1;
    if (f >= 0 && !sx_h5_get_i64(&h, f, "/", "count", &count, 1, true)) count = -1;
    if (f >= 0) H5Fclose(f);
    sx_h5_end(&h);
    return count;
}
