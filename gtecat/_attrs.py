"""An object's attributes in a dict of its own, so that reading them stays quick.

CPython (3.11, 3.12) keeps a plain object's attributes inline until something asks for its
``__dict__`` (``vars(obj)``, ``obj.__dict__``) or assigns its ``__class__``; that makes a dict
sharing the class's keys, and the interpreter's specialised attribute read then misses on
every read of such a dict: each read takes the generic way, three to four times as long, for
as long as the object lives.  ``vars(ctl).get("crd_bank")`` in ``GT_Stop`` made every later
``ctl.clock`` read 17 -> 77 ns.  The same attributes in a dict of the object's own are read the
quick way (18 ns), and a later ``vars()`` returns that dict without making another.

Also the state one module keeps per object of another (:class:`PerObject`), kept on that
object so that it never keeps its owner alive.
"""

from __future__ import annotations

from operator import attrgetter
from typing import Any, ClassVar, Generic, TypeVar

V = TypeVar("V")
_get = object.__getattribute__


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


class PerObject(Generic[V]):
    """State one module adds to each object of another (a controller, an axis, an axis's
    resources), kept on that object: its ``extensions`` dict, under this kind's name.

    Not a module-level ``weakref.WeakKeyDictionary`` keyed by the object: such a dictionary
    holds its values strongly, and the values nearly always refer back to their key (a
    capture unit holds its controller and the axis's resources), so the key never died and
    every controller ever opened stayed alive, with its bus and drives, for the process's
    life.  Kept on the object, owner and state form a cycle the garbage collector frees
    together once nothing else holds the owner, whatever the state refers to: no value has to
    be written to hold only weak references back.

    The classes it is used on make ``extensions`` in ``__init__`` (an attribute added later
    could move the others out of the quick layout: :func:`own_dict`); any other object gets
    it on first use.  It is read past ``__getattribute__`` (the object is not otherwise
    touched): an axis the bank runs is not given back for it (its guard)."""

    __slots__ = ("name",)
    _names: ClassVar[set[str]] = set()

    def __init__(self, name: str) -> None:
        if name in PerObject._names:
            raise ValueError(f"two kinds of per-object state named {name!r}")
        PerObject._names.add(name)
        self.name = name

    def get(self, owner: object, default: V | None = None) -> V | None:
        return extensions(owner).get(self.name, default)

    def __getitem__(self, owner: object) -> V:
        return extensions(owner)[self.name]  # type: ignore[no-any-return]

    def __setitem__(self, owner: object, value: V) -> None:
        extensions(owner)[self.name] = value

    def __contains__(self, owner: object) -> bool:
        return self.name in extensions(owner)

    def setdefault(self, owner: object, value: V) -> V:
        return extensions(owner).setdefault(self.name, value)  # type: ignore[no-any-return]

    def pop(self, owner: object, default: V | None = None) -> V | None:
        return extensions(owner).pop(self.name, default)


def extensions(owner: object) -> dict[str, Any]:
    """``owner``'s per-object states (:class:`PerObject`), made on first use."""
    try:
        return _get(owner, "extensions")  # type: ignore[no-any-return]
    except AttributeError:
        d: dict[str, Any] = {}
        object.__setattr__(owner, "extensions", d)
        return d
