/* The axis bank's Gear and Follow slaves, a table at a time (gtecat/controller/bank_slaves.py).
 *
 * GearPlanner.step (with _through_clutch) and FollowPlanner.step (with _follow, _advance,
 * _begin_pass, _segment and _finish) of gtecat/controller/motion/gear.py and follow.py,
 * transcribed with the same IEEE operations in the same order (built with -ffp-contract=off,
 * no fast-math), for a slave in motion (Gear _MOVE; Follow _MOVE without a FIFO switch
 * pending): the samples are the scalar planner's, bit for bit.  Each row's state is SL_NST
 * doubles (SL_* below); a Follow row also has its FIFO's points (m rows of master, slave,
 * segment type) and the segments of the pass computed so far (m rows of x0, x1, s0, s1, rs,
 * re, k: the planner's _segs list). */
#include <stdint.h>
#include <string.h>

enum {
    SL_KIND, SL_STATE, SL_T, SL_DIR, SL_MPREV, SL_POS, SL_VEL, SL_ACC,
    /* GearPlanner: _cl, _x, _r0, _r1 */
    SL_CL, SL_GX, SL_R0, SL_R1,
    /* FollowPlanner: _x, _i, len(_segs), _loops_done, _x0, _s0, _carry, _sd, _origin, _loop,
     * the points in the running FIFO */
    SL_X, SL_I, SL_NSEG, SL_LOOPS, SL_X0, SL_S0, SL_CARRY, SL_SD, SL_ORIGIN, SL_LOOP, SL_M,
    SL_NST
};
/* SL_KIND */
enum { SL_GEAR = 1, SL_FOLLOW = 2 };
/* the planners' _state while they move */
enum { GEAR_MOVE = 1, FOLLOW_MOVE = 2 };
/* a segment's fields */
enum { G_X0, G_X1, G_S0, G_S1, G_RS, G_RE, G_K, G_N };

int bank_slaves_state_size(void) { return SL_NST; }

/* gtecat.controller.motion.master.passed */
static double passed(double delta, double dir)
{
    if (dir > 0.0)
        return delta > 0.0 ? delta : 0.0;
    if (dir < 0.0)
        return delta < 0.0 ? delta : 0.0;
    return delta;
}

/* GearPlanner._through_clutch */
static double through_clutch(double *st, double d)
{
    const double r0 = st[SL_R0], r1 = st[SL_R1], span = st[SL_CL], x0 = st[SL_GX];
    const double travel = d < 0.0 ? -d : d; /* abs(d) (d is not 0 here) */
    const double ra = r0 + (r1 - r0) * x0 / span;
    double dist;
    if (x0 + travel >= span) {
        dist = (span - x0) * (ra + r1) * 0.5 + r1 * (x0 + travel - span);
        st[SL_CL] = st[SL_GX] = 0.0;
    } else {
        const double x1 = x0 + travel;
        dist = travel * (ra + r0 + (r1 - r0) * x1 / span) * 0.5;
        st[SL_GX] = x1;
    }
    return d > 0.0 ? dist : -dist;
}

/* GearPlanner.run in motion: n samples against the master positions ms; a gear never ends */
static int64_t gear_run(double *st, const double *ms, int64_t n, double *po, double *vo,
                        double *ao)
{
    const double cyc = st[SL_T], dir = st[SL_DIR], r1 = st[SL_R1];
    double m_prev = st[SL_MPREV], pos = st[SL_POS], vel = st[SL_VEL], acc = st[SL_ACC];
    int64_t j;
    for (j = 0; j < n; j++) {
        const double m = ms[j];
        const double d = passed(m - m_prev, dir);
        double ds, v;
        m_prev = m;
        if (st[SL_CL] > 0.0 && d != 0.0)
            ds = through_clutch(st, d);
        else
            ds = r1 * d;
        pos += ds;
        v = ds / cyc;
        acc = (v - vel) / cyc;
        vel = v;
        po[j] = pos;
        vo[j] = vel;
        ao[j] = acc;
    }
    st[SL_MPREV] = m_prev;
    st[SL_POS] = pos;
    st[SL_VEL] = vel;
    st[SL_ACC] = acc;
    return -1;
}

/* FollowPlanner._segment(i): cam segment i of the current pass (manual 7.6.2 (5)) */
static void follow_segment(const double *st, const double *pts, double *segs, int64_t i)
{
    const double *pt = pts + 3 * i;
    const double x0 = st[SL_X0], s0 = st[SL_S0], kind = pt[2];
    double pm, ps, r_prev, dm, ds, rs, re;
    double *g = segs + G_N * i;
    if (i) {
        pm = pts[3 * (i - 1)];
        ps = pts[3 * (i - 1) + 1];
        r_prev = segs[G_N * (i - 1) + G_RE];
    } else {
        pm = 0.0;
        ps = 0.0;
        r_prev = st[SL_CARRY];
    }
    dm = pt[0] - pm;
    ds = pt[1] - ps;
    if (kind == 1.0) { /* FOLLOW_SEGMENT_EVEN */
        rs = re = ds / dm;
    } else if (kind == 2.0) { /* FOLLOW_SEGMENT_STOP */
        rs = 2.0 * ds / dm;
        re = 0.0;
    } else { /* NORMAL, CONTINUE */
        rs = (i || kind == 3.0) ? r_prev : 0.0;
        re = 2.0 * ds / dm - rs;
    }
    g[G_X0] = x0 + pm;
    g[G_X1] = x0 + pt[0];
    g[G_S0] = s0 + ps;
    g[G_S1] = s0 + pt[1];
    g[G_RS] = rs;
    g[G_RE] = re;
    g[G_K] = (re - rs) / (2.0 * dm);
}

/* FollowPlanner._begin_pass */
static void follow_begin_pass(double *st, const double *pts, double *segs, double x0, double s0,
                              double carry)
{
    st[SL_X0] = x0;
    st[SL_S0] = s0;
    st[SL_CARRY] = carry;
    st[SL_I] = 0.0;
    st[SL_SD] = pts[0] > 0.0 ? 1.0 : -1.0;
    follow_segment(st, pts, segs, 0);
    st[SL_NSEG] = 1.0;
}

/* FollowPlanner._advance without a FIFO switch: 0 when the motion is complete */
static int follow_advance(double *st, const double *pts, double *segs)
{
    const int64_t i = (int64_t)st[SL_I] + 1;
    const double *last;
    double x1, s1, re;
    if (i < (int64_t)st[SL_M]) {
        st[SL_I] = (double)i;
        if (i == (int64_t)st[SL_NSEG]) {
            follow_segment(st, pts, segs, i);
            st[SL_NSEG] = (double)(i + 1);
        }
        return 1;
    }
    last = segs + G_N * (i - 1);
    st[SL_LOOPS] += 1.0;
    if (st[SL_LOOP] >= 1.0 && st[SL_LOOPS] >= st[SL_LOOP])
        return 0;
    x1 = last[G_X1];
    s1 = last[G_S1];
    re = last[G_RE];
    follow_begin_pass(st, pts, segs, x1, s1, re);
    return 1;
}

/* FollowPlanner.run in motion: n samples against the master positions ms; the index of the
 * end sample (the last pass completed) or -1.  The state is held in locals between the
 * boundaries of segments (st[SL_I] is follow_advance's) and stored at the end. */
static int64_t follow_run(double *st, const double *pts, double *segs, const double *ms,
                          int64_t n, double *po, double *vo, double *ao)
{
    const double cyc = st[SL_T], dir = st[SL_DIR], origin = st[SL_ORIGIN];
    double x = st[SL_X], m_prev = st[SL_MPREV], pos = st[SL_POS], vel = st[SL_VEL];
    double acc = st[SL_ACC], sd = st[SL_SD];
    int64_t i = (int64_t)st[SL_I], j, end = -1;
    const double *seg = segs + G_N * i;
    for (j = 0; j < n; j++) {
        const double m = ms[j];
        double u, s, v;
        x += passed(m - m_prev, dir);
        m_prev = m;
        while ((x - seg[G_X1]) * sd >= 0.0) {
            st[SL_I] = (double)i;
            if (!follow_advance(st, pts, segs)) { /* _finish(origin + seg.s1) */
                pos = origin + seg[G_S1];
                vel = acc = 0.0;
                st[SL_STATE] = 0.0;
                po[j] = pos;
                vo[j] = 0.0;
                ao[j] = 0.0;
                end = j;
                goto out;
            }
            i = (int64_t)st[SL_I];
            sd = st[SL_SD];
            seg = segs + G_N * i;
        }
        while (i > 0 && (x - seg[G_X0]) * sd < 0.0) {
            i -= 1;
            seg = segs + G_N * i;
        }
        u = x - seg[G_X0];
        if (u * sd < 0.0)
            u = 0.0; /* behind the start of the pass: wait there */
        s = origin + seg[G_S0] + u * (seg[G_RS] + seg[G_K] * u);
        v = (s - pos) / cyc;
        acc = (v - vel) / cyc;
        vel = v;
        pos = s;
        po[j] = s;
        vo[j] = v;
        ao[j] = acc;
    }
    st[SL_I] = (double)i;
out:
    st[SL_X] = x;
    st[SL_MPREV] = m_prev;
    st[SL_POS] = pos;
    st[SL_VEL] = vel;
    st[SL_ACC] = acc;
    return end;
}

/* The tables of a cluster's slaves at once (bank_modes.Cluster.fill): a[] holds the row
 * count, the samples per table, the table width and the addresses of the arrays (SF_* below).
 * For each row r: its state st[r] is kept in before[r]; a row that moves (moving[r], its
 * planner in motion) has the last sample taken moved to its spare slot (as
 * AxisBank.keep_last_sample does), its table filled from the master positions at mp[r] (the
 * address of n doubles: what the slave reads in each cycle) and st[r] moved on, and the
 * table's cursor, length and end follow.  Returns the samples written. */
enum {
    SF_NR, SF_N, SF_TABLE, SF_ROWS, SF_ST, SF_BEFORE, SF_PTS, SF_SEGS, SF_MP, SF_MOVING, SF_TP,
    SF_TV, SF_TA, SF_BASE, SF_IDX, SF_LEN, SF_CUR, SF_END, SF_NARGS
};

int bank_slaves_fill_args(void) { return SF_NARGS; }

int64_t bank_slaves_fill(const int64_t *a)
{
#define PA(T, k) ((T *)(intptr_t)a[k])
    const int64_t nr = a[SF_NR], n = a[SF_N], table = a[SF_TABLE];
    const int64_t *rows = PA(const int64_t, SF_ROWS);
    double *st = PA(double, SF_ST), *before = PA(double, SF_BEFORE);
    const int64_t *pts = PA(const int64_t, SF_PTS), *segs = PA(const int64_t, SF_SEGS);
    const int64_t *mp = PA(const int64_t, SF_MP);
    const uint8_t *moving = PA(const uint8_t, SF_MOVING);
    double *tp = PA(double, SF_TP), *tv = PA(double, SF_TV), *ta = PA(double, SF_TA);
    const int64_t *base = PA(const int64_t, SF_BASE);
    int64_t *idx = PA(int64_t, SF_IDX), *len = PA(int64_t, SF_LEN);
    int64_t *cur = PA(int64_t, SF_CUR), *end = PA(int64_t, SF_END);
    int64_t i, total = 0;
#undef PA
    for (i = 0; i < nr; i++) {
        const int64_t r = rows[i], b = base[r], spare = b + table, last = idx[r];
        double *s = st + SL_NST * r;
        const double *ms = (const double *)(intptr_t)mp[r];
        int64_t e;
        memcpy(before + SL_NST * r, s, SL_NST * sizeof(double));
        if (!moving[r])
            continue;
        if (s[SL_KIND] == SL_GEAR && s[SL_STATE] == GEAR_MOVE) {
            tp[spare] = tp[last];
            tv[spare] = tv[last];
            ta[spare] = ta[last];
            idx[r] = spare;
            e = gear_run(s, ms, n, tp + b, tv + b, ta + b);
        } else if (s[SL_KIND] == SL_FOLLOW && s[SL_STATE] == FOLLOW_MOVE) {
            tp[spare] = tp[last];
            tv[spare] = tv[last];
            ta[spare] = ta[last];
            idx[r] = spare;
            e = follow_run(s, (const double *)(intptr_t)pts[r], (double *)(intptr_t)segs[r], ms,
                           n, tp + b, tv + b, ta + b);
        } else {
            continue; /* at rest: a cycle does not step it */
        }
        len[r] = e >= 0 ? e + 1 : n;
        cur[r] = 0;
        end[r] = e;
        total += len[r];
    }
    return total;
}
