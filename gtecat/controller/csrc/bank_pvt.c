/* The axis bank's PVT rows, a table at a time (gtecat/controller/bank_pvt.py).
 *
 * PvtPlanner.step in motion and PvtSegment.at (gtecat/controller/motion/pvt.py), transcribed
 * with the same IEEE operations in the same order (built with -ffp-contract=off, no
 * fast-math): the samples are the scalar planner's, bit for bit, passes and the end of the
 * last one included.  Each row's state is PV_NST doubles (PV_* below); its table is m rows of
 * t0, t1, p0, p1, v0, v1 (the planner's segments). */
#include <math.h>
#include <stdint.h>
#include <string.h>

enum { PV_K, PV_T, PV_I, PV_LOOP, PV_LOOPS, PV_ORIGIN, PV_POS, PV_VEL, PV_ACC, PV_STATE, PV_NST };
enum { S_T0, S_T1, S_P0, S_P1, S_V0, S_V1, S_N };

int bank_pvt_state_size(void) { return PV_NST; }

/* n samples from the state st (moved on to the state after them) into po/vo/ao; returns the
 * index of the end sample (the last pass ended) or -1. */
int64_t bank_pvt_run(double *st, const double *sg, int64_t m, int64_t n, double *po, double *vo,
                     double *ao)
{
    const double cyc = st[PV_T], loop = st[PV_LOOP];
    const double *lst = sg + S_N * (m - 1);
    const double first = sg[S_T0], end = lst[S_T1];
    int64_t j, k = (int64_t)st[PV_K], i = (int64_t)st[PV_I];
    double origin = st[PV_ORIGIN], loops = st[PV_LOOPS];
    for (j = 0; j < n; j++) {
        double t, h, s, dp, m0, m1, c2, c3;
        const double *g;
        k += 1;
        t = first + (double)k * cyc;
        while (t > end + 1e-9) {
            loops += 1.0;
            if (loop != 0.0 && loops >= loop) { /* _finish(origin + p1) */
                st[PV_K] = (double)k;
                st[PV_I] = (double)i;
                st[PV_LOOPS] = loops;
                st[PV_ORIGIN] = origin;
                st[PV_POS] = origin + lst[S_P1];
                st[PV_VEL] = st[PV_ACC] = 0.0;
                st[PV_STATE] = 0.0;
                po[j] = st[PV_POS];
                vo[j] = 0.0;
                ao[j] = 0.0;
                return j;
            }
            origin += lst[S_P1] - sg[S_P0]; /* the next pass from here */
            k = (int64_t)nearbyint((t - end) / cyc); /* round(): half to even */
            i = 0;
            t = first + (double)k * cyc;
        }
        while (i < m - 1 && sg[S_N * i + S_T1] < t)
            i++;
        g = sg + S_N * i; /* PvtSegment.at */
        h = g[S_T1] - g[S_T0];
        s = (t - g[S_T0]) / h;
        dp = g[S_P1] - g[S_P0];
        m0 = g[S_V0] * h;
        m1 = g[S_V1] * h;
        c2 = 3.0 * dp - 2.0 * m0 - m1;
        c3 = -2.0 * dp + m0 + m1;
        po[j] = origin + (g[S_P0] + s * (m0 + s * (c2 + s * c3)));
        vo[j] = (m0 + s * (2.0 * c2 + 3.0 * s * c3)) / h;
        ao[j] = (2.0 * c2 + 6.0 * s * c3) / (h * h);
    }
    st[PV_K] = (double)k;
    st[PV_I] = (double)i;
    st[PV_LOOPS] = loops;
    st[PV_ORIGIN] = origin;
    if (n > 0) {
        st[PV_POS] = po[n - 1];
        st[PV_VEL] = vo[n - 1];
        st[PV_ACC] = ao[n - 1];
    }
    return -1;
}

/* The tables of many PVT rows at once (AxisBank._fill_tables, as bank_pt_fill does for PT):
 * a[] holds the row count, the samples per table, the table width and the addresses of the
 * arrays (PF_* below).  For each row r: its state st[r] is kept in before[r], the last sample
 * taken moves to the row's spare slot, bank_pvt_run fills the table and moves st[r] on, and
 * the table's cursor, length and end follow; the samples written are returned. */
enum {
    PF_NR, PF_N, PF_TABLE, PF_ROWS, PF_ST, PF_BEFORE, PF_SEGS, PF_M, PF_TP, PF_TV, PF_TA,
    PF_BASE, PF_IDX, PF_LEN, PF_CUR, PF_END, PF_TAKEN, PF_FILLTAKEN, PF_NARGS
};

int bank_pvt_fill_args(void) { return PF_NARGS; }

int64_t bank_pvt_fill(const int64_t *a)
{
#define PA(T, k) ((T *)(intptr_t)a[k])
    const int64_t nr = a[PF_NR], n = a[PF_N], table = a[PF_TABLE];
    const int64_t *rows = PA(const int64_t, PF_ROWS);
    double *st = PA(double, PF_ST), *before = PA(double, PF_BEFORE);
    const int64_t *segs = PA(const int64_t, PF_SEGS), *m = PA(const int64_t, PF_M);
    double *tp = PA(double, PF_TP), *tv = PA(double, PF_TV), *ta = PA(double, PF_TA);
    const int64_t *base = PA(const int64_t, PF_BASE);
    int64_t *idx = PA(int64_t, PF_IDX), *len = PA(int64_t, PF_LEN);
    int64_t *cur = PA(int64_t, PF_CUR), *end = PA(int64_t, PF_END);
    const int64_t *taken = PA(const int64_t, PF_TAKEN);
    int64_t *fill_taken = PA(int64_t, PF_FILLTAKEN);
    int64_t i, total = 0;
#undef PA
    for (i = 0; i < nr; i++) {
        const int64_t r = rows[i], b = base[r], spare = b + table, last = idx[r];
        int64_t e;
        memcpy(before + PV_NST * r, st + PV_NST * r, PV_NST * sizeof(double));
        tp[spare] = tp[last];
        tv[spare] = tv[last];
        ta[spare] = ta[last];
        idx[r] = spare;
        e = bank_pvt_run(st + PV_NST * r, (const double *)(intptr_t)segs[r], m[r], n, tp + b,
                         tv + b, ta + b);
        len[r] = e >= 0 ? e + 1 : n;
        cur[r] = 0;
        end[r] = e;
        fill_taken[r] = taken[r];
        total += len[r];
    }
    return total;
}
