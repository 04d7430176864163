/* gts_runtime.c - the transport of libgts: connect (or start) a controller, one request
 * and one reply per GT call (gtecat/native/protocol.py describes the bytes).
 *
 * Hand-written and function-independent; the per-function stubs are generated from the
 * function table into gts_stubs.c.  Calls of all threads are serialised by one mutex.
 * Nothing here ever waits without a bound: a controller that does not answer within
 * GTECAT_TIMEOUT_MS (default 30000) is given up, the call returns -1 and
 * GTE_GetLastError says why.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "gts.h"
#include "gts_runtime.h"

#define CMD_COMM (-1)
#define CMD_PARAM 7

static pthread_mutex_t g_mu = PTHREAD_MUTEX_INITIALIZER;
static int g_fd = -1;              /* connection to the controller */
static pid_t g_fd_pid;             /* process that made it (a forked child reconnects) */
static char g_addr[300];           /* unix:/path of the connection */
static char g_private_addr[300];   /* unix:/path of the controller this library started */
static pid_t g_child;              /* that controller's pid */
static int g_lifeline = -1;        /* its lifeline: EOF when this process ends */
static char g_lost[1300];          /* why the connection was lost ("" if it was not) */
static char g_err[2048];           /* the last error, for GTE_GetLastError */
static unsigned char *g_buf;       /* request/reply buffer */
static size_t g_cap;

/* ---- small helpers ------------------------------------------------------------------- */
static void set_err(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(g_err, sizeof g_err, fmt, ap);
    va_end(ap);
}

static long long now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static long env_ms(const char *name, long dflt)
{
    const char *v = getenv(name);
    if (v && *v) {
        char *end;
        long x = strtol(v, &end, 10);
        if (*end == '\0' && x > 0)
            return x;
    }
    return dflt;
}

static int reserve(size_t n)
{
    if (n <= g_cap)
        return 0;
    size_t cap = g_cap ? g_cap : 4096;
    while (cap < n)
        cap *= 2;
    unsigned char *b = realloc(g_buf, cap);
    if (!b)
        return -1;
    g_buf = b;
    g_cap = cap;
    return 0;
}

/* wait until fd is ready for ev, at most until deadline; 0 ok, -1 timeout/error */
static int wait_fd(int fd, short ev, long long deadline)
{
    for (;;) {
        long long left = deadline - now_ms();
        if (left < 0)
            left = 0;
        struct pollfd p = {fd, ev, 0};
        int r = poll(&p, 1, left > 0x7fffffff ? 0x7fffffff : (int)left);
        if (r > 0)
            return 0;
        if (r == 0) {
            errno = ETIMEDOUT;
            return -1;
        }
        if (errno != EINTR)
            return -1;
    }
}

/* send one message: records of at most GTE_CHUNK bytes (SOCK_SEQPACKET keeps each whole) */
static int send_all(int fd, const unsigned char *p, size_t n, long long deadline)
{
    while (n) {
        size_t part = n > GTE_CHUNK ? GTE_CHUNK : n;
        ssize_t w = send(fd, p, part, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (w > 0) {
            p += w;
            n -= (size_t)w;
            continue;
        }
        if (w < 0 && errno == EINTR)
            continue;
        if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            if (wait_fd(fd, POLLOUT, deadline) < 0)
                return -1;
            continue;
        }
        return -1;
    }
    return 0;
}

/* How long a call spins for its reply before it sleeps in poll (GTECAT_SPIN_US; by
 * default 200 us where this process may run on two CPUs or more, else 0: spinning on
 * one CPU only keeps the controller from answering).  The controller answers a common
 * getter within about 20 us; waking a sleeping thread costs as much again in a VM.
 * The spin adapts (spin_allowed): it never runs while more threads are runnable than this
 * process has CPUs (the controller would be waiting for the CPU the spin holds), and a spin
 * that ends without the reply halves the next one (down to none; a short probe every 256
 * calls finds out whether spinning pays again). */
#define GTE_DEFAULT_SPIN_US 200
static int g_cpus = 1;
static long spin_ns(void)
{
    static long cached = -1;
    if (cached < 0) {
        const char *v = getenv("GTECAT_SPIN_US");
        long us = 0;
        cpu_set_t set;
        if (sched_getaffinity(0, sizeof set, &set) == 0)
            g_cpus = CPU_COUNT(&set);
        if (v && *v) {
            char *end;
            long x = strtol(v, &end, 10);
            if (*end == '\0' && x >= 0)
                us = x;
        } else if (g_cpus >= 2) {
            us = GTE_DEFAULT_SPIN_US;
        }
        cached = us * 1000;
    }
    return cached;
}

static long long now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

/* More threads runnable than this process has CPUs (the 4th field of /proc/loadavg, read at
 * most every 10 ms): then spinning only takes the CPU the other side waits for. */
static int cpus_busy(long long t)
{
    static long long next_check = 0;
    static int busy = 0;
    if (t >= next_check) {
        char b[128];
        int fd = open("/proc/loadavg", O_RDONLY | O_CLOEXEC);
        next_check = t + 10000000LL;
        busy = 0;
        if (fd >= 0) {
            ssize_t n = read(fd, b, sizeof b - 1);
            close(fd);
            if (n > 0) {
                char *slash, *q;
                b[n] = '\0';
                slash = strchr(b, '/');
                if (slash) {
                    for (q = slash; q > b && q[-1] != ' '; q--)
                        ;
                    busy = strtol(q, NULL, 10) > g_cpus;
                }
            }
        }
    }
    return busy;
}

/* The spin budget of this call in ns (0: sleep in poll at once); spin_done() reports how
 * it went. */
static long g_budget = -1;
static unsigned g_since_probe;
static long spin_allowed(void)
{
    long full = spin_ns();
    if (full <= 0)
        return 0;
    if (g_budget < 0)
        g_budget = full;
    if (cpus_busy(now_ns()))
        return 0;
    if (g_budget == 0 && ++g_since_probe >= 256) {
        g_since_probe = 0;
        return full / 8; /* a probe */
    }
    return g_budget;
}

static void spin_done(int answered_while_spinning, long budget)
{
    long full = spin_ns();
    if (budget <= 0)
        return;
    if (answered_while_spinning)
        g_budget = g_budget * 2 > full ? full : (g_budget ? g_budget * 2 : budget);
    else
        g_budget = g_budget / 2 < 1000 ? 0 : g_budget / 2;
}

/* Receive one message (frame header included) into g_buf, always offering a read at least
 * GTE_CHUNK bytes of room, so one recv takes a whole record (SOCK_SEQPACKET; usually the
 * whole reply).  0 ok with *total = 4 + body; -1 error (errno); -2 the peer closed. */
static int recv_msg(int fd, size_t *total, long long deadline)
{
    size_t got = 0, need = 4;
    long long spin_until = 0;
    long budget = -1; /* this call's spin, asked for when the reply is not there at once */
    int slept = 0;
    while (got < need) {
        if (reserve(got + GTE_CHUNK) < 0) {
            errno = ENOMEM;
            return -1;
        }
        ssize_t r = recv(fd, g_buf + got, g_cap - got, MSG_DONTWAIT);
        if (r > 0) {
            got += (size_t)r;
            if (need == 4 && got >= 4) {
                uint32_t body;
                memcpy(&body, g_buf, 4);
                if (body > GTE_MAX_FRAME) {
                    errno = EPROTO;
                    return -1;
                }
                need = 4 + (size_t)body;
            }
            continue;
        }
        if (r == 0)
            return -2;
        if (errno == EINTR)
            continue;
        if (errno == EAGAIN || errno == EWOULDBLOCK) {
            if (budget < 0)
                budget = spin_allowed();
            if (budget > 0 && !slept) {
                long long t = now_ns();
                if (!spin_until)
                    spin_until = t + budget;
                if (t < spin_until) {
                    sched_yield(); /* the controller first, where it shares this CPU */
                    continue;
                }
            }
            slept = 1;
            if (wait_fd(fd, POLLIN, deadline) < 0)
                return -1;
            continue;
        }
        return -1;
    }
    if (budget > 0)
        spin_done(!slept, budget);
    *total = need;
    return 0;
}

static void put_u32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static uint32_t get_u32(const unsigned char *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static uint16_t get_u16(const unsigned char *p) { uint16_t v; memcpy(&v, p, 2); return v; }
static int16_t get_i16(const unsigned char *p) { int16_t v; memcpy(&v, p, 2); return v; }

/* ---- the connection ------------------------------------------------------------------ */
static const char *child_fate(void)
{
    static char text[160];
    int status;
    if (g_child <= 0)
        return "";
    pid_t r = waitpid(g_child, &status, WNOHANG);
    if (r == g_child) {
        if (WIFEXITED(status))
            snprintf(text, sizeof text, "; the controller process %d exited with status %d",
                     (int)g_child, WEXITSTATUS(status));
        else if (WIFSIGNALED(status))
            snprintf(text, sizeof text, "; the controller process %d was killed by signal %d",
                     (int)g_child, WTERMSIG(status));
        else
            text[0] = '\0';
        g_child = 0;
        return text;
    }
    return "";
}

static void drop(const char *why)
{
    if (g_fd >= 0)
        close(g_fd);
    g_fd = -1;
    snprintf(g_lost, sizeof g_lost, "%s%s", why, child_fate());
}

static int split_address(const char *addr, struct sockaddr_un *sa, socklen_t *len)
{
    const char *path = strncmp(addr, "unix:", 5) == 0 ? addr + 5 : addr;
    size_t n = strlen(path);
    memset(sa, 0, sizeof *sa);
    sa->sun_family = AF_UNIX;
    if (n == 0 || n >= sizeof sa->sun_path)
        return -1;
    memcpy(sa->sun_path, path, n);
    if (path[0] == '@')
        sa->sun_path[0] = '\0'; /* Linux abstract namespace */
    *len = (socklen_t)(offsetof(struct sockaddr_un, sun_path) + n + (path[0] == '@' ? 0 : 1));
    return 0;
}

/* the client's long as the stubs were compiled: 8 on Linux, 4 in the LLP64 build that serves
 * programs written for Windows (C# / VB.NET under Mono, gtecat.native.llp64) */
#ifndef GTE_CLIENT_LONG_SIZE
#define GTE_CLIENT_LONG_SIZE sizeof(long)
#endif

/* hello: announce protocol, sizeof(long) and the table digest; 0 ok */
static int hello(int fd, const char *fname, long long deadline)
{
    unsigned char msg[4 + 24];
    uint16_t version = GTE_PROTOCOL_VERSION, lsize = (uint16_t)GTE_CLIENT_LONG_SIZE;
    put_u32(msg, 24);
    memset(msg + 4, 0, 24);
    msg[4] = GTE_MSG_HELLO;
    memcpy(msg + 8, &version, 2);
    memcpy(msg + 10, &lsize, 2);
    memcpy(msg + 12, GTE_TABLE_DIGEST, 16);
    if (send_all(fd, msg, sizeof msg, deadline) < 0) {
        set_err("%s returned -1: cannot greet the controller at %s: %s", fname, g_addr,
                strerror(errno));
        return -1;
    }
    size_t total = 0;
    int r = recv_msg(fd, &total, deadline);
    if (r < 0 || total < 8) {
        set_err("%s returned -1: the controller at %s did not answer the greeting (%s)", fname,
                g_addr, r == -2 ? "connection closed" : r < 0 ? strerror(errno) : "too short");
        return -1;
    }
    int16_t status = get_i16(g_buf + 4);
    uint16_t tlen = get_u16(g_buf + 6);
    char text[1024];
    size_t keep = tlen < sizeof text - 1 ? tlen : sizeof text - 1;
    if (keep > total - 8)
        keep = total - 8;
    memcpy(text, g_buf + 8, keep);
    text[keep] = '\0';
    if (status != 0) {
        set_err("%s returned -1: the controller at %s refused this library: %s", fname, g_addr,
                text);
        return -1;
    }
    return 0;
}

static int connect_to(const char *addr, const char *fname, long long deadline)
{
    struct sockaddr_un sa;
    socklen_t len;
    snprintf(g_addr, sizeof g_addr, "%s", addr);
    if (split_address(addr, &sa, &len) < 0) {
        set_err("%s returned -1: controller address '%s' is not unix:/path", fname, addr);
        return -1;
    }
    int fd = socket(AF_UNIX, GTE_SOCKET_TYPE | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        set_err("%s returned -1: socket: %s", fname, strerror(errno));
        return -1;
    }
    if (connect(fd, (struct sockaddr *)&sa, len) < 0) {
        set_err("%s returned -1: cannot reach the controller at %s: %s", fname, addr,
                strerror(errno));
        close(fd);
        return -1;
    }
    if (hello(fd, fname, deadline) < 0) {
        close(fd);
        return -1;
    }
    g_fd = fd;
    g_fd_pid = getpid();
    g_lost[0] = '\0';
    return 0;
}

/* Start `python -m gtecat controller` on a socket of our own; it ends with this process
 * (its lifeline pipe reaches EOF when we exit).  0 once it listens. */
static int start_private(const char *fname)
{
    const char *python = getenv("GTECAT_PYTHON");
    if (!python || !*python)
        python = gte_default_python;
    const char *tmp = getenv("TMPDIR");
    char dir[160];
    if (!tmp || !*tmp || strlen(tmp) > 80)
        tmp = "/tmp";
    snprintf(dir, sizeof dir, "%s/gtecat-XXXXXX", tmp);
    if (!mkdtemp(dir)) {
        set_err("%s returned -1: cannot make a directory for the controller socket in %s: %s",
                fname, tmp, strerror(errno));
        return -1;
    }
    char addr[200];
    snprintf(addr, sizeof addr, "unix:%s/controller.sock", dir);

    int ready[2], life[2];
    if (pipe2(ready, O_CLOEXEC) < 0) {
        set_err("%s returned -1: pipe: %s", fname, strerror(errno));
        rmdir(dir);
        return -1;
    }
    if (pipe2(life, O_CLOEXEC) < 0) {
        set_err("%s returned -1: pipe: %s", fname, strerror(errno));
        close(ready[0]);
        close(ready[1]);
        rmdir(dir);
        return -1;
    }
    char *argv[] = {(char *)python, "-m", "gtecat", "controller", "--listen", addr,
                    "--private", "--ready-fd", "3", "--lifeline-fd", "4", NULL};
    pid_t pid = fork();
    if (pid < 0) {
        set_err("%s returned -1: fork: %s", fname, strerror(errno));
        close(ready[0]); close(ready[1]); close(life[0]); close(life[1]);
        rmdir(dir);
        return -1;
    }
    if (pid == 0) { /* child: async-signal-safe calls only until exec */
        int r = fcntl(ready[1], F_DUPFD, 10);
        int l = fcntl(life[0], F_DUPFD, 10);
        if (r < 0 || l < 0 || dup2(r, 3) < 0 || dup2(l, 4) < 0)
            _exit(126);
        setpgid(0, 0); /* the terminal's Ctrl-C is for the program, which then ends us */
        execv(python, argv);
        {
            char msg[64] = "exec failed: errno ";
            int e = errno, n = (int)strlen(msg);
            char digits[12];
            int k = 0;
            do {
                digits[k++] = (char)('0' + e % 10);
                e /= 10;
            } while (e && k < 11);
            while (k)
                msg[n++] = digits[--k];
            msg[n++] = '\n';
            (void)!write(3, msg, (size_t)n);
        }
        _exit(127);
    }
    close(ready[1]);
    close(life[0]);
    long start_ms = env_ms("GTECAT_START_TIMEOUT_MS", 60000);
    long long deadline = now_ms() + start_ms;
    char line[128];
    size_t got = 0;
    int ok = 0;
    while (got < sizeof line - 1) {
        if (wait_fd(ready[0], POLLIN, deadline) < 0)
            break;
        ssize_t r = read(ready[0], line + got, sizeof line - 1 - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        got += (size_t)r;
        line[got] = '\0';
        if (strchr(line, '\n')) {
            ok = strncmp(line, "ready", 5) == 0;
            break;
        }
    }
    line[got] = '\0';
    close(ready[0]);
    g_child = pid;
    if (!ok) {
        char *nl = strchr(line, '\n');
        if (nl)
            *nl = '\0';
        int timed_out = got == 0 && now_ms() >= deadline;
        if (timed_out)
            kill(pid, SIGKILL);
        int status = 0;
        waitpid(pid, &status, timed_out ? 0 : WNOHANG);
        if (!timed_out && kill(pid, 0) == 0) { /* still running, but said no ready */
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
        }
        g_child = 0;
        close(life[1]);
        rmdir(dir);
        if (timed_out)
            set_err("%s returned -1: the controller (%s -m gtecat controller) did not start "
                    "within %ld ms (GTECAT_START_TIMEOUT_MS)", fname, python, start_ms);
        else
            set_err("%s returned -1: the controller (%s -m gtecat controller) did not start%s%s"
                    "; its messages are on stderr (set GTECAT_PYTHON to the Python that has "
                    "gtecat)", fname, python, line[0] ? ": " : "", line);
        return -1;
    }
    g_lifeline = life[1];
    snprintf(g_private_addr, sizeof g_private_addr, "%s", addr);
    if (connect_to(addr, fname, now_ms() + start_ms) < 0)
        return -1;
    return 0;
}

static int ensure_open(const char *fname)
{
    if (g_fd >= 0 && g_fd_pid == getpid())
        return 0;
    if (g_fd >= 0) { /* a forked child: leave the parent's connection to the parent */
        close(g_fd);
        g_fd = -1;
    }
    long long deadline = now_ms() + env_ms("GTECAT_TIMEOUT_MS", 30000);
    const char *named = getenv("GTECAT_CONTROLLER");
    if (named && *named)
        return connect_to(named, fname, deadline);
    if (g_private_addr[0] && g_child > 0) {
        if (kill(g_child, 0) == 0 && connect_to(g_private_addr, fname, deadline) == 0)
            return 0;
        child_fate();
    }
    return start_private(fname);
}

/* ---- one call ------------------------------------------------------------------------- */
static long long count_of(const gte_function *f, int i, const gte_arg *a)
{
    const gte_param *p = &f->params[i];
    if (p->count_arg >= 0)
        return a[p->count_arg].i;
    return p->count;
}

/* bytes a pointer argument sends: >= 0, or GTE_PTR_TOO_BIG */
static long long ptr_bytes(const gte_function *f, int i, const gte_arg *a)
{
    long long n = count_of(f, i, a);
    if (n <= 0)
        return 0;
    if (n > (long long)GTE_MAX_POINTER_BYTES / f->params[i].elem)
        return GTE_PTR_TOO_BIG;
    return n * (long long)f->params[i].elem;
}

static short invoke_locked(const gte_function *f, int gtn, short core, const gte_arg *a)
{
    if (f->flags & GTE_F_OPEN) {
        if (ensure_open(f->name) < 0)
            return CMD_COMM;
    } else if (g_fd < 0 || g_fd_pid != getpid()) {
        if ((f->flags & GTE_F_CLOSE) && g_fd < 0)
            return 0; /* closing what is not open: nothing to do (as in Python) */
        if (g_fd >= 0 && g_fd_pid != getpid()) {
            close(g_fd); /* forked child: reconnect to the same controller */
            g_fd = -1;
            if (g_addr[0] && connect_to(g_addr, f->name,
                                        now_ms() + env_ms("GTECAT_TIMEOUT_MS", 30000)) == 0)
                goto connected;
        }
        if (g_lost[0])
            set_err("%s returned -1: controller not responding: %s", f->name, g_lost);
        else
            set_err("%s returned -1: no controller: call GT_Open first", f->name);
        return CMD_COMM;
    }
connected:;
    /* ---- request ---- */
    size_t size = 4 + 6;
    for (int i = 0; i < f->nparams; i++) {
        const gte_param *p = &f->params[i];
        if (p->kind == GTE_K_INT || p->kind == GTE_K_DOUBLE)
            size += 8;
        else if (p->kind == GTE_K_TEXT)
            size += 4 + (a[i].p ? strnlen((const char *)a[i].p, GTE_MAX_POINTER_BYTES - 1) + 1 : 0);
        else if (p->kind == GTE_K_OUT_ANY || !a[i].p)
            size += 4;
        else {
            long long n = ptr_bytes(f, i, a);
            size += 4 + (n > 0 ? (size_t)n : 0);
        }
    }
    if (reserve(size) < 0) {
        set_err("%s returned 7: out of memory for a request of %zu bytes", f->name, size);
        return CMD_PARAM;
    }
    unsigned char *w = g_buf;
    put_u32(w, (uint32_t)(size - 4));
    w += 4;
    *w++ = GTE_MSG_CALL;
    *w++ = (unsigned char)(gtn ? 1 : 0);
    memcpy(w, &f->id, 2);
    w += 2;
    memcpy(w, &core, 2);
    w += 2;
    for (int i = 0; i < f->nparams; i++) {
        const gte_param *p = &f->params[i];
        int32_t n32;
        switch (p->kind) {
        case GTE_K_INT:
            memcpy(w, &a[i].i, 8);
            w += 8;
            break;
        case GTE_K_DOUBLE:
            memcpy(w, &a[i].d, 8);
            w += 8;
            break;
        case GTE_K_TEXT:
            if (!a[i].p) {
                n32 = GTE_PTR_NULL;
                memcpy(w, &n32, 4);
                w += 4;
            } else {
                size_t len = strnlen((const char *)a[i].p, GTE_MAX_POINTER_BYTES - 1);
                n32 = (int32_t)(len + 1);
                memcpy(w, &n32, 4);
                memcpy(w + 4, a[i].p, len);
                w[4 + len] = '\0';
                w += 4 + len + 1;
            }
            break;
        case GTE_K_OUT_ANY:
            n32 = a[i].p ? GTE_PTR_UNKNOWN : GTE_PTR_NULL;
            memcpy(w, &n32, 4);
            w += 4;
            break;
        default: {
            if (!a[i].p) {
                n32 = GTE_PTR_NULL;
                memcpy(w, &n32, 4);
                w += 4;
                break;
            }
            long long n = ptr_bytes(f, i, a);
            n32 = (int32_t)n;
            memcpy(w, &n32, 4);
            w += 4;
            if (n > 0) {
                memcpy(w, a[i].p, (size_t)n);
                w += n;
            }
        }
        }
    }
    long timeout = env_ms("GTECAT_TIMEOUT_MS", 30000);
    long long deadline = now_ms() + timeout;
    if (send_all(g_fd, g_buf, size, deadline) < 0) {
        char why[1024];
        snprintf(why, sizeof why, "sending %s to %s failed: %s", f->name, g_addr,
                 strerror(errno));
        drop(why);
        set_err("%s returned -1: controller not responding: %s", f->name, g_lost);
        return CMD_COMM;
    }
    /* ---- reply ---- */
    size_t total = 0;
    int r = recv_msg(g_fd, &total, deadline);
    if (r < 0) {
        char why[1024];
        if (r == -2)
            snprintf(why, sizeof why, "the controller at %s closed the connection during %s",
                     g_addr, f->name);
        else if (errno == ETIMEDOUT)
            snprintf(why, sizeof why, "no reply to %s within %ld ms (GTECAT_TIMEOUT_MS)",
                     f->name, timeout);
        else
            snprintf(why, sizeof why, "reading the reply to %s failed: %s", f->name,
                     strerror(errno));
        drop(why);
        set_err("%s returned -1: controller not responding: %s", f->name, g_lost);
        return CMD_COMM;
    }
    if (total < 4 + 6) {
        drop("a malformed reply");
        set_err("%s returned -1: controller not responding: %s", f->name, g_lost);
        return CMD_COMM;
    }
    short rc = get_i16(g_buf + 4);
    uint16_t nblocks = get_u16(g_buf + 6), nerr = get_u16(g_buf + 8);
    const unsigned char *q = g_buf + 10, *end = g_buf + total;
    unsigned used = 0;
    for (int i = 0; i < f->nparams && used < nblocks; i++) {
        const gte_param *p = &f->params[i];
        if (!(p->kind == GTE_K_OUT || p->kind == GTE_K_INOUT || p->kind == GTE_K_OUT_ANY) ||
            !a[i].p)
            continue;
        if (end - q < 4)
            break;
        uint32_t n = get_u32(q);
        q += 4;
        if ((size_t)(end - q) < n)
            break;
        size_t copy = n;
        if (p->kind != GTE_K_OUT_ANY) {
            long long sent = ptr_bytes(f, i, a);
            if (sent < 0)
                sent = 0;
            if ((long long)copy > sent)
                copy = (size_t)sent;
        }
        if (copy)
            memcpy((void *)a[i].p, q, copy);
        q += n;
        used++;
    }
    if (nerr && (size_t)(end - q) >= nerr) {
        size_t keep = nerr < sizeof g_err - 1 ? nerr : sizeof g_err - 1;
        memcpy(g_err, q, keep);
        g_err[keep] = '\0';
    } else if (rc != 0) {
        set_err("%s returned %d", f->name, rc);
    } else {
        g_err[0] = '\0'; /* per call, as in Python: a call that returns 0 clears it */
    }
    return rc;
}

short gte_invoke(const gte_function *f, int gtn, short core, const gte_arg *a)
{
    pthread_mutex_lock(&g_mu);
    short rc = invoke_locked(f, gtn, core, a);
    if ((f->flags & GTE_F_CLOSE) && g_fd >= 0 && g_fd_pid == getpid()) {
        /* GT_Close ends this connection; a private controller lives on until the
         * program ends, so the next GT_Open finds it again */
        close(g_fd);
        g_fd = -1;
        g_lost[0] = '\0';
    }
    pthread_mutex_unlock(&g_mu);
    return rc;
}

short gte_no_card(const char *name, short card, short code)
{
    pthread_mutex_lock(&g_mu);
    if (code == -6)
        set_err("%s returned -6: no card %d: the emulator is card 0", name, card);
    else if (code == -7)
        set_err("%s returned -7: libgts_mc found no %s in libgts", name, name);
    else
        set_err("%s returned %d: card %d is not open: the emulator is card 0", name, code, card);
    pthread_mutex_unlock(&g_mu);
    return code;
}

short gte_declared(int index, int gtn, short core)
{
    const gte_declared_info *d = &gte_declared_table[index];
    gte_function f = {d->name, d->id, 0, GTE_F_DECLARED, NULL};
    char name[128];
    snprintf(name, sizeof name, "%s%s", gtn ? "GTN_" : "", gtn ? d->name + 3 : d->name);
    pthread_mutex_lock(&g_mu);
    short rc = -1;
    if (g_fd >= 0 && g_fd_pid == getpid())
        rc = invoke_locked(&f, gtn, core, NULL); /* the controller logs it and says why */
    if (rc != GTE_CMD_DECLARED)
        set_err("%s returned %d: %s is declared but not emulated (group: %s)", name,
                GTE_CMD_DECLARED, name, d->group);
    pthread_mutex_unlock(&g_mu);
    return GTE_CMD_DECLARED;
}

short GTE_GetLastError(char *buf, short size)
{
    if (!buf || size < 1)
        return CMD_PARAM;
    pthread_mutex_lock(&g_mu);
    snprintf(buf, (size_t)size, "%s", g_err);
    pthread_mutex_unlock(&g_mu);
    return 0;
}
