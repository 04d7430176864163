"""Extension IO modules through the GT API: GTS ``ExtMdl``, its ``*Gts`` forms, GTN modules, gLink.

The modules are the machine description's (``[ext.N]``, ``[glink.N]``;
:mod:`gtecat.controller.ext_io` holds their terminals).  What each family does, as the
vendor's manual of the ``ExtMdl`` library describes it, and what it leaves open:

* **GTS ExtMdl.**  ``GT_OpenExtMdl(dllName)`` takes the access (after ``GT_Open``; the
  DLL name - ``"gts.dll"``, ``"ExtMdl.dll"``, NULL - names the motion library on Windows
  and changes nothing here); ``GT_LoadExtConfig(file)`` loads the module configuration;
  then ``GT_Set/GetExtIo*``, ``GT_GetExtAd*``, ``GT_SetExtDa*``, ``GT_GetStsExtMdl``
  (0: the module communicates, 1: it does not).  ``mdl`` 0..15, ``index`` 0..15 (a
  module with up to 32 terminals: 0..31), values are terminal levels (these modules are
  active low: ``GT_SetExtIoBit(mdl, i, 0)`` switches output ``i`` on).
  Decisions: every call but ``GT_OpenExtMdl`` returns 1 until the access is open, and the
  terminal calls until a configuration is loaded (1, saying which call is missing);
  ``GT_ResetExtMdl`` scans the chain: it needs the access open, switches every output off
  and answers 1 naming a module that does not communicate.  The configuration file must
  exist (a Windows path that does not is looked up by its file name in the working folder,
  with a master-log line); its contents are the vendor tool's and are not read: the machine
  description says which modules exist.  A module the machine description lacks, or one
  that is offline, makes a terminal call return 1 (``GT_GetStsExtMdl`` returns 0 and
  status 1 for it); a terminal or channel the module lacks returns 7.
* **``*Gts`` forms** (the multi-card wrappers): ``cardNum`` first, the card whose modules
  the call addresses (each card has its own, :mod:`gtecat.controller.cards`): 7 outside
  0..15, -1 for a card that is not open.  ``GT_SwitchtoCardNoExtMdl(card)`` accepts the
  current card; another card's modules are reached with ``GT_SetCardNo`` (or a ``*Gts``
  form): switching them here returns 1 and says so.
* **GTN cores** (``GTN_ExtModuleInit`` ...): the same chain numbered from 1 across the
  modules in order (module 0's inputs first), values are levels with 1 = on unless the
  module says ``active_low``; ``GTN_Get/SetExtDo`` and ``GTN_GetExtDi`` work on 32
  terminals from the index; analog channels are numbered from 1 across the modules too.
  Every call but ``GTN_ExtModuleInit`` returns 1 before it; ``GTN_ExtModuleInit`` returns 1
  when the machine has no module.
* **gLink-II** (``GT_GLinkInit`` ...): slaves 0..63 from ``[glink.N]``, bit indices from 0,
  byte offsets from 0, 1 = on; every call but ``GT_GLinkInit`` returns 1 before it.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

from ..controller.cards import MAX_CARDS as _MAX_CARDS
from ..controller.core import Controller
from ..controller.ext_io import GLINK, GTN_EXT, GTS_EXTMDL, ExtIo, ExtModule, ext_io
from ..errors import CommandError, ParameterError
from ._core import (
    SESSION,
    NotOpen,
    check_range,
    gt_function,
    load_bytes,
    store,
    store_array,
    store_bytes,
)

_U16 = 0xFFFF


# --- GTS ExtMdl --------------------------------------------------------------------------------
def _opened(ctl: Controller, name: str) -> ExtIo:
    io = ext_io(ctl)
    if not io.opened:
        raise CommandError(f"{name}: the extension modules are not open (GT_OpenExtMdl first)")
    return io


def _module(ctl: Controller, name: str, mdl: int) -> ExtModule:
    io = _opened(ctl, name)
    if not io.configured:
        raise CommandError(
            f"{name}: no extension module configuration is loaded (GT_LoadExtConfig first)"
        )
    m = io.modules.get(int(mdl))
    if m is None:
        have = ", ".join(f"[ext.{n}]" for n in io.modules) or "none"
        raise CommandError(
            f"{name}: there is no extension module {mdl} (the machine description has {have})"
        )
    if not m.online:
        raise CommandError(f"{name}: extension module {mdl} does not answer on its bus")
    return m


def _bit(m: ExtModule, index: int, count: int, what: str) -> int:
    i = int(index)
    if not 0 <= i < count:
        raise ParameterError(
            f"index={i}: extension module {m.number} has {count} {what}"
            + (f" (0..{count - 1})" if count else "")
        )
    return i


def _channel(m: ExtModule, chn: int, count: int, what: str) -> int:
    c = int(chn)
    if not 0 <= c < count:
        raise ParameterError(
            f"chn={c}: extension module {m.number} has {count} {what} channel(s)"
            + (f" (0..{count - 1})" if count else "")
        )
    return c


def _to_raw(volts: float, rng: tuple[float, float]) -> int:
    lo, hi = rng
    return round((min(max(volts, lo), hi) - lo) / (hi - lo) * _U16)


def _from_raw(raw: int, rng: tuple[float, float]) -> float:
    lo, hi = rng
    return lo + (int(raw) & _U16) * (hi - lo) / _U16


def _config_path(ctl: Controller, name: str) -> Path:
    """The file ``name`` names; a path that does not exist by its file name in the working
    folder (an application written for Windows: ``"D:\\cfg\\ExtModule.cfg"``)."""
    p = Path(name)
    if p.is_file():
        return p
    base = re.split(r"[\\/]", name)[-1]
    local = Path(base)
    if base and local.is_file():
        ctl.log(f"GT_LoadExtConfig: {name!r} does not exist; using {base} of the working folder.")
        return local
    raise CommandError(
        f"GT_LoadExtConfig: no file {name!r} (nor {base!r} in the working folder {os.getcwd()})"
    )


@gt_function
def GT_OpenExtMdl(ctl: Controller, pDllName: Any = None) -> int:
    """Take the access to the extension modules (the module docstring)."""
    io = ext_io(ctl)
    io.opened = True
    return 0


@gt_function
def GT_CloseExtMdl(ctl: Controller) -> int:
    """Give the access back; the outputs keep their state."""
    io = _opened(ctl, "GT_CloseExtMdl")
    io.opened = io.configured = False
    return 0


@gt_function
def GT_SwitchtoCardNoExtMdl(ctl: Controller, card: int) -> int:
    """The card whose modules the calls address: the current card (module docstring)."""
    _opened(ctl, "GT_SwitchtoCardNoExtMdl")
    n = check_range("card", card, 0, _MAX_CARDS - 1)
    if n != SESSION.card:
        raise CommandError(
            f"GT_SwitchtoCardNoExtMdl: card {n}'s modules are addressed through that card "
            f"(GT_SetCardNo({n}), or the *Gts forms with cardNum {n}); switching the modules "
            f"of card {SESSION.card} over to it is not emulated"
        )
    return 0


@gt_function
def GT_ResetExtMdl(ctl: Controller) -> int:
    """Scan the chain: every output off; 1 naming a module that does not answer."""
    io = _opened(ctl, "GT_ResetExtMdl")
    for m in io.modules.values():
        m.all_off()
    silent = [n for n, m in io.modules.items() if not m.online]
    if silent:
        raise CommandError(f"GT_ResetExtMdl: extension module(s) {silent} do not answer")
    return 0


@gt_function
def GT_LoadExtConfig(ctl: Controller, pFileName: Any) -> int:
    """Load the module configuration file (it must exist; the modules are the machine's)."""
    io = _opened(ctl, "GT_LoadExtConfig")
    path = _config_path(ctl, str(pFileName))
    io.configured, io.config_file = True, str(path)
    have = ", ".join(str(n) for n in io.modules) or "none"
    ctl.log(f"GT_LoadExtConfig: {path}; extension modules of the machine: {have}.")
    return 0


@gt_function
def GT_SetExtIoValue(ctl: Controller, mdl: int, value: int) -> int:
    """The 16 output levels of module ``mdl`` (bit i = output i; 0 = on)."""
    _module(ctl, "GT_SetExtIoValue", mdl).write_output_levels(GTS_EXTMDL, int(value), _U16)
    return 0


@gt_function
def GT_GetExtIoValue(ctl: Controller, mdl: int, pValue: Any) -> int:
    """The 16 input levels of module ``mdl`` (bit i = input i; 0 = active)."""
    store(pValue, _module(ctl, "GT_GetExtIoValue", mdl).input_levels(GTS_EXTMDL, 16))
    return 0


@gt_function
def GT_SetExtIoBit(ctl: Controller, mdl: int, index: int, value: int) -> int:
    """Output ``index`` of module ``mdl`` to level ``value`` (0 = on)."""
    m = _module(ctl, "GT_SetExtIoBit", mdl)
    i = _bit(m, index, m.spec.do, "output(s)")
    m.write_output_levels(GTS_EXTMDL, int(value) << i, 1 << i)
    return 0


@gt_function
def GT_GetExtIoBit(ctl: Controller, mdl: int, index: int, pValue: Any) -> int:
    """The level of input ``index`` of module ``mdl`` (0 = active)."""
    m = _module(ctl, "GT_GetExtIoBit", mdl)
    i = _bit(m, index, m.spec.di, "input(s)")
    store(pValue, m.input_levels(GTS_EXTMDL) >> i & 1)
    return 0


@gt_function
def GT_GetExtDoValue(ctl: Controller, mdl: int, pValue: Any) -> int:
    """The 16 output levels module ``mdl`` drives (as written)."""
    store(pValue, _module(ctl, "GT_GetExtDoValue", mdl).output_levels(GTS_EXTMDL, 16))
    return 0


@gt_function
def GT_GetExtAdValue(ctl: Controller, mdl: int, chn: int, pValue: Any) -> int:
    """Analog input ``chn``: 0..65535 over the module's range."""
    m = _module(ctl, "GT_GetExtAdValue", mdl)
    c = _channel(m, chn, m.spec.ai, "analog input")
    store(pValue, _to_raw(m.ai[c], m.spec.ai_range))
    return 0


@gt_function
def GT_GetExtAdVoltage(ctl: Controller, mdl: int, chn: int, pValue: Any) -> int:
    """Analog input ``chn`` in volts."""
    m = _module(ctl, "GT_GetExtAdVoltage", mdl)
    store(pValue, m.ai[_channel(m, chn, m.spec.ai, "analog input")])
    return 0


@gt_function
def GT_SetExtDaValue(ctl: Controller, mdl: int, chn: int, value: int) -> int:
    """Analog output ``chn``: 0..65535 over the module's range."""
    m = _module(ctl, "GT_SetExtDaValue", mdl)
    c = _channel(m, chn, m.spec.ao, "analog output")
    m.ao[c] = _from_raw(value, m.spec.ao_range)
    return 0


@gt_function
def GT_SetExtDaVoltage(ctl: Controller, mdl: int, chn: int, value: float) -> int:
    """Analog output ``chn`` in volts; beyond the module's range returns 7."""
    m = _module(ctl, "GT_SetExtDaVoltage", mdl)
    c = _channel(m, chn, m.spec.ao, "analog output")
    lo, hi = m.spec.ao_range
    v = float(value)
    if not lo <= v <= hi:
        raise ParameterError(f"value={v} V: module {m.number} outputs {lo}..{hi} V")
    m.ao[c] = v
    return 0


@gt_function
def GT_GetStsExtMdl(ctl: Controller, mdl: int, chn: int, pStatus: Any) -> int:
    """0: module ``mdl`` communicates; 1: it does not (absent, offline, or no such channel
    on an analog module).  ``chn`` matters for analog modules only."""
    io = _opened(ctl, "GT_GetStsExtMdl")
    if not io.configured:
        raise CommandError("GT_GetStsExtMdl: no configuration is loaded (GT_LoadExtConfig first)")
    m = io.modules.get(int(mdl))
    ok = m is not None and m.online
    if ok and m is not None and (m.spec.ai or m.spec.ao) and not (m.spec.di or m.spec.do):
        ok = 0 <= int(chn) < max(m.spec.ai, m.spec.ao)
    store(pStatus, 0 if ok else 1)
    return 0


@gt_function
def GT_GetExtMdlMode(ctl: Controller, pMode: Any) -> int:
    """0: direct mode (the host drives the modules), 1: internal (motion programs)."""
    store(pMode, _opened(ctl, "GT_GetExtMdlMode").mode)
    return 0


@gt_function
def GT_SetExtMdlMode(ctl: Controller, mode: int) -> int:
    """The working mode; after GT_LoadExtConfig (as the vendor's manual says).  Both modes
    leave the terminals to the GT calls here."""
    io = _opened(ctl, "GT_SetExtMdlMode")
    if not io.configured:
        raise CommandError("GT_SetExtMdlMode: call GT_LoadExtConfig first")
    io.mode = int(mode)
    return 0


# --- the multi-card wrappers' *Gts forms -------------------------------------------------------
def _card(ctl: Controller, card_num: int, name: str = "cardNum") -> Controller:
    """The controller of card ``card_num``: 7 outside 0..15, -1 when it is not open."""
    n = check_range(name, card_num, 0, _MAX_CARDS - 1)
    if n == SESSION.card:
        return ctl
    other = SESSION.cards.get(n, {}).get(1)
    if other is None:
        raise NotOpen(f"{name}={n}: card {n} is not open (GT_SetCardNo({n}), then GT_Open)")
    return other


def _gts_form(fn: Any) -> Any:
    """The multi-card ``<name>Gts`` form of GT function ``fn``: ``cardNum`` first, the card
    whose modules it addresses, then ``fn``'s own implementation (one call: one host-call
    latency, one reason)."""
    impl = fn.__wrapped__

    def twin(ctl: Controller, cardNum: int, *args: Any) -> int:
        target = _card(ctl, cardNum)
        if target is not ctl and target.clock.threaded:
            with target.clock.lock:  # atomic with respect to that card's cycle
                return impl(target, *args)
        return impl(target, *args)

    twin.__name__ = twin.__qualname__ = fn.__name__ + "Gts"
    twin.__doc__ = f"``{fn.__name__}`` of card ``cardNum``."
    return gt_function(twin)


GT_OpenExtMdlGts = _gts_form(GT_OpenExtMdl)
GT_CloseExtMdlGts = _gts_form(GT_CloseExtMdl)
GT_SwitchtoCardNoExtMdlGts = _gts_form(GT_SwitchtoCardNoExtMdl)
GT_ResetExtMdlGts = _gts_form(GT_ResetExtMdl)
GT_LoadExtConfigGts = _gts_form(GT_LoadExtConfig)
GT_SetExtIoValueGts = _gts_form(GT_SetExtIoValue)
GT_GetExtIoValueGts = _gts_form(GT_GetExtIoValue)
GT_SetExtIoBitGts = _gts_form(GT_SetExtIoBit)
GT_GetExtIoBitGts = _gts_form(GT_GetExtIoBit)
GT_GetExtAdValueGts = _gts_form(GT_GetExtAdValue)
GT_GetExtAdVoltageGts = _gts_form(GT_GetExtAdVoltage)
GT_SetExtDaValueGts = _gts_form(GT_SetExtDaValue)
GT_SetExtDaVoltageGts = _gts_form(GT_SetExtDaVoltage)
GT_GetStsExtMdlGts = _gts_form(GT_GetStsExtMdl)
GT_GetExtDoValueGts = _gts_form(GT_GetExtDoValue)


# --- the GTN cores' extension modules ----------------------------------------------------------
def _gtn(ctl: Controller, name: str) -> ExtIo:
    io = ext_io(ctl)
    if not io.gtn_ready:
        raise CommandError(f"{name}: the extension modules are not initialised (GTN_ExtModuleInit)")
    return io


def _terminals(io: ExtIo, kind: str) -> list[tuple[ExtModule, int]]:
    """Every terminal of ``kind`` (di, do, ai, ao) in chain order: (module, its index)."""
    return [(m, i) for m in io.flat() for i in range(getattr(m.spec, kind))]


def _terminal(io: ExtIo, kind: str, index: int, what: str) -> tuple[ExtModule, int]:
    terms = _terminals(io, kind)
    i = int(index)
    if not 1 <= i <= len(terms):
        raise ParameterError(
            f"{what}={i}: the extension modules have {len(terms)} {kind.upper()}"
            + (f" (1..{len(terms)})" if terms else "")
        )
    m, k = terms[i - 1]
    if not m.online:
        raise CommandError(f"{what}={i} is on extension module {m.number}, which does not answer")
    return m, k


def _word(io: ExtIo, kind: str, first: int, what: str) -> list[tuple[ExtModule, int]]:
    """The (up to) 32 terminals from ``first``; the first one must exist."""
    _terminal(io, kind, first, what)
    terms = _terminals(io, kind)[int(first) - 1 : int(first) - 1 + 32]
    for m, _ in terms:
        if not m.online:
            raise CommandError(f"extension module {m.number} does not answer on its bus")
    return terms


@gt_function
def GT_ExtModuleInit(ctl: Controller, method: int = 1) -> int:
    """Scan the extension modules of the core; 1 when there is none or one does not answer."""
    io = ext_io(ctl)
    if not io.modules:
        raise CommandError(
            f"GT_ExtModuleInit: no extension module on this machine ({io.source} has no [ext.N])"
        )
    silent = [n for n, m in io.modules.items() if not m.online]
    if silent:
        raise CommandError(f"GT_ExtModuleInit: extension module(s) {silent} do not answer")
    io.gtn_ready, io.gtn_method = True, int(method)
    return 0


@gt_function
def GT_SetExtDoBit(ctl: Controller, doIndex: int, value: int) -> int:
    """Output ``doIndex`` (from 1 over the chain) to level ``value``."""
    m, k = _terminal(_gtn(ctl, "GT_SetExtDoBit"), "do", doIndex, "doIndex")
    m.write_output_levels(GTN_EXT, int(value) << k, 1 << k)
    return 0


@gt_function
def GT_GetExtDoBit(ctl: Controller, doIndex: int, pValue: Any) -> int:
    m, k = _terminal(_gtn(ctl, "GT_GetExtDoBit"), "do", doIndex, "doIndex")
    store(pValue, m.output_levels(GTN_EXT) >> k & 1)
    return 0


@gt_function
def GT_SetExtDo(ctl: Controller, doIndex: int, value: int, mask: int) -> int:
    """The outputs ``doIndex`` .. ``doIndex + 31`` under ``mask`` take ``value``'s levels."""
    terms = _word(_gtn(ctl, "GT_SetExtDo"), "do", doIndex, "doIndex")
    v, msk = int(value) & 0xFFFFFFFF, int(mask) & 0xFFFFFFFF
    for bit, (m, k) in enumerate(terms):
        if msk >> bit & 1:
            m.write_output_levels(GTN_EXT, (v >> bit & 1) << k, 1 << k)
    return 0


@gt_function
def GT_GetExtDo(ctl: Controller, doIndex: int, pValue: Any) -> int:
    terms = _word(_gtn(ctl, "GT_GetExtDo"), "do", doIndex, "doIndex")
    store(
        pValue,
        _signed32(sum((m.output_levels(GTN_EXT) >> k & 1) << b for b, (m, k) in enumerate(terms))),
    )
    return 0


@gt_function
def GT_GetExtDiBit(ctl: Controller, diIndex: int, pValue: Any) -> int:
    m, k = _terminal(_gtn(ctl, "GT_GetExtDiBit"), "di", diIndex, "diIndex")
    store(pValue, m.input_levels(GTN_EXT) >> k & 1)
    return 0


@gt_function
def GT_GetExtDi(ctl: Controller, diIndex: int, pValue: Any) -> int:
    """The levels of inputs ``diIndex`` .. ``diIndex + 31`` (bit 0 = ``diIndex``)."""
    terms = _word(_gtn(ctl, "GT_GetExtDi"), "di", diIndex, "diIndex")
    store(
        pValue,
        _signed32(sum((m.input_levels(GTN_EXT) >> k & 1) << b for b, (m, k) in enumerate(terms))),
    )
    return 0


def _analog(io: ExtIo, kind: str, index: int, count: int) -> list[tuple[ExtModule, int]]:
    n = check_range("count", count, 1, 0x7FFF)
    first = int(index)
    _terminal(io, kind, first, "index")
    _terminal(io, kind, first + n - 1, "index + count - 1")
    return _terminals(io, kind)[first - 1 : first - 1 + n]


def _full_scale(rng: tuple[float, float]) -> float:
    return max(abs(rng[0]), abs(rng[1]))


@gt_function
def GT_SetExtAo(ctl: Controller, index: int, pValue: Any, count: int = 1) -> int:
    """Analog outputs ``index`` .. (from 1 over the chain) in volts."""
    chans = _analog(_gtn(ctl, "GT_SetExtAo"), "ao", index, count)
    values = [float(v) for v in pValue.load_values(len(chans))]
    for (m, _k), v in zip(chans, values, strict=True):
        lo, hi = m.spec.ao_range
        if not lo <= v <= hi:
            raise ParameterError(f"{v} V: extension module {m.number} outputs {lo}..{hi} V")
    for (m, k), v in zip(chans, values, strict=True):
        m.ao[k] = v
    return 0


@gt_function
def GT_GetExtAo(ctl: Controller, index: int, pValue: Any, count: int = 1) -> int:
    chans = _analog(_gtn(ctl, "GT_GetExtAo"), "ao", index, count)
    store_array(pValue, [m.ao[k] for m, k in chans])
    return 0


@gt_function
def GT_GetExtAi(ctl: Controller, index: int, pValue: Any, count: int = 1) -> int:
    chans = _analog(_gtn(ctl, "GT_GetExtAi"), "ai", index, count)
    store_array(pValue, [m.ai[k] for m, k in chans])
    return 0


@gt_function
def GT_SetExtAoValue(ctl: Controller, index: int, pValue: Any, count: int = 1) -> int:
    """Analog outputs as ``short`` values: +-32767 = +-max(|low|, |high|) volts."""
    chans = _analog(_gtn(ctl, "GT_SetExtAoValue"), "ao", index, count)
    raw = [int(v) for v in pValue.load_values(len(chans))]
    for (m, k), r in zip(chans, raw, strict=True):
        lo, hi = m.spec.ao_range
        m.ao[k] = min(max(r / 32767 * _full_scale(m.spec.ao_range), lo), hi)
    return 0


@gt_function
def GT_GetExtAiValue(ctl: Controller, index: int, pValue: Any, count: int = 1) -> int:
    chans = _analog(_gtn(ctl, "GT_GetExtAiValue"), "ai", index, count)
    store_array(
        pValue,
        [
            max(-32768, min(32767, round(m.ai[k] / _full_scale(m.spec.ai_range) * 32767)))
            for m, k in chans
        ],
    )
    return 0


# --- gLink-II ----------------------------------------------------------------------------------
def _glink(ctl: Controller, name: str, slaveno: int) -> ExtModule:
    io = ext_io(ctl)
    if not io.glink_ready:
        raise CommandError(f"{name}: gLink is not initialised (GT_GLinkInit first)")
    m = io.glink.get(int(slaveno))
    if m is None or not m.online:
        have = ", ".join(str(n) for n, s in io.glink.items() if s.online) or "none"
        raise CommandError(f"{name}: gLink slave {slaveno} is not online (online: {have})")
    return m


def _bytes_of(m: ExtModule, kind: str, offset: int, n: int) -> range:
    bits = m.spec.di if kind == "di" else m.spec.do
    size = (bits + 7) // 8
    if n < 1 or offset + n > size:
        raise ParameterError(
            f"offset={offset}, bytelength={n}: gLink slave {m.number} has {size} "
            f"{kind.upper()} byte(s)"
        )
    return range(offset, offset + n)


@gt_function
def GT_GLinkInit(ctl: Controller, cardNum: int) -> int:
    """Start the gLink-II master of card ``cardNum``; 1 when no slave is connected."""
    io = ext_io(_card(ctl, cardNum))
    if not io.glink:
        raise CommandError(
            f"GT_GLinkInit: no gLink slave on this machine ({io.source} has no [glink.N])"
        )
    io.glink_ready = True
    return 0


@gt_function
def GT_GetGLinkOnlineSlaveNum(ctl: Controller, slavenum: Any) -> int:
    io = ext_io(ctl)
    if not io.glink_ready:
        raise CommandError(
            "GT_GetGLinkOnlineSlaveNum: gLink is not initialised (GT_GLinkInit first)"
        )
    store(slavenum, sum(m.online for m in io.glink.values()))
    return 0


@gt_function
def GT_SetGLinkDo(ctl: Controller, slaveno: int, offset: int, pData: Any, bytelength: int) -> int:
    """Output bytes ``offset`` .. of slave ``slaveno`` (bit 0 of byte 0 = output 0; 1 = on)."""
    m = _glink(ctl, "GT_SetGLinkDo", slaveno)
    span = _bytes_of(m, "do", int(offset), int(bytelength))
    data = load_bytes(pData, len(span))
    for b, byte in zip(span, data, strict=True):
        m.write_output_levels(GLINK, byte << (8 * b), 0xFF << (8 * b))
    return 0


@gt_function
def GT_GetGLinkDo(ctl: Controller, slaveno: int, offset: int, pData: Any, bytelength: int) -> int:
    m = _glink(ctl, "GT_GetGLinkDo", slaveno)
    span = _bytes_of(m, "do", int(offset), int(bytelength))
    levels = m.output_levels(GLINK)
    store_bytes(pData, bytes(levels >> (8 * b) & 0xFF for b in span))
    return 0


@gt_function
def GT_GetGLinkDi(ctl: Controller, slaveno: int, offset: int, pData: Any, bytelength: int) -> int:
    m = _glink(ctl, "GT_GetGLinkDi", slaveno)
    span = _bytes_of(m, "di", int(offset), int(bytelength))
    levels = m.input_levels(GLINK)
    store_bytes(pData, bytes(levels >> (8 * b) & 0xFF for b in span))
    return 0


@gt_function
def GT_SetGLinkDoBit(ctl: Controller, slaveno: int, doIndex: int, value: int) -> int:
    m = _glink(ctl, "GT_SetGLinkDoBit", slaveno)
    i = _bit(m, doIndex, m.spec.do, "output(s)")
    m.write_output_levels(GLINK, int(value) << i, 1 << i)
    return 0


@gt_function
def GT_GetGLinkDiBit(ctl: Controller, slaveno: int, diIndex: int, pValue: Any) -> int:
    m = _glink(ctl, "GT_GetGLinkDiBit", slaveno)
    i = _bit(m, diIndex, m.spec.di, "input(s)")
    store(pValue, m.input_levels(GLINK) >> i & 1)
    return 0


# --- the field side ----------------------------------------------------------------------------
def _field_module(ctl: Controller, mdl: int) -> ExtModule:
    io = ext_io(ctl)
    m = io.modules.get(int(mdl))
    if m is None:
        raise ParameterError(f"mdl={mdl}: the machine description has no [ext.{mdl}]")
    return m


@gt_function
def GTE_SetExtDi(ctl: Controller, mdl: int, index: int, active: int) -> int:
    """Emulator only: input ``index`` (from 0) of extension module ``mdl`` becomes active (1)."""
    _field_module(ctl, mdl).set_input(index, bool(active))
    return 0


@gt_function
def GTE_SetExtAdVoltage(ctl: Controller, mdl: int, chn: int, voltage: float) -> int:
    """Emulator only: the voltage on analog input ``chn`` (from 0) of module ``mdl``."""
    _field_module(ctl, mdl).set_voltage(chn, voltage)
    return 0


@gt_function
def GTE_SetGLinkDi(ctl: Controller, slaveno: int, diIndex: int, active: int) -> int:
    """Emulator only: input ``diIndex`` (from 0) of gLink slave ``slaveno`` becomes active."""
    m = ext_io(ctl).glink.get(int(slaveno))
    if m is None:
        raise ParameterError(f"slaveno={slaveno}: the machine description has no [glink.{slaveno}]")
    m.set_input(diIndex, bool(active))
    return 0


def GTE_ExtModule(mdl: int, core: int = 1) -> ExtModule:
    """The field side of extension module ``mdl`` (``set_input``, ``output``, ``online`` ...)."""
    from ._core import SESSION

    return _field_module(SESSION.controller(core), mdl)


def GTE_GLinkSlave(slaveno: int, core: int = 1) -> ExtModule:
    """The field side of gLink slave ``slaveno``."""
    from ._core import SESSION

    m = ext_io(SESSION.controller(core)).glink.get(int(slaveno))
    if m is None:
        raise ParameterError(f"slaveno={slaveno}: the machine description has no [glink.{slaveno}]")
    return m


def _signed32(v: int) -> int:
    v &= 0xFFFFFFFF
    return v - (1 << 32) if v >= 1 << 31 else v
