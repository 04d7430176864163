/* The axis bank's PVT rows, a table at a time (gtecat/controller/bank_pvt.py).
 *
 * PvtPlanner.step in motion and PvtSegment.at (gtecat/controller/motion/pvt.py), transcribed
 * with the same IEEE operations in the same order (built with -ffp-contract=off, no
 * fast-math): the samples are the scalar planner's, bit for bit, passes and the end of the
 * last one included.  Each row's state is PV_NST doubles (PV_* below); its table is m rows of
 * t0, t1, p0, p1, v0, v1 (the planner's segments).  bank_pvt_run has bank_pt_run's form: the
 * kernel's bank_pt_fill fills many PVT rows' tables with it in one call. */
#include <math.h>
#include <stdint.h>

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
