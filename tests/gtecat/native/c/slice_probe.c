/* The time slice libgts asks for on behalf of each calling thread (Linux 6.12 and later):
 * prints `key value` lines the test reads: the slice in ns (/proc: se.slice) of a thread
 * before and after its first call, then of the main thread before and after its own, then
 * of a thread the main thread starts afterwards (it inherits the main thread's).
 * GT_GetCardNo is answered by the library itself, so no controller is started.
 *
 *     gcc slice_probe.c $(python3 -m gtecat lib --cflags --libs)
 */
#define _GNU_SOURCE
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "gts.h"

static long slice_ns(void)
{
    char line[256];
    long ns = -1;
    FILE *f = fopen("/proc/thread-self/sched", "r");
    if (!f)
        return -1;
    while (fgets(line, sizeof line, f))
        if (strncmp(line, "se.slice", 8) == 0) {
            char *colon = strchr(line, ':');
            if (colon && sscanf(colon + 1, "%ld", &ns) != 1)
                ns = -1;
        }
    fclose(f);
    return ns;
}

static void *inherited(void *unused)
{
    (void)unused;
    printf("child_thread %ld\n", slice_ns());
    return NULL;
}

static void *second(void *unused)
{
    short card = -1;
    (void)unused;
    printf("thread_before %ld\n", slice_ns());
    printf("thread_call %d\n", GT_GetCardNo(&card));
    printf("thread_after %ld\n", slice_ns());
    return NULL;
}

int main(void)
{
    short card = -1;
    pthread_t t;
    if (pthread_create(&t, NULL, second, NULL) != 0 || pthread_join(t, NULL) != 0)
        return 1;
    printf("before %ld\n", slice_ns());
    printf("call %d\n", GT_GetCardNo(&card));
    printf("after %ld\n", slice_ns());
    if (pthread_create(&t, NULL, inherited, NULL) != 0 || pthread_join(t, NULL) != 0)
        return 1;
    return 0;
}
