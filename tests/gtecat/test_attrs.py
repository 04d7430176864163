"""gtecat._attrs.own_dict: an object's attributes kept as they were, in a dict of its own that
a later ``vars()`` returns (no other made), across a class assignment too; an object with
slots only is left alone."""

from __future__ import annotations

from gtecat._attrs import own_dict


class _Plain:
    def __init__(self) -> None:
        self.a, self.b = 1, [2]


class _Slots:
    __slots__ = ("a",)

    def __init__(self) -> None:
        self.a = 1


def test_attributes_stay_and_vars_returns_the_own_dict() -> None:
    o = _Plain()
    b = o.b
    own_dict(o)
    d = vars(o)
    assert d == {"a": 1, "b": [2]} and o.b is b
    assert vars(o) is d  # (no other dict made)
    o.c = 3
    assert d["c"] == 3 and o.a == 1


def test_an_object_with_slots_only_is_left_alone() -> None:
    o = _Slots()
    own_dict(o)
    assert o.a == 1 and not hasattr(o, "__dict__")


def test_a_class_assigned_keeps_the_own_dict() -> None:
    class _Sub(_Plain):
        __slots__ = ()

    o = _Plain()
    object.__setattr__(o, "__class__", _Sub)
    own_dict(o)
    d = vars(o)
    object.__setattr__(o, "__class__", _Plain)
    assert vars(o) is d and o.a == 1


def test_per_object_state_does_not_keep_its_owner_alive() -> None:
    import gc
    import weakref

    from gtecat._attrs import PerObject

    kept: PerObject[list[object]] = PerObject("test_kept")
    o = _Plain()
    assert kept.get(o) is None and o not in kept
    value = kept.setdefault(o, [o])  # (a value that refers back to its owner)
    assert kept[o] is value and o in kept and kept.setdefault(o, []) is value
    ref = weakref.ref(o)
    del o, value
    gc.collect()
    assert ref() is None
