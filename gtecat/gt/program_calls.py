"""GT calls of chapter 10 (motion programs), 11.8 (MRAM) and 12 (GetMacAddress).

Manual chapter 13 entries 1, 6, 9, 10, 52, 57, 58, 72, 75, 76, 85, 97, 114, 126, 128,
132, 134.  The work is done by :mod:`gtecat.programs` (compiler, program image,
threads, MRAM); these wrappers check arguments and move structures.  docs/programs.md
is the user's guide.

Decisions where the manual is silent:

* ``GT_Compile`` runs on the host (it needs no ``GT_Open``, as MCT2008 is a host
  tool): it writes ``x.bin`` and ``x.ini`` beside ``x.c`` and returns 0, or returns 1
  and writes nothing when the source has errors.  ``TCompileInfo`` then points at
  memory of this module that stays valid until the next ``GT_Compile``:
  ``pFileName`` the file, ``*pLineNo`` the first error's line (0 after a success, or
  when the file cannot be read), ``pMessage`` its message ("" after a success).
  ``GTE_GetLastError`` lists every error as ``file:line: message``.
* ``GT_Download`` returns 2007 when the image is missing (or its name too long),
  2008 when it or the ``.ini`` beside it cannot be used (entry 10), 7 when the file
  holds more than 32 functions; a download replaces the previous one (threads stop,
  memory is zeroed) and is lost at ``GT_Close``.  ``GT_GetFunId`` / ``GT_GetVarId``
  return 1 before a download and for unknown names.
* ``GT_GetVarId``: ``pFunName`` NULL, 0 or "" names a global.  ``TVarInfo.id`` is the
  variable's word address in its area (globals, or a data page), ``dataType`` 0
  ``int`` / 1 ``double``, ``name`` the variable's name.  ``GT_SetVarValue`` /
  ``GT_GetVarValue`` (page -1 globals, 0..31 a data page; ``count`` 1..6 as entry
  76/126 say) move ``count`` elements from element ``id - address``: an array longer
  than 6 is reached by stepping ``pVarInfo->id``.  Values beyond the variable, a
  ``dataType`` that is not the variable's, a value outside the type's range return 7.
  A page bound to a thread is read with that thread's function's locals; an unbound
  page with the function that has a local of that name.
* ``GT_GetThreadSts`` answers for any thread, before a download too (all zeros);
  ``run`` is 1 running, 2 paused, 0 not running (:mod:`gtecat.programs.threads`).
  ``GT_RunThread`` resumes a paused thread and returns 1 for a running one;
  ``GT_PauseThread`` returns 1 for a thread that is not running; ``GT_StopThread``
  of a stopped thread is 0.  ``GT_Reset`` stops every thread (bindings, pages and the
  download stay).
* ``GTE_SetProgramSpeed(instructionsPerMs)``: the program execution rate (default
  100 per ms of controller time, or ``GTECAT_PROGRAM_SPEED``); ``GTE_GetThreadError``
  the reason of a thread's runtime error ("" if none).
* MRAM: :mod:`gtecat.programs.mram`.  Address and count are checked together
  (``address + count <= 4096``, else 7); ``GT_StartAccessMRAM`` during an access
  abandons it and starts the new one; a store that cannot be read or written makes
  the access fail (status stays 0; the next ``GT_GetMRAMStatus`` returns 1 with the reason).
* ``GetMacAddress`` (and ``GT_GetMacAddress``, the spelling with the prefix):
  adapter 0 (the EtherCAT port) or 1 (the host port); 6 bytes, the first 02 (a
  locally administered unicast address), then 47:54 ("GT"), then 3 bytes of the
  SHA-256 of the adapter number and the ENI file's contents (its path when it does
  not exist): the same configuration always gives the same address, another ENI
  another one.  ``ulAddressSize`` < 6 returns 7.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import weakref
from pathlib import Path
from typing import TYPE_CHECKING as _TYPE_CHECKING
from typing import Any

from .._attrs import PerObject
from ..controller.core import Controller
from ..errors import ParameterError
from ..programs.model import MAX_FUNCTIONS
from . import _core
from ._core import fail, gt_function, store, store_array, store_bytes, struct_arg
from .structs import TCompileInfo, TThreadSts, TVarInfo

if _TYPE_CHECKING:
    from ..programs import mram, threads

# (the motion programs' modules but their model are imported by the calls that use them: an
# application without programs does not pay for them at ``from gtecat import gt``)

_RUNTIMES: PerObject[threads.ProgramRuntime] = PerObject("program_runtime")
_MRAMS: PerObject[mram.Mram] = PerObject("program_mram")


# --- the controller's program runtime ------------------------------------------------------
def _speed_from_env() -> float:
    from ..programs import threads

    text = os.environ.get("GTECAT_PROGRAM_SPEED", "")
    try:
        v = float(text) if text else threads.DEFAULT_SPEED
    except ValueError:
        v = threads.DEFAULT_SPEED
    return v if v > 0 else threads.DEFAULT_SPEED


def runtime(ctl: Controller, create: bool = True) -> threads.ProgramRuntime | None:
    """The program runtime of ``ctl`` (created, and hooked into its cycle, on first use)."""
    from ..programs import threads

    rt = _RUNTIMES.get(ctl)
    if rt is None and create:
        rt = threads.ProgramRuntime(_caller(ctl), _speed_from_env())
        _RUNTIMES[ctl] = rt
        ctl.before_cycle.append(_cycle_hook(ctl, rt))
        ctl.on_reset.append(_reset_hook(rt))
    return rt


def untapped(fn: Any) -> Any:
    """The function a recording's tap wraps (:mod:`gtecat.faults.tap`), or ``fn`` (None
    stays None)."""
    return getattr(fn, "tap_of", fn)


def _caller(ctl: Controller):
    """How a program calls a GT function: the registered function itself (same checks)."""
    ref = weakref.ref(ctl)

    def call(name: str, args: tuple) -> tuple[int, str]:
        c = ref()
        at = None if c is None else _core.SESSION.where(c)
        if at is None:
            return _core.CMD_COMM, "the controller running the program is closed"
        card, core = at  # the program's own card and core, whatever the host addresses
        # (the functions themselves, not a recording's tap: a program's calls are not the
        # host application's, and on the realtime clock they run in the cycle's thread)
        fn = untapped(_core.REGISTRY[name])
        twin = untapped(_core.REGISTRY.get("GTN_" + name[3:])) if core != 1 else None
        host_last = _core.SESSION.last  # the host's GTE_GetLastError is not the program's
        try:
            with _core.SESSION.selected(card):
                rc = twin(core, *args) if twin is not None else fn(*args)
            e = _core.last_error()
            reason = e.reason if rc != 0 and e is not None and e.function == name else ""
        finally:
            _core.SESSION.last = host_last
        return rc, reason

    return call


def _cycle_hook(ctl: Controller, rt: threads.ProgramRuntime):
    clock_ref = weakref.ref(ctl.clock)

    def now() -> int:
        clock = clock_ref()
        return clock.now_ns if clock is not None else 0

    def hook() -> None:
        clock = clock_ref()
        if clock is None:
            return
        saved = clock.call_latency_ns
        clock.call_latency_ns = 0  # a GT call from a program is no host round trip
        try:
            rt.step(clock.now_ns, clock.cycle_ns, now)
        finally:
            clock.call_latency_ns = saved

    return hook


def _reset_hook(rt: threads.ProgramRuntime):
    def reset(ctl: Controller) -> None:
        rt.stop_all()

    return reset


def _downloaded(ctl: Controller) -> threads.ProgramRuntime:
    rt = runtime(ctl, create=False)
    if rt is None or rt.program is None:
        fail(1, "no motion program is downloaded (call GT_Download first)")
    assert rt is not None
    return rt


def _do(action, *args: Any) -> Any:
    from ..programs import threads

    try:
        return action(*args)
    except threads.RuntimeRefusal as r:
        fail(r.code, str(r))


# --- compile and download ------------------------------------------------------------------
_COMPILE_FILE = ctypes.create_string_buffer(4096)
_COMPILE_LINE = ctypes.c_int16(0)
_COMPILE_MESSAGE = ctypes.create_string_buffer(1024)


def _report(info: Any, filename: str, line: int, message: str) -> None:
    _COMPILE_FILE.value = filename.encode("utf-8", "replace")[:4095]
    _COMPILE_LINE.value = max(-32768, min(32767, line))
    _COMPILE_MESSAGE.value = message.encode("utf-8", "replace")[:1023]
    info.pFileName = ctypes.addressof(_COMPILE_FILE)
    info.pLineNo = ctypes.pointer(_COMPILE_LINE)
    info.pMessage = ctypes.addressof(_COMPILE_MESSAGE)


@gt_function
def GT_Compile(pFileName: str, pWrongInfo: Any) -> int:
    """Compile a motion program; ``x.bin`` and ``x.ini`` beside ``x.c`` (entry 9, 10.3.2)."""
    # the compiler (and its parser, lark) loads on the first compile, not with gtecat.gt
    from ..programs import compiler, image

    info = struct_arg(pWrongInfo, TCompileInfo, "pWrongInfo")
    try:
        program = compiler.compile_file(pFileName)
    except compiler.CompileFailed as e:
        first = e.first
        _report(info, pFileName, first.line, first.message)
        name = Path(pFileName).name
        fail(1, "compile errors:\n" + "\n".join(x.format(name) for x in e.errors))
    try:
        image.write(program, pFileName)
    except OSError as e:
        _report(info, pFileName, 0, f"cannot write the program image: {e.strerror or e}")
        fail(1, f"cannot write the program image beside {pFileName}: {e.strerror or e}")
    _report(info, pFileName, 0, "")
    return 0


@gt_function
def GT_Download(ctl: Controller, pFileName: str) -> int:
    """Load a program image (and the .ini beside it) into the controller (entry 10)."""
    from ..programs import image
    from ..programs.verify import ImageInvalid, verify

    try:
        program = image.load(pFileName)
    except image.ImageError as e:
        fail(e.code, str(e))
    if len(program.functions) > MAX_FUNCTIONS:
        fail(
            7,
            f"{pFileName} holds {len(program.functions)} functions; a download holds at most "
            f"{MAX_FUNCTIONS} (entry 10)",
        )
    try:
        verify(program)
    except ImageInvalid as e:
        fail(7, f"{pFileName} cannot run: {e}")
    rt = runtime(ctl)
    assert rt is not None
    rt.download(program)
    return 0


@gt_function
def GT_GetFunId(ctl: Controller, pFunName: str, pFunId: Any) -> int:
    """The id of a function of the downloaded program, for GT_Bind (entry 52)."""
    rt = _downloaded(ctl)
    store(pFunId, _do(rt.function_id, pFunName))
    return 0


@gt_function
def GT_GetVarId(ctl: Controller, pFunName: str | None, pVarName: str, pVarInfo: Any) -> int:
    """A variable's handle: ``pFunName`` NULL/0 for a global (entry 75)."""
    rt = _downloaded(ctl)
    var = _do(rt.variable, pFunName or None, pVarName)
    info = struct_arg(pVarInfo, TVarInfo, "pVarInfo")
    info.id = var.address
    info.dataType = int(var.type)
    info.name = var.name.encode("utf-8")[:31]
    return 0


# --- threads -------------------------------------------------------------------------------
@gt_function
def GT_Bind(ctl: Controller, thread: int, funId: int, page: int) -> int:
    """Thread ``thread`` runs function ``funId`` with its locals on data page ``page`` (entry 6)."""
    _do(_downloaded(ctl).bind, thread, funId, page)
    return 0


@gt_function
def GT_RunThread(ctl: Controller, thread: int) -> int:
    """Start the thread from its function's first line, or resume it when paused (entry 97)."""
    _do(_downloaded(ctl).run, thread)
    return 0


@gt_function
def GT_PauseThread(ctl: Controller, thread: int) -> int:
    _do(_downloaded(ctl).pause, thread)
    return 0


@gt_function
def GT_StopThread(ctl: Controller, thread: int) -> int:
    _do(_downloaded(ctl).stop, thread)
    return 0


@gt_function
def GT_GetThreadSts(ctl: Controller, thread: int, pThreadSts: Any) -> int:
    """run (1 running, 2 paused, 0 not), error, result, line (entry 72)."""
    s = struct_arg(pThreadSts, TThreadSts, "pThreadSts")
    rt = runtime(ctl, create=False)
    if rt is None:
        s.run, s.error, s.result, s.line = 0, 0, 0.0, 0
        return 0
    st = rt.status(thread)
    s.run, s.error, s.result, s.line = st.run, st.error, st.result, max(-32768, min(32767, st.line))
    return 0


def _var_info(pVarInfo: Any) -> tuple[int, int, str]:
    info = struct_arg(pVarInfo, TVarInfo, "pVarInfo")
    try:
        name = bytes(info.name).split(b"\0", 1)[0].decode("utf-8")
    except UnicodeDecodeError:
        raise ParameterError("pVarInfo: the name is not text (use GT_GetVarId)") from None
    return int(info.id), int(info.dataType), name


@gt_function
def GT_SetVarValue(ctl: Controller, page: int, pVarInfo: Any, pValue: Any, count: int = 1) -> int:
    """Write ``count`` elements of a program variable; page -1 for globals (entry 126)."""
    rt = _downloaded(ctl)
    var_id, data_type, name = _var_info(pVarInfo)
    values = pValue.load_values(count)
    _do(rt.set_values, page, var_id, data_type, name, [float(v) for v in values])
    return 0


@gt_function
def GT_GetVarValue(ctl: Controller, page: int, pVarInfo: Any, pValue: Any, count: int = 1) -> int:
    """Read ``count`` elements of a program variable; page -1 for globals (entry 76)."""
    rt = _downloaded(ctl)
    var_id, data_type, name = _var_info(pVarInfo)
    store_array(pValue, _do(rt.get_values, page, var_id, data_type, name, count))
    return 0


@gt_function
def GTE_SetProgramSpeed(ctl: Controller, instructionsPerMs: float) -> int:
    """Emulator: motion-program instructions per millisecond of controller time (100)."""
    rt = runtime(ctl)
    assert rt is not None
    rt.speed = float(instructionsPerMs)
    return 0


@gt_function
def GTE_GetThreadError(ctl: Controller, thread: int, pText: Any) -> int:
    """Emulator: why the thread's last run stopped with an error ("" if it did not)."""
    rt = runtime(ctl, create=False)
    text = rt.reason(thread) if rt is not None else ""
    store_bytes(pText, text.encode("utf-8")[:255] + b"\0")
    return 0


# --- MRAM (11.8) ---------------------------------------------------------------------------
def _mram(ctl: Controller) -> mram.Mram:
    from ..programs import mram

    m = _MRAMS.get(ctl)
    if m is None:
        path = ctl.options.mram or mram.default_path(ctl.options.log)  # option > GTECAT_MRAM
        m = mram.Mram(mram.MramStore(path))
        _MRAMS[ctl] = m
        m_ref = weakref.ref(m)

        def tick(t_ns: int, dt_ns: int) -> None:
            dev = m_ref()
            if dev is not None:
                dev.tick(t_ns + dt_ns)

        ctl.post_cycle.append(tick)
    return m


def _span(address: int, count: int) -> None:
    from ..programs import mram

    if address + count > mram.WORDS:
        raise ParameterError(
            f"address={address}, count={count}: words {address}..{address + count - 1} run past "
            f"the {mram.WORDS}-word buffer"
        )


@gt_function
def GT_SetMRAMData(ctl: Controller, address: int, pData: Any, count: int) -> int:
    """Copy ``count`` (<= 24) words into the controller's MRAM buffer (entry 114)."""
    _span(address, count)
    words = [int(v) for v in pData.load_values(count)]
    _mram(ctl).set_data(address, words)
    return 0


@gt_function
def GT_GetMRAMData(ctl: Controller, address: int, pData: Any, count: int) -> int:
    """Read ``count`` (<= 24) words of the controller's MRAM buffer (entry 57)."""
    _span(address, count)
    store_array(pData, _mram(ctl).get_data(address, count))
    return 0


@gt_function
def GT_StartAccessMRAM(ctl: Controller, address: int, count: int, mode: int) -> int:
    """Mode 1: buffer -> memory; mode 0: memory -> buffer; status 0 until done (entry 128)."""
    from ..programs import mram

    _span(address, count)
    try:
        _mram(ctl).start(address, count, mode, ctl.clock.now_ns)
    except mram.MramError as e:
        fail(1, str(e))
    return 0


@gt_function
def GT_StopAccessMRAM(ctl: Controller) -> int:
    _mram(ctl).stop()
    return 0


@gt_function
def GT_GetMRAMStatus(ctl: Controller, pSts: Any) -> int:
    """0 while an access runs (or none completed), 1 once it is done (entry 58)."""
    m = _mram(ctl)
    store(pSts, m.status)
    if m.error:
        reason, m.error = m.error, ""
        fail(1, f"the MRAM access failed: {reason}")
    return 0


# --- MAC address (chapter 12) --------------------------------------------------------------
def mac_address(ctl: Controller, adapter: int) -> bytes:
    """The emulated controller's address of network port ``adapter`` (module docstring)."""
    eni = ctl.eni_path()
    try:
        content = eni.read_bytes()
    except OSError:
        content = str(eni.resolve()).encode()
    digest = hashlib.sha256(b"gtecat-mac\0" + bytes([adapter]) + content).digest()
    return bytes([0x02, 0x47, 0x54]) + digest[:3]


def _get_mac(ctl: Controller, ulAdapterNumber: int, pMacAddress: Any, ulAddressSize: int) -> int:
    if ulAdapterNumber > 1:
        raise ParameterError(
            f"ulAdapterNumber={ulAdapterNumber}: the controller has ports 0 (EtherCAT) and 1"
        )
    if ulAddressSize < 6:
        raise ParameterError(f"ulAddressSize={ulAddressSize}: a MAC address needs 6 bytes")
    store_bytes(pMacAddress, mac_address(ctl, ulAdapterNumber))
    return 0


@gt_function
def GetMacAddress(ctl: Controller, ulAdapterNumber: int, pMacAddress: Any, ulAddressSize: int):
    """The network address of the controller's port (chapter 12, entry 1)."""
    return _get_mac(ctl, ulAdapterNumber, pMacAddress, ulAddressSize)


@gt_function
def GT_GetMacAddress(ctl: Controller, ulAdapterNumber: int, pMacAddress: Any, ulAddressSize: int):
    """``GetMacAddress`` with the GT_ prefix."""
    return _get_mac(ctl, ulAdapterNumber, pMacAddress, ulAddressSize)


__all__ = ["mac_address", "runtime"]
