"""Bring-up of GSN-E and ring-net controllers: ``GTN_OpenCard``, ``GTN_NetInit``,
``GTN_RN_GetAbsEncPosEx``.

A GSN-E application opens the card with ``GTN_OpenCard(CHANNEL_PCIE, NULL, NULL)``, then
must call ``GTN_NetInit(mode, "Gecat.xml", overTime, &status)`` before anything else; it
initialises the card's EtherCAT network (and its ring net) and reports in ``status`` 1
when the slaves and the controller communicate.  Decisions (the header says no more):

* ``GTN_OpenCard`` is ``GT_Open`` (the controller this process runs or attaches to, as
  ``GTECAT_*`` say); ``channel`` and the reserved ``pPrm``/``pFileName`` are not used.
* ``GTN_NetInit`` brings the bus up as manual example 5-5 does: ``GT_InitEcatComm``, wait
  until ``GT_IsEcatReady`` says 1 (at most ``overTime`` seconds of controller time; 0:
  10 s), ``GT_StartEcatComm``.  The network is the one the controller was opened with
  (``GTECAT_ENI``, else ``Gecat.eni`` in the working folder); the file the application
  names in ``pPrm`` is written to the master log.  ``mode`` (the vendor's 0..100 ways of
  matching the file to the bus) is accepted as given.  Codes, as the vendor's
  application notes list them: 0 with ``*pStatus`` 1 when the bus is up; 11902 when
  there is no network description; 11702 when the network cannot be brought up
  (``*pStatus`` 0; ``GTE_GetLastError`` says why).  A second ``GTN_NetInit`` on a running
  bus brings it up again.
* ``GTN_RN_GetAbsEncPosEx(core, encoder, pEncPos)``: the absolute position of the
  encoder as a 64-bit count: the encoder's position (``GT_GetEncPos``) as a whole
  number; the emulated drives keep their absolute position across power cycles.
"""

from __future__ import annotations

from ctypes import byref, c_short
from typing import Any

from ..controller.core import Controller
from ..errors import ParameterError
from . import _core
from ._core import SESSION, fail, gt_function, store

NET_INIT_ERROR = 11702
NET_NO_DESCRIPTION = 11902


@gt_function
def GTN_OpenCard(
    channel: int = 0,
    pPrm: Any = None,
    pFileName: Any = None,
    *,
    eni: str | None = None,
    machine: Any = None,
    clock: str | None = None,
    card: str | None = None,
    log: str | None = None,
    cycle_ms: float | None = None,
) -> int:
    """Open the controller (``GT_Open``; keyword options as ``GT_Open`` takes them)."""
    options = {
        k: v
        for k, v in {
            "eni": eni, "machine": machine, "clock": clock, "card": card, "log": log,
            "cycle_ms": cycle_ms,
        }.items()
        if v is not None
    }  # fmt: skip
    return _core.REGISTRY["GT_Open"](**options)


@gt_function
def GTN_NetInit(mode: int = 0, pPrm: Any = None, overTime: int = 0, pStatus: Any = None) -> int:
    """Bring the EtherCAT network up; ``*pStatus`` 1 when it runs."""
    if int(overTime) < 0:
        raise ParameterError(f"overTime={overTime}: seconds, 0 (the default) or more")
    reg = _core.REGISTRY
    ctl = SESSION.controller(1)
    if pPrm:
        ctl.log(f"GTN_NetInit: the application names {pPrm!r}; the bus is {ctl.eni_path}")
    store(pStatus, 0)
    rc = reg["GT_InitEcatComm"]()
    if rc != 0:
        why = _core.last_error()
        reason = why.reason if why is not None else f"GT_InitEcatComm returned {rc}"
        code = NET_NO_DESCRIPTION if rc == _core.ECAT_NO_ENI else NET_INIT_ERROR
        fail(code, f"the EtherCAT network cannot be initialised: {reason}")
    ready = c_short()
    ms = (int(overTime) or 10) * 1000
    for _ in range(ms):
        if reg["GT_IsEcatReady"](byref(ready)) == 0 and ready.value == 1:
            break
        reg["GTE_Wait"](1)
    else:
        fail(NET_INIT_ERROR, f"the EtherCAT network was not ready within {ms // 1000} s")
    if reg["GT_StartEcatComm"]() != 0:
        why = _core.last_error()
        fail(NET_INIT_ERROR, why.reason if why is not None else "GT_StartEcatComm failed")
    store(pStatus, 1)
    return 0


@gt_function
def GTN_RN_GetAbsEncPosEx(ctl: Controller, core: int, encoder: int, pEncPos: Any) -> int:
    """The encoder's absolute position, a 64-bit count."""
    from ..controller.resources import axis_resources

    c = ctl if int(core) == 1 else SESSION.controller(int(core))
    res = axis_resources(c, encoder)
    store(pEncPos, round(res.encoder.pos))
    return 0
