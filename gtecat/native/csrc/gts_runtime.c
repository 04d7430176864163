/* gts_runtime.c - the transport of libgts and of gts.dll: connect (or start) a controller,
 * one request and one reply per GT call (gtecat/native/protocol.py describes the bytes).
 *
 * Hand-written and function-independent; the per-function stubs are generated from the
 * function table into gts_stubs.c.  Calls of all threads are serialised by one mutex.
 * Nothing here ever waits without a bound: a controller that does not answer within
 * GTECAT_TIMEOUT_MS (default 30000) is given up, the call returns -1 and
 * GTE_GetLastError says why.
 *
 * Where the controller is: GTECAT_CONTROLLER (unix:/path, or tcp:HOST:PORT /
 * tcp://HOST:PORT), else a private controller this library starts (Linux): inside this
 * program where it can (GTECAT_INPROCESS, the in-process controller below), else as a
 * process of its own.  A TCP
 * controller wants a token: GTECAT_TOKEN, else the file GTECAT_TOKEN_FILE names, else the
 * controller's default token file (same user, same machine).  Every GTECAT_x setting may
 * also be written `x = value` in a gtecat.ini beside the program's executable (or the
 * file GTECAT_INI names); the environment wins.  On Windows (gts.dll, built with
 * mingw-w64) the transport is TCP over winsock and there is no private controller.
 */
#define _GNU_SOURCE
#if defined(_WIN32)
#ifndef _WIN32_WINNT
#define _WIN32_WINNT 0x0600 /* WSAPoll */
#endif
#define WIN32_LEAN_AND_MEAN
#include <winsock2.h>
#include <ws2tcpip.h>
#include <windows.h>
#endif
#include <errno.h>
#include <locale.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <time.h>
#if !defined(_WIN32)
#include <dlfcn.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>
#include <wchar.h>
#endif

#include "gts.h"
#include "gts_runtime.h"

#define CMD_COMM (-1)
#define CMD_PARAM 7

/* ---- the platform ---------------------------------------------------------------------- */
#if defined(_WIN32)
typedef SOCKET gte_sock;
typedef DWORD gte_pid;
#define GTE_NO_SOCK INVALID_SOCKET
#define GTE_SEND_FLAGS 0
#define GTE_RECV_FLAGS 0
#define GTE_STDCALL __stdcall
#define sock_close closesocket
#define gte_getpid() GetCurrentProcessId()
static SRWLOCK g_mu = SRWLOCK_INIT;
#define LOCK() AcquireSRWLockExclusive(&g_mu)
#define UNLOCK() ReleaseSRWLockExclusive(&g_mu)
static int net_errno(void) { return WSAGetLastError(); }
#define NET_WOULDBLOCK(e) ((e) == WSAEWOULDBLOCK)
#define NET_INTR(e) ((e) == WSAEINTR)
#define NET_INPROGRESS(e) ((e) == WSAEWOULDBLOCK || (e) == WSAEINPROGRESS)
#define gte_yield() SwitchToThread()
#else
typedef int gte_sock;
typedef pid_t gte_pid;
#define GTE_NO_SOCK (-1)
#define GTE_SEND_FLAGS (MSG_NOSIGNAL | MSG_DONTWAIT)
#define GTE_RECV_FLAGS MSG_DONTWAIT
#define GTE_STDCALL
#define sock_close close
#define gte_getpid() getpid()
static pthread_mutex_t g_mu = PTHREAD_MUTEX_INITIALIZER;
#define LOCK() pthread_mutex_lock(&g_mu)
#define UNLOCK() pthread_mutex_unlock(&g_mu)
static int net_errno(void) { return errno; }
#define NET_WOULDBLOCK(e) ((e) == EAGAIN || (e) == EWOULDBLOCK)
#define NET_INTR(e) ((e) == EINTR)
#define NET_INPROGRESS(e) ((e) == EINPROGRESS)
#define gte_yield() sched_yield()
#endif

static gte_sock g_fd = GTE_NO_SOCK; /* connection to the controller */
static gte_pid g_fd_pid;           /* process that made it (a forked child reconnects) */
static char g_addr[300];           /* unix:/path or tcp:host:port of the connection */
#if !defined(_WIN32)
static char g_private_addr[300];   /* unix:/path of the controller this library started */
static pid_t g_child;              /* that controller's pid */
static int g_lifeline = -1;        /* its lifeline: EOF when this process ends */
#endif
static int g_inproc;               /* the connection is to the in-process controller */
static int inproc_call(size_t size, size_t *total, int opening);
static char g_lost[1300];          /* why the connection was lost ("" if it was not) */
/* the current card of the process (GT_SetCardNo; gtecat/controller/cards.py), the cards it
 * has open (bit n: card n; the connection ends when the last one closes), and a card one
 * call of this thread addresses instead (the multi-card ABI, gte_use_card) */
static short g_card;
static short g_core = 1; /* the core of the GT_x calls (GT_SetCore); GTN_x name theirs */
static unsigned g_cards_open;
#if defined(_MSC_VER)
static __declspec(thread) short t_card = -1;
#else
static __thread short t_card = -1;
#endif
static char g_err[2048];           /* the last error, for GTE_GetLastError */
static unsigned char *g_buf;       /* request/reply buffer */
static size_t g_cap;
/* a reason of our own for the last I/O failure (NULL: the system's error says it) */
static const char *g_io_why;
static const char TIMED_OUT[] = "timed out";

/* ---- small helpers ------------------------------------------------------------------- */
static void set_err(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(g_err, sizeof g_err, fmt, ap);
    va_end(ap);
}

/* the text of the last I/O failure */
static const char *io_error(void)
{
    if (g_io_why)
        return g_io_why;
#if defined(_WIN32)
    static char text[256];
    int e = WSAGetLastError();
    DWORD n = FormatMessageA(FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS, NULL,
                             (DWORD)e, 0, text, sizeof text, NULL);
    while (n > 0 && (text[n - 1] == '\n' || text[n - 1] == '\r' || text[n - 1] == '.'))
        text[--n] = '\0';
    if (n == 0)
        snprintf(text, sizeof text, "winsock error %d", e);
    return text;
#else
    return strerror(errno);
#endif
}

static long long now_ns(void)
{
#if defined(_WIN32)
    static LARGE_INTEGER freq;
    LARGE_INTEGER t;
    if (!freq.QuadPart)
        QueryPerformanceFrequency(&freq);
    QueryPerformanceCounter(&t);
    return (long long)((double)t.QuadPart * 1e9 / (double)freq.QuadPart);
#else
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000000000LL + ts.tv_nsec;
#endif
}

static long long now_ms(void) { return now_ns() / 1000000; }

/* ---- settings: the environment, else gtecat.ini ---------------------------------------- */
#define INI_MAX 32
static struct { char key[40]; char value[600]; } g_ini[INI_MAX];
static int g_ini_n = -1;           /* -1: not read yet */
static char g_ini_path[600];       /* the file looked for ("" if none could be named) */

static char *trim(char *t)
{
    while (*t == ' ' || *t == '\t')
        t++;
    size_t n = strlen(t);
    while (n && (t[n - 1] == ' ' || t[n - 1] == '\t' || t[n - 1] == '\r' || t[n - 1] == '\n'))
        t[--n] = '\0';
    if (n >= 2 && (t[0] == '"' || t[0] == '\'') && t[n - 1] == t[0]) {
        t[n - 1] = '\0';
        t++;
    }
    return t;
}

static void ini_locate(void)
{
    const char *named = getenv("GTECAT_INI");
    if (named && *named) {
        snprintf(g_ini_path, sizeof g_ini_path, "%s", named);
        return;
    }
    char exe[520];
    size_t n = 0;
#if defined(_WIN32)
    DWORD r = GetModuleFileNameA(NULL, exe, sizeof exe);
    if (r > 0 && r < sizeof exe)
        n = r;
#else
    ssize_t r = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (r > 0)
        n = (size_t)r;
#endif
    exe[n] = '\0';
    while (n && exe[n - 1] != '/' && exe[n - 1] != '\\')
        exe[--n] = '\0';
    if (n)
        snprintf(g_ini_path, sizeof g_ini_path, "%sgtecat.ini", exe);
}

/* key = value lines; [sections], ; and # comments ignored */
static void ini_read(void)
{
    g_ini_n = 0;
    ini_locate();
    if (!g_ini_path[0])
        return;
    FILE *f = fopen(g_ini_path, "r");
    if (!f)
        return;
    char line[700];
    while (g_ini_n < INI_MAX && fgets(line, sizeof line, f)) {
        char *t = trim(line);
        if (!*t || *t == ';' || *t == '#' || *t == '[')
            continue;
        char *eq = strchr(t, '=');
        if (!eq)
            continue;
        *eq = '\0';
        char *k = trim(t), *v = trim(eq + 1);
        if (strlen(k) >= sizeof g_ini[0].key)
            continue;
        for (char *c = k; *c; c++)
            if (*c >= 'A' && *c <= 'Z')
                *c = (char)(*c - 'A' + 'a');
        snprintf(g_ini[g_ini_n].key, sizeof g_ini[0].key, "%s", k);
        snprintf(g_ini[g_ini_n].value, sizeof g_ini[0].value, "%s", v);
        g_ini_n++;
    }
    fclose(f);
}

/* GTECAT_x from the environment, else `x = ...` (any case) from gtecat.ini; NULL if neither */
static const char *setting(const char *name)
{
    const char *v = getenv(name);
    if (v && *v)
        return v;
    if (g_ini_n < 0)
        ini_read();
    const char *key = strncmp(name, "GTECAT_", 7) == 0 ? name + 7 : name;
    for (int i = 0; i < g_ini_n; i++) {
        const char *a = g_ini[i].key, *b = key;
        while (*a && *b && (*a == *b || *a == *b - 'A' + 'a'))
            a++, b++;
        if (!*a && !*b && g_ini[i].value[0])
            return g_ini[i].value;
    }
    return NULL;
}

static long env_ms(const char *name, long dflt)
{
    const char *v = setting(name);
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
static int wait_fd(gte_sock fd, short ev, long long deadline)
{
    for (;;) {
        long long left = deadline - now_ms();
        if (left < 0)
            left = 0;
#if defined(_WIN32)
        WSAPOLLFD p = {fd, ev, 0};
        int r = WSAPoll(&p, 1, left > 0x7fffffff ? 0x7fffffff : (int)left);
#else
        struct pollfd p = {fd, ev, 0};
        int r = poll(&p, 1, left > 0x7fffffff ? 0x7fffffff : (int)left);
#endif
        if (r > 0)
            return 0;
        if (r == 0) {
            g_io_why = TIMED_OUT;
            return -1;
        }
        if (!NET_INTR(net_errno()))
            return -1;
    }
}

/* send one message: records of at most GTE_CHUNK bytes (SOCK_SEQPACKET keeps each whole) */
static int send_all(gte_sock fd, const unsigned char *p, size_t n, long long deadline)
{
    g_io_why = NULL;
    while (n) {
        size_t part = n > GTE_CHUNK ? GTE_CHUNK : n;
        long w = (long)send(fd, (const char *)p, (int)part, GTE_SEND_FLAGS);
        if (w > 0) {
            p += w;
            n -= (size_t)w;
            continue;
        }
        int e = net_errno();
        if (w < 0 && NET_INTR(e))
            continue;
        if (w < 0 && NET_WOULDBLOCK(e)) {
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
        const char *v = setting("GTECAT_SPIN_US");
        long us = 0;
#if defined(_WIN32)
        DWORD_PTR mine, all;
        if (GetProcessAffinityMask(GetCurrentProcess(), &mine, &all)) {
            int n = 0;
            for (; mine; mine &= mine - 1)
                n++;
            g_cpus = n;
        }
#else
        cpu_set_t set;
        if (sched_getaffinity(0, sizeof set, &set) == 0)
            g_cpus = CPU_COUNT(&set);
#endif
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

/* More threads runnable than this process has CPUs (the 4th field of /proc/loadavg, read at
 * most every 10 ms): then spinning only takes the CPU the other side waits for. */
#if defined(_WIN32)
static int cpus_busy(long long t)
{
    (void)t;
    return 0; /* no /proc/loadavg: the adaptive halving alone */
}
#else
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
#endif

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

/* ---- the calling thread's time slice (Linux 6.12 and later) ---------------------------
 * Where GTECAT_SLICE_US names one (100 us is the shortest the kernel grants; 0, the
 * default, leaves every thread alone), each thread that calls into this library asks the
 * kernel for that time slice once, at its first call.  Why one may want it: the thread
 * sleeps while the controller works and is woken by the reply; with other programs keeping
 * the CPUs busy, a woken thread with the default slice (milliseconds) may wait for another
 * program's slice to end, where one with a shorter slice gets the earlier deadline and, as
 * long as it has not used more than its share of the CPU, the CPU at once (EEVDF).  What it
 * changes for the thread: how soon it gets a CPU back after waking, and that while it
 * computes and others want its CPU it is preempted every slice; not its share of the CPU
 * (its nice value, its weight).  Threads and processes it starts afterwards inherit the
 * slice, as they inherit its nice value.  Asked only where the thread runs SCHED_OTHER with
 * a longer slice (a shorter one chosen by the program is kept); a kernel without custom
 * slices reports none and is not asked, and a refusal (older kernels: EINVAL, E2BIG; a
 * sandbox: EPERM) is silent.  The controller's serving thread asks for the same
 * (gtecat/scheduling.py: short_slice).  Off by default: measured on a loaded 2-vCPU VM
 * (docs/performance.md), it did not help the round trip's p50 or p99, with or without the
 * controller's real-time priority. */
#define GTE_DEFAULT_SLICE_US 0
#if !defined(_WIN32) /* gts.dll asks for nothing: Windows has no such slice */
static long slice_us(void)
{
    const char *v = setting("GTECAT_SLICE_US");
    if (v && *v) {
        char *end;
        long x = strtol(v, &end, 10);
        if (*end == '\0' && x >= 0)
            return x;
    }
    return GTE_DEFAULT_SLICE_US;
}
#endif

#if defined(__linux__) && defined(SYS_sched_setattr) && defined(SYS_sched_getattr)
struct gte_sched_attr { /* the kernel's struct sched_attr, version 0 (48 bytes) */
    uint32_t size, policy;
    uint64_t flags;
    int32_t nice;
    uint32_t priority;
    uint64_t runtime, deadline, period; /* runtime: a SCHED_OTHER thread's slice (ns) */
};
static __thread int t_slice_asked;
static void ask_short_slice(void)
{
    struct gte_sched_attr a;
    long us;
    if (t_slice_asked)
        return;
    t_slice_asked = 1;
    us = slice_us();
    if (us <= 0)
        return;
    memset(&a, 0, sizeof a);
    if (syscall(SYS_sched_getattr, 0, &a, (unsigned)sizeof a, 0u) != 0)
        return;
    if (a.policy != SCHED_OTHER || a.runtime <= (uint64_t)us * 1000u)
        return; /* not a normal thread, a kernel without slices (0), or short already */
    a.size = sizeof a;
    a.flags &= 0x01; /* SCHED_FLAG_RESET_ON_FORK as it was; policy and nice as they were */
    a.runtime = (uint64_t)us * 1000u;
    (void)syscall(SYS_sched_setattr, 0, &a, 0u);
}
#else
static void ask_short_slice(void) {}
#endif

/* Receive one message (frame header included) into g_buf, always offering a read at least
 * GTE_CHUNK bytes of room, so one recv takes a whole record (SOCK_SEQPACKET; usually the
 * whole reply).  0 ok with *total = 4 + body; -1 error (errno); -2 the peer closed. */
static int recv_msg(gte_sock fd, size_t *total, long long deadline)
{
    size_t got = 0, need = 4;
    long long spin_until = 0;
    /* this call's spin; without one, the reply is waited for in poll at once (a read
     * right after the request finds nothing yet and costs a system call) */
    long budget = spin_allowed();
    int slept = 0;
    g_io_why = NULL;
    if (budget <= 0) {
        slept = 1;
        if (wait_fd(fd, POLLIN, deadline) < 0)
            return -1;
    }
    while (got < need) {
        if (reserve(got + GTE_CHUNK) < 0) {
            g_io_why = "out of memory";
            return -1;
        }
        size_t room = g_cap - got;
        long r = (long)recv(fd, (char *)g_buf + got, (int)(room > 0x40000000 ? 0x40000000 : room),
                            GTE_RECV_FLAGS);
        if (r > 0) {
            got += (size_t)r;
            if (need == 4 && got >= 4) {
                uint32_t body;
                memcpy(&body, g_buf, 4);
                if (body > GTE_MAX_FRAME) {
                    g_io_why = "a reply larger than the protocol allows";
                    return -1;
                }
                need = 4 + (size_t)body;
            }
            continue;
        }
        if (r == 0)
            return -2;
        int e = net_errno();
        if (NET_INTR(e))
            continue;
        if (NET_WOULDBLOCK(e)) {
            if (budget > 0 && !slept) {
                long long t = now_ns();
                if (!spin_until)
                    spin_until = t + budget;
                if (t < spin_until) {
                    gte_yield(); /* the controller first, where it shares this CPU */
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
#if defined(_WIN32)
static const char *child_fate(void) { return ""; }
#else
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
#endif

static void drop(const char *why)
{
    if (g_fd != GTE_NO_SOCK)
        sock_close(g_fd);
    g_fd = GTE_NO_SOCK;
    g_inproc = 0;
    snprintf(g_lost, sizeof g_lost, "%s%s", why, child_fate());
}

#if !defined(_WIN32)
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
#endif

/* tcp:HOST:PORT, tcp://HOST:PORT, tcp:PORT (127.0.0.1), tcp:[v6]:PORT -> host, port; 0 ok */
static int split_tcp(const char *addr, char *host, size_t hcap, char *port, size_t pcap)
{
    const char *rest = addr + 4;
    if (strncmp(rest, "//", 2) == 0)
        rest += 2;
    char buf[300];
    snprintf(buf, sizeof buf, "%s", rest);
    size_t n = strlen(buf);
    while (n && buf[n - 1] == '/')
        buf[--n] = '\0';
    const char *h = "127.0.0.1", *p = buf;
    if (buf[0] == '[') {
        char *close = strstr(buf, "]:");
        if (!close)
            return -1;
        *close = '\0';
        h = buf + 1;
        p = close + 2;
    } else {
        char *colon = strrchr(buf, ':');
        if (colon) {
            *colon = '\0';
            h = buf;
            p = colon + 1;
        }
    }
    if (!*h || !*p || strlen(p) > 5 || strspn(p, "0123456789") != strlen(p) || atoi(p) > 65535)
        return -1;
    size_t hl = strlen(h), pl = strlen(p);
    if (hl + 1 > hcap || pl + 1 > pcap)
        return -1;
    memcpy(host, h, hl + 1);
    memcpy(port, p, pl + 1);
    return 0;
}

/* the token a TCP controller wants (see the top of this file); 0 ok ("" if none), -1 error */
static int client_token(char *out, size_t cap, const char *fname, const char *port)
{
    out[0] = '\0';
    const char *t = setting("GTECAT_TOKEN");
    if (t) {
        snprintf(out, cap, "%s", t);
        char *s = trim(out);
        memmove(out, s, strlen(s) + 1);
        return 0;
    }
    const char *file = setting("GTECAT_TOKEN_FILE");
#if !defined(_WIN32)
    char dflt[400];
#endif
    if (!file) {
#if defined(_WIN32)
        (void)port; /* no default token file on Windows: gtecat.ini or the environment */
        return 0;
#else
        const char *base = getenv("XDG_RUNTIME_DIR");
        if (!base || !*base) {
            base = getenv("TMPDIR");
            if (!base || !*base)
                base = "/tmp";
        }
        snprintf(dflt, sizeof dflt, "%s/gtecat-%u/controller-%s.token", base, (unsigned)getuid(),
                 port);
        if (access(dflt, R_OK) != 0)
            return 0;
        file = dflt;
#endif
    }
    FILE *f = fopen(file, "r");
    char line[600] = "";
    if (!f || !fgets(line, sizeof line, f)) {
        set_err("%s returned -1: cannot read the token file %s%s%s", fname, file, f ? "" : ": ",
                f ? " (it is empty)" : strerror(errno));
        if (f)
            fclose(f);
        return -1;
    }
    fclose(f);
    snprintf(out, cap, "%s", trim(line));
    return 0;
}

/* hello: announce protocol, the client's sizeof(long) and the table digest (and the token,
 * for TCP); 0 ok */
static int hello(gte_sock fd, const char *token, const char *fname, long long deadline)
{
    unsigned char msg[4 + 24 + 2 + 256];
    uint16_t version = GTE_PROTOCOL_VERSION, lsize = gte_client_long_size;
    size_t toklen = strlen(token), body = 24;
    if (toklen > 256) {
        set_err("%s returned -1: the token is longer than 256 bytes", fname);
        return -1;
    }
    memset(msg, 0, sizeof msg);
    msg[4] = GTE_MSG_HELLO;
    memcpy(msg + 8, &version, 2);
    memcpy(msg + 10, &lsize, 2);
    memcpy(msg + 12, GTE_TABLE_DIGEST, 16);
    if (toklen) {
        uint16_t t16 = (uint16_t)toklen;
        memcpy(msg + 28, &t16, 2);
        memcpy(msg + 30, token, toklen);
        body += 2 + toklen;
    }
    put_u32(msg, (uint32_t)body);
    size_t total = 0;
    int r;
    if (g_inproc) { /* the in-process controller: the same greeting, as a call */
        if (reserve(4 + body) < 0) {
            set_err("%s returned -1: out of memory", fname);
            return -1;
        }
        memcpy(g_buf, msg, 4 + body);
        r = inproc_call(4 + body, &total, 1);
    } else {
        if (send_all(fd, msg, 4 + body, deadline) < 0) {
            set_err("%s returned -1: cannot greet the controller at %s: %s", fname, g_addr,
                    io_error());
            return -1;
        }
        r = recv_msg(fd, &total, deadline);
    }
    if (r < 0 || total < 8) {
        set_err("%s returned -1: the controller at %s did not answer the greeting (%s)", fname,
                g_addr, r == -2 ? (toklen ? "connection closed" :
                                   "connection closed; a TCP controller needs GTECAT_TOKEN")
                        : r < 0 ? io_error() : "too short");
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

static int set_nonblocking(gte_sock fd)
{
#if defined(_WIN32)
    u_long one = 1;
    return ioctlsocket(fd, FIONBIO, &one) == 0 ? 0 : -1;
#else
    int fl = fcntl(fd, F_GETFL);
    return fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK) < 0 ? -1 : 0;
#endif
}

/* a connected TCP socket (non-blocking, no Nagle delay), GTE_NO_SOCK with the reason set */
static gte_sock connect_tcp(const char *addr, const char *fname, long long deadline)
{
    char host[300], port[8];
    if (split_tcp(addr, host, sizeof host, port, sizeof port) < 0) {
        set_err("%s returned -1: controller address '%s' is not tcp:HOST:PORT", fname, addr);
        return GTE_NO_SOCK;
    }
    struct addrinfo hints, *res = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    int gai = getaddrinfo(host, port, &hints, &res);
    if (gai != 0 || !res) {
#if defined(_WIN32)
        set_err("%s returned -1: cannot find the controller's host %s (winsock error %d)",
                fname, host, gai);
#else
        set_err("%s returned -1: cannot find the controller's host %s: %s", fname, host,
                gai_strerror(gai));
#endif
        return GTE_NO_SOCK;
    }
    gte_sock fd = GTE_NO_SOCK;
    char why[300] = "no address";
    for (struct addrinfo *ai = res; ai; ai = ai->ai_next) {
#if defined(_WIN32)
        fd = socket(ai->ai_family, SOCK_STREAM, IPPROTO_TCP);
#else
        fd = socket(ai->ai_family, SOCK_STREAM | SOCK_CLOEXEC, IPPROTO_TCP);
#endif
        if (fd == GTE_NO_SOCK || set_nonblocking(fd) < 0) {
            snprintf(why, sizeof why, "socket: %s", io_error());
            if (fd != GTE_NO_SOCK)
                sock_close(fd);
            fd = GTE_NO_SOCK;
            continue;
        }
        g_io_why = NULL;
        int r = connect(fd, ai->ai_addr, (int)ai->ai_addrlen);
        if (r != 0 && NET_INPROGRESS(net_errno())) {
            if (wait_fd(fd, POLLOUT, deadline) == 0) {
                int err = 0;
                socklen_t len = sizeof err;
                getsockopt(fd, SOL_SOCKET, SO_ERROR, (char *)&err, &len);
                r = err ? -1 : 0;
#if defined(_WIN32)
                WSASetLastError(err);
#else
                errno = err;
#endif
            } else {
                r = -1;
            }
        }
        if (r == 0) {
            int one = 1;
            setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, (const char *)&one, sizeof one);
            break;
        }
        snprintf(why, sizeof why, "%s", io_error());
        sock_close(fd);
        fd = GTE_NO_SOCK;
    }
    freeaddrinfo(res);
    if (fd == GTE_NO_SOCK)
        set_err("%s returned -1: cannot reach the controller at %s: %s", fname, addr, why);
    return fd;
}

static int connect_to(const char *addr, const char *fname, long long deadline)
{
    snprintf(g_addr, sizeof g_addr, "%s", addr);
    gte_sock fd;
    char token[600] = "";
    if (strncmp(addr, "tcp:", 4) == 0) {
        char host[300], port[8];
        if (split_tcp(addr, host, sizeof host, port, sizeof port) < 0)
            port[0] = '\0'; /* connect_tcp says what is wrong with the address */
        if (client_token(token, sizeof token, fname, port) < 0)
            return -1;
        fd = connect_tcp(addr, fname, deadline);
        if (fd == GTE_NO_SOCK)
            return -1;
    } else {
#if defined(_WIN32)
        set_err("%s returned -1: controller address '%s' is not tcp:HOST:PORT (Windows reaches "
                "a controller over TCP)", fname, addr);
        return -1;
#else
        struct sockaddr_un sa;
        socklen_t len;
        if (split_address(addr, &sa, &len) < 0) {
            set_err("%s returned -1: controller address '%s' is not unix:/path or "
                    "tcp:HOST:PORT", fname, addr);
            return -1;
        }
        fd = socket(AF_UNIX, GTE_SOCKET_TYPE | SOCK_CLOEXEC, 0);
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
#endif
    }
    if (hello(fd, token, fname, deadline) < 0) {
        sock_close(fd);
        return -1;
    }
    g_fd = fd;
    g_fd_pid = gte_getpid();
    g_lost[0] = '\0';
    return 0;
}

#if !defined(_WIN32)
/* a folder of our own for a private controller's socket (dir[160]) and the socket's
 * address in it (addr[200]); 0 ok */
static int private_socket(const char *fname, char *dir, char *addr)
{
    const char *tmp = getenv("TMPDIR");
    if (!tmp || !*tmp || strlen(tmp) > 80)
        tmp = "/tmp";
    snprintf(dir, 160, "%s/gtecat-XXXXXX", tmp);
    if (!mkdtemp(dir)) {
        set_err("%s returned -1: cannot make a directory for the controller socket in %s: %s",
                fname, tmp, strerror(errno));
        return -1;
    }
    snprintf(addr, 200, "unix:%s/controller.sock", dir);
    return 0;
}

/* Start `python -m gtecat controller` on a socket of our own; it ends with this process
 * (its lifeline pipe reaches EOF when we exit).  0 once it listens. */
static int start_private(const char *fname)
{
    const char *python = getenv("GTECAT_PYTHON");
    if (!python || !*python)
        python = gte_default_python;
    char dir[160], addr[200];
    if (private_socket(fname, dir, addr) < 0)
        return -1;

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
    /* the scheduling setting may come from gtecat.ini, which the controller does not read */
    const char *rt = setting("GTECAT_RT_PRIORITY");
    char rt_arg[16];
    snprintf(rt_arg, sizeof rt_arg, "%s", rt && strlen(rt) < sizeof rt_arg ? rt : "");
    /* and so may the time slice (slice_us: a number read here) */
    char slice_arg[24];
    const char *sl = setting("GTECAT_SLICE_US");
    snprintf(slice_arg, sizeof slice_arg, "%ld", slice_us());
    char *argv[16] = {(char *)python, "-m", "gtecat", "controller", "--listen", addr,
                      "--private", "--ready-fd", "3", "--lifeline-fd", "4"};
    int argc = 11;
    if (rt_arg[0]) {
        argv[argc++] = "--rt-priority";
        argv[argc++] = rt_arg;
    }
    if (sl && *sl) {
        argv[argc++] = "--slice-us";
        argv[argc++] = slice_arg;
    }
    argv[argc] = NULL;
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
#endif

#if defined(__linux__)
/* ---- the in-process controller (GTECAT_INPROCESS) -------------------------------------
 * Instead of starting `python -m gtecat controller`, load the Python runtime gtecat was
 * installed for into this program (dlopen, RTLD_GLOBAL), start the same controller server
 * there (gtecat/native/inprocess.py: it listens on the private socket too, and keeps the
 * wall floor from its own thread), and hand each request frame to it as a function call
 * under the interpreter's lock: no process to wake, twice per call.  Where the runtime
 * cannot be found or started, the private controller process is started instead.  Not in
 * a program that runs a Python interpreter already (its own, or ctypes from Python), and
 * a forked child reaches its parent's in-process controller over the socket. */
typedef void *pyobj;
static struct {
    int (*IsInitialized)(void);
    void (*InitializeEx)(int);
    void (*SetPythonHome)(const wchar_t *);
    wchar_t *(*DecodeLocale)(const char *, size_t *);
    void *(*SaveThread)(void);
    int (*GILEnsure)(void);
    void (*GILRelease)(int);
    pyobj (*ImportModule)(const char *);
    pyobj (*GetAttrString)(pyobj, const char *);
    pyobj (*CallObjArgs)(pyobj, ...);
    pyobj (*BytesFrom)(const char *, ssize_t);
    int (*BytesAs)(pyobj, char **, ssize_t *);
    pyobj (*UnicodeFrom)(const char *);
    void (*DecRef)(pyobj);
    void (*ErrFetch)(pyobj *, pyobj *, pyobj *);
    pyobj (*Str)(pyobj);
    const char *(*Utf8)(pyobj);
    pyobj (*SysGet)(const char *);
    int (*ListInsert)(pyobj, ssize_t, pyobj);
} py;
static pid_t g_inproc_pid;         /* the process the runtime was started in (0: none) */
static pyobj g_host, g_host_call;  /* gtecat.native.inprocess.Host and its call */
static char g_inproc_why[1000];     /* why the in-process controller was not started */
static __thread int t_py_state;    /* this thread has a Python thread state of its own */

/* GTECAT_INPROCESS: 1 (or on/yes/true) in-process, 0 (off/no/false) the process;
 * unset: GTE_DEFAULT_INPROCESS (in-process; where it cannot be, the process, silently).
 * *asked: the setting was given */
#ifndef GTE_DEFAULT_INPROCESS
#define GTE_DEFAULT_INPROCESS 1
#endif
static int inproc_wanted(int *asked)
{
    const char *v = setting("GTECAT_INPROCESS");
    *asked = v && *v;
    if (!*asked)
        return GTE_DEFAULT_INPROCESS;
    return !(strcmp(v, "0") == 0 || strcasecmp(v, "off") == 0 || strcasecmp(v, "no") == 0 ||
             strcasecmp(v, "false") == 0);
}

/* the text of the Python exception set now (cleared) */
static void py_error(char *out, size_t cap)
{
    pyobj t = NULL, v = NULL, tb = NULL;
    py.ErrFetch(&t, &v, &tb);
    pyobj s = (v || t) ? py.Str(v ? v : t) : NULL;
    const char *u = s ? py.Utf8(s) : NULL;
    snprintf(out, cap, "%s", u ? u : "a Python error without text");
    if (!u)
        py.ErrFetch(&t, &v, &tb); /* (an error of Str itself: cleared too) */
    pyobj all[] = {s, t, v, tb};
    for (int i = 0; i < 4; i++)
        if (all[i])
            py.DecRef(all[i]);
}

/* the interpreter's lock for this thread; every thread keeps its Python thread state */
static int py_enter(void)
{
    if (!t_py_state) {
        py.GILEnsure(); /* a thread state of its own, then the lock released: kept */
        py.SaveThread();
        t_py_state = 1;
    }
    return py.GILEnsure();
}

/* obj.name() (a new reference; NULL with the error set) */
static pyobj py_method(pyobj obj, const char *name)
{
    pyobj m = py.GetAttrString(obj, name);
    if (!m)
        return NULL;
    pyobj r = py.CallObjArgs(m, NULL);
    py.DecRef(m);
    return r;
}

/* run `python -m gtecat.native.inprocess` and read its answer into out; 0 ok */
static int ask_python(const char *python, char *out, size_t cap, long long deadline)
{
    int p[2];
    if (pipe2(p, O_CLOEXEC) < 0) {
        snprintf(g_inproc_why, sizeof g_inproc_why, "pipe: %s", strerror(errno));
        return -1;
    }
    char *argv[] = {(char *)python, "-m", "gtecat.native.inprocess", NULL};
    pid_t pid = fork();
    if (pid < 0) {
        snprintf(g_inproc_why, sizeof g_inproc_why, "fork: %s", strerror(errno));
        close(p[0]);
        close(p[1]);
        return -1;
    }
    if (pid == 0) { /* (its errors: the controller process, started next, says them) */
        int null = open("/dev/null", O_WRONLY);
        if (dup2(p[1], 1) < 0 || null < 0 || dup2(null, 2) < 0)
            _exit(126);
        execv(python, argv);
        _exit(127);
    }
    close(p[1]);
    size_t got = 0;
    while (got < cap - 1 && wait_fd(p[0], POLLIN, deadline) == 0) {
        ssize_t r = read(p[0], out + got, cap - 1 - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        got += (size_t)r;
    }
    out[got] = '\0';
    close(p[0]);
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == 0) {
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        snprintf(g_inproc_why, sizeof g_inproc_why, "%s -m gtecat.native.inprocess failed "
                 "(status %d)", python, WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        return -1;
    }
    return 0;
}

/* the next line of *text (NUL-terminated in place) */
static char *next_line(char **text)
{
    char *line = *text, *nl = strchr(line, '\n');
    if (nl) {
        *nl = '\0';
        *text = nl + 1;
    } else {
        *text = line + strlen(line);
    }
    return line;
}

static void inproc_cleanup(void)
{
    if (g_inproc_pid != getpid() || !g_host)
        return;
    int st = py_enter(); /* the program's atexit: the session ends as a Python program's */
    pyobj r = py_method(g_host, "end");
    if (r)
        py.DecRef(r);
    else
        py_error(g_inproc_why, sizeof g_inproc_why);
    py.GILRelease(st);
}

/* Load the runtime and start the controller in it at addr; 0 ok, else -1 with
 * g_inproc_why set (nothing of the program changed but a library loaded). */
static int inproc_start(const char *addr)
{
    static char answer[65536];
    static wchar_t *home_w;
    const char *python = getenv("GTECAT_PYTHON");
    if (!python || !*python)
        python = gte_default_python;
    if (dlsym(RTLD_DEFAULT, "Py_IsInitialized")) {
        snprintf(g_inproc_why, sizeof g_inproc_why,
                 "this program runs a Python interpreter of its own");
        return -1;
    }
    if (ask_python(python, answer, sizeof answer,
                   now_ms() + env_ms("GTECAT_START_TIMEOUT_MS", 60000)) < 0)
        return -1;
    char *rest = answer;
    char *lib = next_line(&rest), *home = next_line(&rest), *version = next_line(&rest);
    char *root = next_line(&rest), *env = next_line(&rest);
    if (!*lib) {
        snprintf(g_inproc_why, sizeof g_inproc_why, "%s has no shared Python library to load "
                 "(an interpreter built without --enable-shared)", python);
        return -1;
    }
    char stdlib[700];
    struct stat st;
    snprintf(stdlib, sizeof stdlib, "%s/lib/python%s/os.py", home, version);
    if (stat(stdlib, &st) != 0) {
        snprintf(g_inproc_why, sizeof g_inproc_why, "no standard library at %s", stdlib);
        return -1;
    }
    void *h = dlopen(lib, RTLD_NOW | RTLD_GLOBAL);
    if (!h) {
        snprintf(g_inproc_why, sizeof g_inproc_why, "cannot load %s: %s", lib, dlerror());
        return -1;
    }
    struct { void *slot; const char *name; } syms[] = {
        {&py.IsInitialized, "Py_IsInitialized"}, {&py.InitializeEx, "Py_InitializeEx"},
        {&py.SetPythonHome, "Py_SetPythonHome"}, {&py.DecodeLocale, "Py_DecodeLocale"},
        {&py.SaveThread, "PyEval_SaveThread"}, {&py.GILEnsure, "PyGILState_Ensure"},
        {&py.GILRelease, "PyGILState_Release"}, {&py.ImportModule, "PyImport_ImportModule"},
        {&py.GetAttrString, "PyObject_GetAttrString"},
        {&py.CallObjArgs, "PyObject_CallFunctionObjArgs"},
        {&py.BytesFrom, "PyBytes_FromStringAndSize"},
        {&py.BytesAs, "PyBytes_AsStringAndSize"}, {&py.UnicodeFrom, "PyUnicode_DecodeFSDefault"},
        {&py.DecRef, "Py_DecRef"}, {&py.ErrFetch, "PyErr_Fetch"}, {&py.Str, "PyObject_Str"},
        {&py.Utf8, "PyUnicode_AsUTF8"}, {&py.SysGet, "PySys_GetObject"},
        {&py.ListInsert, "PyList_Insert"},
    };
    for (size_t i = 0; i < sizeof syms / sizeof syms[0]; i++) {
        void *f = dlsym(h, syms[i].name);
        if (!f) {
            snprintf(g_inproc_why, sizeof g_inproc_why, "%s has no %s", lib, syms[i].name);
            return -1;
        }
        memcpy(syms[i].slot, &f, sizeof f);
    }
    if (py.IsInitialized()) {
        snprintf(g_inproc_why, sizeof g_inproc_why, "%s is started already in this program", lib);
        return -1;
    }
    home_w = py.DecodeLocale(home, NULL);
    if (!home_w) {
        snprintf(g_inproc_why, sizeof g_inproc_why, "cannot decode %s", home);
        return -1;
    }
    py.SetPythonHome(home_w);
    /* the program's character locale stays its own (the runtime sets it from the
     * environment while it starts; its encodings are decided by then) */
    char *ctype = setlocale(LC_CTYPE, NULL);
    char saved[200];
    snprintf(saved, sizeof saved, "%s", ctype ? ctype : "C");
    /* the program's Ctrl-C: Python's `signal` module, when first imported, takes SIGINT
     * where it was left at its default (to raise KeyboardInterrupt) even in a runtime started
     * without signal handlers; it is imported below, then SIGINT is given back as it was */
    struct sigaction program_int;
    sigaction(SIGINT, NULL, &program_int);
    py.InitializeEx(0); /* 0: the program's signal handlers stay its own */
    setlocale(LC_CTYPE, saved);
    g_inproc_pid = getpid();
    t_py_state = 1; /* this thread's state is the main one: kept */
    /* the environment's modules first: the folder gtecat is in, then settle() */
    pyobj path = py.SysGet("path"), dir = py.UnicodeFrom(root);
    if (dir) {
        py.ListInsert(path, 0, dir);
        py.DecRef(dir);
    }
    pyobj mod = py.ImportModule("gtecat.native.inprocess"), r = NULL;
    pyobj settle = mod ? py.GetAttrString(mod, "settle") : NULL;
    pyobj envb = settle ? py.BytesFrom(env, (ssize_t)strlen(env)) : NULL;
    r = envb ? py.CallObjArgs(settle, envb, NULL) : NULL;
    pyobj start = r ? py.GetAttrString(mod, "start") : NULL;
    pyobj where = start ? py.UnicodeFrom(addr) : NULL;
    pyobj host = where ? py.CallObjArgs(start, where, NULL) : NULL;
    pyobj call = host ? py.GetAttrString(host, "call") : NULL;
    if (!call)
        py_error(g_inproc_why, sizeof g_inproc_why);
    pyobj sigmod = call ? py.ImportModule("signal") : NULL; /* (its taking of SIGINT, now) */
    if (call && !sigmod) {
        char ignored[256];
        py_error(ignored, sizeof ignored); /* (cleared: the calls need no signal module) */
    }
    sigaction(SIGINT, &program_int, NULL);
    pyobj refs[] = {mod, settle, envb, r, start, where, sigmod};
    for (size_t i = 0; i < sizeof refs / sizeof refs[0]; i++)
        if (refs[i])
            py.DecRef(refs[i]);
    py.SaveThread(); /* the lock is taken per call from now on */
    if (!call) {
        if (host)
            py.DecRef(host); /* (the runtime stays loaded: it cannot be unloaded) */
        return -1;
    }
    g_host = host;
    g_host_call = call;
    atexit(inproc_cleanup);
    return 0;
}

/* SIGPIPE blocked in the calling thread (the threads Python starts meanwhile inherit it:
 * the server's, the inspection endpoint's), so that a client that goes away while the
 * controller writes to it is an error of the write, not the end of the program (a Python
 * program ignores SIGPIPE; the runtime was started without touching the program's
 * signals) */
static void block_sigpipe(sigset_t *old)
{
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &set, old);
}

/* One request frame in g_buf (size bytes) -> the reply frame in g_buf; 0 ok, -1 with
 * g_io_why set.  opening: a call that may start threads (GT_Open) */
static int inproc_call(size_t size, size_t *total, int opening)
{
    static char why[800];
    sigset_t old;
    if (opening)
        block_sigpipe(&old);
    int st = py_enter();
    pyobj req = py.BytesFrom((const char *)g_buf, (ssize_t)size);
    pyobj r = req ? py.CallObjArgs(g_host_call, req, NULL) : NULL;
    int rc = -1;
    char *p;
    ssize_t n = 0;
    if (req)
        py.DecRef(req);
    if (r && py.BytesAs(r, &p, &n) == 0) {
        if (n < 4) {
            g_io_why = "the controller refused the request (its log says why)";
        } else if (reserve((size_t)n) < 0) {
            g_io_why = "out of memory";
        } else {
            memcpy(g_buf, p, (size_t)n);
            *total = (size_t)n;
            rc = 0;
        }
    } else {
        snprintf(why, sizeof why, "the in-process controller failed: ");
        py_error(why + strlen(why), sizeof why - strlen(why));
        g_io_why = why;
    }
    if (r)
        py.DecRef(r);
    py.GILRelease(st);
    if (opening)
        pthread_sigmask(SIG_SETMASK, &old, NULL);
    return rc;
}

/* a new connection of this process to its in-process controller, greeted; 0 ok */
static int inproc_connect(const char *fname)
{
    int st = py_enter();
    pyobj r = py_method(g_host, "connect");
    char why[1000] = "";
    if (r)
        py.DecRef(r);
    else
        py_error(why, sizeof why);
    py.GILRelease(st);
    if (!r) {
        set_err("%s returned -1: the in-process controller failed: %s", fname, why);
        return -1;
    }
    g_inproc = 1;
    g_fd_pid = getpid();
    if (hello(GTE_NO_SOCK, "", fname, 0) < 0) {
        g_inproc = 0;
        return -1;
    }
    g_lost[0] = '\0';
    return 0;
}
#else
static int inproc_call(size_t size, size_t *total, int opening)
{
    (void)size;
    (void)total;
    (void)opening;
    return -1;
}
#endif

#if defined(__linux__)
/* the in-process controller where it is wanted and can be started (else 1: start the
 * controller process instead; the reason on stderr where GTECAT_INPROCESS asked for it);
 * 0 connected, -1 failed */
static int open_inproc(const char *fname, long long deadline)
{
    static int tried;
    int asked;
    if (g_inproc_pid == getpid())
        return inproc_connect(fname);
    if (g_inproc_pid) { /* a forked child: its parent's controller, over the socket */
        if (g_private_addr[0] && connect_to(g_private_addr, fname, deadline) == 0)
            return 0;
        return 1;
    }
    if (tried || !inproc_wanted(&asked))
        return 1;
    tried = 1;
    const char *rt = setting("GTECAT_RT_PRIORITY");
    if (rt && *rt && strcasecmp(rt, "off") != 0) { /* the priority of a controller process */
        if (asked)
            fprintf(stderr, "gtecat: the in-process controller is not used (GTECAT_RT_PRIORITY "
                    "is the priority of the controller process): starting that process\n");
        return 1;
    }
    char dir[160], addr[200];
    if (private_socket(fname, dir, addr) < 0)
        return -1;
    sigset_t old;
    block_sigpipe(&old);
    int started = inproc_start(addr);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (started == 0) {
        snprintf(g_private_addr, sizeof g_private_addr, "%s", addr);
        snprintf(g_addr, sizeof g_addr, "%s", addr);
        return inproc_connect(fname);
    }
    char sock[200];
    snprintf(sock, sizeof sock, "%s/controller.sock", dir);
    unlink(sock);
    rmdir(dir);
    if (asked)
        fprintf(stderr, "gtecat: the in-process controller is not used (%s): starting the "
                "controller process instead\n", g_inproc_why);
    return 1;
}
#endif

static int ensure_open(const char *fname)
{
    if ((g_fd != GTE_NO_SOCK || g_inproc) && g_fd_pid == gte_getpid())
        return 0;
    if (g_fd != GTE_NO_SOCK) { /* a forked child: leave the parent's connection to the parent */
        sock_close(g_fd);
        g_fd = GTE_NO_SOCK;
    }
    g_inproc = 0;
#if defined(_WIN32)
    static int wsa_ready;
    if (!wsa_ready) {
        WSADATA wsa;
        int e = WSAStartup(MAKEWORD(2, 2), &wsa);
        if (e != 0) {
            set_err("%s returned -1: winsock did not start (error %d)", fname, e);
            return -1;
        }
        wsa_ready = 1;
    }
#endif
    long long deadline = now_ms() + env_ms("GTECAT_TIMEOUT_MS", 30000);
    const char *named = setting("GTECAT_CONTROLLER");
    if (named)
        return connect_to(named, fname, deadline);
#if defined(_WIN32)
    set_err("%s returned -1: no controller named: write controller = tcp://HOST:PORT (and "
            "token = ...) in %s, or set GTECAT_CONTROLLER and GTECAT_TOKEN", fname,
            g_ini_path[0] ? g_ini_path : "gtecat.ini beside the program");
    return -1;
#else
#if defined(__linux__)
    int in = open_inproc(fname, deadline);
    if (in <= 0)
        return in;
#endif
    if (g_private_addr[0] && g_child > 0) {
        if (kill(g_child, 0) == 0 && connect_to(g_private_addr, fname, deadline) == 0)
            return 0;
        child_fate();
    }
    return start_private(fname);
#endif
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

static short invoke_locked(const gte_function *f, int gtn, short core, short card,
                           const gte_arg *a)
{
    if (f->flags & GTE_F_OPEN) {
        if (ensure_open(f->name) < 0)
            return CMD_COMM;
    } else if ((g_fd == GTE_NO_SOCK && !g_inproc) || g_fd_pid != gte_getpid()) {
        if ((f->flags & GTE_F_CLOSE) && g_fd == GTE_NO_SOCK && !g_inproc)
            return 0; /* closing what is not open: nothing to do (as in Python) */
        if ((g_fd != GTE_NO_SOCK || g_inproc) && g_fd_pid != gte_getpid()) {
            if (g_fd != GTE_NO_SOCK)
                sock_close(g_fd); /* forked child: reconnect to the same controller */
            g_fd = GTE_NO_SOCK;
            g_inproc = 0; /* (the parent's in-process one: over its socket) */
            char addr[sizeof g_addr]; /* (connect_to writes g_addr: not from itself) */
            snprintf(addr, sizeof addr, "%s", g_addr);
            if (addr[0] && connect_to(addr, f->name,
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
    *w++ = (unsigned char)((gtn ? GTE_CALL_GTN : 0) | ((card & 15) << GTE_CARD_SHIFT));
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
    size_t total = 0;
    if (g_inproc) { /* a function call: the controller runs in this process */
        if (inproc_call(size, &total, f->flags & GTE_F_OPEN) < 0) {
            set_err("%s returned -1: %s", f->name, g_io_why);
            return CMD_COMM;
        }
        goto replied;
    }
    long timeout = env_ms("GTECAT_TIMEOUT_MS", 30000);
    long long deadline = now_ms() + timeout;
    if (send_all(g_fd, g_buf, size, deadline) < 0) {
        char why[1024];
        snprintf(why, sizeof why, "sending %s to %s failed: %s", f->name, g_addr, io_error());
        drop(why);
        set_err("%s returned -1: controller not responding: %s", f->name, g_lost);
        return CMD_COMM;
    }
    /* ---- reply ---- */
    int r = recv_msg(g_fd, &total, deadline);
    if (r < 0) {
        char why[1024];
        if (r == -2)
            snprintf(why, sizeof why, "the controller at %s closed the connection during %s",
                     g_addr, f->name);
        else if (g_io_why == TIMED_OUT)
            snprintf(why, sizeof why, "no reply to %s within %ld ms (GTECAT_TIMEOUT_MS)",
                     f->name, timeout);
        else
            snprintf(why, sizeof why, "reading the reply to %s failed: %s", f->name, io_error());
        drop(why);
        set_err("%s returned -1: controller not responding: %s", f->name, g_lost);
        return CMD_COMM;
    }
replied:
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

/* GT_SetCardNo / GT_GetCardNo, GT_SetCore / GT_GetCore: the process's own settings,
 * answered here (before GT_Open too, as applications call them) with the codes and reasons
 * of the Python functions */
static short own_setting(const gte_function *f, int gtn, short core, const gte_arg *a)
{
    int set = f->flags & (GTE_F_CARDNO | GTE_F_SETCORE);
    int card = f->flags & (GTE_F_CARDNO | GTE_F_GETCARDNO);
    if (gtn && core != 1) {
        set_err("%s returned 7: core=%d: the EtherCAT core is 1", f->name, core);
        return CMD_PARAM;
    }
    if (set) {
        long long v = a[0].i, top = card ? 15 : 2;
        if (v < (card ? 0 : 1) || v > top) {
            set_err("%s returned 7: %s=%lld out of range %d..%lld", f->name,
                    card ? "index" : "core", v, card ? 0 : 1, top);
            return CMD_PARAM;
        }
        if (card)
            g_card = (short)v;
        else
            g_core = (short)v;
    } else {
        if (!a[0].p) {
            set_err("%s returned 7: %s is NULL; this pointer is required", f->name,
                    card ? "pIndex" : "pCore");
            return CMD_PARAM;
        }
        *(short *)a[0].p = card ? g_card : g_core;
    }
    g_err[0] = '\0';
    return 0;
}

short gte_invoke(const gte_function *f, int gtn, short core, const gte_arg *a)
{
    short card = t_card; /* the multi-card ABI's card for this one call, else the current */
    t_card = -1;
    LOCK();
    ask_short_slice(); /* once per thread (it reads the settings: under the lock) */
    if (f->flags & (GTE_F_CARDNO | GTE_F_GETCARDNO | GTE_F_SETCORE | GTE_F_GETCORE)) {
        short rc = own_setting(f, gtn, core, a);
        UNLOCK();
        return rc;
    }
    if (card < 0)
        card = g_card;
    if (!gtn)
        core = g_core; /* a GT_x call: the core GT_SetCore chose */
    short rc = invoke_locked(f, gtn, core, card, a);
    if (rc == 0 && (f->flags & GTE_F_OPEN))
        g_cards_open |= 1u << (card & 15);
    if (f->flags & GTE_F_CLOSE)
        g_cards_open &= ~(1u << (card & 15));
    if ((f->flags & GTE_F_CLOSE) && !g_cards_open && (g_fd != GTE_NO_SOCK || g_inproc) &&
        g_fd_pid == gte_getpid()) {
        /* the last card's GT_Close ends this connection; a private controller lives on
         * until the program ends, so the next GT_Open finds it again */
        if (g_fd != GTE_NO_SOCK)
            sock_close(g_fd);
        g_fd = GTE_NO_SOCK;
        g_inproc = 0;
        g_lost[0] = '\0';
    }
    UNLOCK();
    return rc;
}

void gte_use_card(short card)
{
    t_card = card;
}

short gte_no_card(const char *name, short card, short code)
{
    LOCK();
    if (code == -6)
        set_err("%s returned -6: no card %d: cards are numbered 0..15", name, card);
    else if (code == -7)
        set_err("%s returned -7: libgts_mc found no %s in libgts", name, name);
    else
        set_err("%s returned %d: no card %d: cards are numbered 0..15", name, code, card);
    UNLOCK();
    return code;
}

short gte_declared(int index, int gtn, short core)
{
    const gte_declared_info *d = &gte_declared_table[index];
    gte_function f = {d->name, d->id, 0, GTE_F_DECLARED, NULL};
    char name[128];
    snprintf(name, sizeof name, "%s%s", gtn ? "GTN_" : "", gtn ? d->name + 3 : d->name);
    LOCK();
    short rc = -1;
    if ((g_fd != GTE_NO_SOCK || g_inproc) && g_fd_pid == gte_getpid())
        rc = invoke_locked(&f, gtn, core, g_card, NULL); /* the controller logs it, says why */
    if (rc != GTE_CMD_DECLARED)
        set_err("%s returned %d: %s is declared but not emulated (group: %s)", name,
                GTE_CMD_DECLARED, name, d->group);
    UNLOCK();
    return GTE_CMD_DECLARED;
}

short GTE_STDCALL GTE_GetLastError(char *buf, short size)
{
    if (!buf || size < 1)
        return CMD_PARAM;
    LOCK();
    snprintf(buf, (size_t)size, "%s", g_err);
    UNLOCK();
    return 0;
}
