"""An object's attributes in a dict of its own, so that reading them stays quick.

CPython (3.11, 3.12) keeps a plain object's attributes inline until something asks for its
``__dict__`` (``vars(obj)``, ``obj.__dict__``) or assigns its ``__class__``; that makes a dict
sharing the class's keys, and the interpreter's specialised attribute read then misses on
every read of such a dict: each read takes the generic way, three to four times as long, for
as long as the object lives.  ``vars(ctl).get("crd_bank")`` in ``GT_Stop`` made every later
``ctl.clock`` read 17 -> 77 ns.  The same attributes in a dict of the object's own are read the
quick way (18 ns), and a later ``vars()`` returns that dict without making another.
"""

from __future__ import annotations

from operator import attrgetter


def own_dict(obj: object) -> None:
    """Give ``obj`` its attributes in a dict of its own (nothing for an object with slots
    only).  Call it where nothing else runs on ``obj`` (an attribute set meanwhile by another
    thread would be lost)."""
    try:
        d = object.__getattribute__(obj, "__dict__")
    except AttributeError:
        return
    object.__setattr__(obj, "__dict__", dict(d))


def in_array(where: str, slot: int, doc: str) -> property:
    """An int attribute kept in slot ``slot`` of the object's int64 array attribute ``where``
    (``array('q')``): memory compiled code reads and adds to without Python (the auto
    clock's quick cycle counts the clock's, the master's and the axis bank's cycles so)."""
    arr = attrgetter(where)

    def get(self: object) -> int:
        return arr(self)[slot]  # type: ignore[no-any-return]

    def put(self: object, n: int) -> None:
        arr(self)[slot] = n

    return property(get, put, doc=doc)
