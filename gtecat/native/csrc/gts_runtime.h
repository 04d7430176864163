/* gts_runtime.h - what the generated stubs of libgts need from its transport.
 *
 * Hand-written, small and function-independent: every GT_x / GTN_x stub (generated
 * from the function table into gts_stubs.c) fills an array of gte_arg and calls
 * gte_invoke with its gte_function descriptor; gts_runtime.c does the rest.
 */
#ifndef GTECAT_GTS_RUNTIME_H
#define GTECAT_GTS_RUNTIME_H

#include "gts_wire.h"

/* one parameter: how it travels (GTE_K_*), and for pointers how many bytes */
typedef struct gte_param {
    unsigned char kind;     /* GTE_K_* */
    signed char count_arg;  /* index of the parameter holding the element count, -1: fixed */
    unsigned int elem;      /* sizeof one element (pointers) */
    long count;             /* fixed element count when count_arg is -1 */
} gte_param;

typedef struct gte_function {
    const char *name;       /* GT_x (GTE_x) as the table writes it */
    unsigned short id;      /* the protocol's function id */
    unsigned char nparams;
    unsigned char flags;    /* GTE_F_* */
    const gte_param *params;
} gte_function;

enum {
    GTE_F_OPEN = 1,
    GTE_F_CLOSE = 2,
    GTE_F_DECLARED = 4,
    GTE_F_CARDNO = 8,     /* GT_SetCardNo: the process's current card (gts_runtime.c) */
    GTE_F_GETCARDNO = 16, /* GT_GetCardNo */
    GTE_F_SETCORE = 32,   /* GT_SetCore: the core of the GT_x calls */
    GTE_F_GETCORE = 64    /* GT_GetCore */
};

typedef union gte_arg {
    long long i;
    double d;
    const void *p;
} gte_arg;

/* Marshal one call, send it to the controller, copy the out-pointers back, return the code.
 * gtn: 1 for GTN_x (the core is checked), 0 for GT_x / GTE_x. */
#if defined(__GNUC__) && !defined(_WIN32)
#define GTE_INTERNAL __attribute__((visibility("hidden")))
#else
#define GTE_INTERNAL
#endif
GTE_INTERNAL short gte_invoke(const gte_function *f, int gtn, short core, const gte_arg *a);

/* A function the table declares but gtecat does not emulate: returns GTE_CMD_DECLARED (8,
 * the vendor's CMD_ERROR_UNKNOWN) whatever happens; a connected controller is told (it
 * writes the master-log line), else the reason is set here. */
typedef struct gte_declared_info {
    const char *name;       /* GT_x as the table writes it */
    const char *group;      /* the group's title */
    unsigned short id;      /* the protocol's function id */
} gte_declared_info;
GTE_INTERNAL extern const gte_declared_info gte_declared_table[]; /* gts_declared.c */
GTE_INTERNAL short gte_declared(int index, int gtn, short core);

/* the multi-card ABI (libgts_mc, a layer over this library) given a card outside 0..15:
 * code (-6 for GT_Open, else -1) with a reason; exported for libgts_mc, not in gts.h */
short gte_no_card(const char *name, short card, short code);
/* the multi-card ABI: the next call of this thread addresses card ``card`` (0..15) instead
 * of the current card; exported for libgts_mc, not in gts.h */
void gte_use_card(short card);

/* the interpreter that built the library (generated beside the stubs) */
GTE_INTERNAL extern const char gte_default_python[];
/* sizeof(long) of the client the stubs serve (generated beside them): 8 on Linux, 4 in the
 * LLP64 build that serves programs written for Windows (C# / VB.NET under Mono) */
GTE_INTERNAL extern const unsigned short gte_client_long_size;

#endif
