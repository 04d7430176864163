/* Which object a ctypes byref() points at: the GT fast path's check of a pointer argument
 * (gtecat/gt/byref_target.py builds, binds and tests this file).
 *
 * A client passes byref(x) or byref(x, offset); ctypes keeps the address it passes in the
 * pointer object and offers no reader for it.  This one function answers, in one call from
 * Python, "is p byref(x) of an x of an accepted type, with no offset?" by comparing the
 * address p passes with the address x's own memory has.  It uses no Python header: the
 * interpreter's layout (where the pointer object keeps its address and its object, where an
 * object keeps its type, where a ctypes object keeps its memory) is handed over by the loader,
 * which found it by probing objects whose answers it knows, and the loader tests this
 * function against those answers before using it.
 */
#include <stddef.h>

typedef void (*incref_fn)(void *);

static ptrdiff_t carg_value = -1; /* the address a byref() passes */
static ptrdiff_t carg_obj = -1;   /* the object it refers to (NULL for some pointer objects) */
static ptrdiff_t ob_type = -1;    /* an object's type */
static ptrdiff_t b_ptr = -1;      /* a ctypes object's memory */
static incref_fn incref;
static void *carg_type;           /* the type of the pointer objects byref() makes */

#define AT(base, off) (*(char **)((char *)(base) + (off)))

int gtecat_byref_layout(ptrdiff_t value, ptrdiff_t obj, ptrdiff_t type, ptrdiff_t mem,
                        incref_fn inc, void *carg)
{
    if (value < 0 || obj < 0 || type < 0 || mem < 0 || !inc || !carg)
        return 1;
    carg_type = carg;
    carg_value = value;
    carg_obj = obj;
    ob_type = type;
    b_ptr = mem;
    incref = inc;
    return 0;
}

/* A METH_O function whose self is a ctypes array of type addresses ended by 0: for a pointer
 * object p, p's object when that object's type, or its type's type (an array type's
 * metatype), is in the table and p passes the address of the object's own memory; else
 * (anything else too) p itself.  A new reference either way. */
void *gtecat_byref_target(void *self, void *p)
{
    char *out = p;
    char *obj = AT(p, ob_type) == carg_type ? AT(p, carg_obj) : NULL;
    if (obj) {
        char *tp = AT(obj, ob_type);
        char *meta = AT(tp, ob_type);
        char **table = (char **)AT(self, b_ptr);
        for (; *table; table++) {
            if (*table == tp || *table == meta) {
                if (AT(p, carg_value) == AT(obj, b_ptr))
                    out = obj;
                break;
            }
        }
    }
    incref(out);
    return out;
}
