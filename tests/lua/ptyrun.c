/* ptyrun: drives a program through a real terminal, expect-style, for the
 * REPL test.
 *   ptyrun SCRIPT -- command [args...]
 * The script, one command per line ('#' starts a comment line):
 *   spawn              start the command on a new pseudo-terminal (120x40, TERM=xterm)
 *   send TEXT          type TEXT; escapes \n \r \t \\ \e and \xHH (\x03 is Ctrl-C, \x04 Ctrl-D)
 *   expect TEXT        wait until TEXT appears in the output after the last match
 *   reject TEXT        TEXT must not appear in the output read so far after the last match
 *   sleep SECONDS      let the program run
 *   timeout SECONDS    the wait of each expect (default 15)
 *   exit STATUS        wait for the program to end with this exit status
 *   file PATH TEXT     the file must contain TEXT ($VAR in PATH is expanded)
 *   remove PATH        delete the file if it exists ($VAR expanded)
 *   write PATH TEXT    (re)write the file with TEXT, escapes as for send ($VAR expanded)
 * The output is matched with terminal escape sequences and carriage
 * returns removed. Each expect, reject, exit and file is a check; the first
 * failing one ends the run, showing the end of the transcript. Prints
 * "N passed, M failed"; exits 1 on a failure. */
#define _XOPEN_SOURCE 700
#define _DEFAULT_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

static char *out;  // the transcript, escape sequences removed
static size_t len, cap, mark;
static int master = -1;
static pid_t child = -1;
static int esc_state;  // 0 text, 1 after ESC, 2 in CSI, 3 in OSC

static void append_char(char c)
{
    if (len + 2 > cap) {
        cap = cap ? 2 * cap : 65536;
        out = realloc(out, cap);
        if (!out) abort();
    }
    out[len++] = c;
    out[len] = 0;
}

/* Strips ESC sequences (CSI ... final, OSC ... BEL, ESC x) and \r. */
static void take(const char *buf, ssize_t n)
{
    for (ssize_t i = 0; i < n; i++) {
        const unsigned char c = (unsigned char)buf[i];
        switch (esc_state) {
        case 0:
            if (c == 0x1b) esc_state = 1;
            else if (c != '\r' && c != 7) append_char((char)c);
            break;
        case 1: esc_state = c == '[' ? 2 : c == ']' ? 3 : 0; break;
        case 2:
            if (c >= 0x40 && c <= 0x7e) esc_state = 0;
            break;
        case 3:
            if (c == 7) esc_state = 0;
            break;
        }
    }
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Reads what the program wrote, for at most `wait` seconds; false at its end. */
static bool pump(double wait)
{
    if (master < 0) return false;
    struct pollfd p = {master, POLLIN, 0};
    const int r = poll(&p, 1, (int)(wait * 1000));
    if (r <= 0) return true;
    char buf[4096];
    const ssize_t n = read(master, buf, sizeof buf);
    if (n <= 0) return false;  // EIO: the slave side is closed
    take(buf, n);
    return true;
}

static void spawn(char **argv)
{
    master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) || unlockpt(master)) {
        perror("ptyrun: pty");
        exit(2);
    }
    const char *name = ptsname(master);
    child = fork();
    if (child < 0) {
        perror("ptyrun: fork");
        exit(2);
    }
    if (child == 0) {
        setsid();
        const int slave = open(name, O_RDWR);
        if (slave < 0) _exit(127);
#ifdef TIOCSCTTY
        ioctl(slave, TIOCSCTTY, 0);
#endif
        struct winsize ws = {40, 120, 0, 0};
        ioctl(slave, TIOCSWINSZ, &ws);
        dup2(slave, 0);
        dup2(slave, 1);
        dup2(slave, 2);
        if (slave > 2) close(slave);
        close(master);
        setenv("TERM", "xterm", 1);
        execvp(argv[0], argv);
        _exit(127);
    }
    esc_state = 0;
}

/* Decodes the escapes of a send argument in place; returns its length. */
static size_t unescape(char *s)
{
    char *w = s;
    for (const char *r = s; *r; r++) {
        if (*r != '\\' || !r[1]) {
            *w++ = *r;
            continue;
        }
        switch (*++r) {
        case 'n': *w++ = '\n'; break;
        case 'r': *w++ = '\r'; break;
        case 't': *w++ = '\t'; break;
        case 'e': *w++ = 0x1b; break;
        case 'x':
            if (r[1] && r[2]) {
                char hex[3] = {r[1], r[2], 0};
                *w++ = (char)strtol(hex, NULL, 16);
                r += 2;
            }
            break;
        default: *w++ = *r; break;
        }
    }
    *w = 0;
    return (size_t)(w - s);
}

static int passed, failed;

static void fail(int line, const char *what, const char *arg)
{
    failed++;
    fprintf(stderr, "FAIL line %d: %s '%s'\n--- transcript (end) ---\n%s\n--- end ---\n", line, what, arg,
            len > 3000 ? out + len - 3000 : (out ? out : ""));
}

static bool expect(const char *text, double timeout)
{
    const double end = now() + timeout;
    for (;;) {
        const char *hit = out ? strstr(out + mark, text) : NULL;
        if (hit) {
            mark = (size_t)(hit - out) + strlen(text);
            return true;
        }
        const double left = end - now();
        if (left <= 0) return false;
        if (!pump(left > 0.1 ? 0.1 : left) && master >= 0) {
            /* the program ended: one last look */
            hit = out ? strstr(out + mark, text) : NULL;
            if (hit) mark = (size_t)(hit - out) + strlen(text);
            return hit != NULL;
        }
    }
}

static bool wait_exit(int status, double timeout)
{
    const double end = now() + timeout;
    while (now() < end) {
        pump(0.05);
        int st;
        const pid_t r = waitpid(child, &st, WNOHANG);
        if (r == child) {
            child = -1;
            return WIFEXITED(st) && WEXITSTATUS(st) == status;
        }
    }
    return false;
}

/* PATH with a leading $VAR expanded, into full. */
static void expand(const char *path, char *full, size_t size)
{
    if (path[0] == '$') {
        const char *slash = strchr(path, '/');
        char var[256];
        const size_t n = slash ? (size_t)(slash - path - 1) : strlen(path + 1);
        if (n >= sizeof var) {
            full[0] = 0;
            return;
        }
        memcpy(var, path + 1, n);
        var[n] = 0;
        const char *val = getenv(var);
        snprintf(full, size, "%s%s", val ? val : "", slash ? slash : "");
    } else {
        snprintf(full, size, "%s", path);
    }
}

static bool file_contains(const char *path, const char *text)
{
    char full[4096];
    expand(path, full, sizeof full);
    FILE *f = fopen(full, "r");
    if (!f) return false;
    char *buf = calloc(1, 1 << 20);
    const size_t n = buf ? fread(buf, 1, (1 << 20) - 1, f) : 0;
    fclose(f);
    const bool ok = buf && n > 0 && strstr(buf, text);
    free(buf);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc < 4 || strcmp(argv[2], "--") != 0) {
        fprintf(stderr, "usage: ptyrun SCRIPT -- command [args...]\n");
        return 2;
    }
    FILE *script = fopen(argv[1], "r");
    if (!script) {
        perror(argv[1]);
        return 2;
    }
    signal(SIGPIPE, SIG_IGN);
    double timeout = 15;
    char line[4096];
    int lineno = 0;
    while (!failed && fgets(line, sizeof line, script)) {
        lineno++;
        line[strcspn(line, "\n")] = 0;
        if (!line[0] || line[0] == '#') continue;
        char *arg = strchr(line, ' ');
        if (arg) *arg++ = 0;
        else arg = line + strlen(line);
        if (strcmp(line, "spawn") == 0) {
            spawn(argv + 3);
        } else if (strcmp(line, "send") == 0) {
            const size_t n = unescape(arg);
            for (size_t i = 0; i < n; i++) {  // one key at a time, as a person types
                if (write(master, arg + i, 1) != 1) break;
                pump(0.002);
            }
        } else if (strcmp(line, "expect") == 0) {
            if (expect(arg, timeout)) passed++;
            else fail(lineno, "expected", arg);
        } else if (strcmp(line, "reject") == 0) {
            pump(0.2);
            if (out && strstr(out + mark, arg)) fail(lineno, "unexpected", arg);
            else passed++;
        } else if (strcmp(line, "sleep") == 0) {
            const double end = now() + atof(arg);
            while (now() < end) pump(0.05);
        } else if (strcmp(line, "timeout") == 0) {
            timeout = atof(arg);
        } else if (strcmp(line, "exit") == 0) {
            if (wait_exit(atoi(arg), timeout)) passed++;
            else fail(lineno, "exit status", arg);
            if (master >= 0) close(master);
            master = -1;
            mark = len;
        } else if (strcmp(line, "remove") == 0) {
            char full[4096];
            expand(arg, full, sizeof full);
            remove(full);
        } else if (strcmp(line, "write") == 0) {
            char *text = strchr(arg, ' ');
            if (text) *text++ = 0;
            char full[4096];
            expand(arg, full, sizeof full);
            FILE *f = fopen(full, "w");
            const size_t n = text ? unescape(text) : 0;
            if (!f || fwrite(text ? text : "", 1, n, f) != n || fclose(f) != 0) {
                fprintf(stderr, "ptyrun: line %d: cannot write %s\n", lineno, full);
                return 2;
            }
        } else if (strcmp(line, "file") == 0) {
            char *text = strchr(arg, ' ');
            if (text) *text++ = 0;
            if (text && file_contains(arg, text)) passed++;
            else fail(lineno, "file lacks", text ? text : "");
        } else {
            fprintf(stderr, "ptyrun: line %d: unknown command '%s'\n", lineno, line);
            return 2;
        }
    }
    fclose(script);
    if (child > 0) {
        kill(child, SIGKILL);
        waitpid(child, NULL, 0);
    }
    printf("%d passed, %d failed\n", passed, failed);
    free(out);
    return failed ? 1 : 0;
}
