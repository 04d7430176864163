/* One cycle of the axis bank's claimed rows, compiled (gtecat/controller/bank_kernel.py).
 *
 * The numpy cycle of gtecat/controller/bank.py (AxisBank.cycle) and drives/csp_bank.py
 * (CspBank.step/commit/output) transcribed row by row: the same IEEE operations in the
 * same order (built with -ffp-contract=off, no fast-math), so every value is the same bit
 * pattern as numpy's and the scalar reference's.  It only runs the plain cycle: when a
 * raw write touched a claimed slave's outputs (return 1) nothing is written and the caller
 * runs the numpy cycle; when rows would leave the bank (return 3: a limit switch, a soft
 * limit, the following error, the drive's following error window, a homing event) nothing
 * is written, s_hit marks them and the caller releases them and runs the cycle again.
 * Return 0: committed; io[OUT_FIN] says a Trap move ended.
 *
 * bank_kernel_run runs up to n such cycles back to back (t advancing by dt_ns each), for a
 * controller whose cycle has nothing else to do (AxisBank.run_cycles): it stops before the
 * first cycle that is not committed and returns the cycles committed; io[OUT_FIN] then says
 * whether any of them ended a Trap move.
 *
 * Two checks follow the scalar objects' hooks where the bank holds them: a row whose 60FDh
 * bits in dwatch change (the home input a capture unit samples every cycle) and a Trap row
 * whose sample runs toward a limit already latched (lvel: bit 0 the positive side, bit 1
 * the negative; AxisResources._post stops such a motion) leave the bank before that cycle;
 * a change of the bits in dpost (the home input of a capture unit that can take the edge
 * after the cycle) is committed with the cycle and marked in s_evt for the caller (a run of
 * many cycles ends before it, as before the others).  A touch probe edge of a row whose
 * dpost has TP_POST is committed and marked the same way (s_p0: where the travel started).
 * A third follows the drive's touch probe: a row whose probe is armed (c_tpw) leaves before
 * a cycle whose travel reaches c_tp_lo or c_tp_hi, the nearest edges the probe latches, so
 * that the drive's TouchProbe.step of every cycle the bank runs finds nothing.
 *
 * A row standing on a limit switch (60FDh bit 0/1 in c_din: the drive's cycle reads the last
 * value) stays while its flag is latched (lvel): the drive's own reaction runs here
 * (Channel._limit_switches, c_lreact 1: a demand into the switch is braked with 6085h, c_qsd,
 * c_lstop the drive's limit_stop; 2, a fault: the row leaves first); a switch reached anew, or
 * one whose flag is not latched, sends the row back before that cycle as before.
 *
 * Arrays arrive as one table of addresses in the order of FIELDS below (the Python side
 * binds them by these names and refuses a library whose list differs).
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__)
#define INLINE static inline __attribute__((always_inline))
#else
#define INLINE static inline
#endif

/* The hot loops built twice, the processor picking at load time (glibc's ifunc): with SSE4.1
 * rint is one instruction (roundsd, rounding as rint does: the same bits), else the baseline
 * sequence.  Nothing else differs (no FMA: -ffp-contract=off either way). */
#if defined(__x86_64__) && defined(__GNUC__) && defined(__GLIBC__) && defined(__has_attribute)
#if __has_attribute(target_clones)
#define CLONES __attribute__((target_clones("sse4.1", "default")))
#endif
#endif
#ifndef CLONES
#define CLONES
#endif

#define FIELDS                                                                          \
    X(alive, u8) X(moving, u8) X(jog, u8) X(ended, u8) X(base, i64) X(t_cur, i64)          \
    X(t_end, i64) X(t_idx, i64) X(taken, i64) X(t_p, f64)                                  \
    X(prf_ratio, f64) X(prf_off, f64) X(unit2, f64) X(drive_offset, i64)                   \
    X(external, u8) X(sense, i64) X(unit, f64) X(enc_prev, i64) X(enc_pos, f64)            \
    X(enc_step0, f64) X(enc_step1, f64) X(enc_ratio, f64) X(enc_off, f64)                  \
    X(soft_pos, f64) X(soft_neg, f64) X(pos_err, f64) X(band, f64) X(hold_ns, i64)         \
    X(since, i64) X(arrived, u8) X(a_last, f64)                                            \
    X(ls, u8) X(ls_dir, i64) X(ls_prm, f64) X(ls_ix, i64) X(ls_tab, f64) X(ls_last, f64)   \
    X(jrp, f64) X(jrv, f64) X(jp, f64) X(jv, f64) X(ja, f64) X(tau, f64) X(jE, f64)        \
    X(jgoal, f64) X(jacc, f64) X(jdec, f64)                                                \
    X(c_pos, f64) X(c_vel, f64) X(c_acc, f64) X(c_dpos, f64) X(c_dvel, f64)                \
    X(c_fe_time, f64) X(c_limited, u8) X(c_sw_limited, u8) X(c_start, i64) X(c_din, i64)   \
    X(c_target, i64) X(c_vmax, f64) X(c_e, f64) X(c_c, f64) X(c_lim, f64) X(c_off, i64)   \
    X(c_pos_offset, i64) X(c_sw_min, i64) X(c_sw_max, i64) X(c_fe_window, f64)             \
    X(c_fe_check, u8) X(c_fe_timeout, f64) X(c_nl, f64) X(c_pl, f64) X(c_sw_const, i64)    \
    X(c_a_rated, f64) X(c_visc, f64)                                                       \
    X(w2_lo, f64) X(w2_hi, f64) X(w16_lo, f64) X(w16_hi, f64) X(w17_lo, f64) X(w17_hi, f64) \
    X(pl_row, i64) X(pl_off, i64) X(pl_size, i64) X(pl_col, i64)                           \
    X(rx_idx, i64) X(rx_ref, u8) X(buf, u8)                                                \
    X(s_target, i64) X(s_raw, i64) X(s_a, f64) X(s_enc, f64) X(s_step, f64)                \
    X(s_pos, f64) X(s_vel, f64) X(s_acc, f64) X(s_dpos, f64) X(s_dvel, f64)                \
    X(s_fe, f64) X(s_lim, u8) X(s_swl, u8) X(s_din, i64) X(s_since, i64) X(s_arr, u8)      \
    X(hm, u8) X(h_last, f64) X(h_el, f64) X(h_tr, f64) X(h_v, f64) X(h_p, f64)             \
    X(h_rest, f64) X(h_set, u8) X(h_vt, f64) X(h_acc, f64) X(h_lo, f64) X(h_hi, f64)       \
    X(h_maxtr, f64) X(h_tmo, f64) X(h_idx, u8) X(h_fd, f64) X(h_from, f64) X(h_ilim, f64)  \
    X(s_hm, f64) X(s_hit, u8) X(frz, u8) X(s_jog, f64)                                    \
    X(t_len, i64) X(k0, i64) X(nseg, i64) X(seg, f64) X(tprm, f64) X(t_v, f64) X(t_a, f64)    \
    X(c_tpw, u8) X(c_tp_lo, f64) X(c_tp_hi, f64)                                           \
    X(dwatch, i64) X(lvel, u8) X(h_done, u8) X(rx_row, i64) X(dpost, i64) X(s_evt, u8)   \
    X(s_p0, f64) X(c_lstop, u8) X(s_lstop, u8) X(c_qsd, f64) X(c_lreact, i64)

enum {
#define X(name, type) F_##name,
    FIELDS
#undef X
    N_FIELDS
};

/* io: int64 in/out slots */
enum {
    IN_N, IN_T_NS, IN_N_PLC, IN_N_RX, IN_W2, IN_W16, IN_W17, OUT_FIN,
    IN_TABLE, IN_MAXC, IN_DT_NS, OUT_DONE, OUT_FILLED, N_IO
};
/* dpost: the drive's touch probe takes an edge of the cycle's travel after the cycle */
#define TP_POST ((int64_t)1 << 62)
/* the segments a row's Trap move may hold for the kernel to fill its table itself */
#define MAXSEG 16
/* tprm per row: t_done, ts, t_final, target, dir, the planner's cycle (ms) */
#define NTPRM 6
/* fp: double inputs */
enum { FP_DT, FP_T, N_FP };

#define STR_(x) #x
#define NAME_(name, type) STR_(name) ","
const char *bank_kernel_fields(void)
{
    return
#define X(name, type) NAME_(name, type)
        FIELDS
#undef X
        ;
}

int bank_kernel_abi(void) { return (N_FIELDS << 8) | (N_IO << 4) | N_FP; }

/* the sizes the Python side allocates: MAXSEG << 8 | NTPRM */
int bank_kernel_sizes(void) { return (MAXSEG << 8) | NTPRM; }

#define U8(f) ((uint8_t *)ptr[F_##f])
#define I64(f) ((int64_t *)ptr[F_##f])
#define F64(f) ((double *)ptr[F_##f])

/* numpy's float -> int64 cast on x86-64 (cvttsd2si): out of range and NaN give INT64_MIN;
 * on x86-64 that instruction itself, elsewhere the same result spelled out */
#if defined(__x86_64__) && defined(__SSE2__)
#include <emmintrin.h>
INLINE int64_t to_i64(double x) { return _mm_cvttsd_si64(_mm_set_sd(x)); }
#else
static int64_t to_i64(double x)
{
    if (x >= -9223372036854775808.0 && x < 9223372036854775808.0)
        return (int64_t)x;
    return INT64_MIN;
}
#endif

/* Python's float floor division (Objects/floatobject.c _float_div_mod; numpy's npy_divmod) */
static double floor_div(double vx, double wx)
{
    double mod = fmod(vx, wx);
    double div = (vx - mod) / wx;
    double fd;
    if (mod) {
        if ((wx < 0) != (mod < 0))
            div -= 1.0;
    }
    if (div) {
        fd = floor(div);
        if (div - fd > 0.5)
            fd += 1.0;
    } else {
        fd = copysign(0.0, vx / wx);
    }
    return fd;
}

/* drives.mechanics._closing_speed */
static double closing_speed(double dist, double lim, double dt)
{
    double d, half, m, v = 0.0;
    int k;
    if (dist <= 0.0 || lim <= 0.0)
        return 0.0;
    d = dist / dt;
    half = 0.5 * lim;
    m = floor_div(sqrt(half * half + 2.0 * lim * d) - half, lim);
    m = (double)to_i64(m); /* int(...) */
    for (k = 0; k < 8; k++) {
        v = (d + lim * m * (m + 1.0) / 2.0) / (m + 1.0);
        if (v < m * lim && m > 0.0)
            m -= 1.0;
        else if (v >= (m + 1.0) * lim)
            m += 1.0;
        else
            return v;
    }
    return d < v ? d : v; /* min(v, d) */
}

/* AxisBank._link / AffineLink.axis */
static double link(double x, double ratio, double off)
{
    if (ratio == 1.0)
        return off != 0.0 ? x + off : x;
    return ratio * x + off;
}

static int in_window(const double *lo, const double *hi, int64_t width, int64_t r, double x)
{
    int64_t j;
    for (j = 0; j < width; j++)
        if (lo[r * width + j] <= x && x < hi[r * width + j])
            return 1;
    return 0;
}

/* the travel p0 -> p1 lies strictly between row r's touch probe edges (CspBank.step) */
INLINE int tp_inside(void **ptr, int64_t r, double p0, double p1)
{
    const double lo = p0 < p1 ? p0 : p1, hi = p0 < p1 ? p1 : p0;
    return F64(c_tp_lo)[r] < lo && hi < F64(c_tp_hi)[r];
}

/* np.minimum(np.maximum(np.rint(x), -32768), 32767).astype(np.int64): NaN stays NaN */
static int64_t clip16(double x)
{
    double t = rint(x);
    if (t < -32768.0)
        t = -32768.0;
    if (t > 32767.0)
        t = 32767.0;
    return to_i64(t);
}

/* drives.homing.Homing.step of a row in a search phase (SEARCH, APPROACH, INDEX), not halted,
 * and the demand step_hm hands to the mechanics.  The row was claimed between two events:
 * h_lo < every position it has been at < h_hi, where h_lo/h_hi are the nearest positions at
 * which _scan would find something (a switch edge, a limit, an index pulse).  Returns 1 when
 * this cycle would leave that state (an event crossed, a search bound reached): nothing is
 * written and the row goes back to the scalar drive for this cycle.  A row with h_done is past
 * its procedure (completed, failed or interrupted): Homing.step then scans nothing and counts
 * no search time or travel, its speed ramps to 0 and stands; h_done 2 moves back onto the home
 * point found (RETURN, _toward); a cycle that would change its settled flag (SW10) sends it
 * back. */
/* drives.homing._toward: one cycle of the move onto target (ramp a, top speed vmax), stopping
 * exactly; the same operations in the same order */
INLINE void toward(double *pp, double *pv, double target, double vmax, double a, double dt)
{
    double p = *pp, v = *pv, d, a_dt, s, half, v_stop, v_des, dv, step;
    if (dt <= 0.0)
        return;
    d = target - p;
    a_dt = a * dt;
    if (fabs(d) <= 1e-9 && fabs(v) <= a_dt) {
        *pp = target;
        *pv = 0.0;
        return;
    }
    s = d > 0 ? 1.0 : -1.0;
    half = 0.5 * a_dt;
    v_stop = sqrt(half * half + 2.0 * a * fabs(d)) - half;
    v_des = s * (v_stop < vmax ? v_stop : vmax); /* min(vmax, v_stop) */
    dv = v_des - v;
    dv = dv < a_dt ? dv : a_dt;                  /* min(a_dt, v_des - v) */
    dv = dv > -a_dt ? dv : -a_dt;                /* max(-a_dt, ...) */
    v = v + dv;
    step = v * dt;
    if (step * s >= fabs(d)) {
        *pp = target;
        *pv = 0.0;
        return;
    }
    *pp = p + step;
    *pv = v;
}

INLINE int homing_row(void **ptr, int64_t r, double dt, double *demand, double *dvel)
{
    double pos = F64(c_pos)[r], p0 = F64(h_last)[r];
    double el = F64(h_el)[r], tr = F64(h_tr)[r], v = F64(h_v)[r], vt = F64(h_vt)[r];
    double a_dt, p, rest = F64(h_rest)[r], x;
    double *sh = F64(s_hm) + 7 * r;
    int settled;
    if (!U8(h_done)[r]) {
        el += dt;
        if (pos != p0) {
            double lo = pos < p0 ? pos : p0, hi = pos < p0 ? p0 : pos;
            tr += fabs(pos - p0);
            if (!(F64(h_lo)[r] < lo && hi < F64(h_hi)[r]))
                return 1; /* _scan would meet an event */
        }
        /* _check_bounds */
        if (U8(h_idx)[r] && (pos - F64(h_from)[r]) * F64(h_fd)[r] > F64(h_ilim)[r])
            return 1;
        if (tr > F64(h_maxtr)[r] || el > F64(h_tmo)[r])
            return 1;
    }
    /* _move */
    if (U8(h_done)[r] == 2) { /* RETURN: onto the home point (h_from), capped at h_vt */
        p = F64(h_p)[r];
        toward(&p, &v, F64(h_from)[r], vt, F64(h_acc)[r], dt);
    } else {
        a_dt = F64(h_acc)[r] * dt;
        if (v < vt) {
            x = v + a_dt;
            v = vt < x ? vt : x; /* min(v + a_dt, v_target) */
        } else if (v > vt) {
            x = v - a_dt;
            v = vt > x ? vt : x; /* max(v - a_dt, v_target) */
        }
        p = F64(h_p)[r] + v * dt;
    }
    /* settling (RETURN: only on the home point) */
    if (v == 0.0 && (U8(h_done)[r] != 2 || p == F64(h_from)[r])) {
        rest += dt;
        settled = fabs(pos - p) <= 1.0 || rest >= 0.05; /* POSITION_WINDOW, SETTLE_TIME_S */
    } else {
        rest = 0.0;
        settled = 0;
    }
    if (U8(h_done)[r] && settled != U8(h_set)[r])
        return 1; /* SW10, the phase (RETURN -> COMPLETED), the result: the scalar drive's */
    sh[0] = pos;
    sh[1] = el;
    sh[2] = tr;
    sh[3] = v;
    sh[4] = p;
    sh[5] = rest;
    sh[6] = settled ? 1.0 : 0.0;
    /* step_hm: the demand and its speed */
    *dvel = (p - F64(c_dpos)[r]) / dt;
    *demand = p;
    return 0;
}


/* bank_trap_fill's final approach of a sample (t - ts = ta): min(p, target) / max(p, target) */
INLINE double final_approach(double p, double ta, double t_final, double tgt, double dir)
{
    if (ta >= t_final) {
        if (dir > 0.0)
            p = tgt < p ? tgt : p;
        else
            p = tgt > p ? tgt : p;
    }
    return p;
}

#if defined(__GNUC__)
typedef double v2d __attribute__((vector_size(16)));

/* Samples kk and kk + 1 of bank_trap_fill's smoothed move (ts > 0) at once, two lanes of the
 * same operations in the same order (each lane its own IEEE result: the same bits), where
 * both lie in one raw piece, their smoothing windows start in that piece too and neither is
 * the end sample; 0 (nothing written) otherwise.  *pi, *pj: the pieces of the last sample
 * (moved on as the scalar loop would). */
INLINE int trap_pair(const double *sg, int64_t m, double cyc, const double *prm, double thr,
                     int64_t kk, int64_t *pi, int64_t *pj, double *po, double *vo, double *ao)
{
    const double ts = prm[1], t_final = prm[2];
    const double t0 = (double)kk * cyc, t1 = (double)(kk + 1) * cyc;
    const double ta0 = t0 - ts, ta1 = t1 - ts;
    int64_t i = *pi, j = *pj;
    if (!(t0 < thr && t1 < thr))
        return 0;
    while (i + 1 < m && sg[4 * (i + 1)] <= t0)
        i++;
    while (j + 1 < m && sg[4 * (j + 1)] <= ta0)
        j++;
    *pi = i;
    *pj = j;
    if (i != j || (i + 1 < m && sg[4 * (i + 1)] <= t1) || !(t1 - ta1 > 0.0 && t0 - ta0 > 0.0))
        return 0;
    {
        const v2d half = {0.5, 0.5}, six = {6.0, 6.0}, zero = {0.0, 0.0}, tsv = {ts, ts};
        const v2d s0 = {sg[4 * i], sg[4 * i]}, s1 = {sg[4 * i + 1], sg[4 * i + 1]};
        const v2d s2 = {sg[4 * i + 2], sg[4 * i + 2]}, s3 = {sg[4 * i + 3], sg[4 * i + 3]};
        const v2d t = {t0, t1}, ta = {ta0, ta1};
        v2d tau = t - s0;
        v2d p = s1 + tau * (s2 + half * s3 * tau);
        v2d v = s2 + s3 * tau;
        v2d tk = ta - s0; /* the window's start, in the same piece */
        v2d vk = s2 + s3 * tk;
        v2d pk = s1 + tk * (s2 + half * s3 * tk) - p;
        v2d span = t - ta;
        /* the divisions that give a zero back are left out (a piece at constant speed):
         * ak * span / 6.0 and (v - va) / ts of a zero are that zero (ts > 0) */
        v2d as6 = s3[0] == 0.0 ? s3 * span : s3 * span / six;
        v2d total = zero + span * (pk + span * (half * vk + as6));
        v2d dist = zero + span * (vk + half * s3 * span);
        v2d a = v - vk;
        if (a[0] != 0.0 || a[1] != 0.0)
            a = a / tsv;
        p = p + total / tsv;
        v = dist / tsv;
        po[0] = final_approach(p[0], ta0, t_final, prm[3], prm[4]);
        po[1] = final_approach(p[1], ta1, t_final, prm[3], prm[4]);
        vo[0] = v[0];
        vo[1] = v[1];
        ao[0] = a[0];
        ao[1] = a[1];
    }
    return 1;
}
#endif

/* motion/trap_table.py's trap_table for one planner, sample by sample in the planner's own
 * order of operations (TrapPlanner._sample): samples k0+1 .. k0+n of the move whose raw
 * pieces are sg[4*q .. 4*q+3] = (t0, p0, v0, a), q < m.  Writes min(end + 1, n) samples;
 * returns end, the index of the end sample (target, 0, 0), or n when the move goes on. */
CLONES int64_t bank_trap_fill(const double *sg, int64_t m, double cyc, const double *prm,
                              int64_t k0, int64_t n, double *po, double *vo, double *ao)
{
    const double t_done = prm[0], ts = prm[1], t_final = prm[2], tgt = prm[3], dir = prm[4];
    const double thr = t_done - 1e-9 * (1.0 + t_done * 1e-3); /* _EPS_T */
    int64_t s, i = 0, j = 0;
    for (s = 0; s < n; s++) {
        double t = (double)(k0 + 1 + s) * cyc;
        double tau, p, v, a;
#if defined(__GNUC__)
        if (ts > 0.0 && s + 1 < n && trap_pair(sg, m, cyc, prm, thr, k0 + 1 + s, &i, &j, po + s,
                                               vo + s, ao + s)) {
            s++;
            continue;
        }
#endif
        if (t >= thr) {
            po[s] = tgt;
            vo[s] = 0.0;
            ao[s] = 0.0;
            return s;
        }
        while (i + 1 < m && sg[4 * (i + 1)] <= t)
            i++;
        tau = t - sg[4 * i];
        p = sg[4 * i + 1] + tau * (sg[4 * i + 2] + 0.5 * sg[4 * i + 3] * tau);
        v = sg[4 * i + 2] + sg[4 * i + 3] * tau;
        a = sg[4 * i + 3];
        if (ts > 0.0) {
            double ta = t - ts, pk, vk, ak, va, lo, hi, span, total = 0.0, dist = 0.0;
            int64_t k;
            while (j + 1 < m && sg[4 * (j + 1)] <= ta)
                j++;
            tau = ta - sg[4 * j];
            ak = sg[4 * j + 3];
            vk = sg[4 * j + 2] + ak * tau;
            pk = sg[4 * j + 1] + tau * (sg[4 * j + 2] + 0.5 * ak * tau) - p;
            va = vk;
            lo = ta;
            for (k = j;; k++) {
                if (k > j) {
                    lo = sg[4 * k];
                    pk = sg[4 * k + 1] - p;
                    vk = sg[4 * k + 2];
                    ak = sg[4 * k + 3];
                }
                hi = k == i ? t : sg[4 * (k + 1)];
                span = hi - lo;
                if (span > 0.0) {
                    /* ak * span / 6.0, the division left out where it gives its zero back
                     * (a piece at constant speed): the divider is this loop's bottleneck */
                    const double as = ak * span, as6 = as == 0.0 ? as : as / 6.0;
                    total = total + span * (pk + span * (0.5 * vk + as6));
                    dist = dist + span * (vk + 0.5 * ak * span);
                }
                if (k >= i)
                    break;
            }
            p = p + total / ts;
            a = v - va; /* (v - va) / ts: a zero stays the same zero (ts > 0) */
            if (a != 0.0)
                a = a / ts;
            v = dist / ts;
        }
        po[s] = final_approach(p, t - ts, t_final, tgt, dir);
        vo[s] = v;
        ao[s] = a;
    }
    return n;
}

/* gtecat.controller.motion.jog.ramp_step (advance, then the snap onto the goal) for a jog
 * whose raw speed is not at its goal: the raw ramp in constant-acceleration pieces, a ramp
 * end inside the cycle split there, each piece through the smoothing filter; the same
 * operations in the same order (exp is the C library's, as Python's math.exp).
 * o[0..4] = raw position, raw speed, output position, speed, acceleration. */
static void jog_ramp(double p, double v, double goal, double acc, double dec, double dt,
                     double tau, double fp, double fv, double fa, double *o)
{
    for (;;) {
        double a, h, rate, aim = 0.0;
        int reached;
        if (v == goal) {
            a = 0.0;
            h = dt;
            reached = 0;
        } else {
            if (v == 0.0 || ((v > 0.0) == (goal > 0.0) && fabs(goal) > fabs(v))) {
                rate = acc; /* speeding up (from rest or in the same direction) */
                aim = goal;
            } else if ((v > 0.0) == (goal > 0.0) && goal != 0.0) {
                rate = dec; /* slowing down to a lower speed */
                aim = goal;
            } else {
                rate = dec; /* braking to reverse or to stop */
                aim = 0.0;
            }
            a = aim > v ? rate : -rate;
            h = (aim - v) / a;
            reached = h <= dt;
            if (!reached)
                h = dt;
        }
        if (h > 0.0) {
            const double p1 = p + h * (v + 0.5 * a * h);
            const double v1 = v + a * h;
            if (tau > 0.0) {
                const double e = exp(-h / tau);
                const double ta = tau * a;
                fp = p1 - tau * (v1 - ta) + (fp - p + tau * (v - ta)) * e;
                fv = v1 - ta + (fv - v + ta) * e;
                fa = a + (fa - a) * e;
            }
            p = p1;
            v = reached ? aim : v1;
            dt -= h;
        } else if (reached) {
            v = aim;
        }
        if (!reached) {
            if (tau <= 0.0) {
                fp = p;
                fv = v;
                fa = a;
            }
            if (v == goal && fv != goal && fabs(fv - goal) <= 1e-9 * (1.0 + fabs(goal))) {
                fv = goal;
                fa = 0.0;
            }
            o[0] = p;
            o[1] = v;
            o[2] = fp;
            o[3] = fv;
            o[4] = fa;
            return;
        }
    }
}

/* AxisBank._refill of row r in the kernel: the last sample taken moves to the row's spare
 * slot (TABLE), so a declined cycle still finds it; 0, or 1 when the row's pieces are not
 * here (the caller refills it) */
INLINE int refill_row(void **ptr, int64_t *io, int64_t r)
{
    const int64_t table = io[IN_TABLE], base = I64(base)[r], last = I64(t_idx)[r];
    int64_t m = I64(nseg)[r], end, got;
    if (m <= 0)
        return 1;
    F64(t_p)[base + table] = F64(t_p)[last];
    F64(t_v)[base + table] = F64(t_v)[last];
    F64(t_a)[base + table] = F64(t_a)[last];
    I64(t_idx)[r] = base + table;
    end = bank_trap_fill(F64(seg) + 4 * MAXSEG * r, m, F64(tprm)[NTPRM * r + 5], F64(tprm) + NTPRM * r,
                         I64(k0)[r] + I64(taken)[r], table, F64(t_p) + base, F64(t_v) + base,
                         F64(t_a) + base);
    got = end < table ? end + 1 : table;
    I64(t_len)[r] = got;
    I64(t_cur)[r] = 0;
    I64(t_end)[r] = end < table ? end : -1;
    io[OUT_FILLED] = 1;
    return 0;
}

/* Lead-screw compensation (gtecat/controller/lead_screw_bank.py): LeadScrew.hook and
 * LeadScrew.value (gtecat/controller/lead_screw.py) with the same operations in the same
 * order.  ls: 0 no table, 1 a table (off: the direction only), 2 on; the hook's last planned
 * position is the row's a_last, but in a homing row (its plan follows the drive after the
 * hook) ls_last (not a number: none yet). */

/* the direction the axis last moved in, after a cycle whose planned position is a */
INLINE int64_t ls_direction(int64_t dir, double a, double last)
{
    if (a != last)
        return a > last ? 1 : -1;
    return dir;
}

/* the table's value at pos in direction dir (not a number where pos is none: the command is
 * none then, and the row leaves before the cycle) */
INLINE double ls_value(void **ptr, int64_t r, double pos, int64_t dir)
{
    const int64_t n = I64(ls_ix)[2 * r + 1];
    const double *t = F64(ls_tab) + I64(ls_ix)[2 * r] + (dir >= 0 ? 0 : n);
    const double x = (pos - F64(ls_prm)[2 * r]) / F64(ls_prm)[2 * r + 1];
    int64_t k;
    double f;
    if (x <= 0.0)
        return t[0];
    if (x >= (double)(n - 1))
        return t[n - 1];
    if (x != x)
        return x;
    k = (int64_t)x;
    f = x - (double)k;
    return t[k] + f * (t[k + 1] - t[k]);
}

/* Axis.pre: 607Ah follows the planned position plus the compensation (dir: this cycle's) */
INLINE double ls_command(void **ptr, int64_t r, double a, int64_t dir)
{
    return U8(ls)[r] == 2 ? a + ls_value(ptr, r, a, dir) : a;
}

/* the commit of row r's direction (before a_last takes the cycle's planned position); a
 * homing row's hook saw the planned position of the cycle before */
INLINE void ls_commit(void **ptr, int64_t r, int homing)
{
    if (!U8(ls)[r])
        return;
    if (homing) {
        const double p = F64(a_last)[r], last = F64(ls_last)[r];
        if (last == last)
            I64(ls_dir)[r] = ls_direction(I64(ls_dir)[r], p, last);
        F64(ls_last)[r] = p;
    } else {
        I64(ls_dir)[r] = ls_direction(I64(ls_dir)[r], F64(s_a)[r], F64(a_last)[r]);
    }
}

#define COPY(dst, src, type) memcpy(ptr[F_##dst], ptr[F_##src], (size_t)n * sizeof(type))

/* the commit of a cycle in which every row stepped in CSP (none left out, frozen or homing):
 * the same values as the row-by-row commit, copied array by array */
INLINE void commit_all(void **ptr, int64_t n, int64_t n_jog, int any_ls)
{
    int64_t r;
    if (n_jog)
        for (r = 0; r < n; r++)
            if (U8(jog)[r]) {
                F64(jrp)[r] = F64(s_jog)[5 * r + 0];
                F64(jrv)[r] = F64(s_jog)[5 * r + 1];
                F64(jp)[r] = F64(s_jog)[5 * r + 2];
                F64(jv)[r] = F64(s_jog)[5 * r + 3];
                F64(ja)[r] = F64(s_jog)[5 * r + 4];
            }
    COPY(c_pos, s_pos, double);
    COPY(c_vel, s_vel, double);
    COPY(c_acc, s_acc, double);
    COPY(c_dpos, s_dpos, double);
    COPY(c_dvel, s_dvel, double);
    COPY(c_fe_time, s_fe, double);
    COPY(c_limited, s_lim, uint8_t);
    COPY(c_sw_limited, s_swl, uint8_t);
    COPY(c_lstop, s_lstop, uint8_t);
    COPY(c_target, s_target, int64_t);
    COPY(c_din, s_din, int64_t);
    for (r = 0; any_ls && r < n; r++)
        ls_commit(ptr, r, 0);
    COPY(a_last, s_a, double);
    COPY(enc_prev, s_raw, int64_t);
    COPY(enc_pos, s_enc, double);
    COPY(enc_step0, enc_step1, double);
    COPY(enc_step1, s_step, double);
    COPY(since, s_since, int64_t);
    COPY(arrived, s_arr, uint8_t);
}

/* the table cursors of every row after commit_all; 1 when a Trap move ended */
INLINE int commit_cursors(void **ptr, int64_t n)
{
    int64_t r;
    int fin_any = 0;
    int64_t *t_idx = I64(t_idx), *t_cur = I64(t_cur), *taken = I64(taken);
    const int64_t *base = I64(base), *t_end = I64(t_end);
    uint8_t *moving = U8(moving), *ended = U8(ended);
    for (r = 0; r < n; r++) {
        const int64_t cur = t_cur[r];
        const int mv = moving[r];
        t_idx[r] = base[r] + cur;
        taken[r] += mv;
        if (mv) {
            if (cur == t_end[r]) {
                ended[r] = 1;
                moving[r] = 0;
                fin_any = 1;
            } else {
                t_cur[r] = cur + 1;
            }
        }
    }
    return fin_any;
}

/* 8. the image: 607Ah out, the drives' TxPDO in (the committed values of every placement of a
 * claimed row; a frozen row's TxPDO keeps what its scalar objects wrote, its 607Ah is written
 * as the scalar axis writes it every cycle, over a raw write since) */
INLINE void write_image(void **ptr, const int64_t *io)
{
    uint8_t *buf = U8(buf);
    const uint8_t *alive = U8(alive), *frz = U8(frz);
    int64_t i;
    for (i = 0; i < io[IN_N_PLC]; i++) {
        int64_t row = I64(pl_row)[i], val;
        uint32_t u;
        if (!alive[row] || (frz[row] && I64(pl_col)[i] != 0))
            continue;
        switch (I64(pl_col)[i]) {
        case 0: val = I64(c_target)[row]; break;
        case 1: val = to_i64(rint(F64(c_pos)[row] - (double)I64(c_off)[row])); break;
        case 2: val = I64(c_din)[row]; break;
        case 3:
            val = I64(c_sw_const)[row] +
                  ((U8(c_limited)[row] | U8(c_sw_limited)[row] | U8(c_lstop)[row]) ? 0x800 : 0);
            if (U8(c_lstop)[row]) /* _refresh_status: no SW12, the warning bit */
                val += 0x80 - 0x1000;
            break;
        case 4: val = to_i64(rint(F64(c_dpos)[row] - (double)I64(c_off)[row])); break;
        case 5: val = to_i64(rint(F64(c_vel)[row])); break;
        case 6: val = to_i64(rint(F64(c_dpos)[row] - F64(c_pos)[row])); break;
        default:
            val = clip16(F64(c_acc)[row] / F64(c_a_rated)[row] * 1000.0 +
                         F64(c_vel)[row] * F64(c_visc)[row]);
        }
        u = (uint32_t)(uint64_t)val;
        {
            int64_t k, off = I64(pl_off)[i], size = I64(pl_size)[i];
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
            if (size == 4) { /* the PDO's little-endian bytes are the value's own */
                memcpy(buf + off, &u, 4);
                continue;
            }
            if (size == 2) {
                uint16_t u16 = (uint16_t)u;
                memcpy(buf + off, &u16, 2);
                continue;
            }
#endif
            for (k = 0; k < size; k++)
                buf[off + k] = (uint8_t)(u >> (8 * k));
        }
    }
}

/* Channel._limit_switches of a CSP row: din is 60FDh as the drive read it at the start of the
 * cycle (the last one's value), p0 and v0 the motor's position and speed then, *demand and
 * *dvel step_csp's.  0: no reaction; 1: braked (*demand, *dvel the drive's, limit_stop);
 * -1: the drive would raise a fault (the row leaves first). */
INLINE int limit_reaction(int64_t din, int64_t react, double p0, double v0, double dt,
                          double qsd, double *demand, double *dvel)
{
    int into_pos, into_neg;
    double step, v;
    if (!(din & 3) || !react)
        return 0;
    into_pos = (din & 2) && (*demand > p0 || v0 > 0.0);
    into_neg = (din & 1) && (*demand < p0 || v0 < 0.0);
    if (!(into_pos || into_neg))
        return 0;
    if (react == 2)
        return -1;
    step = qsd * dt;
    v = v0;
    if (into_pos)
        v = v > step ? v - step : (0.0 < v ? 0.0 : v); /* min(v, 0.0) */
    else
        v = v < -step ? v + step : (0.0 > v ? 0.0 : v); /* max(v, 0.0) */
    *dvel = v;
    *demand = p0 + v * dt;
    return 1;
}

/* a limit switch active after the cycle (din) sends the row back first unless it was active
 * before it too (c_din) and its flag is latched (lvel bit 0 the positive side, 1 the
 * negative): nothing new for the controller (its flag, AxisResources._post) nor for a hook */
INLINE int limit_leaves(int64_t din, int64_t before, int lvel)
{
    const int64_t on = din & 3;
    if (!on)
        return 0;
    if (on & ~before)
        return 1;
    return ((on & 2) && !(lvel & 1)) || ((on & 1) && !(lvel & 2));
}

/* a homing row on a limit switch (the drive ignores its limit inputs in homing mode; the
 * search met the switch as an event) stays while the flag of each switch it is on is latched
 * (lvel: AxisResources._post latches nothing new) */
INLINE int hm_limit_leaves(int64_t din, int lvel)
{
    return ((din & 2) && !(lvel & 1)) || ((din & 1) && !(lvel & 2));
}

/* inlined where the field table is a local copy: the compiler then knows no store through a
 * row's arrays changes it, and keeps the arrays' addresses instead of reloading them */
INLINE int cycle_once(void **ptr, int64_t *io, const double *fp, uint8_t *go, int check_rx,
                      int post)
{
    const int64_t n = io[IN_N], t_ns = io[IN_T_NS];
    const double dt = fp[FP_DT], h = fp[FP_T];
    const double half_per_dt = 0.5 / dt;
    const uint8_t *alive = U8(alive);
    uint8_t *buf = U8(buf);
    int64_t r, i, n_csp = 0, n_jog = 0;
    int fin_any = 0, any_hit = 0, any_ls = 0;
    const uint8_t *hm = U8(hm);
    uint8_t *s_hit = U8(s_hit);
    uint8_t *s_evt = U8(s_evt);

    /* 1. a raw write to a claimed slave's outputs: the numpy cycle hands it back (looked at
     * in the first cycle of a call: nothing else writes them until it returns, the cycle
     * itself writes no such byte); rx_row: the row whose slave owns the byte */
    for (i = 0; check_rx && i < io[IN_N_RX]; i++)
        if (buf[I64(rx_idx)[i]] != U8(rx_ref)[i] && alive[I64(rx_row)[i]])
            return 1;

    /* 2.-7. every claimed row, tentatively (scratch arrays s_*), in three passes over the
     * rows (the profile and the demand; the mechanics; the feedback and the checks): each
     * pass's rows are independent and short, so the processor overlaps several rows' chains
     * of divisions instead of waiting on one long chain per row.  Per row the operations
     * and their order are those of one pass. */
    for (r = 0; r < n; r++) {
        int64_t cur, counts, x, target;
        double prf, a, demand, dvel;
        int swl = 0, hit = 0, ended, lstop = 0;
        go[r] = 0;
        s_hit[r] = 0;
        s_evt[r] = 0;
        if (!alive[r] || U8(frz)[r]) /* a frozen row: nothing of its cycle changes */
            continue;
        if (hm[r]) {
            if (homing_row(ptr, r, dt, &demand, &dvel)) {
                s_hit[r] = 1;
                any_hit = 1;
                continue;
            }
            /* Axis.pre: 607Ah follows 6064h (the value in the image since the last cycle) */
            target = (int32_t)(uint32_t)(uint64_t)to_i64(rint(F64(c_pos)[r] - (double)I64(c_off)[r]));
            swl = U8(c_sw_limited)[r]; /* step_csp does not run: 6041h bit 11 keeps its cause */
            a = 0.0;  /* from 6064h below */
            ended = 1;
        } else {
            cur = I64(t_cur)[r];
            if (U8(moving)[r] && cur >= I64(t_len)[r]) { /* the table is used up: the next one */
                if (refill_row(ptr, io, r))
                    return 4; /* nothing written: the caller refills it */
                cur = 0;
            }
            prf = F64(t_p)[I64(base)[r] + cur];
            ended = cur == I64(t_end)[r];
            if (U8(lvel)[r]) { /* toward a latched limit: AxisResources._post stops it */
                const double v = F64(prf_ratio)[r] * F64(t_v)[I64(base)[r] + cur];
                if (((U8(lvel)[r] & 1) && v > 0.0) || ((U8(lvel)[r] & 2) && v < 0.0)) {
                    s_hit[r] = 1;
                    any_hit = 1;
                    continue;
                }
            }
            if (U8(jog)[r] && F64(jrv)[r] != F64(jgoal)[r]) { /* a ramp: jog.ramp_step */
                double *o = F64(s_jog) + 5 * r;
                jog_ramp(F64(jrp)[r], F64(jrv)[r], F64(jgoal)[r], F64(jacc)[r], F64(jdec)[r], h,
                         F64(tau)[r], F64(jp)[r], F64(jv)[r], F64(ja)[r], o);
                prf = o[2];
            } else if (U8(jog)[r]) { /* AxisBank._jog_step */
                double rp = F64(jrp)[r], jv = F64(jrv)[r], fp_ = F64(jp)[r], fv = F64(jv)[r];
                double fa = F64(ja)[r], tau = F64(tau)[r], e = F64(jE)[r];
                double p1 = rp + h * (jv + 0.5 * 0.0 * h);
                double v1 = jv + 0.0 * h;
                double nfp, nfv, nfa;
                if (tau > 0.0) {
                    nfp = p1 - tau * (v1 - 0.0) + (fp_ - rp + tau * (jv - 0.0)) * e;
                    nfv = v1 - 0.0 + (fv - jv + 0.0) * e;
                    nfa = 0.0 + (fa - 0.0) * e;
                } else {
                    nfp = p1;
                    nfv = v1;
                    nfa = 0.0;
                }
                if (nfv != v1 && fabs(nfv - v1) <= 1e-9 * (1.0 + fabs(v1))) {
                    nfv = v1;
                    nfa = 0.0;
                }
                F64(s_jog)[5 * r + 0] = p1;
                F64(s_jog)[5 * r + 1] = v1;
                F64(s_jog)[5 * r + 2] = nfp;
                F64(s_jog)[5 * r + 3] = nfv;
                F64(s_jog)[5 * r + 4] = nfa;
                prf = nfp;
            }
            a = link(prf, F64(prf_ratio)[r], F64(prf_off)[r]);
            /* 3. 607Ah: Axis.pulses_to_counts, int32 like the PDO entry */
            {
                double cmd = a;
                if (U8(ls)[r]) { /* a lead screw's compensation (ls_command) */
                    any_ls = 1;
                    cmd = ls_command(ptr, r, a, ls_direction(I64(ls_dir)[r], a, F64(a_last)[r]));
                }
                double scaled = cmd * F64(unit2)[r];
                if (!(fabs(scaled) < 4611686018427387904.0)) /* 2**62, bank.HUGE_COUNTS */
                    hit = 1;
                counts = to_i64(rint(scaled)) + I64(drive_offset)[r];
            }
            if (hit) { /* it leaves: the scalar path's exact integers (bank.HUGE_COUNTS) */
                s_hit[r] = 1;
                any_hit = 1;
                continue;
            }
            target = (int32_t)(uint32_t)(uint64_t)counts;
            /* CspBank.step: step_csp */
            x = target + I64(c_pos_offset)[r];
            if (x < I64(c_sw_min)[r] || x > I64(c_sw_max)[r])
                swl = 1;
            if (x < I64(c_sw_min)[r])
                x = I64(c_sw_min)[r];
            if (x > I64(c_sw_max)[r])
                x = I64(c_sw_max)[r];
            x += I64(c_off)[r];
            demand = (double)x;
            dvel = (demand - F64(c_dpos)[r]) / dt;
            lstop = limit_reaction(I64(c_din)[r], I64(c_lreact)[r], F64(c_pos)[r],
                                   F64(c_vel)[r], dt, F64(c_qsd)[r], &demand, &dvel);
            if (lstop < 0) { /* the drive's fault reaction: the scalar path */
                s_hit[r] = 1;
                any_hit = 1;
                continue;
            }
        }
        U8(s_lstop)[r] = (uint8_t)lstop;
        go[r] = (uint8_t)(1 + ended);
        n_csp += !hm[r];
        n_jog += U8(jog)[r];
        I64(s_target)[r] = target;
        F64(s_a)[r] = a;
        F64(s_dpos)[r] = demand;
        F64(s_dvel)[r] = dvel;
        U8(s_swl)[r] = (uint8_t)swl;
    }

    /* Mechanics.track */
    for (r = 0; r < n; r++) {
        double demand, dvel, p, v0, vmax, vff, e1, v, lim, dist, rel, vstop, dv;
        int limited = 0;
        if (!go[r])
            continue;
        demand = F64(s_dpos)[r];
        dvel = F64(s_dvel)[r];
        p = F64(c_pos)[r];
        v0 = F64(c_vel)[r];
        vmax = F64(c_vmax)[r];
        vff = dvel;
        if (vff < -vmax)
            vff = -vmax;
        if (vff > vmax)
            vff = vmax;
        e1 = (demand - vff * dt - p) * F64(c_e)[r] + F64(c_c)[r] * vff;
        v = (demand - e1 - p) / dt;
        lim = F64(c_lim)[r];
        dist = demand - p;
        rel = dist - vff * dt;
        /* the closing-speed cap (CspBank.step's shortcut, per row): vstop >= min(|rel|/dt,
         * lim), so a row within half of that of vff cannot be capped */
        vstop = fabs(rel) * half_per_dt;
        if (vstop > 0.5 * lim)
            vstop = 0.5 * lim;
        if (fabs(v - vff) > vstop) {
            vstop = closing_speed(fabs(rel), lim, dt);
            if (rel > 0.0 && v > vff + vstop) {
                v = vff + vstop;
                limited = 1;
            } else if (rel < 0.0 && v < vff - vstop) {
                v = vff - vstop;
                limited = 1;
            }
        }
        dv = v - v0;
        if (dv > lim) {
            v = v0 + lim;
            limited = 1;
        } else if (dv < -lim) {
            v = v0 - lim;
            limited = 1;
        }
        if (limited) {
            if (rel > 0.0 && dist > 0.0 && v * dt > dist)
                v = dist / dt;
            else if (rel < 0.0 && dist < 0.0 && v * dt < dist)
                v = dist / dt;
        }
        if (v > vmax) {
            v = vmax;
            limited = 1;
        } else if (v < -vmax) {
            v = -vmax;
            limited = 1;
        }
        F64(s_acc)[r] = (v - v0) / dt;
        F64(s_pos)[r] = p + v * dt;
        F64(s_vel)[r] = v;
        U8(s_lim)[r] = (uint8_t)limited;
    }

    /* the feedback (6064h, 60FDh, the encoder), the checks and the in-position band */
    for (r = 0; r < n; r++) {
        int64_t target, raw, pa, din, since;
        int32_t d32;
        double a, demand, pos, fe, step, enc, err, band;
        int hit = 0, ended, standing, inb, arr;
        if (!go[r])
            continue;
        ended = go[r] == 2;
        target = I64(s_target)[r];
        a = F64(s_a)[r];
        demand = F64(s_dpos)[r];
        pos = F64(s_pos)[r];
        /* following-error window 6065h/6066h */
        fe = 0.0;
        if (U8(s_lstop)[r]) /* no following-error check while the limit brakes it */
            fe = F64(c_fe_time)[r];
        else if (U8(c_fe_check)[r]) {
            if (fabs(demand - pos) > F64(c_fe_window)[r]) {
                fe = F64(c_fe_time)[r] + dt;
                if (fe * 1000.0 > F64(c_fe_timeout)[r])
                    hit = 1;
            }
        }
        /* 6064h and 60FDh (limit switches, home switch, probes) */
        pa = to_i64(rint(pos - (double)I64(c_off)[r]));
        din = 2 * (pos >= F64(c_pl)[r]) + (pos <= F64(c_nl)[r]);
        if (io[IN_W2] && in_window(F64(w2_lo), F64(w2_hi), io[IN_W2], r, pos))
            din |= 1 << 2;
        if (io[IN_W16] && in_window(F64(w16_lo), F64(w16_hi), io[IN_W16], r, pos))
            din |= 1 << 16;
        if (io[IN_W17] && in_window(F64(w17_lo), F64(w17_hi), io[IN_W17], r, pos))
            din |= 1 << 17;
        if ((din ^ I64(c_din)[r]) & I64(dwatch)[r]) /* an input a hook samples changes */
            hit = 1;
        else if ((din ^ I64(c_din)[r]) & I64(dpost)[r]) {
            if (post)
                s_evt[r] = 1; /* its hook takes it after the cycle (the caller reads s_evt) */
            else
                hit = 1; /* (a run of many cycles ends before it) */
        }
        if (U8(c_tpw)[r] && pos != F64(c_pos)[r] && !tp_inside(ptr, r, F64(c_pos)[r], pos)) {
            /* the travel reaches an edge the touch probe latches: the drive's probe takes it
             * after the cycle where dpost says so (TP_POST), else the row leaves first */
            if (post && (I64(dpost)[r] & TP_POST))
                s_evt[r] = 1;
            else
                hit = 1;
        }
        F64(s_p0)[r] = F64(c_pos)[r]; /* (the travel's start, for the caller's probe) */
        if (hm[r]) /* AxisResources._post of an axis not in CSP: the plan follows 6064h */
            a = (double)((int64_t)(int32_t)(uint32_t)(uint64_t)pa - I64(drive_offset)[r]) /
                F64(unit2)[r];
        /* 4. encoder (Encoder.sample) */
        raw = U8(external)[r] ? pa : target;
        d32 = (int32_t)(uint32_t)(uint64_t)(raw - I64(enc_prev)[r]);
        step = (double)(I64(sense)[r] * (int64_t)d32) * F64(unit)[r];
        enc = F64(enc_pos)[r] + step;
        /* 5. limits and following error */
        err = a - link(enc, F64(enc_ratio)[r], F64(enc_off)[r]);
        if (a > F64(soft_pos)[r] || a < F64(soft_neg)[r])
            hit = 1;
        if (hm[r] ? hm_limit_leaves(din, U8(lvel)[r]) : limit_leaves(din, I64(c_din)[r], U8(lvel)[r]))
            hit = 1;
        if (fabs(err) > F64(pos_err)[r] && !hm[r]) /* the following error: in CSP only */
            hit = 1;
        if (hit) {
            s_hit[r] = 1;
            any_hit = 1;
            continue;
        }
        /* 6. the in-position band (bit 11) */
        band = F64(band)[r];
        since = I64(since)[r];
        arr = U8(arrived)[r];
        if (band > 0.0) {
            standing = (ended || !U8(moving)[r]) && !U8(jog)[r];
            inb = standing && -band <= err && err <= band;
            since = inb ? (since < 0 ? t_ns : since) : -1;
            arr = inb && (arr || t_ns - since >= I64(hold_ns)[r]);
        }
        I64(s_raw)[r] = raw;
        F64(s_a)[r] = a;
        F64(s_enc)[r] = enc;
        F64(s_step)[r] = step;
        F64(s_fe)[r] = fe;
        I64(s_din)[r] = din;
        I64(s_since)[r] = since;
        U8(s_arr)[r] = (uint8_t)arr;
    }
    if (any_hit)
        return 3; /* nothing written: the caller releases the rows in s_hit first */

    /* commit (CspBank.commit, the bank's state, the table cursors) */
    if (n_csp == n) {
        commit_all(ptr, n, n_jog, any_ls);
        fin_any = commit_cursors(ptr, n);
        goto image;
    }
    for (r = 0; r < n; r++) {
        int64_t cur;
        int mv, en;
        if (!alive[r]) {
            I64(c_start)[r] += 1; /* a row left out did not step */
            continue;
        }
        if (U8(frz)[r])
            continue;
        if (U8(jog)[r]) {
            F64(jrp)[r] = F64(s_jog)[5 * r + 0];
            F64(jrv)[r] = F64(s_jog)[5 * r + 1];
            F64(jp)[r] = F64(s_jog)[5 * r + 2];
            F64(jv)[r] = F64(s_jog)[5 * r + 3];
            F64(ja)[r] = F64(s_jog)[5 * r + 4];
        }
        F64(c_pos)[r] = F64(s_pos)[r];
        F64(c_vel)[r] = F64(s_vel)[r];
        F64(c_acc)[r] = F64(s_acc)[r];
        F64(c_dpos)[r] = F64(s_dpos)[r];
        F64(c_dvel)[r] = F64(s_dvel)[r];
        F64(c_fe_time)[r] = F64(s_fe)[r];
        U8(c_limited)[r] = U8(s_lim)[r];
        U8(c_sw_limited)[r] = U8(s_swl)[r];
        U8(c_lstop)[r] = U8(s_lstop)[r];
        I64(c_target)[r] = I64(s_target)[r];
        I64(c_din)[r] = I64(s_din)[r];
        ls_commit(ptr, r, hm[r]);
        F64(a_last)[r] = F64(s_a)[r];
        cur = I64(t_cur)[r];
        I64(t_idx)[r] = I64(base)[r] + cur;
        I64(enc_prev)[r] = I64(s_raw)[r];
        F64(enc_pos)[r] = F64(s_enc)[r];
        F64(enc_step0)[r] = F64(enc_step1)[r];
        F64(enc_step1)[r] = F64(s_step)[r];
        I64(since)[r] = I64(s_since)[r];
        U8(arrived)[r] = U8(s_arr)[r];
        if (hm[r]) {
            const double *sh = F64(s_hm) + 7 * r;
            F64(h_last)[r] = sh[0];
            F64(h_el)[r] = sh[1];
            F64(h_tr)[r] = sh[2];
            F64(h_v)[r] = sh[3];
            F64(h_p)[r] = sh[4];
            F64(h_rest)[r] = sh[5];
            U8(h_set)[r] = sh[6] != 0.0;
            continue;
        }
        mv = U8(moving)[r];
        en = cur == I64(t_end)[r];
        I64(taken)[r] += mv;
        if (mv && en) {
            U8(ended)[r] = 1;
            U8(moving)[r] = 0;
            fin_any = 1;
        } else if (mv) {
            I64(t_cur)[r] = cur + 1;
        }
    }

    /* 8. the image: 607Ah out, the drives' TxPDO in */
image:
    write_image(ptr, io);
    io[OUT_FIN] = fin_any;
    return 0;
}

/* Many cycles row by row (bank_kernel_run when every stepping row is in CSP).  The rows of
 * such a bank do not read each other: a row's cycles are its own chain, the same operations
 * in the same order as in cycle_once's three passes and its commit, whichever row runs
 * first.  So each row runs all the cycles of the call at once with its state in locals, and
 * the call commits the cycles every row could run: a row stops before a cycle it declines
 * (cycle_once would decline that cycle for the whole bank) and after the cycle that ends its
 * Trap move (the run stops there).  A row that ran further than the shortest one is put back
 * (its table as it was) and runs again to that length. */
typedef struct {
    double pos, vel, acc, dpos, dvel, fe_time, a, enc_pos, step0, step1;
    double jrp, jrv, jp, jv, ja;
    int64_t target, din, enc_prev, since, cur, t_idx, taken, t_len, t_end;
    int64_t ls_dir;
    int64_t len; /* the cycles run */
    int code;    /* 0, or why the next cycle is declined */
    uint8_t lim, swl, arrived, moving, ended, fin, refilled, lstop;
} RowRun;

INLINE void row_store(void **ptr, int64_t r, const RowRun *s)
{
    F64(c_pos)[r] = s->pos;
    F64(c_vel)[r] = s->vel;
    F64(c_acc)[r] = s->acc;
    F64(c_dpos)[r] = s->dpos;
    F64(c_dvel)[r] = s->dvel;
    F64(c_fe_time)[r] = s->fe_time;
    F64(a_last)[r] = s->a;
    F64(enc_pos)[r] = s->enc_pos;
    F64(enc_step0)[r] = s->step0;
    F64(enc_step1)[r] = s->step1;
    F64(jrp)[r] = s->jrp;
    F64(jrv)[r] = s->jrv;
    F64(jp)[r] = s->jp;
    F64(jv)[r] = s->jv;
    F64(ja)[r] = s->ja;
    I64(c_target)[r] = s->target;
    I64(c_din)[r] = s->din;
    I64(enc_prev)[r] = s->enc_prev;
    I64(since)[r] = s->since;
    I64(t_cur)[r] = s->cur;
    I64(t_idx)[r] = s->t_idx;
    I64(taken)[r] = s->taken;
    I64(t_len)[r] = s->t_len;
    I64(t_end)[r] = s->t_end;
    I64(ls_dir)[r] = s->ls_dir;
    U8(c_limited)[r] = s->lim;
    U8(c_sw_limited)[r] = s->swl;
    U8(c_lstop)[r] = s->lstop;
    U8(arrived)[r] = s->arrived;
    U8(moving)[r] = s->moving;
    U8(ended)[r] = s->ended;
}

/* Row r's cycles from the state in s, at most `limit` of them (see RowRun).  Before its first
 * refill the row's table (TABLE + 1 samples of position, speed, acceleration) is kept in bk. */
INLINE void row_cycles_t(void **ptr, const int64_t *io, const double *fp, int64_t r, RowRun *s,
                         int64_t limit, double *bk, const int plain)
{
    const double dt = fp[FP_DT], h = fp[FP_T];
    const double half_per_dt = 0.5 / dt;
    const int64_t t0 = io[IN_T_NS], dt_ns = io[IN_DT_NS], table = io[IN_TABLE];
    const int64_t base = I64(base)[r];
    double *const tp = F64(t_p), *const tv = F64(t_v), *const ta = F64(t_a);
    const int jog = plain ? 0 : U8(jog)[r];
    const double tau = F64(tau)[r], e = F64(jE)[r];
    const double prf_ratio = F64(prf_ratio)[r], prf_off = F64(prf_off)[r], unit2 = F64(unit2)[r];
    const int64_t drive_offset = I64(drive_offset)[r], pos_offset = I64(c_pos_offset)[r];
    const int64_t sw_min = I64(c_sw_min)[r], sw_max = I64(c_sw_max)[r], off = I64(c_off)[r];
    const double vmax = F64(c_vmax)[r], ce = F64(c_e)[r], cc = F64(c_c)[r], lim = F64(c_lim)[r];
    const int fe_check = U8(c_fe_check)[r];
    const double fe_window = F64(c_fe_window)[r], fe_timeout = F64(c_fe_timeout)[r];
    const double pl = F64(c_pl)[r], nl = F64(c_nl)[r];
    const int external = U8(external)[r];
    const int64_t sense = I64(sense)[r];
    const double unit = F64(unit)[r], enc_ratio = F64(enc_ratio)[r], enc_off = F64(enc_off)[r];
    const double soft_pos = F64(soft_pos)[r], soft_neg = F64(soft_neg)[r];
    const double pos_err = F64(pos_err)[r], band = plain ? 0.0 : F64(band)[r];
    const int64_t hold_ns = I64(hold_ns)[r];
    const int64_t w2 = plain ? 0 : io[IN_W2], w16 = plain ? 0 : io[IN_W16];
    const int64_t w17 = plain ? 0 : io[IN_W17];
    /* (an input a hook takes after the cycle ends a run before that cycle, as the others) */
    const int64_t dwatch = I64(dwatch)[r] | I64(dpost)[r];
    const int lvel = U8(lvel)[r];
    const int tpw = plain ? 0 : U8(c_tpw)[r];
    const int ls = plain ? 0 : U8(ls)[r]; /* (a row with a lead screw is not plain) */
    int64_t q_ls_dir = I64(ls_dir)[r];
    /* the row's state in locals (from the committed arrays: a row run again starts there) */
    double q_pos = F64(c_pos)[r], q_vel = F64(c_vel)[r], q_acc = F64(c_acc)[r],
        q_dpos = F64(c_dpos)[r], q_dvel = F64(c_dvel)[r], q_fe_time = F64(c_fe_time)[r],
        q_a = F64(a_last)[r], q_enc_pos = F64(enc_pos)[r], q_step0 = F64(enc_step0)[r],
        q_step1 = F64(enc_step1)[r], q_jrp = F64(jrp)[r], q_jrv = F64(jrv)[r], q_jp = F64(jp)[r],
        q_jv = F64(jv)[r], q_ja = F64(ja)[r];
    int64_t q_target = I64(c_target)[r], q_din = I64(c_din)[r], q_enc_prev = I64(enc_prev)[r],
        q_since = I64(since)[r], q_cur = I64(t_cur)[r], q_t_idx = I64(t_idx)[r],
        q_taken = I64(taken)[r], q_t_len = I64(t_len)[r], q_t_end = I64(t_end)[r];
    const int64_t lreact = I64(c_lreact)[r];
    const double qsd = F64(c_qsd)[r];
    uint8_t q_lstop = U8(c_lstop)[r];
    uint8_t q_lim = U8(c_limited)[r], q_swl = U8(c_sw_limited)[r], q_arrived = U8(arrived)[r],
        q_moving = U8(moving)[r], q_ended = U8(ended)[r], q_fin = 0, q_refilled = 0;
    int q_code = 0;
    int64_t c;
    for (c = 0; c < limit; c++) {
        const int64_t t_ns = t0 + c * dt_ns;
        int64_t cur = q_cur, counts, x, target, pa, din, raw, since, ls_dir = q_ls_dir;
        int32_t d32;
        double prf, a, demand, dvel, p1 = 0.0, v1 = 0.0, nfp = 0.0, nfv = 0.0, nfa = 0.0;
        double p, v0, vff, e1, v, dist, rel, vstop, dv, pos, fe, step, enc, err;
        int swl = 0, ended, limited = 0, arr, lstop;
        /* pass 1: the profile and the demand */
        if (q_moving && cur >= q_t_len) { /* the table is used up: the next one (refill_row) */
            const int64_t m = I64(nseg)[r];
            int64_t end;
            if (m <= 0) {
                q_code = 4;
                break;
            }
            if (!q_refilled) {
                memcpy(bk, tp + base, (size_t)(table + 1) * sizeof(double));
                memcpy(bk + table + 1, tv + base, (size_t)(table + 1) * sizeof(double));
                memcpy(bk + 2 * (table + 1), ta + base, (size_t)(table + 1) * sizeof(double));
                q_refilled = 1;
            }
            tp[base + table] = tp[q_t_idx];
            tv[base + table] = tv[q_t_idx];
            ta[base + table] = ta[q_t_idx];
            q_t_idx = base + table;
            end = bank_trap_fill(F64(seg) + 4 * MAXSEG * r, m, F64(tprm)[NTPRM * r + 5],
                                 F64(tprm) + NTPRM * r, I64(k0)[r] + q_taken, table, tp + base,
                                 tv + base, ta + base);
            q_t_len = end < table ? end + 1 : table;
            q_t_end = end < table ? end : -1;
            q_cur = cur = 0;
        }
        prf = tp[base + cur];
        ended = cur == q_t_end;
        if (lvel) { /* toward a latched limit: AxisResources._post stops it */
            const double vl = prf_ratio * tv[base + cur];
            if (((lvel & 1) && vl > 0.0) || ((lvel & 2) && vl < 0.0)) {
                q_code = 2;
                break;
            }
        }
        if (jog) { /* AxisBank._jog_step */
            const double rp = q_jrp, jv = q_jrv, fp_ = q_jp, fv = q_jv, fa = q_ja;
            p1 = rp + h * (jv + 0.5 * 0.0 * h);
            v1 = jv + 0.0 * h;
            if (tau > 0.0) {
                nfp = p1 - tau * (v1 - 0.0) + (fp_ - rp + tau * (jv - 0.0)) * e;
                nfv = v1 - 0.0 + (fv - jv + 0.0) * e;
                nfa = 0.0 + (fa - 0.0) * e;
            } else {
                nfp = p1;
                nfv = v1;
                nfa = 0.0;
            }
            if (nfv != v1 && fabs(nfv - v1) <= 1e-9 * (1.0 + fabs(v1))) {
                nfv = v1;
                nfa = 0.0;
            }
            prf = nfp;
        }
        a = plain ? prf : link(prf, prf_ratio, prf_off);
        {
            double scaled = a;
            if (ls) {
                ls_dir = ls_direction(q_ls_dir, a, q_a);
                scaled = ls_command(ptr, r, a, ls_dir);
            }
            scaled *= unit2;
            if (!(fabs(scaled) < 4611686018427387904.0)) { /* 2**62, bank.HUGE_COUNTS */
                q_code = 2;
                break;
            }
            counts = to_i64(rint(scaled)) + drive_offset;
        }
        target = (int32_t)(uint32_t)(uint64_t)counts;
        x = target + pos_offset;
        if (x < sw_min || x > sw_max)
            swl = 1;
        if (x < sw_min)
            x = sw_min;
        if (x > sw_max)
            x = sw_max;
        x += off;
        demand = (double)x;
        dvel = (demand - q_dpos) / dt;
        lstop = limit_reaction(q_din, lreact, q_pos, q_vel, dt, qsd, &demand, &dvel);
        if (lstop < 0) { /* the drive's fault reaction: the scalar path */
            q_code = 2;
            break;
        }
        /* pass 2: Mechanics.track */
        p = q_pos;
        v0 = q_vel;
        vff = dvel;
        if (vff < -vmax)
            vff = -vmax;
        if (vff > vmax)
            vff = vmax;
        e1 = (demand - vff * dt - p) * ce + cc * vff;
        v = (demand - e1 - p) / dt;
        dist = demand - p;
        rel = dist - vff * dt;
        vstop = fabs(rel) * half_per_dt;
        if (vstop > 0.5 * lim)
            vstop = 0.5 * lim;
        if (fabs(v - vff) > vstop) {
            vstop = closing_speed(fabs(rel), lim, dt);
            if (rel > 0.0 && v > vff + vstop) {
                v = vff + vstop;
                limited = 1;
            } else if (rel < 0.0 && v < vff - vstop) {
                v = vff - vstop;
                limited = 1;
            }
        }
        dv = v - v0;
        if (dv > lim) {
            v = v0 + lim;
            limited = 1;
        } else if (dv < -lim) {
            v = v0 - lim;
            limited = 1;
        }
        if (limited) {
            if (rel > 0.0 && dist > 0.0 && v * dt > dist)
                v = dist / dt;
            else if (rel < 0.0 && dist < 0.0 && v * dt < dist)
                v = dist / dt;
        }
        if (v > vmax) {
            v = vmax;
            limited = 1;
        } else if (v < -vmax) {
            v = -vmax;
            limited = 1;
        }
        pos = p + v * dt;
        /* pass 3: the feedback, the checks and the in-position band */
        {
            /* without a branch on the window: a following error near it comes and goes
             * from cycle to cycle, which no branch predictor follows */
            const int out = (lstop == 0) & fe_check & (fabs(demand - pos) > fe_window);
            const double fe_in = q_fe_time + dt;
            fe = lstop ? q_fe_time : out ? fe_in : 0.0; /* (no check while the limit brakes) */
            if (out && fe * 1000.0 > fe_timeout) {
                q_code = 2;
                break;
            }
        }
        pa = to_i64(rint(pos - (double)off));
        din = 2 * (pos >= pl) + (pos <= nl);
        if (w2 && in_window(F64(w2_lo), F64(w2_hi), w2, r, pos))
            din |= 1 << 2;
        if (w16 && in_window(F64(w16_lo), F64(w16_hi), w16, r, pos))
            din |= 1 << 16;
        if (w17 && in_window(F64(w17_lo), F64(w17_hi), w17, r, pos))
            din |= 1 << 17;
        raw = external ? pa : target;
        d32 = (int32_t)(uint32_t)(uint64_t)(raw - q_enc_prev);
        step = (double)(sense * (int64_t)d32) * unit;
        enc = q_enc_pos + step;
        err = a - (plain ? enc : link(enc, enc_ratio, enc_off));
        if (a > soft_pos || limit_leaves(din, q_din, lvel) || a < soft_neg || fabs(err) > pos_err ||
            ((din ^ q_din) & dwatch) || (tpw && pos != p && !tp_inside(ptr, r, p, pos))) {
            q_code = 2;
            break;
        }
        since = q_since;
        arr = q_arrived;
        if (band > 0.0) {
            const int standing = (ended || !q_moving) && !jog;
            const int inb = standing && -band <= err && err <= band;
            since = inb ? (since < 0 ? t_ns : since) : -1;
            arr = inb && (arr || t_ns - since >= hold_ns);
        }
        /* the commit */
        if (jog) {
            q_jrp = p1;
            q_jrv = v1;
            q_jp = nfp;
            q_jv = nfv;
            q_ja = nfa;
        }
        q_pos = pos;
        q_vel = v;
        q_acc = (v - v0) / dt;
        q_dpos = demand;
        q_dvel = dvel;
        q_fe_time = fe;
        q_lim = (uint8_t)limited;
        q_swl = (uint8_t)swl;
        q_lstop = (uint8_t)lstop;
        q_target = target;
        q_din = din;
        q_a = a;
        q_ls_dir = ls_dir;
        q_t_idx = base + cur;
        q_enc_prev = raw;
        q_enc_pos = enc;
        q_step0 = q_step1;
        q_step1 = step;
        q_since = since;
        q_arrived = (uint8_t)arr;
        q_taken += q_moving;
        if (q_moving) {
            if (ended) {
                q_ended = 1;
                q_moving = 0;
                q_fin = 1;
                c++;
                break;
            }
            q_cur = cur + 1;
        }
    }
    s->len = c;
    s->code = q_code;
    s->pos = q_pos;
    s->vel = q_vel;
    s->acc = q_acc;
    s->dpos = q_dpos;
    s->dvel = q_dvel;
    s->fe_time = q_fe_time;
    s->a = q_a;
    s->enc_pos = q_enc_pos;
    s->step0 = q_step0;
    s->step1 = q_step1;
    s->jrp = q_jrp;
    s->jrv = q_jrv;
    s->jp = q_jp;
    s->jv = q_jv;
    s->ja = q_ja;
    s->target = q_target;
    s->din = q_din;
    s->enc_prev = q_enc_prev;
    s->since = q_since;
    s->cur = q_cur;
    s->t_idx = q_t_idx;
    s->taken = q_taken;
    s->t_len = q_t_len;
    s->t_end = q_t_end;
    s->ls_dir = q_ls_dir;
    s->lim = q_lim;
    s->swl = q_swl;
    s->lstop = q_lstop;
    s->arrived = q_arrived;
    s->moving = q_moving;
    s->ended = q_ended;
    s->fin = q_fin;
    s->refilled = q_refilled;
}

/* a row with none of the rarer parts (see row_plain): the same cycles with less to look at */
CLONES static void row_cycles_plain(void **ptr, const int64_t *io, const double *fp, int64_t r,
                                    RowRun *s, int64_t limit, double *bk)
{
    row_cycles_t(ptr, io, fp, r, s, limit, bk, 1);
}

CLONES static void row_cycles(void **ptr, const int64_t *io, const double *fp, int64_t r, RowRun *s,
                              int64_t limit, double *bk)
{
    row_cycles_t(ptr, io, fp, r, s, limit, bk, 0);
}

/* row r has none of the rarer parts row_cycles_plain leaves out: no Jog, no lead screw, no
 * touch probe armed, no switch windows
 * (home switch, probes), its plan and encoder in pulses as they are (links of ratio 1 and
 * offset 0) and no in-position band */
INLINE int row_plain(void **ptr, const int64_t *io, int64_t r)
{
    return !U8(jog)[r] && !U8(ls)[r] && !U8(c_tpw)[r] && !io[IN_W2] && !io[IN_W16] &&
           !io[IN_W17] && F64(prf_ratio)[r] == 1.0 && F64(prf_off)[r] == 0.0 &&
           F64(enc_ratio)[r] == 1.0 && F64(enc_off)[r] == 0.0 && !(F64(band)[r] > 0.0);
}

/* Row r back where it stood before row_cycles (its table refilled: the table kept in bk). */
INLINE void row_undo(void **ptr, const int64_t *io, int64_t r, RowRun *s, const double *bk)
{
    const int64_t table = io[IN_TABLE], base = I64(base)[r];
    if (s->refilled) {
        memcpy(F64(t_p) + base, bk, (size_t)(table + 1) * sizeof(double));
        memcpy(F64(t_v) + base, bk + table + 1, (size_t)(table + 1) * sizeof(double));
        memcpy(F64(t_a) + base, bk + 2 * (table + 1), (size_t)(table + 1) * sizeof(double));
    }
}

/* bank_kernel_run row by row (see RowRun); the cycles committed */
static int64_t run_rows(void **ptr, int64_t *io, const double *fp, RowRun *rs, double *bk,
                        int *rc)
{
    const int64_t n = io[IN_N], maxc = io[IN_MAXC], width = 3 * (io[IN_TABLE] + 1);
    const uint8_t *alive = U8(alive), *frz = U8(frz);
    int64_t r, lim = maxc, code_row = -1;
    int fin_any = 0, filled = 0;
    for (r = 0; r < n; r++) {
        if (!alive[r] || frz[r])
            continue;
        if (row_plain(ptr, io, r))
            row_cycles_plain(ptr, io, fp, r, rs + r, lim, bk + width * r);
        else
            row_cycles(ptr, io, fp, r, rs + r, lim, bk + width * r);
        if (rs[r].len < lim) /* it stops there (declines the next cycle, or its move ended) */
            lim = rs[r].len;
    }
    for (r = 0; r < n; r++) {
        RowRun *s = rs + r;
        if (!alive[r] || frz[r])
            continue;
        if (s->len > lim) { /* it ran past the cycles the bank commits: again, that far */
            row_undo(ptr, io, r, s, bk + width * r);
            if (row_plain(ptr, io, r))
                row_cycles_plain(ptr, io, fp, r, s, lim, bk + width * r);
            else
                row_cycles(ptr, io, fp, r, s, lim, bk + width * r);
        }
        if (s->code && s->len == lim && code_row < 0)
            code_row = r;
        fin_any |= s->fin && s->len == lim;
        filled |= s->refilled;
    }
    for (r = 0; r < n; r++) {
        if (!alive[r]) {
            I64(c_start)[r] += lim; /* a row left out did not step */
            continue;
        }
        if (!frz[r])
            row_store(ptr, r, rs + r);
    }
    if (lim)
        write_image(ptr, io);
    io[OUT_FIN] = fin_any;
    if (filled)
        io[OUT_FILLED] = 1;
    *rc = code_row >= 0 ? rs[code_row].code : 0;
    return lim;
}

/* the row flags of one cycle's passes (0: the row does not step, 1: it steps, 2: it steps
 * and its Trap move ends here): on the stack for the usual banks, else on the heap */
#define GO_STACK 4096

/* One cycle (io[IN_T_NS], fp[FP_DT]): 0 committed, else what was declined (nothing written). */
int bank_kernel_cycle(void **ptr, int64_t *io, const double *fp)
{
    void *lp[N_FIELDS]; /* a local copy: stores through the rows cannot alias it */
    uint8_t stack[GO_STACK], *go = stack;
    int rc;
    memcpy(lp, ptr, sizeof lp);
    io[OUT_FILLED] = 0;
    if (io[IN_N] > GO_STACK && !(go = malloc((size_t)io[IN_N])))
        return 5; /* no memory: the numpy cycle runs it */
    rc = cycle_once(lp, io, fp, go, 1, 1);
    if (go != stack)
        free(go);
    return rc;
}

/* the fewest cycles a call runs row by row: each row's run costs its loads and stores once,
 * which a call of a few cycles does not win back (measured: 128 rows, even at 5-6) */
#define ROWS_FROM 6

/* Up to io[IN_MAXC] cycles from io[IN_T_NS], io[IN_DT_NS] apart; io[OUT_DONE] = cycles
 * committed.  Stops after a cycle that ended a Trap move (io[OUT_FIN]) and before one the
 * kernel declines (its code is returned, nothing of that cycle written).  Without a homing
 * row or a ramping jog, ROWS_FROM cycles and more run row by row (run_rows), the image written
 * once after the last. */
int bank_kernel_run(void **ptr, int64_t *io, const double *fp)
{
    void *lp[N_FIELDS];
    uint8_t stack[GO_STACK], *go = stack;
    int64_t c, r, maxc = io[IN_MAXC], t0 = io[IN_T_NS], n = io[IN_N];
    int rc = 0, rows = 1;
    memcpy(lp, ptr, sizeof lp);
    io[OUT_FILLED] = 0;
    io[OUT_DONE] = 0;
    io[OUT_FIN] = 0;
    {
        const uint8_t *alive = U8(alive), *frz = U8(frz), *hm = U8(hm), *jog = U8(jog);
        /* a homing row, or a jog whose raw speed still ramps to its goal (jog.ramp_step:
         * row_cycles steps a cruising jog only), runs cycle by cycle */
        for (r = 0; r < n; r++)
            if (alive[r] && !frz[r] && (hm[r] || (jog[r] && F64(jrv)[r] != F64(jgoal)[r])))
                rows = 0;
    }
    if (rows && maxc >= ROWS_FROM) {
        const uint8_t *buf = U8(buf);
        RowRun *rs;
        double *bk;
        for (r = 0; r < io[IN_N_RX]; r++) /* a raw write to a claimed slave's outputs */
            if (buf[I64(rx_idx)[r]] != U8(rx_ref)[r] && U8(alive)[I64(rx_row)[r]])
                return 1;
        rs = malloc((size_t)(n > 0 ? n : 1) * sizeof(RowRun));
        bk = malloc((size_t)(n > 0 ? n : 1) * (size_t)(3 * (io[IN_TABLE] + 1)) * sizeof(double));
        if (!rs || !bk) {
            free(rs);
            free(bk);
            return 5; /* no memory: the numpy cycle runs it */
        }
        io[OUT_DONE] = run_rows(lp, io, fp, rs, bk, &rc);
        free(rs);
        free(bk);
        return rc;
    }
    if (io[IN_N] > GO_STACK && !(go = malloc((size_t)io[IN_N])))
        return 5; /* no memory: the numpy cycle runs it */
    for (c = 0; c < maxc; c++) {
        io[IN_T_NS] = t0 + c * io[IN_DT_NS];
        rc = cycle_once(lp, io, fp, go, c == 0, 0);
        if (rc)
            break;
        if (io[OUT_FIN]) {
            c++;
            break;
        }
    }
    if (go != stack)
        free(go);
    io[OUT_DONE] = c;
    io[IN_T_NS] = t0;
    return rc;
}

/* PtPlanner.run of a static FIFO (gtecat/controller/motion/pt.py, step/_next/_enter/_finish
 * transcribed with the same operations in the same order): n samples of the motion from the
 * state st (PT_ST_* below; updated to the state after them) over the running FIFO's points
 * pts (m rows of position, time, segment type) into po/vo/ao; returns the index of the end
 * sample (the motion ran out of passes) or -1. */
enum {
    PT_K, PT_T, PT_I, PT_LOOP, PT_LOOPS, PT_TOFF, PT_POFF, PT_T0, PT_P0, PT_T1, PT_P1, PT_VS,
    PT_VE, PT_A, PT_ORIGIN, PT_POS, PT_VEL, PT_ACC, PT_STATE, PT_NST
};

int bank_pt_state_size(void) { return PT_NST; }

static void pt_enter(double *st, const double *pt, int first)
{
    const double t0 = st[PT_T1], p0 = st[PT_P1], v_prev = st[PT_VE];
    const double t1 = pt[1] + st[PT_TOFF], p1 = pt[0] + st[PT_POFF];
    const double dt = t1 - t0, dp = p1 - p0;
    double vs, ve;
    if (pt[2] == 1.0) { /* PT_SEGMENT_EVEN */
        vs = ve = dp / dt;
    } else if (pt[2] == 2.0) { /* PT_SEGMENT_STOP */
        vs = 2.0 * dp / dt;
        ve = 0.0;
    } else {
        vs = first ? 0.0 : v_prev;
        ve = 2.0 * dp / dt - vs;
    }
    st[PT_T0] = t0;
    st[PT_P0] = p0;
    st[PT_T1] = t1;
    st[PT_P1] = p1;
    st[PT_VS] = vs;
    st[PT_VE] = ve;
    st[PT_A] = (ve - vs) / dt;
}

static int pt_next(double *st, const double *pts, int64_t m)
{
    const int64_t i = (int64_t)st[PT_I];
    if (i + 1 < m) {
        st[PT_I] = (double)(i + 1);
        pt_enter(st, pts + 3 * (i + 1), 0);
        return 1;
    }
    st[PT_LOOPS] += 1.0;
    if (st[PT_LOOP] != 0.0 && st[PT_LOOPS] >= st[PT_LOOP])
        return 0;
    st[PT_TOFF] = st[PT_T1];
    st[PT_POFF] = st[PT_P1];
    st[PT_I] = 0.0;
    pt_enter(st, pts, 1);
    return 1;
}

int64_t bank_pt_run(double *st, const double *pts, int64_t m, int64_t n, double *po, double *vo,
                    double *ao)
{
    int64_t j, k = (int64_t)st[PT_K];
    const double cyc = st[PT_T];
    for (j = 0; j < n; j++) {
        double t, tau, a;
        k += 1;
        t = (double)k * cyc;
        while (t >= st[PT_T1] - 1e-9 * (1.0 + fabs(st[PT_T1]) * 1e-3)) { /* _EPS_T */
            if (!pt_next(st, pts, m)) { /* _finish(origin + p1) */
                st[PT_K] = (double)k;
                st[PT_POS] = st[PT_ORIGIN] + st[PT_P1];
                st[PT_VEL] = st[PT_ACC] = 0.0;
                st[PT_STATE] = 0.0;
                po[j] = st[PT_POS];
                vo[j] = 0.0;
                ao[j] = 0.0;
                return j;
            }
        }
        tau = t - st[PT_T0];
        a = st[PT_A];
        po[j] = st[PT_ORIGIN] + st[PT_P0] + tau * (st[PT_VS] + 0.5 * a * tau);
        vo[j] = st[PT_VS] + a * tau;
        ao[j] = a;
    }
    st[PT_K] = (double)k;
    if (n > 0) {
        st[PT_POS] = po[n - 1];
        st[PT_VEL] = vo[n - 1];
        st[PT_ACC] = ao[n - 1];
    }
    return -1;
}

/* The tables of many static PT rows at once (AxisBank._fill_tables): a[] holds the row count,
 * the samples per table, the table width and the addresses of the arrays (PT_FILL_* below).
 * For each row r: its state st[r] (PT_NST doubles) is kept in before[r], the last sample taken
 * moves to the row's spare slot (as AxisBank._refill does), bank_pt_run fills the table from
 * the row's points and moves st[r] on, and the table's cursor, length and end follow; the
 * samples written are returned.  PT_FILL_RUN, when not 0, is the address of another run of
 * bank_pt_run's form (a PVT row's: bank_pvt.c) and PT_FILL_NST the size of its state. */
enum {
    PT_FILL_NR, PT_FILL_N, PT_FILL_TABLE, PT_FILL_ROWS, PT_FILL_ST, PT_FILL_BEFORE,
    PT_FILL_PTS, PT_FILL_M, PT_FILL_TP, PT_FILL_TV, PT_FILL_TA, PT_FILL_BASE, PT_FILL_IDX,
    PT_FILL_LEN, PT_FILL_CUR, PT_FILL_END, PT_FILL_TAKEN, PT_FILL_FILLTAKEN, PT_FILL_RUN,
    PT_FILL_NST, PT_FILL_NARGS
};
typedef int64_t (*row_run)(double *, const double *, int64_t, int64_t, double *, double *,
                           double *);

int bank_pt_fill_args(void) { return PT_FILL_NARGS; }

int64_t bank_pt_fill(const int64_t *a)
{
#define PA(T, k) ((T *)(intptr_t)a[k])
    const row_run run = a[PT_FILL_RUN] ? (row_run)(intptr_t)a[PT_FILL_RUN] : bank_pt_run;
    const int64_t nst = a[PT_FILL_RUN] ? a[PT_FILL_NST] : PT_NST;
    const int64_t nr = a[PT_FILL_NR], n = a[PT_FILL_N], table = a[PT_FILL_TABLE];
    const int64_t *rows = PA(const int64_t, PT_FILL_ROWS);
    double *st = PA(double, PT_FILL_ST), *before = PA(double, PT_FILL_BEFORE);
    const int64_t *pts = PA(const int64_t, PT_FILL_PTS), *m = PA(const int64_t, PT_FILL_M);
    double *tp = PA(double, PT_FILL_TP), *tv = PA(double, PT_FILL_TV), *ta = PA(double, PT_FILL_TA);
    const int64_t *base = PA(const int64_t, PT_FILL_BASE);
    int64_t *idx = PA(int64_t, PT_FILL_IDX), *len = PA(int64_t, PT_FILL_LEN);
    int64_t *cur = PA(int64_t, PT_FILL_CUR), *end = PA(int64_t, PT_FILL_END);
    const int64_t *taken = PA(const int64_t, PT_FILL_TAKEN);
    int64_t *fill_taken = PA(int64_t, PT_FILL_FILLTAKEN);
    int64_t i, total = 0;
#undef PA
    for (i = 0; i < nr; i++) {
        const int64_t r = rows[i], b = base[r], spare = b + table, last = idx[r];
        int64_t e;
        memcpy(before + nst * r, st + nst * r, nst * sizeof(double));
        tp[spare] = tp[last];
        tv[spare] = tv[last];
        ta[spare] = ta[last];
        idx[r] = spare;
        e = run(st + nst * r, (const double *)(intptr_t)pts[r], m[r], n, tp + b, tv + b, ta + b);
        len[r] = e >= 0 ? e + 1 : n;
        cur[r] = 0;
        end[r] = e;
        fill_taken[r] = taken[r];
        total += len[r];
    }
    return total;
}
