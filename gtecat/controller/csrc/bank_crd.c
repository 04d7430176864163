/* The axis bank's coordinate systems: the cycles inside one motion segment at a time
 * (gtecat/controller/bank_crd.py).
 *
 * CoordSystem.run's common case of gtecat/controller/crd/system.py (the path time by one
 * addition a cycle, Trapezoid.s and Trapezoid.v of crd/velocity.py, Line.point and
 * Arc.point of crd/path.py, then each slot's p = o + x, v = (p - p_before) / cyc,
 * a = (v - v_before) / cyc), transcribed with the same IEEE operations in the same order
 * (built with -ffp-contract=off, no fast-math; the cosines and sines are the C library's,
 * as Python's math module takes them): the samples are the scalar cycle's, bit for bit. */
#include <math.h>
#include <stdint.h>

/* a segment's fields (CR_*): the trapezoid, the geometry, the origin */
enum {
    CR_KIND, CR_DIMS,
    CR_ACC, CR_V0, CR_VP, CR_T1, CR_TC, CR_D1, CR_DC, CR_VEND, CR_PLEN, CR_DUR,
    CR_LEN, CR_I, CR_J, CR_AXIS3, CR_R0, CR_R1, CR_TH0, CR_SWEEP, CR_CX, CR_CY, CR_RISE,
    CR_START, CR_DELTA = CR_START + 4, CR_END = CR_DELTA + 4, CR_ORIGIN = CR_END + 4,
    CR_N = CR_ORIGIN + 4
};
enum { KIND_LINE = 1, KIND_ARC = 2 };
/* the state of a call (IO_*): in, and out after the cycles taken */
enum {
    IO_T, IO_DT, IO_CYC, IO_S, IO_SPEED, IO_POS, IO_VEL = IO_POS + 4, IO_ACC = IO_VEL + 4,
    IO_N = IO_ACC + 4
};

int bank_crd_sizes(void) { return CR_N * 100 + IO_N; }

/* cos and sin called as Python's math module calls them: through pointers the compiler cannot
 * see through, so it does not merge the two into one sincos call (whose last bit the C
 * library does not promise to be theirs) */
static double (*volatile crd_cos)(double) = cos;
static double (*volatile crd_sin)(double) = sin;

/* Trapezoid.s and Trapezoid.v at t < duration */
static void trapezoid(const double *g, double t, double *s, double *v)
{
    const double a = g[CR_ACC], v0 = g[CR_V0], vp = g[CR_VP];
    if (t <= 0.0) {
        *s = 0.0;
        *v = v0;
        return;
    }
    if (t < g[CR_T1]) {
        const double a1 = vp >= v0 ? a : -a;
        *s = v0 * t + 0.5 * a1 * t * t;
        *v = v0 + (vp >= v0 ? a : -a) * t;
        return;
    }
    const double t2 = t - g[CR_T1];
    if (t2 < g[CR_TC]) {
        *s = g[CR_D1] + vp * t2;
        *v = vp;
        return;
    }
    const double t3 = t2 - g[CR_TC];
    const double a3 = g[CR_VEND] <= vp ? -a : a;
    const double x = g[CR_D1] + g[CR_DC] + vp * t3 + 0.5 * a3 * t3 * t3;
    const double ln = g[CR_PLEN];
    *s = ln < x ? ln : x; /* min(x, length) */
    *v = vp - a * (t2 - g[CR_TC]);
}

/* Line.point / Arc.point */
static void point(const double *g, int dims, double s, double *x)
{
    const double ln = g[CR_LEN];
    int k;
    if (s >= ln || ln == 0.0) {
        for (k = 0; k < dims; k++)
            x[k] = g[CR_END + k];
        return;
    }
    const double u = (0.0 > s ? 0.0 : s) / ln; /* max(s, 0.0) / ln */
    if (g[CR_KIND] == KIND_LINE) {
        for (k = 0; k < dims; k++)
            x[k] = g[CR_START + k] + g[CR_DELTA + k] * u;
        return;
    }
    const int i = (int)g[CR_I], j = (int)g[CR_J], k3 = (int)g[CR_AXIS3];
    const double r0 = g[CR_R0];
    const double r = r0 + (g[CR_R1] - r0) * u;
    const double th = g[CR_TH0] + g[CR_SWEEP] * u;
    for (k = 0; k < dims; k++)
        x[k] = g[CR_START + k];
    x[i] = g[CR_CX] + r * crd_cos(th);
    x[j] = g[CR_CY] + r * crd_sin(th);
    if (k3 >= 0)
        x[k3] = g[CR_START + k3] + g[CR_RISE] * u;
}

/* At most m cycles of segment g from the state io, while the path time stays before the
 * segment's end: slot k's samples of cycle c go to out[q * qs + k * ks + c] (q: position,
 * speed, acceleration), the path speed to speeds[c]; io holds the state after them.
 * Returns the cycles taken. */
int64_t bank_crd_segment(const double *g, double *io, double *out, int64_t qs, int64_t ks,
                         int64_t m, double *speeds)
{
    const int dims = (int)g[CR_DIMS];
    const double dt = io[IO_DT], cyc = io[IO_CYC], dur = g[CR_DUR];
    double t = io[IO_T], s = io[IO_S], sp = io[IO_SPEED];
    double x[4];
    int64_t c;
    int k;
    for (c = 0; c < m; c++) {
        const double tn = t + dt;
        if (!(tn < dur))
            break;
        t = tn;
        trapezoid(g, t, &s, &sp);
        speeds[c] = sp;
        point(g, dims, s, x);
        for (k = 0; k < dims; k++) {
            const double p = g[CR_ORIGIN + k] + x[k];
            const double v = (p - io[IO_POS + k]) / cyc;
            const double a = (v - io[IO_VEL + k]) / cyc;
            io[IO_POS + k] = p;
            io[IO_VEL + k] = v;
            io[IO_ACC + k] = a;
            out[k * ks + c] = p;
            out[qs + k * ks + c] = v;
            out[2 * qs + k * ks + c] = a;
        }
    }
    io[IO_T] = t;
    io[IO_S] = s;
    io[IO_SPEED] = sp;
    return c;
}
