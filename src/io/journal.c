/* A write-ahead journal under the files that seixo appends to in place
 * (output series): an HDF5 file driver that makes each flush atomic.
 *
 * HDF5 rewrites metadata in place (a group's header when a link is added,
 * a growing dataset's chunk index, the superblock) and writes the dirty
 * pieces of a flush in address order, so a parent that now points at a
 * new child often reaches the disk before the child: a writer killed
 * between the two leaves every object reached through that parent
 * unreadable, complete snapshots included (HDF5 orders its writes only
 * under SWMR, which cannot create groups). This driver passes HDF5's
 * writes to the sec2 driver, except those that overwrite bytes the last
 * completed flush left in the file: those are kept in memory and, at the
 * next flush, written to `<file>.journal` with a checksum, then to the
 * file, then the journal is removed (each step synced before the next).
 * Bytes beyond the last flush's end are reached only through overwritten
 * ones, so writing them at once is safe, and a shrinking truncation waits
 * for the journal too. A kill leaves the file as the last completed flush
 * left it, or a complete journal beside it; opening the file through this
 * driver first applies a complete journal and discards an incomplete one.
 * The file itself stays a plain HDF5 file. */
#include "h5util.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <H5FDsec2.h>

/* Whether the flush under way must also survive a power failure (each
 * step synced before the next), or only a kill (sx_h5_flush). */
static bool durable = true;

static const char journal_magic[8] = {'S', 'X', 'J', 'O', 'U', 'R', 'N', '1'};
static const char journal_end[8] = {'S', 'X', 'J', 'E', 'N', 'D', '0', '1'};

/* An overwrite waiting for the next flush. */
typedef struct pending {
    haddr_t at;
    size_t n;
    unsigned char *bytes;
} pending;

typedef struct jfile {
    H5FD_t pub; /* first: HDF5 sees a jfile as an H5FD_t */
    H5FD_t *inner;
    char *journal;     /* <file>.journal */
    int fd;            /* the inner driver's descriptor */
    haddr_t committed; /* the file's end at the last completed flush */
    pending *p;
    size_t np, cap;
    bool shrink; /* a truncation below `committed` waits for the journal */
    bool broken; /* a commit failed after its journal was complete */
} jfile;

/* ------------------------------------------------------------- errors */

static hid_t error_class = -1;

static void push_error(const char *fmt, const char *path)
{
    if (error_class < 0) error_class = H5Eregister_class("seixo", "seixo", "1");
    if (error_class >= 0)
        H5Epush2(H5E_DEFAULT, __FILE__, __func__, __LINE__, error_class, H5E_VFL, H5E_CANTOPENFILE, fmt, path);
}

/* --------------------------------------------------- the journal file */

/* FNV-1a, 64 bits: its offset basis starts a checksum */
static const uint64_t fnv_basis = 1469598103934665603ULL;

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 1099511628211ULL;
    return h;
}

static bool put_all(int fd, const void *p, size_t n, off_t *at)
{
    const char *b = p;
    while (n > 0) {
        const ssize_t w = pwrite(fd, b, n, *at);
        if (w <= 0) return false;
        b += w, n -= (size_t)w, *at += w;
    }
    return true;
}

/* The journal: magic, then per overwrite its address, length and bytes,
 * then the count, the truncation (UINT64_MAX: none), the checksum of all
 * before it, and the end mark. */
static bool journal_write(const jfile *f, uint64_t truncate_to)
{
    const int fd = open(f->journal, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) return false;
    off_t at = 0;
    uint64_t h = fnv(fnv_basis, journal_magic, sizeof journal_magic);
    bool ok = put_all(fd, journal_magic, sizeof journal_magic, &at);
    for (size_t i = 0; ok && i < f->np; i++) {
        const uint64_t head[2] = {f->p[i].at, f->p[i].n};
        h = fnv(fnv(h, head, sizeof head), f->p[i].bytes, f->p[i].n);
        ok = put_all(fd, head, sizeof head, &at) && put_all(fd, f->p[i].bytes, f->p[i].n, &at);
    }
    const uint64_t tail[2] = {f->np, truncate_to};
    h = fnv(h, tail, sizeof tail);
    ok = ok && put_all(fd, tail, sizeof tail, &at) && put_all(fd, &h, sizeof h, &at) &&
         put_all(fd, journal_end, sizeof journal_end, &at) && (!durable || fsync(fd) == 0);
    close(fd);
    return ok;
}

/* Applies the complete journal `journal` (n bytes) to `path`, then
 * removes it; an incomplete one (its writer was killed while writing it:
 * the file was not touched yet) is removed. False, with HDF5's error stack
 * told why, when a journal cannot be read or a complete one applied. */
static bool journal_apply(const char *path, const char *journal, size_t n)
{
    const int jfd = open(journal, O_RDONLY);
    unsigned char *b = jfd >= 0 ? malloc(n ? n : 1) : NULL;
    /* a journal that cannot be read may be complete: never drop it unread */
    const bool got = b && (n == 0 || pread(jfd, b, n, 0) == (ssize_t)n);
    if (jfd >= 0) close(jfd);
    if (!got) {
        free(b);
        push_error("%s: the journal of its last flush cannot be read", path);
        return false;
    }
    const size_t fixed = sizeof journal_magic + 3 * sizeof(uint64_t) + sizeof journal_end;
    bool whole = n >= fixed && memcmp(b, journal_magic, sizeof journal_magic) == 0 &&
            memcmp(b + n - sizeof journal_end, journal_end, sizeof journal_end) == 0;
    uint64_t h = 0, stored = 0, count = 0, truncate_to = UINT64_MAX;
    if (whole) {
        memcpy(&stored, b + n - sizeof journal_end - sizeof stored, sizeof stored);
        h = fnv(fnv_basis, b, n - sizeof journal_end - sizeof stored);
        memcpy(&count, b + n - sizeof journal_end - 3 * sizeof(uint64_t), sizeof count);
        memcpy(&truncate_to, b + n - sizeof journal_end - 2 * sizeof(uint64_t), sizeof truncate_to);
        whole = h == stored;
    }
    bool ok = true;
    if (whole) {
        const int fd = open(path, O_WRONLY);
        ok = fd >= 0;
        size_t at = sizeof journal_magic;
        const size_t end = n - fixed + sizeof journal_magic;
        for (uint64_t i = 0; ok && i < count; i++) {
            uint64_t head[2];
            ok = at + sizeof head <= end;
            if (!ok) break;
            memcpy(head, b + at, sizeof head);
            at += sizeof head;
            ok = head[1] <= end - at && head[0] <= (uint64_t)INT64_MAX;
            off_t where = (off_t)head[0];
            ok = ok && put_all(fd, b + at, (size_t)head[1], &where);
            at += (size_t)head[1];
        }
        if (ok && truncate_to != UINT64_MAX)
            ok = truncate_to <= (uint64_t)INT64_MAX && ftruncate(fd, (off_t)truncate_to) == 0;
        ok = ok && fsync(fd) == 0;
        if (fd >= 0) close(fd);
        if (!ok)
            push_error("%s: its writer was killed while completing a write, and the journal that completes it "
                       "cannot be applied (open the file once with write access)", path);
    }
    free(b);
    if (ok && unlink(journal) != 0 && whole) ok = false;
    return ok;
}

/* Completes a flush of `path` that its writer was killed in (journal.c's
 * opening comment), unless the file is open elsewhere. */
static bool journal_recover(const char *path, const char *journal)
{
    struct stat st;
    if (stat(journal, &st) != 0) return true;
    /* HDF5 locks a file it opens (flock, kept until it closes the file):
     * locked, the file is open elsewhere, its journal perhaps being written
     * by its live writer, and is left alone (HDF5 then refuses the open) */
    const int lock = open(path, O_RDONLY);
    if (lock >= 0 && flock(lock, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK) {
        close(lock);
        return true;
    }
    const bool ok = journal_apply(path, journal, (size_t)st.st_size);
    if (lock >= 0) close(lock);
    return ok;
}

/* <path>.journal, allocated (NULL when out of memory). */
static char *journal_name(const char *path)
{
    const size_t len = strlen(path);
    char *j = malloc(len + sizeof ".journal");
    if (j) memcpy(j, path, len), memcpy(j + len, ".journal", sizeof ".journal");
    return j;
}

/* ---------------------------------------------------------- the driver */

static hid_t sec2_fapl(void)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl >= 0 && H5Pset_fapl_sec2(fapl) < 0) {
        H5Pclose(fapl);
        return -1;
    }
    return fapl;
}

static H5FD_t *j_open(const char *name, unsigned flags, hid_t fapl, haddr_t maxaddr)
{
    (void)fapl;
    jfile *f = calloc(1, sizeof *f);
    if (!f || !(f->journal = journal_name(name))) {
        free(f);
        return NULL;
    }
    void *handle = NULL;
    /* a file created or emptied: a journal beside its name is an older
     * file's, dropped once the open succeeded (a failed one leaves the old
     * file and its journal). Recovery runs before any call into HDF5's API,
     * which would clear the error it reports. */
    const bool fresh = (flags & (H5F_ACC_TRUNC | H5F_ACC_EXCL)) != 0;
    if (fresh || journal_recover(name, f->journal)) {
        const hid_t inner_fapl = sec2_fapl();
        if (inner_fapl >= 0) f->inner = H5FDopen(name, flags, inner_fapl, maxaddr);
        if (inner_fapl >= 0) H5Pclose(inner_fapl);
        if (f->inner && fresh) sx_h5_journal_drop(name);
    }
    if (!f->inner || H5FDget_vfd_handle(f->inner, H5P_DEFAULT, &handle) < 0 || !handle) {
        if (f->inner) H5FDclose(f->inner);
        free(f->journal);
        free(f);
        return NULL;
    }
    f->fd = *(int *)handle;
    f->committed = H5FDget_eof(f->inner, H5FD_MEM_DEFAULT);
    return &f->pub;
}

static void drop_pending(jfile *f)
{
    for (size_t i = 0; i < f->np; i++) free(f->p[i].bytes);
    f->np = 0;
}

/* The overwrites and a waiting truncation made durable: file (what lies
 * beyond its last end), journal, file, and the journal removed; each
 * synced before the next only when the flush is to be durable. */
static herr_t commit(jfile *f)
{
    /* the file may hold part of the journal's overwrites: only the journal
     * on disk, applied at the next open, completes it; rewriting it now
     * would leave a window with neither */
    if (f->broken) {
        push_error("%s: a flush failed half-way; the journal beside the file completes it when the file is next "
                   "opened", f->journal);
        return -1;
    }
    /* what this flush appended is the last completed flush's from now on:
     * a later overwrite of it must be journaled too */
    if (f->np == 0 && !f->shrink) {
        f->committed = H5FDget_eof(f->inner, H5FD_MEM_DEFAULT);
        return 0;
    }
    const haddr_t eoa = H5FDget_eoa(f->inner, H5FD_MEM_DEFAULT);
    const uint64_t truncate_to = f->shrink ? (uint64_t)eoa : UINT64_MAX;
    if ((durable && fsync(f->fd) != 0) || !journal_write(f, truncate_to)) return -1;
    f->broken = true;
    for (size_t i = 0; i < f->np; i++) {
        off_t at = (off_t)f->p[i].at;
        if (!put_all(f->fd, f->p[i].bytes, f->p[i].n, &at)) return -1;
    }
    if (f->shrink && H5FDtruncate(f->inner, H5P_DEFAULT, false) < 0) return -1;
    if ((durable && fsync(f->fd) != 0) || unlink(f->journal) != 0) return -1;
    f->broken = false;
    drop_pending(f);
    f->shrink = false;
    f->committed = H5FDget_eof(f->inner, H5FD_MEM_DEFAULT);
    return 0;
}

static herr_t j_close(H5FD_t *file)
{
    jfile *f = (jfile *)file;
    herr_t r = commit(f);
    if (H5FDclose(f->inner) < 0) r = -1;
    drop_pending(f);
    free(f->p);
    free(f->journal);
    free(f);
    return r;
}

static int j_cmp(const H5FD_t *a, const H5FD_t *b) { return H5FDcmp(((const jfile *)a)->inner, ((const jfile *)b)->inner); }

static herr_t j_query(const H5FD_t *file, unsigned long *flags)
{
    (void)file;
    /* sec2's, less SWMR: a reader in SWMR mode would read the file while
     * its overwrites wait here */
    *flags = H5FD_FEAT_AGGREGATE_METADATA | H5FD_FEAT_ACCUMULATE_METADATA | H5FD_FEAT_DATA_SIEVE |
             H5FD_FEAT_AGGREGATE_SMALLDATA | H5FD_FEAT_POSIX_COMPAT_HANDLE | H5FD_FEAT_DEFAULT_VFD_COMPATIBLE;
    return 0;
}

static haddr_t j_get_eoa(const H5FD_t *file, H5FD_mem_t type) { return H5FDget_eoa(((const jfile *)file)->inner, type); }

static herr_t j_set_eoa(H5FD_t *file, H5FD_mem_t type, haddr_t addr)
{
    return H5FDset_eoa(((jfile *)file)->inner, type, addr);
}

static haddr_t j_get_eof(const H5FD_t *file, H5FD_mem_t type)
{
    const jfile *f = (const jfile *)file;
    return f->shrink ? H5FDget_eoa(f->inner, type) : H5FDget_eof(f->inner, type);
}

static herr_t j_get_handle(H5FD_t *file, hid_t fapl, void **handle)
{
    return H5FDget_vfd_handle(((jfile *)file)->inner, fapl, handle);
}

static herr_t j_read(H5FD_t *file, H5FD_mem_t type, hid_t dxpl, haddr_t addr, size_t size, void *buf)
{
    jfile *f = (jfile *)file;
    if (H5FDread(f->inner, type, dxpl, addr, size, buf) < 0) return -1;
    /* the overwrites not yet in the file, in the order they were made */
    for (size_t i = 0; i < f->np; i++) {
        const pending *p = &f->p[i];
        const haddr_t lo = p->at > addr ? p->at : addr, hi = p->at + p->n < addr + size ? p->at + p->n : addr + size;
        if (lo < hi) memcpy((char *)buf + (lo - addr), p->bytes + (lo - p->at), hi - lo);
    }
    return 0;
}

static herr_t j_write(H5FD_t *file, H5FD_mem_t type, hid_t dxpl, haddr_t addr, size_t size, const void *buf)
{
    jfile *f = (jfile *)file;
    if (addr >= f->committed) return H5FDwrite(f->inner, type, dxpl, addr, size, buf);
    /* the part beyond the committed end goes to the file now, as any write
     * there: kept pending, it would later cover newer writes to those bytes */
    if (size > f->committed - addr) {
        const size_t below = (size_t)(f->committed - addr);
        if (H5FDwrite(f->inner, type, dxpl, f->committed, size - below, (const char *)buf + below) < 0) return -1;
        size = below;
    }
    if (f->np == f->cap) {
        const size_t cap = f->cap ? 2 * f->cap : 64;
        pending *q = realloc(f->p, cap * sizeof *q);
        if (!q) return -1;
        f->p = q, f->cap = cap;
    }
    unsigned char *b = malloc(size ? size : 1);
    if (!b) return -1;
    memcpy(b, buf, size);
    f->p[f->np++] = (pending){addr, size, b};
    return 0;
}

static herr_t j_flush(H5FD_t *file, hid_t dxpl, hbool_t closing)
{
    jfile *f = (jfile *)file;
    const bool synced = durable && (f->np > 0 || f->shrink);
    if (commit(f) < 0 || H5FDflush(f->inner, dxpl, closing) < 0) return -1;
    /* a durable flush with nothing to journal still syncs what it wrote */
    return durable && !synced && fsync(f->fd) != 0 ? -1 : 0;
}

static herr_t j_truncate(H5FD_t *file, hid_t dxpl, hbool_t closing)
{
    jfile *f = (jfile *)file;
    const haddr_t eoa = H5FDget_eoa(f->inner, H5FD_MEM_DEFAULT);
    /* growing, or cutting only what no completed flush reached, is safe now */
    if (eoa >= f->committed) return H5FDtruncate(f->inner, dxpl, closing) < 0 ? -1 : 0;
    f->shrink = true;
    return 0;
}

static herr_t j_lock(H5FD_t *file, hbool_t rw) { return H5FDlock(((jfile *)file)->inner, rw); }
static herr_t j_unlock(H5FD_t *file) { return H5FDunlock(((jfile *)file)->inner); }

static const H5FD_class_t journal_class = {
    .name = "seixo_journal",
    .maxaddr = ((haddr_t)1 << (8 * sizeof(off_t) - 1)) - 1,
    .fc_degree = H5F_CLOSE_WEAK,
    .open = j_open,
    .close = j_close,
    .cmp = j_cmp,
    .query = j_query,
    .get_eoa = j_get_eoa,
    .set_eoa = j_set_eoa,
    .get_eof = j_get_eof,
    .get_handle = j_get_handle,
    .read = j_read,
    .write = j_write,
    .flush = j_flush,
    .truncate = j_truncate,
    .lock = j_lock,
    .unlock = j_unlock,
    .fl_map = H5FD_FLMAP_DICHOTOMY,
};

bool sx_h5_journal_drop(const char *path)
{
    char *journal = journal_name(path);
    if (!journal) {
        errno = ENOMEM;
        return false;
    }
    const bool gone = unlink(journal) == 0 || errno == ENOENT;
    free(journal);
    return gone;
}

hid_t sx_h5_journal_driver(void)
{
    static hid_t id = -1;
    if (id < 0 || H5Iis_valid(id) <= 0) id = H5FDregister(&journal_class);
    return id;
}

bool sx_h5_flush(hid_t file, bool sync)
{
    durable = sync;
    const bool ok = H5Fflush(file, H5F_SCOPE_LOCAL) >= 0;
    durable = true;
    return ok;
}
