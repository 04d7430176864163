/* The C entry of a GT fast reader (gtecat/gt/centry.py builds, binds and tests this file).
 *
 * GT_GetSts(1, byref(s)) and its kind: the shape of the call is checked here (an exact int
 * for the axis, count absent or 1, pClock absent, None or 0, the value's pointer resolved to
 * the memory of an accepted ctypes object as the byref check does; a ctypes array, or byref of
 * one with or without an offset - C's &arr[k] - takes a span's values from that address where
 * they end within the object: array_of, array_mem; a numpy array of several values:
 * np_array), pClock also pointer(x), GT_GetClock's pLoop the clock's cycles run, the reader's
 * value comes
 * from one Python call (value(n): a number, or a sentinel when the C entry must not answer),
 * and the number is written into the object's memory with the object's width (a reader of
 * a structure: value(n) gives its bytes, copied whole).  Anything
 * else - another shape, the sentinel, a number the type does not hold, any doubt - is the
 * reader's Python fast function called with the very same arguments, which answers as before.
 *
 * The raw image functions (GT_GetEcatRawData(offset, size, buf) and their kind) have an entry
 * of their own: a ctypes array (or byref of one, with an offset too), a bytearray, a numpy uint8
 * array or a memoryview of bytes (or, to write from, bytes) long enough, and plain ints
 * checked here, the runs of the range in the process image from one Python call
 * (value(offset, size, type), as int64 triples in a bytes object: that function checks
 * everything else, the array's type and size included), and the bytes copied run by run
 * with memcpy; a write copies and makes the readers' epoch grow only where a byte differs.
 *
 * In the auto clock an entry whose call's latency makes a cycle due runs the armed quick
 * cycle itself (quick_cycle), and books it itself where its controller's book says that
 * only counting is to do (book_in_c); otherwise the controller's Python book follows.
 *
 * No Python header: where the interpreter keeps a pointer object's address and object, an
 * object's type, a ctypes object's memory and a float's value, and the C API's functions, are
 * handed over by the loader, which probed them on objects whose answers it knows and tests
 * the entry against the Python path before using it.
 */
#if !defined(_WIN32)
#define _POSIX_C_SOURCE 199309L /* (clock_gettime: the cycles' timer, cycle_timer) */
#include <time.h>
#endif
#include <stddef.h>
#include <stdint.h>
#include <string.h>

typedef void *obj;

struct api {
    ptrdiff_t carg_value; /* the address a byref() passes */
    ptrdiff_t carg_obj;   /* the object it refers to (NULL for some pointer objects) */
    ptrdiff_t ob_type;    /* an object's type */
    ptrdiff_t b_ptr;      /* a ctypes object's memory */
    ptrdiff_t fval;       /* a float's value */
    ptrdiff_t bsize;      /* a bytes object's length */
    ptrdiff_t bdata;      /* a bytes object's first byte */
    ptrdiff_t bastart;    /* a bytearray's first byte (its length: where a bytes object's is) */
    ptrdiff_t vc_entry;   /* a vectorcall callable's entry address (see centry.py) */
    ptrdiff_t b_objects;  /* the objects a ctypes object keeps alive (pointer(x): {'1': x}) */
    obj carg_type;        /* the type of the pointer objects byref() makes */
    obj int_type;
    obj float_type;
    obj bytes_type;
    obj array_meta; /* the type of ctypes array types */
    obj bytearray_type;
    obj none;
    obj zero; /* the int 0 (the return code) */
    obj one;  /* the int 1 (an omitted count) */
    obj dict_type;
    obj key_one; /* the str '1': where pointer(x) keeps x */
    void (*incref)(obj);
    void (*decref)(obj);
    obj (*vectorcall)(obj, obj const *, size_t, obj);
    long long (*as_ll)(obj, int *); /* PyLong_AsLongLongAndOverflow */
    obj (*err_occurred)(void);
    void (*err_clear)(void);
    obj (*dict_get)(obj, obj); /* PyDict_GetItem: borrowed, no error left */
    /* the session's gates (gtecat.gt._core keeps them wherever their answer can change):
     * [0] nonzero while the GT_ functions address the in-process lockstep controller of
     * core 1, [1] while the GTN_ functions' core 1 is that controller */
    const ptrdiff_t *gate;
    /* the values' epoch: an int at epoch_off in epoch_obj (gtecat.controller.epoch.EPOCH.n), which
     * Python makes larger wherever a value an entry caches may change (a cycle, a call that
     * is not a cached read, a fault, the session) */
    obj epoch_obj;
    ptrdiff_t epoch_off;
    /* the auto clock's host latency in the common case (gtecat.gt._core.advance's first
     * branch): per gate the numbers of its controller's clock (Clock.quick: the latency
     * pending, a call's latency, the cycle time, 1 while it shares its time with no other
     * clock), 0: none (after() runs it) */
    const ptrdiff_t *clock_quick;
    /* numpy's arrays (numpy's public PyArrayObject fields, probed): the type, where an array
     * keeps its data, its number of dimensions (int), its dimensions, its dtype and its flags
     * (int); the flags a one-dimensional array an entry writes must have */
    obj ndarray_type;
    ptrdiff_t nd_data, nd_nd, nd_dims, nd_descr, nd_flags;
    int nd_want;
    /* the clocks' locks (gtecat.master.clock.Clock.lock, a threading.RLock), per gate: the
     * lock object, 0: none; where an RLock keeps the ident of the thread that holds it (0:
     * nobody; probed); the interpreter's PyThread_get_thread_ident; per gate the lock's
     * acquire and release (bound methods); PyErr_Fetch and PyErr_Restore.  A cycle and a
     * call of the table path run with their controller's clock lock held, and another
     * thread of the program may run them (the lockstep and auto clocks run their cycles in
     * whichever thread lets time pass): an entry that finds the lock held by another thread
     * takes it itself (waiting, the GIL let go) and answers while it holds it (see ANSWER) */
    const ptrdiff_t *clock_lock;
    ptrdiff_t owner_off;
    unsigned long (*thread_ident)(void);
    const ptrdiff_t *lock_acquire;
    const ptrdiff_t *lock_release;
    void (*err_fetch)(obj *, obj *, obj *);
    void (*err_restore)(obj, obj, obj);
    /* the quick cycle (gtecat.controller.core.Controller.arm_quick): per gate its
     * controller's book(after, rc), called once the armed kernel ran (0: none) */
    const ptrdiff_t *clock_calls;
    /* the generation of what an armed cycle relies on (gtecat.master.clock.ARMS) */
    const long long *arms;
    /* where the slaves' AL and outside changes are counted (VirtualSlave's own dict) and
     * their names */
    obj marks_dict;
    obj key_al;
    obj key_out;
    /* the buffer protocol (PyObject_GetBuffer, PyBuffer_Release) for a raw entry's
     * memoryview, the memoryview type, numpy's uint8 dtype (its descr object; NULL: none) */
    int (*get_buffer)(obj, void *, int);
    void (*release_buffer)(void *);
    obj memoryview_type;
    obj np_u8;
    /* the armed quick cycle's book in C (gtecat.controller.core.Controller._book_in_c): per
     * gate its controller's book (0: none), and what it makes: PyLong_FromLongLong,
     * PyDict_New, PyDict_SetItem, PyTuple_Pack and the names of the bank's lists and of the
     * steady verdict's marks */
    const ptrdiff_t *clock_books;
    obj (*long_from)(long long);
    obj (*dict_new)(void);
    int (*dict_set)(obj, obj, obj);
    obj (*tuple_pack)(ptrdiff_t, ...);
    obj key_lists;
    obj key_seen;
    /* a ctypes object's size in bytes (b_size: what ctypes.sizeof gives for the object, the
     * extent byref(x, offset) is checked against) */
    ptrdiff_t b_size;
    /* PyBytes_FromStringAndSize: a span's values gathered here (gather) */
    obj (*bytes_new)(const char *, ptrdiff_t);
    /* PyFloat_FromDouble: one axis's double made again (kept) */
    obj (*float_new)(double);
    /* the metatypes of ctypes' simple types, structures and unions (array_meta: arrays'):
     * a raw entry copies into or out of any such object whose memory is raw (its value
     * function checks the type: no pointers, big enough) */
    obj simple_meta, struct_meta, union_meta;
    /* the metatype of ctypes' pointer types (POINTER(c_uint32)) and the simple types that
     * hold a pointer (c_void_p, c_char_p, c_wchar_p): such an object whose value is NULL is
     * a NULL pointer argument, as None and 0 are */
    obj pointer_meta, voidp_type, charp_type, wcharp_type;
    /* where a tuple keeps its first item (its length: where a bytes object's is) */
    ptrdiff_t tuple_items;
};

#define MAX_TYPES 16

/* Where a value's doubles come from, as its value function says it (strong references while
 * kept; src NULL: not said): for each of its doubles the same operations on the bank's
 * arrays across the cycles booked in C (make_doubles): rows (int64 bytes) the rows, ratios
 * (float64 bytes, NULL: none) a factor per value, op what is read of src and idx at a row,
 * t the cycle time op 1 and 2 divide by. */
struct recipe {
    obj src, idx, rows, ratios;
    long long op;
    double t;
};

/* a value kept for the epoch it was asked in (value: a strong reference, NULL: none) */
struct slot {
    long long epoch;
    obj value;
    long long booked; /* c_booked when it was kept */
    /* holds: 1 where the value is a status word of the bank's (value(n) gave (word,)), which
     * stands across the cycles that keep every flag; keeps: flag_keeping when it was kept */
    long long holds, keeps;
    struct recipe rc; /* where a double comes from: made again after cycles booked in C */
};

static int make_doubles(const struct recipe *rc, long long count, double *out);
static const char *vector(obj a, ptrdiff_t *len);
static int ll_of(obj o, long long *v);

/* a span's bytes kept for its key and epoch (tp: a strong reference while kept); holds: 1
 * where they stand across the cycles that keep every status flag (their value function gave
 * them as such: status words alone), keeps: flag_keeping when they were last kept */
struct aslot {
    long long epoch, n, count, clock;
    obj tp;
    obj value;
    long long holds, keeps;
    /* where the bytes come from, as avalue said (gather); booked: c_booked when kept */
    struct recipe rc;
    long long booked;
};

/* one reader's entry: the memory of the ctypes object that is the C function's self */
struct entry {
    obj fallback;  /* the Python fast function: every shape this entry does not answer */
    obj value;     /* value(n): the number (or bytes) to write, or sentinel */
    obj sentinel;
    ptrdiff_t core; /* 1: the GTN_ form, the core (which must be 1) first */
    ptrdiff_t kind; /* 0: integers, 1: doubles, 2: bytes (a structure's, its whole size) */
    ptrdiff_t most; /* arguments after the core: 2 (n, p), 4 (n, p, count 1, pClock NULL) */
    obj types[MAX_TYPES]; /* the ctypes types *pValue may have, NULL-ended */
    ptrdiff_t sizes[MAX_TYPES];
    ptrdiff_t signs[MAX_TYPES]; /* an integer type: 1 signed, 0 unsigned */
    ptrdiff_t derefs[MAX_TYPES]; /* a ctypes pointer type: its _type_ (pointer(x): x's memory) */
    ptrdiff_t noaxis; /* 1: f(p[, q]) (GT_GetClock(pClock, pLoop)): q NULL, value() */
    obj avalue; /* NULL, or avalue(n, count, array type, pClock): a ctypes array's bytes */
    ptrdiff_t gate; /* 0: none; k: value (and avalue) only while A.gate[k - 1] is nonzero */
    obj after; /* NULL, or after(): the call's return code once written, where A.gate[k - 1] is
                * 2 (the auto clock: the call's host latency, which may run cycles) */
    struct slot *cache; /* value(n) kept per n below ncache for its epoch (NULL: none) */
    ptrdiff_t ncache;
    /* the integer types a span's pClock may point at (byref(x) or x), NULL-ended: none, the
     * reader takes no clock */
    obj ctypes_[MAX_TYPES];
    ptrdiff_t csizes[MAX_TYPES];
    ptrdiff_t csigns[MAX_TYPES];
    struct aslot *acache; /* the spans' bytes, a lane each (nacache; NULL: none kept) */
    /* the numpy dtypes (their descr objects) whose one-dimensional arrays take the value in
     * their first element, NULL-ended, with their sizes and signs */
    obj nptypes[8];
    ptrdiff_t npsizes[8];
    ptrdiff_t npsigns[8];
    /* an array's element stride where it is not the value's bytes per element (a structure
     * reader: the structure's size, its value the fields' bytes); 0: the bytes' own */
    ptrdiff_t stride;
    /* the tuple type and where a tuple keeps its first item: avalue's (bytes,) says its
     * bytes are status words alone (NULL: avalue gives bytes only) */
    obj tuple_type;
    ptrdiff_t titems;
    /* per clock type of ctypes_: a ctypes pointer type's _type_ (pointer(x): x's memory), 0 */
    ptrdiff_t cderefs[MAX_TYPES];
    /* 1: its values stand across the cycles booked in C (an attribute no cycle changes: a
     * profile's mode), see c_booked */
    ptrdiff_t steady;
    /* the slots of acache: a lane per span (n, count, type, clock) a program reads in turn
     * (GT_GetEncPos(1, a, 8) then GT_GetEncPos(9, byref(a, 64), 4)), each kept with where its
     * bytes come from; 0 or 1: the last span's alone */
    ptrdiff_t nacache;
    /* NULL, or viewer(v): for a memoryview v of *pValue the ctypes array it shows whole, of
     * a type this reader takes (the call is then that array's), else None */
    obj viewer;
    /* NULL, or the GT session's own dict (with key_last, its last error's key): the value is
     * the gate's clock's (clock_ms: GT_GetClock's), made in C where the session has no last
     * error for value() to clear (a call that succeeds clears it) */
    obj session;
    obj key_last;
};

static struct api A;
static int ready;

/* The quick cycles booked in C that kept every status flag (no in-position band, no move
 * ended: book_in_c's b[14]), each of which made the readers' epoch grow by one: where the
 * epoch grew by as much as this count since a span of status words, or one axis's word of
 * the bank, was kept, every change since was such a cycle and the words stand (array_value,
 * kept) */
static long long flag_keeping;

/* The quick cycles booked in C (book_in_c; each made the readers' epoch grow by one): where
 * the epoch grew by as much as this count since a value was kept, every change since was
 * such a cycle - no Python ran in them: the bank's arrays the same objects, its rows the
 * same, their values moved in place by the kernel, every Python attribute as it was - and a
 * span's bytes are made again from where they came from (array_value, gather), and a
 * steady entry's values (an attribute's: GT_GetPrfMode) stand (kept, array_value) */
static long long c_booked;

/* The epoch's growths that moved no more than the process image's bytes: the quick cycles
 * booked in C and the raw writes (their changed(): one growth each).  Where the epoch grew by
 * as much as this count since a raw range's runs were kept, they stand (the image's buffer
 * the same, every slave on the bus). */
static long long c_moved;

#define AT(base, off) (*(char **)((char *)(base) + (off)))
/* the flag a vectorcall's caller may set in nargsf (PY_VECTORCALL_ARGUMENTS_OFFSET) */
#define VECTORCALL_OFFSET ((size_t)1 << (8 * sizeof(size_t) - 1))
#define TYPE(o) AT(o, A.ob_type)

int gtecat_centry_api(const struct api *api)
{
    if (api->carg_value < 0 || api->carg_obj < 0 || api->ob_type < 0 || api->b_ptr < 0 ||
        api->fval < 0 || api->bsize < 0 || api->bdata < 0 || api->bastart < 0 ||
        api->vc_entry < 0 || api->b_objects < 0 || !api->dict_type || !api->key_one ||
        !api->dict_get ||
        !api->bytearray_type || !api->carg_type ||
        !api->int_type || !api->float_type || !api->bytes_type || !api->array_meta ||
        !api->none ||
        !api->zero || !api->one || !api->incref || !api->decref || !api->vectorcall || !api->as_ll ||
        !api->err_occurred || !api->err_clear || !api->gate || !api->epoch_obj ||
        api->epoch_off <= 0 || !api->clock_quick || !api->clock_lock || api->owner_off <= 0 ||
        !api->thread_ident || !api->lock_acquire || !api->lock_release || !api->err_fetch ||
        !api->err_restore || !api->clock_calls || !api->arms ||
        !api->marks_dict || !api->key_al || !api->key_out || !api->get_buffer ||
        !api->release_buffer || !api->memoryview_type || !api->clock_books || !api->long_from ||
        !api->dict_new || !api->dict_set || !api->tuple_pack || !api->key_lists || !api->key_seen ||
        api->b_size <= 0 || !api->bytes_new || !api->float_new || !api->simple_meta ||
        !api->struct_meta || !api->union_meta || !api->pointer_meta || !api->voidp_type ||
        !api->charp_type || !api->wcharp_type || api->tuple_items <= 0)
        return 1;
    A = *api;
    ready = 1;
    return 0;
}

/* an exact int equal to want (no error left behind) */
static int int_is(obj o, long long want)
{
    int over = 0;
    long long v;
    if (TYPE(o) != A.int_type)
        return 0;
    v = A.as_ll(o, &over);
    if (v == -1 && !over && A.err_occurred()) {
        A.err_clear();
        return 0;
    }
    return !over && v == want;
}

/* GTN_f(core, n, ...) with core 2.. a view of core 1's bus (gtecat.controller.core_view: core c
 * addresses bus axes 32(c-1)+1 .. 32c, which core 1 takes by their bus numbers): the bus
 * axis's int, which core 1's value function answers as the view would, or NULL (the Python
 * path: core 1, a core of its own, a local axis beyond 1..32, a bus beyond VIEW_AXES). The
 * ints are made once and kept for the process. */
#define VIEW_AXES 4096
static obj view_ints[VIEW_AXES + 1];

static obj view_axis(obj core, obj axis)
{
    int over = 0;
    long long c, n, b;
    if (!A.gate[2] || TYPE(core) != A.int_type || TYPE(axis) != A.int_type)
        return NULL;
    c = A.as_ll(core, &over);
    if (over || c < 2 || c > VIEW_AXES / 32) {
        if (c == -1 && !over && A.err_occurred())
            A.err_clear();
        return NULL;
    }
    n = A.as_ll(axis, &over);
    if (over || n < 1 || n > 32) {
        if (n == -1 && !over && A.err_occurred())
            A.err_clear();
        return NULL;
    }
    b = 32 * (c - 1) + n;
    if (!view_ints[b] && !(view_ints[b] = A.long_from(b))) {
        A.err_clear();
        return NULL;
    }
    return view_ints[b];
}

/* The values' epoch now (-1: unknown, nothing is kept or used). */
static long long epoch(void)
{
    obj o = (obj)AT(A.epoch_obj, A.epoch_off);
    int over = 0;
    long long v;
    if (!o || TYPE(o) != A.int_type)
        return -1;
    v = A.as_ll(o, &over);
    if (v == -1 && !over && A.err_occurred())
        A.err_clear();
    return over || v < 0 ? -1 : v;
}

/* A recipe's references given up (NULL: none), a copy of it (rc emptied first: Python may
 * run in a decref) */
static void let_recipe_go(struct recipe *rc)
{
    struct recipe was = *rc;
    obj refs[4];
    int k;
    rc->src = rc->idx = rc->rows = rc->ratios = NULL;
    refs[0] = was.src, refs[1] = was.idx, refs[2] = was.rows, refs[3] = was.ratios;
    for (k = 0; k < 4; k++)
        if (refs[k])
            A.decref(refs[k]);
}

/* Keep v in s for epoch ep (v: borrowed; s's old value, and where it came from, given up). */
static void keep(struct slot *s, long long ep, obj v)
{
    obj old = s->value;
    A.incref(v);
    s->value = v;
    s->epoch = ep;
    s->booked = c_booked;
    s->holds = 0;
    s->keeps = flag_keeping;
    let_recipe_go(&s->rc);
    if (old)
        A.decref(old);
}

/* The value kept in cache (ncache slots) for the int n in this epoch, a new reference, else
 * NULL; *key is n's slot (-1: n has none) and *ep the epoch (-1: unknown), for keep(). */
static obj kept(struct slot *cache, ptrdiff_t ncache, obj n, long long *key, long long *ep,
                int steady)
{
    struct slot *s;
    int over = 0;
    *key = n ? A.as_ll(n, &over) : 0;
    *ep = -1;
    if (over || *key < 0 || *key >= ncache) {
        if (*key == -1 && !over && A.err_occurred())
            A.err_clear();
        *key = -1;
        return NULL;
    }
    *ep = epoch();
    s = &cache[*key];
    if (*ep >= 0 && s->value &&
        (s->epoch == *ep ||
         (steady && *ep > s->epoch && *ep - s->epoch == c_booked - s->booked) ||
         (s->holds && *ep > s->epoch && *ep - s->epoch == flag_keeping - s->keeps))) {
        /* (a steady value across cycles booked in C, a status word across those that kept
         * every flag: the same) */
        s->epoch = *ep, s->booked = c_booked, s->keeps = flag_keeping;
        A.incref(s->value);
        return s->value;
    }
    if (*ep >= 0 && s->value && s->rc.src && *ep > s->epoch &&
        *ep - s->epoch == c_booked - s->booked) {
        /* (a double of the bank's after cycles booked in C: made again where it comes from) */
        double x;
        obj f, old;
        if (make_doubles(&s->rc, 1, &x) &&
            (f = A.float_new(x)) != NULL) {
            old = s->value;
            s->value = f;
            s->epoch = *ep, s->booked = c_booked, s->keeps = flag_keeping;
            A.decref(old);
            A.incref(f);
            return f;
        }
        if (A.err_occurred())
            A.err_clear();
    }
    return NULL;
}


/* Keep a span's (or a raw range's) bytes v with their key and type tp for epoch ep. */
static void keep_span(struct aslot *s, long long ep, obj v, obj tp, long long n,
                      long long count, long long clock)
{
    obj old = s->value, oldtp = s->tp;
    A.incref(v);
    A.incref(tp);
    s->value = v, s->tp = tp, s->epoch = ep, s->n = n, s->count = count, s->clock = clock;
    s->holds = 0;
    let_recipe_go(&s->rc);
    if (old)
        A.decref(old);
    if (oldtp)
        A.decref(oldtp);
}

/* Another thread and the clock.
 *
 * The readers answer without the clock lock: the GIL makes what an entry does in C atomic
 * against the other threads' Python, but not against a cycle another thread is in the middle
 * of - the interpreter hands the GIL over between any two bytecodes of that cycle (every
 * switch interval, 5 ms by default), and the axis bank's compiled cycle runs with the GIL let
 * go - nor against a cycle run whole while the entry's own value function (Python) let the
 * GIL go.  So an entry answers from what it read only where no other thread held the lock
 * when it began (elsewhere()), and, where Python ran for the value, none held it afterwards
 * and the epoch did not grow meanwhile (every cycle and every call of the table path makes it
 * grow once done: gtecat.controller.epoch); else it answers again holding the lock itself
 * (ANSWER).  The write of the value, the copy of a raw range, follow the last look with no
 * Python in between. */

/* a try's body inlined into its entry (the common case pays no call for the split) */
#if defined(__GNUC__) || defined(__clang__)
#define TRY static inline __attribute__((always_inline)) obj
#define RARE(x) __builtin_expect(!!(x), 0)
#else
#define TRY static inline obj
#define RARE(x) (x)
#endif

/* a try's answer: not one that can stand, answer again holding the clock lock */
static char again_mark;
#define AGAIN ((obj)&again_mark)

/* 1 where a thread other than this one holds the clock lock of gate g (its cycles run, or
 * one of its calls): what the entry reads may be half of one state and half of the next */
static inline int elsewhere(ptrdiff_t g)
{
    const char *lk;
    unsigned long owner;
    if (!g || !(lk = (const char *)A.clock_lock[g - 1]))
        return 0;
    owner = *(const unsigned long *)(lk + A.owner_off);
    return owner && owner != A.thread_ident();
}

/* Gate g's clock lock taken (waiting, the GIL let go while another thread holds it): its
 * release (a new reference, for let_go), or NULL with the error set. */
static obj hold(ptrdiff_t g)
{
    obj acquire = (obj)A.lock_acquire[g - 1], release = (obj)A.lock_release[g - 1], r;
    if (!acquire || !release) /* (the gate closed meanwhile: nothing to wait for) */
        return A.none;
    A.incref(release); /* (the release of the lock taken, whatever the gates become) */
    r = A.vectorcall(acquire, NULL, 0, NULL);
    if (!r) {
        A.decref(release);
        return NULL;
    }
    A.decref(r);
    return release;
}

/* The lock hold() took let go (the call's own error, if any, kept as it was). */
static void let_go(obj release)
{
    obj t, v, tb, r;
    if (release == A.none)
        return;
    A.err_fetch(&t, &v, &tb);
    r = A.vectorcall(release, NULL, 0, NULL);
    if (r)
        A.decref(r);
    else
        A.err_clear();
    A.err_restore(t, v, tb);
    A.decref(release);
}

/* An entry's answer: its try without the lock (inlined), else (AGAIN) its try holding the
 * lock (ANSWER). */
#define ANSWER(try_, e, g, args, nargs, kwnames)                                            \
    do {                                                                                    \
        obj r_ = try_(e, args, nargs, kwnames, 0), release_;                                \
        if (!RARE(r_ == AGAIN))                                                             \
            return r_;                                                                      \
        if (!(release_ = hold(g)))                                                          \
            return NULL;                                                                    \
        r_ = try_##_locked(e, args, nargs, kwnames);                                        \
        let_go(release_);                                                                   \
        return r_;                                                                          \
    } while (0)

/* Whether what Python gave for the epoch ep0 may stand: the epoch the same and no other
 * thread holding the lock (nothing of Python runs after this look before the write). */
static int stands(ptrdiff_t g, long long ep0)
{
    return epoch() == ep0 && !elsewhere(g);
}

/* x held by an integer of size bytes (sign: signed) */
static int fits(long long x, int size, int sign)
{
    long long lo, hi;
    if (size == 1)
        lo = sign ? INT8_MIN : 0, hi = sign ? INT8_MAX : UINT8_MAX;
    else if (size == 2)
        lo = sign ? INT16_MIN : 0, hi = sign ? INT16_MAX : UINT16_MAX;
    else if (size == 4)
        lo = sign ? INT32_MIN : 0, hi = sign ? INT32_MAX : (long long)UINT32_MAX;
    else if (size == 8)
        lo = sign ? INT64_MIN : 0, hi = INT64_MAX;
    else
        return 0;
    return x >= lo && x <= hi;
}

/* x (which fits) written with size bytes */
static void put(char *mem, long long x, int size)
{
    if (size == 1)
        *(int8_t *)mem = (int8_t)x;
    else if (size == 2)
        *(int16_t *)mem = (int16_t)x;
    else if (size == 4)
        *(int32_t *)mem = (int32_t)x;
    else
        *(int64_t *)mem = (int64_t)x;
}

/* A call's return once its value is written: 0, or in the auto clock (its gate says 2)
 * what after() returns (the call's host latency, as the Python path's advance runs it). */
/* An int's value in *v (0: not an exact int that a long long holds; no error left). */
static int ll_of(obj o, long long *v)
{
    int over = 0;
    if (!o || TYPE(o) != A.int_type)
        return 0;
    *v = A.as_ll(o, &over);
    if (*v == -1 && !over && A.err_occurred()) {
        A.err_clear();
        return 0;
    }
    return !over;
}

/* The auto clock's host latency where it runs no cycle, as advance() does it first: the
 * clock's pending latency grows by a call's while that stays below the cycle time and the
 * clock shares its time with no other.  1: done; 0: after() must run it (a cycle is due, or
 * any doubt). */
static int latency(ptrdiff_t gate)
{
    long long *q = (long long *)A.clock_quick[gate - 1];
    long long pend;
    if (!q || !q[3])
        return 0;
    pend = q[0] + q[1];
    if (q[0] < 0 || q[1] < 0 || pend >= q[2])
        return 0;
    q[0] = pend;
    return 1;
}

/* the kernel's run of cycles (gtecat/controller/csrc/bank_kernel.c bank_kernel_run) */
typedef int (*kernel_run)(void *, void *, void *);

/* Whether the armed quick cycle (Controller.arm_quick) may run now: one cycle due on a clock
 * alone (pending latency pend), armed for this epoch, this generation, these slaves' marks
 * and this cycle time, with cycles left in its budget (q[11]: the cycle hooks' quiet ones). */
static int armed_now(const long long *q);

static int armed(const long long *q, long long pend)
{
    if (!q[3] || !q[4] || q[0] < 0 || q[1] < 0 || q[2] <= 0 || pend < q[2] || pend - q[2] >= q[2])
        return 0;
    if (q[11] <= 0)
        return 0;
    return armed_now(q);
}

/* Whether the quick cycle armed on the clock's numbers q stands now: armed for this epoch,
 * this generation, these slaves' marks, their field inputs and this cycle time (armed()
 * without the latency's and the budget's looks; a wait asks them its own way). */
static int armed_now(const long long *q)
{
    long long al, out, i;
    const long long *call, *w;
    if (!q[3] || !q[4] || q[0] < 0 || q[2] <= 0)
        return 0;
    if (q[5] != A.arms[0] || q[4] != epoch())
        return 0;
    call = (const long long *)q[8];
    if (!call || !call[0] || call[4] != q[2])
        return 0;
    if (!(ll_of(A.dict_get(A.marks_dict, A.key_al), &al) && al == q[6] &&
          ll_of(A.dict_get(A.marks_dict, A.key_out), &out) && out == q[7]))
        return 0;
    /* the IO slaves' field inputs as armed: a count, then per buffer its address, its copy's
     * and its length (Backend.fields_watch; they hold while the outside changes do, asked
     * above); a write through the buffer protocol is not counted, only seen here */
    w = (const long long *)call[5];
    if (w)
        for (i = 0; i < w[0]; i++)
            if (memcmp((const void *)w[1 + 3 * i], (const void *)w[2 + 3 * i], (size_t)w[3 + 3 * i]))
                return 0;
    return 1;
}


/* The plain IO slaves' outputs the armed quick cycle takes to the field itself
 * (Controller.arm_quick: call[6], Backend.outputs_watch; 0: none): a count, then per slave
 * the address of its output area in the process image, of its rx, of its field outputs and
 * the bytes - what the exchange and the slave's step do with them in the general cycle (no
 * wire, its inputs the same), so a write that changes them need not disarm the cycle. */
static void io_outputs(const long long *call)
{
    const long long *t = (const long long *)call[6], *r;
    long long i;
    if (t)
        for (i = 0, r = t + 1; i < t[0]; i++, r += 4) {
            memcpy((void *)r[1], (const void *)r[0], (size_t)r[3]);
            memcpy((void *)r[2], (const void *)r[0], (size_t)r[3]);
        }
}

/* GTE_Wait's gate's controller ([0] its clock's quick numbers: gtecat.gt.centry.WAIT_AT),
 * for a GT_ write's look at its armed cycle (io_only); NULL: none */
static const ptrdiff_t *wait_at;

int gtecat_centry_wait_at(const ptrdiff_t *at)
{
    wait_at = at;
    return 0;
}

/* The GT_ gate's armed cycle (its clock's quick numbers) where every run of a write (n
 * triples: first byte, address in the image, bytes) lies in the outputs it takes to the
 * field itself (io_outputs) and it is armed for the epoch now; else NULL. */
static long long *io_only(ptrdiff_t gate, const int64_t *runs, ptrdiff_t n)
{
    long long *q, i;
    const long long *call, *t, *r;
    ptrdiff_t k;
    if (gate != 1 || !wait_at || !wait_at[0])
        return NULL;
    q = (long long *)wait_at[0];
    if (!q[4] || q[4] != epoch() || !q[8])
        return NULL;
    call = (const long long *)q[8];
    t = (const long long *)call[6];
    if (!t)
        return NULL;
    for (k = 0; k < n; k++) {
        long long a = runs[3 * k + 1], len = runs[3 * k + 2];
        for (i = 0, r = t + 1; i < t[0]; i++, r += 4)
            if (a >= r[0] && a + len <= r[0] + r[3])
                break;
        if (i == t[0])
            return NULL;
    }
    return q;
}


/* The book of a quick cycle the kernel ran whole, in C, where the controller's book says it
 * may (gtecat.controller.core.Controller._book_in_c: nothing but counting to do): the
 * objects made first (nothing counted where one cannot be), then the bank's lists anew, the
 * steady verdict's marks, the readers' epoch, the counts, and the next cycle armed - what
 * Controller.quick_book does in this case.  q: the clock's quick numbers (q[9] its time,
 * q[10] its cycles).  1: booked; 0: nothing done, the Python book runs. */
static int book_n(long long *b, long long *q, long long n);

static int book_in_c(ptrdiff_t gate, long long *q)
{
    return book_n((long long *)A.clock_books[gate - 1], q, 1);
}

/* book_in_c's book of n cycles the kernel ran whole at once (b: the controller's book in C;
 * a wait's run: the counts of n cycles, the readers' epoch grown once, as a run of cycles
 * grows it). */
static int book_n(long long *b, long long *q, long long n)
{
    long long *io, *cnt, ep, cycles, now;
    obj lists, e, c, al, out, seen, old;
    if (!b || b[0] != 1)
        return 0;
    io = (long long *)b[1];
    if (!io[b[8]] || io[b[9]]) /* (declined, or a move ended: the Python book) */
        return 0;
    ep = epoch();
    if (ep < 0)
        return 0;
    cycles = q[10] + n;
    now = q[9] + n * q[2];
    lists = A.dict_new();
    e = A.long_from(ep + 1);
    c = A.long_from(cycles);
    al = A.long_from(q[6]); /* (the slaves' marks as armed: armed() found them so) */
    out = A.long_from(q[7]);
    seen = lists && e && c && al && out ? A.tuple_pack(4, e, c, al, out) : NULL;
    if (c)
        A.decref(c);
    if (al)
        A.decref(al);
    if (out)
        A.decref(out);
    if (!seen || A.dict_set((obj)b[5], A.key_lists, lists) < 0 ||
        A.dict_set((obj)b[6], A.key_seen, seen) < 0) {
        /* (only where memory ran out: the Python book makes them again) */
        A.err_clear();
        if (lists)
            A.decref(lists);
        if (e)
            A.decref(e);
        if (seen)
            A.decref(seen);
        return 0;
    }
    A.decref(lists);
    A.decref(seen);
    old = (obj)AT(A.epoch_obj, A.epoch_off); /* EPOCH.n = epoch + 1 (its reference: e's) */
    *(obj *)((char *)A.epoch_obj + A.epoch_off) = e;
    A.decref(old);
    /* the bank's: countdown, refill, rows, cycles, the kernel's, many at once, and its
     * homing, resting and switched-off rows */
    cnt = (long long *)b[2];
    cnt[0] -= n;
    cnt[1] -= n;
    cnt[2] += n * b[7];
    cnt[3] += n;
    cnt[4] += n;
    cnt[5] += n;
    cnt[6] += n * b[11];
    cnt[7] += n * b[12];
    cnt[8] += n * b[13];
    if (b[14] && cnt[9] == ep) /* (the status words made for the epoch stand: no flag moved) */
        cnt[9] = ep + 1;
    if (b[14])
        flag_keeping++;
    c_booked++;
    c_moved++;
    *(long long *)b[3] += n; /* its drives' cycles */
    *(long long *)b[4] += n; /* the master's */
    q[10] = cycles;
    q[9] = now;
    io[b[10]] = now; /* (the next cycle's call as this one's) */
    q[4] = ep + 1;   /* armed again, for the new epoch */
    return 1;
}

/* The cycles' timer (gtecat.gt.centry.CYCLE_TIMER, for a benchmark that tells a call's own
 * cost from the cycles a call's latency runs inside it): [0] nonzero while on, [1] the
 * nanoseconds the quick cycles took (the kernel's cycle and its book, in C or Python), [2]
 * how many; NULL: none (no monotonic clock known here) */
static long long *cycle_timer;

int gtecat_centry_cycle_timer(long long *t)
{
#if defined(_WIN32)
    (void)t;
    return 1;
#else
    cycle_timer = t;
    return 0;
#endif
}

static long long timer_ns(void)
{
#if defined(_WIN32)
    return 0;
#else
    struct timespec t;
    if (clock_gettime(CLOCK_MONOTONIC, &t))
        return 0;
    return (long long)t.tv_sec * 1000000000LL + t.tv_nsec;
#endif
}

/* A quick cycle timed (started at t0) where the timer is on. */
static void timed(long long t0)
{
    if (t0) {
        cycle_timer[1] += timer_ns() - t0;
        cycle_timer[2] += 1;
    }
}

/* The armed quick cycle where the call's latency makes a cycle due: the clock's lock taken
 * (hold: it may wait for another thread's call or cycles, as after() would), armed() asked
 * again with the lock held, the kernel's cycle run here and book(after, rc) doing the rest
 * (its answer, the call's code, in *res; NULL: an exception, kept through let_go), the lock
 * given back.  1: it ran; 0: nothing was done, after() runs the latency. */
static int quick_cycle(ptrdiff_t gate, obj after, obj *res)
{
    long long *q = (long long *)A.clock_quick[gate - 1];
    obj book = (obj)A.clock_calls[gate - 1], release, args[2];
    const long long *call;
    long long t0;
    int rc;
    if (!q || !book || !armed(q, q[0] + q[1]))
        return 0;
    release = hold(gate);
    if (!release) {
        A.err_clear();
        return 0;
    }
    if (release == A.none) /* (no lock known for the gate: the general way) */
        return 0;
    if (!armed(q, q[0] + q[1])) { /* (another thread's call or cycle came first) */
        let_go(release);
        return 0;
    }
    call = (const long long *)q[8];
    t0 = cycle_timer && cycle_timer[0] ? timer_ns() : 0;
    q[4] = 0;  /* (the book arms the next one) */
    q[11] -= 1; /* (one cycle of the budget it was armed with) */
    q[0] += q[1] - q[2];
    io_outputs(call);
    rc = ((kernel_run)call[0])((void *)call[1], (void *)call[2], (void *)call[3]);
    if (!rc && book_in_c(gate, q)) {
        timed(t0);
        A.incref(A.zero);
        *res = A.zero;
        let_go(release);
        return 1;
    }
    args[0] = after;
    args[1] = rc ? A.one : A.zero;
    A.incref(book); /* (the gates may change while it runs) */
    *res = A.vectorcall(book, args, 2, NULL);
    A.decref(book);
    timed(t0);
    let_go(release);
    return 1;
}

static obj done(obj after, ptrdiff_t gate)
{
    if (after && gate && A.gate[gate - 1] == 2 && !latency(gate)) {
        obj res = NULL;
        if (quick_cycle(gate, after, &res))
            return res;
        return A.vectorcall(after, NULL, 0, NULL);
    }
    A.incref(A.zero);
    return A.zero;
}

/* GTE_Wait(ms): the wait's common case in C.
 *
 * A program paced by waits (a pass of reads, GTE_Wait(1)) runs every millisecond's cycle in
 * its wait; in Python (gtecat.gt.fast's wait, Controller.wait_quick) each cost ~7-11 us
 * besides the kernel's cycles: the checks of the clock's and the bank's layers, the book, the
 * arming of the next due cycle for the readers' entries.  Here the wait runs on that armed
 * quick cycle (Controller.arm_quick; on the lockstep clock too, where a C entry waits): ms an
 * exact int or float from 0 to one slice of a long wait, its ns as the Python path makes them
 * (a float's rounded half to even, as round()), the GT_ gate open with its wait's numbers
 * (at: set by gtecat.gt.fast.set_gates), the session's last error and note None (a wait
 * clears the one and would report the other), the armed cycle standing (armed_now, asked
 * again with the clock's lock held) with its book in C and the wait's own conditions met
 * (b[15]: Controller._waits_in_c), the cycles due no more than one run and the cycle hooks'
 * quiet budget.  Then the latency pending grows by the wait's time and the cycles it makes due
 * run in one call of the kernel; a run that went whole (no move ended, none declined) is
 * counted by book_n - the counts of n cycles, the epoch grown once - and stays armed for
 * the next; any other is counted by the controller's waited(rc, pending) in Python with
 * the rest of the wait (wait_python), which answers the call.  Every other call, any doubt:
 * the Python fast function with the same arguments, which answers as before.  On the auto
 * clock the call's host latency follows, as a reader's (done). */
struct wait_entry {
    obj fallback; /* the Python fast function */
    obj after;    /* the call's host latency on the auto clock (a reader's after()) */
    obj rest;     /* rest(rc, pending): the Python book and the rest of a wait, its code */
    obj session;  /* the GT session's own dict: its last error and note */
    obj key_last, key_note;
    long long most;  /* the longest wait in ms (one slice of a long wait) */
    long long batch; /* the most cycles of one run (Controller.BATCH_CYCLES) */
    long long maxc;  /* the kernel's io slot of the cycles a call runs (IN_MAXC) */
    /* the GT_ gate's controller: [0] its clock's quick numbers, [1] its armed cycle's book in
     * C (Controller.quick_cbook); 0: no wait here (gtecat.gt.fast.set_gates) */
    const ptrdiff_t *at;
};

/* A wait's ms (an exact int or float from 0 to most) in ns, as the Python path makes them;
 * 0: not such a number. */
static int wait_ns(const struct wait_entry *e, obj x, long long *ns)
{
    long long v;
    double d, t, f;
    if (TYPE(x) == A.int_type) {
        if (!ll_of(x, &v) || v < 0 || v > e->most)
            return 0;
        *ns = v * 1000000;
        return 1;
    }
    if (TYPE(x) != A.float_type)
        return 0;
    memcpy(&d, (char *)x + A.fval, sizeof d);
    if (!(d >= 0.0 && d <= (double)e->most)) /* (NaN: never) */
        return 0;
    t = d * 1000000.0;
    v = (long long)t; /* (t >= 0: its floor; t - v exact below 2^52) */
    f = t - (double)v;
    if (f > 0.5 || (f == 0.5 && (v & 1)))
        v++;
    *ns = v;
    return 1;
}

static obj wait_call(const struct wait_entry *e, obj const *args, ptrdiff_t nargs, obj kwnames)
{
    long long total, *q, *b, *io, pend, dt, n, rc;
    const long long *call;
    obj release, res, v[2], last, note;
    if (!ready || kwnames || nargs != 1 || !A.gate[0] || !e->at[0] || !e->at[1] ||
        !wait_ns(e, args[0], &total))
        goto python;
    q = (long long *)e->at[0];
    b = (long long *)e->at[1];
    last = A.dict_get(e->session, e->key_last);
    note = A.dict_get(e->session, e->key_note);
    if (last != A.none || note != A.none || b[0] != 1 || !b[15] || !armed_now(q))
        goto python;
    release = hold(1);
    if (!release) {
        A.err_clear();
        goto python;
    }
    if (release == A.none) /* (no lock known for the gate: the Python path) */
        goto python;
    /* (with the lock held: another thread's call or cycles may have come first, its
     * session another controller) */
    if (!A.gate[0] || (long long *)e->at[0] != q || (long long *)e->at[1] != b || b[0] != 1 ||
        !b[15] || !armed_now(q))
        goto unlock;
    dt = q[2];
    pend = q[0] + total;
    if (pend < dt) {
        q[0] = pend;
        let_go(release);
        goto after;
    }
    n = pend / dt;
    call = (const long long *)q[8];
    io = (long long *)b[1];
    if (n > e->batch || q[11] < n || !io || (long long)io != call[2])
        goto unlock;
    q[4] = 0; /* (the book arms the next one) */
    q[0] = pend;
    io[b[10]] = q[9];
    io[e->maxc] = n;
    io_outputs(call);
    rc = ((kernel_run)call[0])((void *)call[1], (void *)call[2], (void *)call[3]);
    io[e->maxc] = 1; /* (the armed call's: one cycle) */
    if (!rc && io[b[8]] == n && book_n(b, q, n)) {
        q[0] = pend - n * dt;
        q[11] -= n;
        let_go(release);
        goto after;
    }
    /* (a move ended, a cycle declined, the run short: the Python book and the rest) */
    v[0] = A.long_from(rc);
    v[1] = v[0] ? A.long_from(pend) : NULL;
    if (!v[1]) {
        if (v[0])
            A.decref(v[0]);
        let_go(release);
        return NULL;
    }
    res = A.vectorcall(e->rest, v, 2, NULL);
    A.decref(v[0]);
    A.decref(v[1]);
    let_go(release);
    return res;
after:
    return done(e->after, 1);
unlock:
    let_go(release);
python:
    return A.vectorcall(e->fallback, args, (size_t)nargs, kwnames);
}

/* METH_FASTCALL | METH_KEYWORDS: self is the entry's ctypes object */
obj gtecat_centry_wait(obj self, obj const *args, ptrdiff_t nargs, obj kwnames)
{
    return wait_call((const struct wait_entry *)AT(self, A.b_ptr), args, nargs, kwnames);
}

/* A call with keywords (GT_GetSts(axis=1, pSts=byref(s))) whose names are the function's
 * next parameters in their order (names: the tuple of them all, the word after an entry
 * callable's weak-reference list; NULL: none known) is its positional call: the values
 * follow the positional ones in args already.  The names are compared as objects (the
 * compiler interns a call's keyword names, the loader the parameters'): any other name, order
 * or spelling keeps its keywords, and the Python path answers it. */
static void positional(obj callable, ptrdiff_t *nargs, obj *kwnames)
{
    obj names = *(obj *)((char *)callable + A.vc_entry + 3 * (ptrdiff_t)sizeof(obj));
    ptrdiff_t nk, nn, k;
    obj *kw, *nm;
    if (!names || !*kwnames)
        return;
    nk = *(ptrdiff_t *)((char *)*kwnames + A.bsize);
    nn = *(ptrdiff_t *)((char *)names + A.bsize);
    if (nk <= 0 || *nargs + nk > nn)
        return;
    kw = (obj *)((char *)*kwnames + A.tuple_items);
    nm = (obj *)((char *)names + A.tuple_items) + *nargs;
    for (k = 0; k < nk; k++)
        if (kw[k] != nm[k])
            return;
    *nargs += nk;
    *kwnames = NULL;
}

obj gtecat_centry_wait_vc(obj callable, obj const *args, size_t nargsf, obj kwnames)
{
    ptrdiff_t nargs = (ptrdiff_t)(nargsf & ~VECTORCALL_OFFSET);
    positional(callable, &nargs, &kwnames);
    return wait_call((const struct wait_entry *)AT(callable, A.vc_entry), args, nargs, kwnames);
}

/* The index of tp among the NULL-ended types (at most n of them), its size and sign in
 * *size and *sign; -1 where it is not among them. */
static int find_type(obj const *types, const ptrdiff_t *sizes, const ptrdiff_t *signs, int n,
                     obj tp, int *size, int *sign)
{
    int k;
    for (k = 0; k < n && types[k]; k++) {
        if (types[k] == tp) {
            *size = (int)sizes[k];
            *sign = (int)signs[k];
            return k;
        }
    }
    return -1;
}

static char *reader_mem(obj p, obj target, obj deref);

/* The memory of p - byref(x) with no offset, or x itself - where x's type is one of the
 * NULL-ended types (at most n), its size and sign in *size and *sign; NULL where it is not
 * (reader_mem: what proves the memory). */
static char *typed_mem(obj p, obj const *types, const ptrdiff_t *sizes, const ptrdiff_t *signs,
                       const ptrdiff_t *derefs, int n, int *size, int *sign)
{
    obj target = p, tp = TYPE(p);
    int k;
    if (tp == A.carg_type) {
        target = AT(p, A.carg_obj);
        if (!target)
            return NULL;
        tp = TYPE(target);
    }
    if ((k = find_type(types, sizes, signs, n, tp, size, sign)) < 0)
        return NULL;
    return reader_mem(p, target, derefs ? (obj)derefs[k] : NULL);
}

/* a NULL pointer argument: None, 0, or a ctypes pointer (POINTER(t)(), c_void_p(),
 * c_char_p(None), ...) whose value is NULL */
static int null_arg(obj a)
{
    obj t;
    char *at;
    if (a == A.none || a == A.zero || int_is(a, 0))
        return 1;
    t = TYPE(a);
    if (TYPE(t) != A.pointer_meta && t != A.voidp_type && t != A.charp_type &&
        t != A.wcharp_type)
        return 0;
    at = AT(a, A.b_ptr);
    return at && !*(void **)at;
}

/* A span's pClock (or GT_GetClock's pLoop): NULL (omitted, None or 0: *mem NULL) or the
 * memory of byref(x) (no offset), x or pointer(x) of one of the entry's clock types (its
 * size and sign); 0 where this entry does not take it. */
static int clock_mem(const struct entry *e, obj pc, char **mem, int *size, int *sign)
{
    *mem = NULL;
    if (null_arg(pc))
        return 1;
    *mem = typed_mem(pc, e->ctypes_, e->csizes, e->csigns, e->cderefs, MAX_TYPES, size, sign);
    return *mem != NULL;
}

/* GT_GetClock's value, which a reader writes into its pClock (the milliseconds since the
 * controller's GT_Reset, 32 bits: gtecat.controller.core.Controller.clock_ms): per gate the
 * address of its controller's time in ns (Clock.now_ns) and of the time GT_Reset counted
 * from (Controller.reset_ns), both int64 (0: none; set by gtecat_centry_clock_ms while the
 * gates are closed).  Read with no Python between the read and the write, as the values. */
static const ptrdiff_t *clock_ms_at;

int gtecat_centry_clock_ms(const ptrdiff_t *at)
{
    clock_ms_at = at;
    return 0;
}

/* Gate g's clock's cycles run in *cycles (Clock.cycles, the word after its now_ns in the
 * clock's quick array: gtecat.master.clock), 32 bits as GT_GetClock's pLoop stores them; 0
 * where the gate has none (the Python path answers). */
static int clock_cycles(ptrdiff_t g, long long *cycles)
{
    const long long *now;
    if (!clock_ms_at || g < 1 || g > 2 || !(now = (const long long *)clock_ms_at[2 * g - 2]))
        return 0;
    *cycles = now[1] & 0xFFFFFFFFLL;
    return 1;
}

/* Gate g's clock value in *ms (Python's ((now - reset) // 1000000) & 0xFFFFFFFF); 0 where
 * the gate has none (the Python path answers). */
static int clock_ms(ptrdiff_t g, long long *ms)
{
    /* (the last difference and its value: a poll asks again before the clock moves on) */
    static long long last_d = -1, last_ms;
    const long long *now, *origin;
    long long d, q;
    if (!clock_ms_at || g < 1 || g > 2 || !(now = (const long long *)clock_ms_at[2 * g - 2]) ||
        !(origin = (const long long *)clock_ms_at[2 * g - 1]))
        return 0;
    d = *now - *origin;
    if (d == last_d && d >= 0) {
        *ms = last_ms;
        return 1;
    }
    q = d / 1000000;
    if (d % 1000000 < 0) /* (floor division, as Python's) */
        q -= 1;
    *ms = q & 0xFFFFFFFFLL;
    last_d = d, last_ms = *ms;
    return 1;
}

/* The clock value for a reader's pClock, or 0 where it must go the Python way: no clock
 * known for the entry's gate, or a value the pClock's type does not hold (the table path
 * refuses it). */
static int clock_for(const struct entry *e, int csize, int csign, long long *ms)
{
    return clock_ms(e->gate, ms) && fits(*ms, csize, csign);
}

/* A pClock looked at again once the value is made where Python ran for it (ran: its memory
 * may have moved, its type changed; where no Python ran nothing could change it: the first
 * look stands) and its value, clock_for's: 0 where the call must go the Python way. */
static int clock_again(const struct entry *e, obj pc, char **mem, int *size, int *sign,
                       long long *ms, int ran)
{
    if (ran && !(clock_mem(e, pc, mem, size, sign) && *mem))
        return 0;
    return clock_for(e, *size, *sign, ms);
}

/* A span's first axis and count, both exact ints a long long holds: 0 where they are not
 * (any error the conversion raised cleared; the Python way answers). */
static int span_args(obj first, obj count, long long *an, long long *ac)
{
    int over = 0;
    if (TYPE(count) != A.int_type)
        return 0;
    *an = A.as_ll(first, &over);
    if (!over)
        *ac = A.as_ll(count, &over);
    if (over || A.err_occurred()) {
        if (A.err_occurred())
            A.err_clear();
        return 0;
    }
    return 1;
}

/* The ctypes array a reader's value pointer p passes: p itself, or the array of
 * byref(array[, offset]) (C's &array[k]); NULL where p is neither. */
static obj array_of(obj p)
{
    obj t;
    if (TYPE(TYPE(p)) == A.array_meta)
        return p;
    if (TYPE(p) == A.carg_type && (t = AT(p, A.carg_obj)) != NULL &&
        TYPE(TYPE(t)) == A.array_meta)
        return t;
    return NULL;
}

/* Where n bytes (count whole elements of arr's, each of stride bytes apart where stride is
 * not 0) go for p (array_of(p) is arr): the array's start, or the address byref(arr, offset)
 * passes where that is inside the array at a whole element and the n bytes end within the
 * object (the table path's room check: ctypes.sizeof
 * of the object); NULL: not proven (the Python path answers, or refuses as the table does).
 * Looked up after the values: Python may have run. */
static char *array_mem(obj p, obj arr, ptrdiff_t n, long long count, ptrdiff_t stride)
{
    char *base = AT(arr, A.b_ptr), *to;
    ptrdiff_t off;
    if (!base)
        return NULL;
    if (p == arr)
        return base;
    if (TYPE(p) != A.carg_type || AT(p, A.carg_obj) != arr || count < 1 || n <= 0 ||
        n % count)
        return NULL;
    to = AT(p, A.carg_value);
    off = to - base;
    if (off < 0 || off % (stride ? stride : n / (ptrdiff_t)count) ||
        off + n > *(ptrdiff_t *)((char *)arr + A.b_size))
        return NULL;
    return to;
}

/* A reader's ctypes array (count from n, pClock NULL or a clock's pointer): the bytes
 * avalue(n, count, array type, clock) gives (clock None or 1: then the clock's value
 * follows the values as an int64) copied to its start, kept for the epoch. */
/* avalue's answer where it must not stand (not bytes): the Python path answers */
static char python_mark;
#define PYTHON ((obj)&python_mark)

/* The bytes avalue(call[0..3]) gives for a ctypes array of type call[2] (n an, count ac,
 * clock asked: clk), kept in the entry's slot for the epoch: a new reference; PYTHON (not
 * bytes: the Python path answers), AGAIN (another thread's cycle or call meanwhile), or NULL
 * with the value's own error. */
/* One C-contiguous dimension of int64 or float64 (what the source was said to be): its data
 * and length, NULL where it is not such an array */
static const char *vector(obj a, ptrdiff_t *len)
{
    if (!A.ndarray_type || TYPE(a) != A.ndarray_type || *(int *)((char *)a + A.nd_nd) != 1 ||
        !AT(a, A.nd_dims) || (*(int *)((char *)a + A.nd_flags) & A.nd_want) != A.nd_want)
        return NULL;
    *len = *(ptrdiff_t *)AT(a, A.nd_dims);
    return AT(a, A.nd_data);
}

/* count doubles made again from the arrays a value was kept with, as its value function made
 * them (the same IEEE operations in the same order), into out: for the k-th, its row r
 * (rows[k]) and x =
 *   op 0: src[idx[r]] (idx NULL: src[r])   (a planned value of the Trap table, a row's own)
 *   op 1: src[r] / t                       (an encoder's speed: its last step over a cycle)
 *   op 2: (src[r] / t - idx[r] / t) / t    (its acceleration: the last two steps)
 * then ratios[k] * x where ratios are given; or, ratios giving each value's link (ratio,
 * offset) and axis(e) its AffineLink.axis (ratio 1: e + offset where offset is not 0,
 * else e; else ratio * e + offset):
 *   op 3: axis(src[r])                     (the axis's encoder position)
 *   op 4: src[r] - axis(idx[r])            (the axis's error: planned less encoder)  0 where an index falls outside an array (the
 * Python way answers).  gather: a span's, as a new bytes object (NULL, no error left: the
 * Python way). */
static int make_doubles(const struct recipe *rc, long long count, double *out)
{
    obj src_ = rc->src, idx_ = rc->idx, rows_ = rc->rows, ratios_ = rc->ratios;
    long long op = rc->op;
    double t = rc->t;
    ptrdiff_t slen = 0, ilen = 0;
    const double *src = (const double *)vector(src_, &slen), *fidx = NULL, *ratios = NULL;
    const int64_t *idx = NULL, *rows;
    double x;
    long long k, r, i;
    if (!src || count < 1 || op < 0 || op > 4 || TYPE(rows_) != A.bytes_type ||
        *(ptrdiff_t *)((char *)rows_ + A.bsize) != count * 8)
        return 0;
    rows = (const int64_t *)((char *)rows_ + A.bdata);
    if (op >= 3 && !ratios_) /* (a link's ratio and offset per value) */
        return 0;
    if (ratios_) {
        if (TYPE(ratios_) != A.bytes_type ||
            *(ptrdiff_t *)((char *)ratios_ + A.bsize) != count * (op >= 3 ? 16 : 8))
            return 0;
        ratios = (const double *)((char *)ratios_ + A.bdata);
    }
    if (idx_) {
        const char *d = vector(idx_, &ilen);
        if (!d)
            return 0;
        idx = (const int64_t *)d, fidx = (const double *)d;
    } else if (op == 2 || op == 4)
        return 0;
    for (k = 0; k < count; k++) {
        r = rows[k];
        if (r < 0 || r >= slen || (idx && r >= ilen))
            return 0;
        if (op == 0) {
            i = idx ? idx[r] : r;
            if (i < 0 || i >= slen)
                return 0;
            x = src[i];
        } else if (op == 1)
            x = src[r] / t;
        else if (op == 2)
            x = (src[r] / t - fidx[r] / t) / t;
        else { /* (AffineLink.axis of the encoder's position, its two branches) */
            double ratio = ratios[2 * k], offset = ratios[2 * k + 1], e = op == 3 ? src[r] : fidx[r];
            double ax = ratio == 1.0 ? (offset != 0.0 ? e + offset : e) : ratio * e + offset;
            out[k] = op == 3 ? ax : src[r] - ax;
            continue;
        }
        out[k] = ratios ? ratios[k] * x : x;
    }
    return 1;
}

static obj gather(const struct aslot *s, long long count)
{
    obj v = A.bytes_new(NULL, (ptrdiff_t)(count * 8));
    if (!v) {
        A.err_clear();
        return NULL;
    }
    if (!make_doubles(&s->rc, count, (double *)((char *)v + A.bdata))) {
        A.decref(v);
        return NULL;
    }
    return v;
}

/* The recipe in a value function's (value, op, src, idx or None, rows, ratios or None, t)
 * (items: the tuple's), its references taken: 1; 0 where it is not one (nothing taken). */
static int take_recipe(obj *items, struct recipe *rc)
{
    ptrdiff_t len;
    if (!(ll_of(items[1], &rc->op) && vector(items[2], &len) &&
          (items[3] == A.none || vector(items[3], &len)) && TYPE(items[4]) == A.bytes_type &&
          (items[5] == A.none || TYPE(items[5]) == A.bytes_type) &&
          TYPE(items[6]) == A.float_type))
        return 0;
    rc->src = items[2];
    rc->idx = items[3] == A.none ? NULL : items[3];
    rc->rows = items[4];
    rc->ratios = items[5] == A.none ? NULL : items[5];
    rc->t = *(double *)((char *)items[6] + A.fval);
    A.incref(rc->src);
    A.incref(rc->rows);
    if (rc->idx)
        A.incref(rc->idx);
    if (rc->ratios)
        A.incref(rc->ratios);
    return 1;
}

/* The slot among the lanes s (n of them) for the span (an, ac, tp, clk): its lane, else the
 * lane to keep it in (a free one, else the one asked least recently: the lowest epoch), NULL
 * where none is kept. */
static struct aslot *lane(struct aslot *s, ptrdiff_t n, long long an, long long ac, obj tp,
                          long long clk)
{
    static size_t turn; /* (the lanes taken in turn where none is older) */
    struct aslot *pick;
    ptrdiff_t k;
    long long newest;
    if (!s)
        return NULL;
    if (n < 1)
        n = 1;
    pick = s;
    newest = s[0].epoch;
    for (k = 0; k < n; k++) {
        if (s[k].value && s[k].n == an && s[k].count == ac && s[k].tp == tp && s[k].clock == clk)
            return &s[k];
        if (pick->value && (!s[k].value || s[k].epoch < pick->epoch))
            pick = &s[k];
        if (s[k].epoch > newest)
            newest = s[k].epoch;
    }
    /* every lane full and of the same epoch (a lockstep program reading ranges in turn,
     * no cycle between): not always the first, which two ranges read in turn would take
     * from each other at every call */
    if (pick->value && pick->epoch == newest)
        pick = &s[turn++ % (size_t)n];
    return pick;
}

static obj array_value(const struct entry *e, obj *call, long long an, long long ac,
                       long long clk, int locked, int *ran)
{
    struct aslot *s = lane(e->acache, e->nacache, an, ac, call[2], clk);
    struct recipe rc = {0};
    long long ep = -1, ep0 = -1;
    int holds = 0;
    obj v, tp = call[2];
    *ran = 0;
    if (s && (ep = epoch()) >= 0 && s->value && s->n == an && s->count == ac && s->tp == tp &&
        s->clock == clk &&
        (s->epoch == ep ||
         (s->holds && ep > s->epoch && ep - s->epoch == flag_keeping - s->keeps) ||
         (e->steady && ep > s->epoch && ep - s->epoch == c_booked - s->booked))) {
        /* (status words across cycles that kept every flag, a steady entry's values across
         * cycles booked in C: the same) */
        s->epoch = ep;
        s->keeps = flag_keeping;
        s->booked = c_booked;
        A.incref(s->value);
        return s->value;
    }
    if (s && ep >= 0 && s->rc.src && s->value && s->n == an && s->count == ac && s->tp == tp &&
        s->clock == clk && ep > s->epoch && ep - s->epoch == c_booked - s->booked &&
        (v = gather(s, ac)) != NULL) {
        /* (the doubles of the same rows after cycles booked in C: from the same arrays) */
        obj old = s->value;
        s->value = v;
        s->epoch = ep;
        s->booked = c_booked;
        A.decref(old);
        A.incref(v);
        return v;
    }
    if (!locked)
        ep0 = epoch();
    *ran = 1;
    v = A.vectorcall(e->avalue, call, 4, NULL);
    if (!v)
        return NULL;
    if (e->tuple_type && TYPE(v) == e->tuple_type &&
        *(ptrdiff_t *)((char *)v + A.bsize) == 1) { /* (bytes,): status words alone */
        obj b = *(obj *)((char *)v + e->titems);
        A.incref(b);
        A.decref(v);
        v = b;
        holds = 1;
    } else if (e->tuple_type && TYPE(v) == e->tuple_type &&
               *(ptrdiff_t *)((char *)v + A.bsize) == 7) {
        /* (bytes, op, src, idx or None, rows, ratios or None, t): doubles made again from
         * there (gather) */
        obj *items = (obj *)((char *)v + e->titems), b = items[0];
        if (!(TYPE(b) == A.bytes_type && *(ptrdiff_t *)((char *)b + A.bsize) == ac * 8 &&
              take_recipe(items, &rc)))
            rc.src = NULL;
        A.incref(b);
        A.decref(v);
        v = b;
    }
    if (TYPE(v) != A.bytes_type || (!locked && !stands(e->gate, ep0))) {
        obj r = TYPE(v) != A.bytes_type ? PYTHON : AGAIN;
        A.decref(v);
        let_recipe_go(&rc);
        return r;
    }
    if (s && ep >= 0) {
        keep_span(s, ep, v, tp, an, ac, clk);
        s->holds = holds;
        s->keeps = flag_keeping;
        s->rc = rc; /* (its references the slot's now) */
        s->booked = c_booked;
    } else
        let_recipe_go(&rc);
    return v;
}

static obj array(const struct entry *e, obj const *args, ptrdiff_t nargs, obj kwnames,
                 ptrdiff_t at, obj arr, int locked)
{
    obj call[4], v, tp = TYPE(arr);
    ptrdiff_t n;
    long long an, ac, clk = 0;
    char *cmem = NULL, *mem;
    int csize = 0, csign = 1, ran;
    call[0] = args[at];
    call[1] = nargs >= 3 + at ? args[at + 2] : A.one;
    if (!span_args(call[0], call[1], &an, &ac))
        goto python;
    if (nargs >= 4 + at && !clock_mem(e, args[at + 3], &cmem, &csize, &csign))
        goto python;
    call[2] = tp;
    call[3] = A.none; /* (the values alone: a pClock's value is written here, clock_for) */
    v = array_value(e, call, an, ac, 0, locked, &ran);
    if (!v || v == AGAIN)
        return v;
    if (v == PYTHON)
        goto python;
    n = *(ptrdiff_t *)((char *)v + A.bsize);
    if (n <= 0)
        goto drop;
    if (cmem && !clock_again(e, args[at + 3], &cmem, &csize, &csign, &clk, ran))
        goto drop;
    /* (avalue checked the array's type and length: the bytes fit its start; an offset's
     * room: array_mem) */
    mem = array_mem(args[at + 1], arr, n, ac, e->stride);
    if (!mem)
        goto drop;
    memcpy(mem, (char *)v + A.bdata, (size_t)n);
    if (cmem)
        put(cmem, clk, csize);
    A.decref(v);
    return done(e->after, e->gate);
drop:
    A.decref(v);
python:
    return A.vectorcall(e->fallback, args, (size_t)nargs, kwnames);
}

static char *np_mem(const struct entry *e, obj p, int *size, int *sign);

/* A reader's numpy array of count >= 2 values from n (pClock NULL or a clock's pointer):
 * the bytes avalue(n, count, the array's dtype, None) gives (of the entry's dtypes, one
 * C-contiguous writable dimension of at least count elements: np_mem, before and after)
 * copied to its start, kept for the epoch as array()'s. */
static obj np_array(const struct entry *e, obj const *args, ptrdiff_t nargs, obj kwnames,
                    ptrdiff_t at, int locked)
{
    obj call[4], v, p = args[at + 1];
    ptrdiff_t n;
    long long an, ac, clk = 0;
    char *cmem = NULL, *mem;
    int csize = 0, csign = 1, size = 0, sign = 1, ran;
    call[0] = args[at];
    call[1] = args[at + 2];
    if (!span_args(call[0], call[1], &an, &ac) || !(mem = np_mem(e, p, &size, &sign)))
        goto python;
    if (nargs >= 4 + at && !clock_mem(e, args[at + 3], &cmem, &csize, &csign))
        goto python;
    if (ac < 2 || *(ptrdiff_t *)AT(p, A.nd_dims) < ac)
        goto python;
    call[2] = (obj)AT(p, A.nd_descr);
    call[3] = A.none; /* (the values alone: a pClock's value is written here, clock_for) */
    v = array_value(e, call, an, ac, 0, locked, &ran);
    if (!v || v == AGAIN)
        return v;
    if (v == PYTHON)
        goto python;
    n = *(ptrdiff_t *)((char *)v + A.bsize);
    if (cmem && !clock_again(e, args[at + 3], &cmem, &csize, &csign, &clk, ran))
        goto drop;
    if (ran) /* (again where Python ran: the array may have changed meanwhile) */
        mem = np_mem(e, p, &size, &sign);
    /* (and the bytes fit: count whole values) */
    if (!mem || *(ptrdiff_t *)AT(p, A.nd_dims) < ac || (obj)AT(p, A.nd_descr) != call[2] ||
        n != ac * (long long)size)
        goto drop;
    memcpy(mem, (char *)v + A.bdata, (size_t)n);
    if (cmem)
        put(cmem, clk, csize);
    A.decref(v);
    return done(e->after, e->gate);
drop:
    A.decref(v);
python:
    return A.vectorcall(e->fallback, args, (size_t)nargs, kwnames);
}

/* A one-pointer reader's ctypes array (f(p[, NULL]): noaxis): the bytes avalue(0, 1, array
 * type, None) gives (its value in the first element; it checks the array's type and
 * length) copied to the array's start, kept for the epoch as array()'s. */
static obj first_of(const struct entry *e, obj const *args, ptrdiff_t nargs, obj kwnames,
                    obj arr, int locked)
{
    obj call[4], v;
    ptrdiff_t n;
    char *mem;
    int ran;
    call[0] = A.zero;
    call[1] = A.one;
    call[2] = TYPE(arr);
    call[3] = A.none;
    v = array_value(e, call, 0, 1, 0, locked, &ran);
    if (!v || v == AGAIN)
        return v;
    if (v == PYTHON)
        goto python;
    n = *(ptrdiff_t *)((char *)v + A.bsize);
    mem = array_mem(args[0], arr, n, 1, e->stride); /* (again: Python may have run) */
    if (n <= 0 || !mem) {
        A.decref(v);
        goto python;
    }
    memcpy(mem, (char *)v + A.bdata, (size_t)n);
    A.decref(v);
    return done(e->after, e->gate);
python:
    return A.vectorcall(e->fallback, args, (size_t)nargs, kwnames);
}

/* the reader entry's work (both ways of calling it, below): reader_try, then ANSWER */
static obj reader(const struct entry *e, obj const *args, ptrdiff_t nargs, obj kwnames);

/* METH_FASTCALL | METH_KEYWORDS: self is the entry's ctypes object */
obj gtecat_centry_reader(obj self, obj const *args, ptrdiff_t nargs, obj kwnames)
{
    return reader((const struct entry *)AT(self, A.b_ptr), args, nargs, kwnames);
}

/* a vectorcall function: the callable keeps its entry's address at A.vc_entry */
obj gtecat_centry_reader_vc(obj callable, obj const *args, size_t nargsf, obj kwnames)
{
    ptrdiff_t nargs = (ptrdiff_t)(nargsf & ~VECTORCALL_OFFSET);
    positional(callable, &nargs, &kwnames);
    return reader((const struct entry *)AT(callable, A.vc_entry), args, nargs, kwnames);
}

/* The first element of a numpy array p an entry takes (one dimension, at least one element,
 * C-contiguous, aligned, writable, of one of the entry's dtypes), its size and sign; NULL
 * where the entry does not take it.  Looked up before and after the value function, as
 * reader_mem is. */
static char *np_mem(const struct entry *e, obj p, int *size, int *sign)
{
    if (*(int *)((char *)p + A.nd_nd) != 1 || !AT(p, A.nd_dims) ||
        *(ptrdiff_t *)AT(p, A.nd_dims) < 1 ||
        (*(int *)((char *)p + A.nd_flags) & A.nd_want) != A.nd_want)
        return NULL;
    if (find_type(e->nptypes, e->npsizes, e->npsigns, 8, (obj)AT(p, A.nd_descr), size,
                  sign) < 0)
        return NULL;
    return AT(p, A.nd_data);
}

/* The memory a reader writes for p (target: p, or a byref's object), or NULL where this
 * entry cannot prove it (the Python path decides).  Looked up before the value function, to
 * know the shape, and again after it: the value function is Python, and meanwhile another
 * thread or a collector callback may re-point a pointer (freeing its old object) or resize a
 * ctypes object (ctypes.resize moves its memory); nothing of Python runs between the second
 * look-up and the write. */
static char *reader_mem(obj p, obj target, obj deref)
{
    char *mem = AT(target, A.b_ptr);
    if (deref) {
        /* pointer(x) itself (not a byref of it): x's memory, only where the pointer is
         * pointer(x) (or p.contents = x) of an x of exactly the pointer's _type_ that it keeps
         * and points at exactly; a cast (of other memory, an address, numpy's data_as, or of
         * pointer(y) to another type: ctypes.cast hands the source's kept objects on) proves
         * no size behind it */
        char *to;
        obj kept, x;
        if (target != p || !mem || !(to = *(char **)mem))
            return NULL;
        kept = AT(p, A.b_objects);
        if (!kept || TYPE(kept) != A.dict_type)
            return NULL;
        x = A.dict_get(kept, A.key_one);
        if (!x || TYPE(x) != deref || AT(x, A.b_ptr) != to)
            return NULL;
        return to;
    }
    if (target != p && AT(p, A.carg_value) != mem)
        return NULL; /* byref(x, offset), or x's memory moved since the byref was made */
    return mem;
}

/* A reader's call with memoryview(arr) for *pValue: the call with arr (e->viewer's answer:
 * the view shows all of it, its element type is the reader's), else the Python path's. */
static obj viewed(const struct entry *e, obj const *args, ptrdiff_t nargs, ptrdiff_t at)
{
    obj a2[8], q, r;
    ptrdiff_t k;
    q = A.vectorcall(e->viewer, &args[at + 1], 1, NULL);
    if (!q)
        return NULL; /* (its own error, as the Python path would raise it) */
    if (q == A.none) {
        A.decref(q);
        return A.vectorcall(e->fallback, args, (size_t)nargs, NULL);
    }
    for (k = 0; k < nargs; k++)
        a2[k] = args[k];
    a2[at + 1] = q;
    r = reader(e, a2, nargs, NULL);
    A.decref(q);
    return r;
}

TRY reader_try(const struct entry *e, obj const *args, ptrdiff_t nargs, obj kwnames,
               int locked)
{
    ptrdiff_t at = e->core;
    obj p, target, tp, v, arr;
    char *mem = NULL, *cmem = NULL, *lmem = NULL;
    obj deref = NULL;
    int k, size = 0, sign = 1, npy = 0, csize = 0, csign = 1, lsize = 0, lsign = 1, ran = 0;
    int holds = 0;
    struct recipe rc = {0};
    long long key = -1, ep = -1, ep0 = -1, clk = 0, loop = 0;
    obj axis = NULL; /* the axis value() answers: args[at], or a core view's bus axis */

    if (!ready || kwnames || (e->gate && !A.gate[e->gate - 1]))
        goto python;
    if (!locked && elsewhere(e->gate))
        return AGAIN; /* (the Python path too answers holding the lock then) */
    if (e->noaxis) {
        if (nargs < 1 || nargs > 2 || nargs > e->most)
            goto python;
        /* q NULL, or (the entry's clock types: GT_GetClock's pLoop) byref(x), x or pointer(x):
         * the clock's cycles run written there too (clock_cycles) */
        if (nargs == 2 && !null_arg(args[1]) &&
            (!e->ctypes_[0] || !clock_mem(e, args[1], &lmem, &lsize, &lsign) || !lmem))
            goto python;
        p = args[0];
        if (e->avalue && (arr = array_of(p)) != NULL) {
            if (lmem)
                goto python;
            return first_of(e, args, nargs, kwnames, arr, locked);
        }
    } else {
        if (nargs < 2 + at || nargs > e->most + at)
            goto python;
        axis = args[at];
        if (at && !int_is(args[0], 1)) {
            /* another core: one value, no array (those paths read args[at] themselves) */
            if (!(axis = view_axis(args[0], args[at])) || (e->avalue && array_of(args[at + 1])))
                goto python;
        }
        if (TYPE(axis) != A.int_type)
            goto python;
        if (axis == args[at] && e->viewer && TYPE(args[at + 1]) == A.memoryview_type &&
            nargs <= 8)
            return viewed(e, args, nargs, at);
        if (axis == args[at] && e->avalue && (arr = array_of(args[at + 1])) != NULL)
            return array(e, args, nargs, kwnames, at, arr, locked);
        /* a numpy array of several values (count 2 or more) */
        if (e->avalue && e->nptypes[0] && nargs >= 3 + at &&
            TYPE(args[at + 1]) == A.ndarray_type && args[at + 2] != A.one &&
            !int_is(args[at + 2], 1)) {
            if (axis != args[at])
                goto python;
            return np_array(e, args, nargs, kwnames, at, locked);
        }
        /* (the cached small ints 1 and 0 first: one compare for the common literals) */
        if (nargs >= 3 + at && args[at + 2] != A.one && !int_is(args[at + 2], 1))
            goto python;
        /* pClock NULL (omitted, None, 0), or byref(x) or x of a clock type: written too */
        if (nargs >= 4 + at && args[at + 3] != A.none && args[at + 3] != A.zero &&
            !clock_mem(e, args[at + 3], &cmem, &csize, &csign))
            goto python;
        p = args[at + 1];
    }
    tp = TYPE(p);
    target = p;
    if (tp == A.ndarray_type && e->nptypes[0]) { /* a numpy array: its first element */
        if (!(mem = np_mem(e, p, &size, &sign)))
            goto python;
        npy = 1;
    } else {
        if (tp == A.carg_type) { /* byref(x) of an accepted x with no offset: x */
            target = AT(p, A.carg_obj);
            if (!target)
                goto python;
            tp = TYPE(target);
        }
        k = find_type(e->types, e->sizes, e->signs, MAX_TYPES, tp, &size, &sign);
        if (k < 0)
            goto python;
        deref = (obj)e->derefs[k];
        if (!(mem = reader_mem(p, target, deref)))
            goto python;
    }

    /* GT_GetClock's own value, the clock's, in C: value() would make the same from the same
     * two numbers (every cycle makes the value kept for an epoch stale: a poll paced by
     * GTE_Wait(1) would ask Python once a cycle); with a last error to clear, the value as
     * before (value() clears it) */
    if (e->session && A.dict_get(e->session, e->key_last) == A.none) {
        long long ms;
        if (!clock_ms(e->gate, &ms) || !fits(ms, size, sign) ||
            (lmem && (!clock_cycles(e->gate, &loop) || !fits(loop, lsize, lsign))))
            goto python;
        put(mem, ms, size);
        if (lmem)
            put(lmem, loop, lsize);
        return done(e->after, e->gate);
    }
    /* the value kept for this epoch, else value(n)'s (kept for it) */
    if (e->cache &&
        (v = kept(e->cache, e->ncache, e->noaxis ? NULL : axis, &key, &ep, (int)e->steady)) !=
            NULL)
        goto have;
    if (!locked)
        ep0 = epoch();
    ran = 1;
    v = e->noaxis ? A.vectorcall(e->value, NULL, 0, NULL)
                  : A.vectorcall(e->value, &axis, 1, NULL);
    if (!v)
        return NULL; /* (the value's own error, as the Python path would raise it) */
    if (v == e->sentinel)
        goto drop;
    if (e->kind == 0 && e->tuple_type && TYPE(v) == e->tuple_type &&
        *(ptrdiff_t *)((char *)v + A.bsize) == 1) { /* (word,): a status word of the bank's */
        obj w = *(obj *)((char *)v + e->titems);
        A.incref(w);
        A.decref(v);
        v = w;
        holds = 1;
    } else if (e->kind == 1 && e->tuple_type && TYPE(v) == e->tuple_type &&
               *(ptrdiff_t *)((char *)v + A.bsize) == 7) {
        /* (x, op, src, idx, rows, ratios, t): a double of the bank's and where it comes from */
        obj *items = (obj *)((char *)v + e->titems), w = items[0];
        if (TYPE(w) != A.float_type || !take_recipe(items, &rc))
            rc.src = NULL;
        A.incref(w);
        A.decref(v);
        v = w;
    }
    if (!locked && !stands(e->gate, ep0)) { /* (another thread's cycle or call meanwhile) */
        A.decref(v);
        let_recipe_go(&rc);
        return AGAIN;
    }
    if (key >= 0 && ep >= 0) {
        struct slot *sl = &e->cache[key];
        keep(sl, ep, v);
        sl->holds = holds;
        sl->rc = rc; /* (its references the slot's now) */
        rc.src = rc.idx = rc.rows = rc.ratios = NULL;
    }
    let_recipe_go(&rc);
have:
    /* q: the cycles run (again: Python ran; a number the type does not hold: Python's) */
    if (lmem && (!clock_cycles(e->gate, &loop) || !clock_mem(e, args[1], &lmem, &lsize, &lsign) ||
                 !lmem || !fits(loop, lsize, lsign)))
        goto drop;
    if (ran) /* (again where Python ran: see reader_mem) */
        mem = npy ? np_mem(e, p, &size, &sign) : reader_mem(p, target, deref);
    if (!mem)
        goto drop;
    if (cmem && !clock_again(e, args[at + 3], &cmem, &csize, &csign, &clk, ran))
        goto drop; /* (again, and its value: written after the value, as the Python path) */
    if (e->kind == 1) {
        if (TYPE(v) != A.float_type || size != 8)
            goto drop;
        *(double *)mem = *(double *)((char *)v + A.fval);
    } else if (e->kind == 2) {
        if (TYPE(v) != A.bytes_type || *(ptrdiff_t *)((char *)v + A.bsize) != size)
            goto drop;
        for (k = 0; k < size; k++)
            mem[k] = ((char *)v + A.bdata)[k];
    } else {
        int over = 0;
        long long x = A.as_ll(v, &over);
        if (x == -1 && !over && A.err_occurred()) {
            A.err_clear();
            goto drop;
        }
        if (over || !fits(x, size, sign)) /* (a value the type does not hold: the Python path) */
            goto drop;
        put(mem, x, size);
    }
    if (cmem)
        put(cmem, clk, csize);
    if (lmem)
        put(lmem, loop, lsize);
    A.decref(v);
    return done(e->after, e->gate);

drop:
    A.decref(v);
python:
    return A.vectorcall(e->fallback, args, (size_t)nargs, kwnames);
}

static obj reader_try_locked(const struct entry *e, obj const *args, ptrdiff_t nargs,
                             obj kwnames)
{
    return reader_try(e, args, nargs, kwnames, 1);
}

static obj reader(const struct entry *e, obj const *args, ptrdiff_t nargs, obj kwnames)
{
    ANSWER(reader_try, e, e->gate, args, nargs, kwnames);
}

/* a raw entry's write: GT_EcatIOBitWriteOutput's (one bit of one output byte) */
#define BIT_WRITE 2

/* a raw image function's entry */
struct raw_entry {
    obj fallback; /* the Python fast function */
    obj value;    /* value([slave,] offset, size, array type): the range's runs, or sentinel */
    obj sentinel;
    ptrdiff_t io;    /* 1: the slave first (GT_EcatIOReadInput / WriteOutput) */
    ptrdiff_t write; /* 1: from the buffer into the image; BIT_WRITE: a bit of it */
    ptrdiff_t gate;  /* 0: none; k: value only while A.gate[k - 1] is nonzero */
    obj after;       /* as struct entry's */
    /* the runs kept for their epoch, a lane per range (ncache of them; n: the offset,
     * count: the size, clock: the slave or -1), and across the cycles booked in C; NULL: none
     * kept.  The runs address the process image's buffer, which the value function keeps
     * alive while it is its image (and the image is replaced only by the calls that make the
     * epoch grow, so a lane of another image is never used); a sentinel empties the lanes. */
    struct aslot *cache;
    /* a writer's changed(): called where the write changed a byte of the image (the epoch
     * grows then, not in its value function, so a write of the bytes the image holds keeps
     * the readers' values, its runs and the armed quick cycle); NULL: the value function
     * makes the epoch grow at every write (nothing kept) */
    obj changed;
    /* the slots of cache: a lane per range a program reads in turn (0 or 1: the last's) */
    ptrdiff_t ncache;
    /* 1: changed is the epoch's own changed() (EPOCH.n += 1), done here without calling it */
    ptrdiff_t grow;
};

static obj raw(const struct raw_entry *e, obj const *args, ptrdiff_t nargs, obj kwnames);

obj gtecat_centry_raw(obj self, obj const *args, ptrdiff_t nargs, obj kwnames)
{
    return raw((const struct raw_entry *)AT(self, A.b_ptr), args, nargs, kwnames);
}

obj gtecat_centry_raw_vc(obj callable, obj const *args, size_t nargsf, obj kwnames)
{
    ptrdiff_t nargs = (ptrdiff_t)(nargsf & ~VECTORCALL_OFFSET);
    positional(callable, &nargs, &kwnames);
    return raw((const struct raw_entry *)AT(callable, A.vc_entry), args, nargs, kwnames);
}

/* Py_buffer (the buffer protocol's view, part of the stable ABI) and the request flags */
struct pybuf {
    void *buf;
    obj obj;
    ptrdiff_t len, itemsize;
    int readonly, ndim;
    char *format;
    ptrdiff_t *shape, *strides, *suboffsets;
    void *internal;
};
#define PYBUF_WRITABLE 0x0001
#define PYBUF_FORMAT 0x0004
#define PYBUF_C_CONTIGUOUS (0x0020 | 0x0010 | 0x0008)
/* numpy's NPY_ARRAY_C_CONTIGUOUS and NPY_ARRAY_WRITEABLE (public ndarraytypes.h) */
#define ND_C 0x0001
#define ND_W 0x0400

/* A buffer format the table path takes as plain memory (numpy reads it: one native number
 * type, or none given, which means bytes); anything else (Python objects, structures,
 * formats numpy does not read) the Python path answers. */
static int plain_format(const char *f)
{
    if (!f)
        return 1;
    if (*f == '@' || *f == '=' || *f == '<' || *f == '>' || *f == '!')
        f++;
    return f[0] && !f[1] && strchr("bBhHiIlLqQfd?", f[0]) != NULL;
}

/* A memoryview's (or a numpy array's of another kind than the bytes raw_mem takes) memory
 * as the table path takes it: C-contiguous (any shape), of a plain format (plain_format), at
 * least size bytes, writable to read into: the view held in *view (given back with
 * A.release_buffer; while held the memoryview cannot be released nor its bytearray resized,
 * nor the array's memory moved), its memory; NULL (nothing held, no error left) where it is
 * not. */
static char *view_mem(const struct raw_entry *e, obj p, long long size, struct pybuf *view)
{
    int flags = PYBUF_FORMAT | PYBUF_C_CONTIGUOUS | (e->write ? 0 : PYBUF_WRITABLE);
    if (A.get_buffer(p, view, flags)) {
        A.err_clear(); /* (released, read only, not contiguous: the Python path says) */
        return NULL;
    }
    if (view->len < size || !view->buf || !plain_format(view->format)) {
        A.release_buffer(view);
        return NULL;
    }
    return (char *)view->buf;
}

/* a ctypes object's type's metatype: an array, simple, structure or union type */
static int cdata_meta(obj m)
{
    return m == A.array_meta || m == A.simple_meta || m == A.struct_meta || m == A.union_meta;
}

/* The buffer a raw entry copies into or out of (target: p, or the array of a byref of one
 * with no offset), or NULL where this entry does not take it.  Looked up before the value
 * function (the shape) and again after it: the value function is Python, and meanwhile
 * another thread or a collector callback may resize a bytearray or a ctypes array
 * (ctypes.resize moves its memory); nothing of Python runs between the second look-up and
 * the copy.  A numpy array is the Python fast path's: exactly an ndarray of numpy's uint8,
 * one dimension, C-contiguous, at least size elements, writable to read into (a memoryview
 * has its own look-up: view_mem). */
static char *raw_mem(const struct raw_entry *e, obj p, obj target, long long size)
{
    obj t = TYPE(target);
    if (t == A.ndarray_type && A.np_u8) {
        int fl;
        if (target != p || *(int *)((char *)p + A.nd_nd) != 1 || !AT(p, A.nd_dims) ||
            *(ptrdiff_t *)AT(p, A.nd_dims) < size || (obj)AT(p, A.nd_descr) != A.np_u8)
            return NULL;
        fl = *(int *)((char *)p + A.nd_flags);
        if (!(fl & ND_C) || (!e->write && !(fl & ND_W)))
            return NULL;
        return AT(p, A.nd_data);
    }
    if (t == A.bytearray_type || (e->write && t == A.bytes_type)) {
        if (target != p || *(ptrdiff_t *)((char *)p + A.bsize) < size)
            return NULL;
        return t == A.bytes_type ? (char *)p + A.bdata : AT(p, A.bastart);
    }
    if (!cdata_meta(TYPE(t)))
        return NULL;
    if (target != p) {
        /* byref(x[, offset]) (C's &array[k], &x): its address, where the size's bytes from
         * there end within the object (the table path's room: ctypes.sizeof of it; any byte
         * offset, as the table path's byte pointer takes it); else (past the end, before
         * the start, the array's memory moved since) the Python path answers */
        char *base = AT(target, A.b_ptr), *to = AT(p, A.carg_value);
        if (!base || to < base || (to - base) + size > *(ptrdiff_t *)((char *)target + A.b_size))
            return NULL;
        return to;
    }
    return AT(target, A.b_ptr);
}

TRY raw_try(const struct raw_entry *e, obj const *args, ptrdiff_t nargs, obj kwnames,
            int locked)
{
    ptrdiff_t at = e->io, k, n;
    obj p, target, v, call[4], res;
    const int64_t *runs;
    long long size, off = 0, slave = -1, ep = -1, ep0 = -1, ep1 = -1, *qio = NULL;
    int over = 0, mv = 0, diff = 0, bit = -1, set = 0;
    char *mem;
    struct pybuf view;
    /* (a write's runs are kept only where the write makes the epoch grow itself) */
    struct aslot *s = e->write && !e->changed ? NULL : e->cache;

    if (!ready || kwnames || nargs != 3 + at || (e->gate && !A.gate[e->gate - 1]))
        goto python;
    if (!locked && elsewhere(e->gate))
        return AGAIN; /* (the Python path too answers holding the lock then) */
    for (k = 0; k < 2 + at; k++)
        if (TYPE(args[k]) != A.int_type)
            goto python;
    p = args[2 + at];
    target = p;
    if (e->write == BIT_WRITE) {
        /* GT_EcatIOBitWriteOutput(slave, offset, bit, value): bit 0..7, value 0 or 1, one
         * output byte (the value function's runs) set or cleared in place */
        long long b = A.as_ll(args[1 + at], &over);
        if (over || b < 0 || b > 7) {
            if (b == -1 && !over && A.err_occurred())
                A.err_clear();
            goto python;
        }
        bit = (int)b;
        if (p == A.one || int_is(p, 1))
            set = 1;
        else if (!(p == A.zero || int_is(p, 0)))
            goto python;
        size = 1;
        goto shaped;
    }
    if (TYPE(p) == A.carg_type) { /* byref(array[, offset]): the array (raw_mem) */
        target = AT(p, A.carg_obj);
        if (!target)
            goto python;
    }
    size = A.as_ll(args[1 + at], &over);
    if (over || size <= 0) {
        if (size == -1 && !over && A.err_occurred())
            A.err_clear();
        goto python;
    }
    if (TYPE(target) == A.memoryview_type ||
        (TYPE(target) == A.ndarray_type && !raw_mem(e, p, target, size))) {
        /* (held from here to the copy: nothing can release or resize it meanwhile; a numpy
         * array other than raw_mem's bytes: its memory as the buffer protocol gives it) */
        if (target != p || !view_mem(e, p, size, &view))
            goto python;
        mv = 1;
    } else if (!raw_mem(e, p, target, size)) {
        goto python;
    }
shaped:
    if (s) {
        off = A.as_ll(args[at], &over);
        if (!over && at)
            slave = A.as_ll(args[0], &over);
        if (over || A.err_occurred()) {
            if (A.err_occurred())
                A.err_clear();
            s = NULL;
        } else if ((s = lane(e->cache, e->ncache, off, size, TYPE(target), slave)) != NULL &&
                   (ep = epoch()) >= 0 && s->value && s->n == off && s->count == size &&
                   s->clock == slave && s->tp == TYPE(target) &&
                   (s->epoch == ep ||
                    (ep > s->epoch && ep - s->epoch == c_moved - s->booked))) {
            /* (the runs of the epoch they were asked in, and across cycles booked in C and
             * raw writes: those move the image's bytes, never its buffer, nor take a slave off
             * the bus) */
            s->epoch = ep;
            s->booked = c_moved;
            v = s->value;
            A.incref(v);
            goto have;
        }
    }
    for (k = 0; k < 2 + at; k++)
        call[k] = args[k];
    call[2 + at] = TYPE(target);
    if (!locked)
        ep0 = epoch();
    v = A.vectorcall(e->value, call, (size_t)(3 + at), NULL);
    if (!v) {
        if (mv)
            A.release_buffer(&view);
        return NULL; /* (the value's own error, as the Python path would raise it) */
    }
    if (v == e->sentinel || TYPE(v) != A.bytes_type) {
        if (s) { /* (the lanes empty: their runs may be of another image) */
            ptrdiff_t j;
            for (j = 0; j < (e->ncache > 1 ? e->ncache : 1); j++) {
                struct aslot *x = &e->cache[j];
                obj old = x->value, oldtp = x->tp;
                if (!old)
                    continue;
                x->value = NULL, x->tp = NULL;
                A.decref(old);
                A.decref(oldtp);
            }
        }
        goto drop;
    }
    /* (a read: the runs are of the image of the epoch it began in; a write's value makes the
     * epoch grow itself, or its changed() does once it has written) */
    if (!locked && (e->write && !e->changed ? elsewhere(e->gate) : !stands(e->gate, ep0))) {
        A.decref(v);
        if (mv)
            A.release_buffer(&view);
        return AGAIN;
    }
    if (s && ep >= 0) {
        keep_span(s, ep, v, TYPE(target), off, size, slave);
        s->booked = c_moved;
    }
have:
    /* the runs: (first byte in the buffer, address in the image, bytes) as int64 triples */
    n = *(ptrdiff_t *)((char *)v + A.bsize);
    if (n <= 0 || n % 24)
        goto drop;
    runs = (const int64_t *)((char *)v + A.bdata);
    /* (again: Python ran; a bit write has no buffer: its byte is the image's own) */
    mem = bit >= 0 ? (char *)&set : mv ? (char *)view.buf : raw_mem(e, p, target, size);
    if (!mem)
        goto drop;
    for (k = 0; k < n / 24; k++) {
        const int64_t *r = runs + 3 * k;
        if (r[0] < 0 || r[2] <= 0 || r[0] + r[2] > size || !r[1])
            goto drop;
    }
    for (k = 0; k < n / 24; k++) {
        const int64_t *r = runs + 3 * k;
        char *image = (char *)(intptr_t)r[1];
        if (bit >= 0) {
            unsigned char was = (unsigned char)*image;
            unsigned char now = set ? (unsigned char)(was | (1u << bit))
                                    : (unsigned char)(was & ~(1u << bit));
            if (now != was) {
                *image = (char)now;
                diff = 1;
            }
        } else if (!e->write)
            memcpy(mem + r[0], image, (size_t)r[2]);
        else if (!e->changed)
            memcpy(image, mem + r[0], (size_t)r[2]);
        else if (memcmp(image, mem + r[0], (size_t)r[2])) {
            memcpy(image, mem + r[0], (size_t)r[2]);
            diff = 1;
        }
    }
    /* (the image changed: what the readers kept asks again; the armed cycle too, unless
     * the write changed only outputs it takes to the field itself: io_outputs) */
    if (diff) {
        ep1 = epoch();
        qio = io_only(e->gate, runs, n / 24);
    }
    A.decref(v);
    if (mv)
        A.release_buffer(&view);
    if (diff) {
        if (e->grow && ep1 >= 0) {
            /* (changed() itself: EPOCH.n = epoch + 1, as the cycles booked in C set it) */
            obj grown = A.long_from(ep1 + 1), was;
            if (!grown)
                return NULL;
            was = (obj)AT(A.epoch_obj, A.epoch_off);
            *(obj *)((char *)A.epoch_obj + A.epoch_off) = grown;
            A.decref(was);
        } else {
            res = A.vectorcall(e->changed, NULL, 0, NULL);
            if (!res)
                return NULL;
            A.decref(res);
        }
        if (ep1 >= 0 && epoch() == ep1 + 1) {
            c_moved++; /* (one growth: the image's bytes moved) */
            if (qio && qio[4] == ep1) {
                /* (armed still; the status words stand: a plain IO slave's outputs move
                 * no axis's flag) */
                qio[4] = ep1 + 1;
                flag_keeping++;
            }
        }
    }
    return done(e->after, e->gate);

drop:
    A.decref(v);
python:
    if (mv) {
        A.release_buffer(&view);
        mv = 0;
    }
    return A.vectorcall(e->fallback, args, (size_t)nargs, kwnames);
}

static obj raw_try_locked(const struct raw_entry *e, obj const *args, ptrdiff_t nargs,
                          obj kwnames)
{
    return raw_try(e, args, nargs, kwnames, 1);
}

static obj raw(const struct raw_entry *e, obj const *args, ptrdiff_t nargs, obj kwnames)
{
    ANSWER(raw_try, e, e->gate, args, nargs, kwnames);
}

/* A reader of several values (GT_GetCaptureStatus(encoder, pStatus, pValue[, count,
 * pClock]), GT_CrdStatus(crd, pRun, pSegment[, fifo])): n, then nout pointers (byref(x)
 * with no offset, or x, of one of each output's types), then at most nextra arguments each
 * of which must be what extra[] says; value(n) gives a tuple of nout numbers, kept per n for
 * its epoch; every number is checked to fit before any is written.  Anything else: the
 * fallback with the very same arguments. */
#define MAX_OUT 3
#define MAX_OTYPES 8

struct multi_entry {
    obj fallback;
    obj value;
    obj sentinel;
    ptrdiff_t nout;
    ptrdiff_t nextra;
    ptrdiff_t extra[3]; /* 1: the int 1; 0: the int 0; 2: None or the int 0 */
    obj types[MAX_OUT][MAX_OTYPES]; /* NULL-ended */
    ptrdiff_t sizes[MAX_OUT][MAX_OTYPES];
    ptrdiff_t signs[MAX_OUT][MAX_OTYPES];
    ptrdiff_t kinds[MAX_OUT]; /* 0: integers, 1: doubles */
    ptrdiff_t gate;
    obj after;
    struct slot *cache;
    ptrdiff_t ncache;
    ptrdiff_t titems; /* a tuple's first item (its length: where a bytes object's is) */
    obj tuple_type;
};

static obj multi(const struct multi_entry *e, obj const *args, ptrdiff_t nargs, obj kwnames);

obj gtecat_centry_multi_vc(obj callable, obj const *args, size_t nargsf, obj kwnames)
{
    ptrdiff_t nargs = (ptrdiff_t)(nargsf & ~VECTORCALL_OFFSET);
    positional(callable, &nargs, &kwnames);
    return multi((const struct multi_entry *)AT(callable, A.vc_entry), args, nargs, kwnames);
}

obj gtecat_centry_multi(obj self, obj const *args, ptrdiff_t nargs, obj kwnames)
{
    return multi((const struct multi_entry *)AT(self, A.b_ptr), args, nargs, kwnames);
}

/* output k's memory, size and sign for p (NULL: not taken) */
static char *out_mem(const struct multi_entry *e, ptrdiff_t k, obj p, int *size, int *sign)
{
    return typed_mem(p, e->types[k], e->sizes[k], e->signs[k], NULL, MAX_OTYPES, size, sign);
}

TRY multi_try(const struct multi_entry *e, obj const *args, ptrdiff_t nargs, obj kwnames,
              int locked)
{
    ptrdiff_t k, nout = e->nout;
    char *mem[MAX_OUT];
    int size[MAX_OUT], sign[MAX_OUT];
    long long ints[MAX_OUT], key = -1, ep = -1, ep0 = -1;
    obj v, item;

    if (!ready || kwnames || (e->gate && !A.gate[e->gate - 1]))
        goto python;
    if (!locked && elsewhere(e->gate))
        return AGAIN; /* (the Python path too answers holding the lock then) */
    if (nargs < 1 + nout || nargs > 1 + nout + e->nextra || TYPE(args[0]) != A.int_type)
        goto python;
    for (k = 1 + nout; k < nargs; k++) {
        obj a = args[k];
        ptrdiff_t want = e->extra[k - 1 - nout];
        if (want == 1 ? !(a == A.one || int_is(a, 1))
                      : !(a == A.zero || int_is(a, 0) || (want == 2 && null_arg(a))))
            goto python;
    }
    for (k = 0; k < nout; k++)
        if (!out_mem(e, k, args[1 + k], &size[k], &sign[k]))
            goto python;
    if (e->cache && (v = kept(e->cache, e->ncache, args[0], &key, &ep, 0)) != NULL)
        goto have;
    if (!locked)
        ep0 = epoch();
    v = A.vectorcall(e->value, args, 1, NULL);
    if (!v)
        return NULL;
    if (v == e->sentinel || TYPE(v) != e->tuple_type ||
        *(ptrdiff_t *)((char *)v + A.bsize) != nout)
        goto drop;
    if (!locked && !stands(e->gate, ep0)) { /* (another thread's cycle or call meanwhile) */
        A.decref(v);
        return AGAIN;
    }
    if (key >= 0 && ep >= 0)
        keep(&e->cache[key], ep, v);
have:
    for (k = 0; k < nout; k++) { /* (every value checked before any is written) */
        item = ((obj *)((char *)v + e->titems))[k];
        if (e->kinds[k] == 1) {
            if (TYPE(item) != A.float_type || size[k] != 8)
                goto drop;
        } else if (!ll_of(item, &ints[k]) || !fits(ints[k], size[k], sign[k])) {
            goto drop;
        }
    }
    for (k = 0; k < nout; k++) /* (again: Python ran) */
        if (!(mem[k] = out_mem(e, k, args[1 + k], &size[k], &sign[k])))
            goto drop;
    for (k = 0; k < nout; k++) {
        item = ((obj *)((char *)v + e->titems))[k];
        if (e->kinds[k] == 1)
            *(double *)mem[k] = *(double *)((char *)item + A.fval);
        else
            put(mem[k], ints[k], size[k]);
    }
    A.decref(v);
    return done(e->after, e->gate);

drop:
    A.decref(v);
python:
    return A.vectorcall(e->fallback, args, (size_t)nargs, kwnames);
}

static obj multi_try_locked(const struct multi_entry *e, obj const *args, ptrdiff_t nargs,
                            obj kwnames)
{
    return multi_try(e, args, nargs, kwnames, 1);
}

static obj multi(const struct multi_entry *e, obj const *args, ptrdiff_t nargs, obj kwnames)
{
    ANSWER(multi_try, e, e->gate, args, nargs, kwnames);
}

/* A replay's loop (gtecat.faults.record._replay): the recorded calls of the simple forms made
 * one after another without a Python frame per call.  A step is a tuple (call, values); its
 * call's runner (found by the call object's address in the table Python fills) says what the
 * replay's compiled run does for it: the values to set into the pooled objects before the call
 * (an integer of 1, 2, 4 or 8 bytes, signed or not, a double, a float, the bytes of an
 * array), the GT function and its arguments, the recorded return code, and the values the
 * objects must hold after it.  The loop stops at the first step it cannot make so (a call the
 * table does not know or leaves to Python, a value of another type or one the object does not
 * hold: nothing of the call made) and gives its index; a call made whose return code or left
 * value differs from the recorded one - or may: not an exact int, a NaN - stops it with (index,
 * the code): Python compares in full and reports, as after its own run of the call. */
#define R_MAX 6
#define R_DOUBLE 100
#define R_FLOAT 101
#define R_UNSIGNED 16

/* a value set before the call or compared after it: where it lies, what it is (1, 2, 4, 8:
 * a signed integer of that size; R_UNSIGNED + size: unsigned; R_DOUBLE, R_FLOAT; -n: n
 * bytes of an array), its place among the step's values */
struct rput {
    char *mem;
    long long kind, k;
};

struct runner {
    obj fn, args, rc; /* the GT function, its arguments (a tuple), the recorded code (an int) */
    long long python; /* 1: the replay's Python makes this call */
    long long nsets, nouts;
    struct rput sets[R_MAX], outs[R_MAX];
};

struct rtable {
    long long mask; /* the table's slots less one (a power of two) */
    obj *keys;      /* per slot the call it is for (NULL: free) */
    struct runner **runners;
    ptrdiff_t titems; /* where a tuple keeps its items */
    obj tuple_type;
};

#define R_ITEM(t, i) (((obj *)((char *)(t) + T->titems))[i])
#define R_SIZE(t) (*(ptrdiff_t *)((char *)(t) + A.bsize))

static int r_set(const struct rput *s, obj x)
{
    long long v;
    double d;
    float f;
    if (s->kind < 0) {
        if (TYPE(x) != A.bytes_type || R_SIZE(x) != -s->kind)
            return 0;
        memcpy(s->mem, (char *)x + A.bdata, (size_t)-s->kind);
        return 1;
    }
    if (s->kind == R_DOUBLE || s->kind == R_FLOAT) {
        if (TYPE(x) != A.float_type)
            return 0;
        memcpy(&d, (char *)x + A.fval, sizeof d);
        if (s->kind == R_DOUBLE) {
            memcpy(s->mem, &d, sizeof d);
            return 1;
        }
        if (d != d || d > 3.4028234663852886e38 || d < -3.4028234663852886e38)
            return 0; /* (NaN, past a float's range: ctypes' own conversion) */
        f = (float)d;
        memcpy(s->mem, &f, sizeof f);
        return 1;
    }
    if (!ll_of(x, &v) || !fits(v, (int)(s->kind % R_UNSIGNED), s->kind < R_UNSIGNED))
        return 0;
    put(s->mem, v, (int)(s->kind % R_UNSIGNED));
    return 1;
}

static int r_same(const struct rput *s, obj x)
{
    long long v, m;
    double d, e;
    float f;
    int size = (int)(s->kind % R_UNSIGNED);
    if (s->kind < 0)
        return TYPE(x) == A.bytes_type && R_SIZE(x) == -s->kind &&
               !memcmp(s->mem, (char *)x + A.bdata, (size_t)-s->kind);
    if (s->kind == R_DOUBLE || s->kind == R_FLOAT) {
        if (TYPE(x) != A.float_type)
            return 0;
        memcpy(&e, (char *)x + A.fval, sizeof e);
        if (s->kind == R_DOUBLE)
            memcpy(&d, s->mem, sizeof d);
        else
            memcpy(&f, s->mem, sizeof f), d = (double)f;
        return d == e;
    }
    if (!ll_of(x, &v))
        return 0;
    if (s->kind < R_UNSIGNED)
        m = size == 1 ? *(int8_t *)s->mem : size == 2 ? *(int16_t *)s->mem
            : size == 4 ? *(int32_t *)s->mem : *(int64_t *)s->mem;
    else if (size == 8) {
        if (*(uint64_t *)s->mem > (uint64_t)INT64_MAX)
            return 0;
        m = (long long)*(uint64_t *)s->mem;
    } else
        m = size == 1 ? *(uint8_t *)s->mem : size == 2 ? *(uint16_t *)s->mem
            : (long long)*(uint32_t *)s->mem;
    return m == v;
}

static obj replay_run(const struct rtable *T, obj const *args, ptrdiff_t nargs)
{
    obj steps, st, p, vals, res, at, out;
    ptrdiff_t n, nv, i;
    long long start, h, k;
    const struct runner *r;
    if (nargs != 2 || TYPE(args[0]) != T->tuple_type || !ll_of(args[1], &start) || start < 0)
        return A.long_from(-1);
    steps = args[0];
    n = R_SIZE(steps);
    for (i = (ptrdiff_t)start; i < n; i++) {
        st = R_ITEM(steps, i);
        if (TYPE(st) != T->tuple_type || R_SIZE(st) != 2)
            break;
        p = R_ITEM(st, 0);
        vals = R_ITEM(st, 1);
        h = (long long)(((size_t)p >> 4) & (size_t)T->mask);
        while (T->keys[h] && T->keys[h] != p)
            h = (h + 1) & T->mask;
        if (!T->keys[h])
            break;
        r = T->runners[h];
        if (r->python || TYPE(vals) != T->tuple_type)
            break;
        nv = R_SIZE(vals);
        for (k = 0; k < r->nsets; k++)
            if (r->sets[k].k >= nv || !r_set(&r->sets[k], R_ITEM(vals, r->sets[k].k)))
                goto stop;
        res = A.vectorcall(r->fn, &R_ITEM(r->args, 0), (size_t)R_SIZE(r->args), NULL);
        if (!res)
            return NULL;
        if (res != r->rc && !(ll_of(res, &h) && ll_of(r->rc, &k) && h == k))
            goto made;
        for (k = 0; k < r->nouts; k++)
            if (r->outs[k].k >= nv || !r_same(&r->outs[k], R_ITEM(vals, r->outs[k].k)))
                goto made;
        A.decref(res);
    }
stop:
    return A.long_from(i);
made:
    at = A.long_from(i);
    out = at ? A.tuple_pack(2, at, res) : NULL;
    if (at)
        A.decref(at);
    A.decref(res);
    return out;
}

/* METH_FASTCALL | METH_KEYWORDS: self is the table's ctypes object; run(steps, start) */
obj gtecat_centry_replay(obj self, obj const *args, ptrdiff_t nargs, obj kwnames)
{
    (void)kwnames;
    return replay_run((const struct rtable *)AT(self, A.b_ptr), args, nargs);
}
