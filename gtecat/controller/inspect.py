"""The bus as the inspection verbs show it: rows of plain values, built from an open controller.

``gtecat slaves|pdos|sdo|sdos|states|reg|sii|data|cstruct|graph`` print what a
:class:`BusView` returns. On a bus of the verb's own the verb calls it directly; with
``--controller`` the controller process calls the same method (``gtecat.native.field``)
and sends the result back, so a verb prints the same either way. Results are JSON as they
are (bytes excepted: the field operations send them as hex).

What the backend can show: the object dictionary, ESC registers and SII of an emulated
slave are the virtual slave's own; on pysoem registers are read and written with FPRD/FPWR
and the SII is read through the slave's EEPROM interface.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from typing import Any

from gtecat.drives.slave import AlState, AlStatusCode
from gtecat.eni.model import Direction

from .._attrs import PerObject
from ..errors import BusError, ParameterError
from .core import Controller

#: SII category types (ETG.1000.6 Table 19): the end marker
_SII_END = 0xFFFF
#: words of the SII before its first category (ETG.1000.6 Table 16)
_SII_HEADER_WORDS = 0x40
#: 4 KiB of SII at most (a 32 kbit EEPROM)
_SII_MAX_WORDS = 2048


def check_position(count: int, position: int) -> int:
    if not 0 <= position < count:
        raise ParameterError(
            f"no slave {position}: the bus has slaves 0..{count - 1}"
            if count
            else f"no slave {position}: the bus has none"
        )
    return position


def slave_rows(master: Any, positions: Sequence[int]) -> list[dict[str, Any]]:
    """One row per slave: position, AL state, identity, axes, GT raw region."""
    states = master.refresh_states()
    rows = []
    for pos in positions:
        sl, cfg = master.layout.slaves[pos], master.layout.config.slaves[pos]
        rows.append(
            {
                "position": sl.position,
                "state": AlState(states[pos]).name,
                "name": cfg.name,
                "vendor_id": cfg.identity.vendor_id,
                "product_code": cfg.identity.product_code,
                "revision": cfg.identity.revision_no,
                "axes": list(sl.axes),
                "gt_offset": sl.gt_offset,
                "gt_size": sl.gt_size,
            }
        )
    return rows


def pdo_rows(config: Any, positions: Sequence[int]) -> list[dict[str, Any]]:
    """Per slave its assigned PDOs (sync manager, direction) and their entries."""
    out = []
    for pos in positions:
        s = config.slaves[pos]
        pdos = []
        for d, plist in ((Direction.OUT, s.rx_pdos), (Direction.IN, s.tx_pdos)):
            for p in plist:
                pdos.append(
                    {
                        "dir": "out" if d == Direction.OUT else "in",
                        "sm": p.sm,
                        "index": p.index,
                        "name": p.name,
                        "entries": [
                            {
                                "index": e.index,
                                "subindex": e.subindex,
                                "bits": e.bit_len,
                                "name": e.name,
                                "type": e.data_type,
                            }
                            for e in p.entries
                        ],
                    }
                )
        out.append({"position": s.position, "name": s.name, "pdos": pdos})
    return out


def al_code_name(code: int) -> str:
    try:
        return AlStatusCode(code).name
    except ValueError:
        return f"0x{code:04X}"


def _od_value(var: Any) -> tuple[Any, str | None]:
    """(value for JSON, hex of the value's bytes) of one dictionary entry."""
    if not var.access.readable:
        return None, None
    try:
        value = var.get()
        raw = var.encode(value)
    except Exception:  # a getter that needs a running drive: show no value, not an error
        return None, None
    if isinstance(value, bytes):
        value = value.hex(" ")
    if isinstance(value, float):
        value = round(value, 6)
    return value, raw.hex()


def _pdo_kind(var: Any) -> str:
    names = [n for n, bit in (("RxPDO", 1), ("TxPDO", 2)) if int(var.pdo) & bit]
    return ",".join(names) or "-"


class BusView:
    """What the inspection verbs ask of one controller's bus (see the module docstring)."""

    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        self._escs: dict[int, Any] = {}
        self._escs_of: Any = None  # the master the ESCs were made for

    # --- slaves and positions ----------------------------------------------------------------
    @property
    def master(self) -> Any:
        m = self.ctl.master
        if m is None:
            raise BusError("the bus is not up yet (GT_InitEcatComm first)")
        return m

    @property
    def count(self) -> int:
        return len(self.master.layout.slaves)

    def check(self, position: int) -> int:
        return check_position(self.count, int(position))

    def positions(self, position: int | None = None) -> list[int]:
        """``-p POSITION`` or every slave."""
        return [self.check(position)] if position is not None else list(range(self.count))

    @property
    def emulated(self) -> bool:
        from ..master.backends.emulated import EmulatedBackend

        return isinstance(self.ctl.backend, EmulatedBackend)

    def virtual(self, position: int, what: str) -> Any:
        """The in-process slave at ``position`` (emulated bus only)."""
        if not self.emulated:
            raise BusError(
                f"{what} needs the emulated bus (this is {type(self.ctl.backend).__name__})"
            )
        return self.ctl.backend.slaves[self.check(position)]

    def od(self, position: int) -> Any:
        """The object dictionary of ``position`` (the emulated slave's own)."""
        slave = self.virtual(position, "listing the object dictionary")
        od = getattr(slave, "od", None)
        if od is None:
            raise BusError(f"slave {position} ({slave.name}) has no CoE object dictionary")
        return od

    # --- slaves, pdos, sdo ---------------------------------------------------------------------
    def slaves(self, position: int | None = None) -> list[dict[str, Any]]:
        return slave_rows(self.master, self.positions(position))

    def pdos(self, position: int | None = None) -> list[dict[str, Any]]:
        return pdo_rows(self.master.layout.config, self.positions(position))

    def sdo_entry(self, slave: int, index: int, subindex: int) -> dict[str, str]:
        """The dictionary's name and type of an object ({} when the slave has none)."""
        self.check(slave)
        try:
            od = self.od(slave)
        except BusError:
            return {}
        var = od.find(int(index), int(subindex))
        return {"name": var.name, "type": var.data_type.name} if var is not None else {}

    def sdo_find(self, slave: int, name: str, subindex: int | None = None) -> dict[str, Any]:
        """The object called ``name`` (an object's or an entry's, any case): {index,
        subindex, name, type}; ParameterError when none or several are."""
        self.check(slave)
        try:
            od = self.od(slave)
        except BusError:
            raise ParameterError(
                f"sdo: {name!r} is not a number; names are looked up in the emulated slave's "
                "dictionary only: give the index, e.g. 0x6041 0"
            ) from None
        wanted = name.casefold()
        hits = []
        for o in od:
            subs = [o.subs[k] for k in sorted(o.subs)]
            if o.name.casefold() == wanted:
                if subindex is None and len(subs) > 1:
                    raise ParameterError(
                        f"sdo: {name!r} is 0x{o.index:04X} with subindexes "
                        f"{', '.join(str(v.subindex) for v in subs)}: give SUB"
                    )
                hits += [v for v in subs if subindex is None or v.subindex == subindex]
            else:
                hits += [
                    v
                    for v in subs
                    if v.name.casefold() == wanted and (subindex is None or v.subindex == subindex)
                ]
        if not hits:
            raise ParameterError(
                f"sdo: slave {slave} has no object called {name!r} "
                f"(`gtecat sdos -p {slave}` lists them)"
            )
        if len({(v.index, v.subindex) for v in hits}) > 1:
            where = ", ".join(f"0x{v.index:04X}:{v.subindex:02X}" for v in hits[:5])
            raise ParameterError(f"sdo: {name!r} names {where}: give the index")
        v = hits[0]
        return {"index": v.index, "subindex": v.subindex, "name": v.name, "type": v.data_type.name}

    def sdo_upload(self, slave: int, index: int, subindex: int) -> bytes:
        # (beside the application: a lost answer runs none of its cycles)
        return bytes(
            self.master.sdo_upload(self.check(slave), int(index), int(subindex), wait=False)
        )

    def sdo_download(self, slave: int, index: int, subindex: int, data: bytes) -> None:
        self.master.sdo_download(
            self.check(slave), int(index), int(subindex), bytes(data), wait=False
        )

    # --- sdos ----------------------------------------------------------------------------------
    def sdos(
        self, position: int | None = None, values: bool = True, grep: str | None = None
    ) -> list[dict[str, Any]]:
        """Every dictionary entry of the slaves (those without CoE are left out, unless
        ``position`` names one: then that is an error)."""
        rows = []
        for pos in self.positions(position):
            try:
                od = self.od(pos)
            except BusError:
                if position is not None:
                    raise
                continue  # an IO terminal without CoE: nothing to list
            for obj in od:
                for k in sorted(obj.subs):
                    var = obj.subs[k]
                    name = var.name if var.name == obj.name or k == 0 else f"{obj.name}: {var.name}"
                    if grep and grep.casefold() not in name.casefold():
                        continue
                    value, raw = _od_value(var) if values else (None, None)
                    rows.append(
                        {
                            "position": pos,
                            "index": var.index,
                            "subindex": var.subindex,
                            "name": name,
                            "type": var.data_type.name,
                            "bits": var.bit_length,
                            "access": var.access.name,
                            "pdo": _pdo_kind(var),
                            "value": value,
                            "hex": raw,
                        }
                    )
        return rows

    # --- states --------------------------------------------------------------------------------
    def states(self, position: int | None = None, target: str | None = None) -> list[dict]:
        """Each slave's AL state and status code; with ``target`` (an AlState name) the
        state is requested first and a refusal named."""
        want = None
        if target is not None:
            try:
                want = AlState[str(target).upper()]
            except KeyError:
                raise ParameterError(
                    f"no AL state {target!r}: give INIT, PREOP, SAFEOP, OP or BOOT"
                ) from None
        backend = self.ctl.backend
        names = self.master.layout.slaves
        rows = []
        for pos in self.positions(position):
            before, _ = backend.state(pos)
            refused = None
            running = self.master._op_requested
            if want == AlState.OP and running:
                # back to OP on a running bus: the master's own walk, InitCmds included
                self.master.held.pop(pos, None)
                self.master.recover()
                st, code = backend.state(pos)
                if st != AlState.OP:
                    refused = al_code_name(int(code)) if code else f"stays in {st.name}"
            elif want is not None:
                code = int(backend.request_state(pos, want))
                if code:
                    refused = al_code_name(code)
                if running:  # the request holds: recovery leaves the slave there until OP
                    self.master.held[pos] = want  # is asked (gtecat.master.bus.Master.held)
            state, code = backend.state(pos)
            rows.append(
                {
                    "position": pos,
                    "name": names[pos].name,
                    "before": AlState(before).name,
                    "state": AlState(state).name,
                    "status_code": int(code),
                    "status": al_code_name(int(code)) if int(code) else "",
                    "refused": refused,
                }
            )
        return rows

    # --- ESC registers and the SII -------------------------------------------------------------
    def _esc(self, position: int) -> Any:
        """The emulated slave's EtherCAT slave controller: registers and SII EEPROM."""
        slave = self.virtual(position, "ESC registers and the SII")
        if self._escs_of is not self.master:  # a new bus (GT_InitEcatComm again)
            self._escs, self._escs_of = {}, self.master
        if position not in self._escs:
            from gtecat.drives.esc.registers import Esc
            from gtecat.drives.esc.sii import build_sii
            from gtecat.drives.esc.sii_eni import sii_for

            info = sii_for(slave, self.master.layout.config.slaves[position])
            self._escs[position] = Esc(
                slave, build_sii(info), position=position, chain_length=self.count
            )
        esc = self._escs[position]
        esc.sync_al()
        return esc

    def _pysoem_slave(self, position: int) -> Any:
        m = getattr(self.ctl.backend, "master", None)
        if m is None:
            raise BusError(
                f"ESC registers and the SII need the emulated or the pysoem bus (this is "
                f"{type(self.ctl.backend).__name__})"
            )
        return m.slaves[self.check(position)]

    def reg_read(self, position: int, address: int, size: int) -> bytes:
        position, address, size = self.check(position), int(address), int(size)
        if self.emulated:
            data = self._esc(position).read(address, size)
            if data is None:
                raise BusError(f"slave {position}: 0x{address:04X}+{size} is not readable")
            return bytes(data)
        return bytes(self._pysoem_slave(position)._fprd(address, size))

    def reg_write(self, position: int, address: int, data: bytes) -> None:
        position, address = self.check(position), int(address)
        if self.emulated:
            if not self._esc(position).write(address, bytes(data)):
                raise BusError(f"slave {position}: 0x{address:04X}+{len(data)} is not writable")
            return
        self._pysoem_slave(position)._fpwr(address, bytes(data))

    def sii(self, position: int) -> bytes:
        position = self.check(position)
        if self.emulated:
            return bytes(self._esc(position).sii)
        return read_sii(self._pysoem_slave(position).eeprom_read)

    # --- the process image ---------------------------------------------------------------------
    def region(self, position: int) -> bytes:
        """Slave ``position``'s GT raw region: its outputs then its inputs, entry by entry."""
        s = self.master.layout.slaves[self.check(position)]
        out = bytearray(s.gt_size)
        image = self.master.image
        for p in s.entries:
            if p.is_padding:
                continue
            value = image.access(p).get()
            if isinstance(value, float):
                raw = struct.pack("<f" if p.bits == 32 else "<d", value)
                start = p.gt_bit // 8 - s.gt_offset
                out[start : start + len(raw)] = raw
                continue
            v = int(value) & ((1 << p.bits) - 1)
            rel = p.gt_bit - s.gt_offset * 8
            for b in range(p.bits):
                if v >> b & 1:
                    out[(rel + b) // 8] |= 1 << ((rel + b) % 8)
        return bytes(out)

    def data(self, position: int | None = None, cycles: int = 0) -> list[dict[str, Any]]:
        """Per slave its GT raw region (hex) and its entries' values, after ``cycles``."""
        if cycles > 0:
            self.ctl.wait_ms(cycles * self.ctl.clock.cycle_ns / 1e6)
        image = self.master.image
        slaves = []
        for pos in self.positions(position):
            s = self.master.layout.slaves[pos]
            entries = []
            for p in s.entries:
                if p.is_padding:
                    continue
                value = image.access(p).get()
                entries.append(
                    {
                        "dir": "out" if p.direction == Direction.OUT else "in",
                        "index": p.index,
                        "subindex": p.subindex,
                        "name": p.name,
                        "bits": p.bits,
                        "gt_bit": p.gt_bit,
                        "value": value,
                    }
                )
            slaves.append(
                {
                    "position": pos,
                    "name": s.name,
                    "gt_offset": s.gt_offset,
                    "gt_size": s.gt_size,
                    "bytes": self.region(pos).hex(),
                    "entries": entries,
                }
            )
        return slaves

    # --- the configuration, rendered -----------------------------------------------------------
    def cstruct(self, prefix: str = "", position: int | None = None) -> str:
        from gtecat.eni.cstruct import render

        if position is not None:
            self.check(position)
        layout = self.master.layout
        return render(layout, layout.config.source, prefix=prefix, only=position)

    def graph(self) -> str:
        from gtecat.eni.graph import render

        layout = self.master.layout
        return render(layout.config, layout)


def read_sii(eeprom_read: Any) -> bytes:
    """A slave's SII through its EEPROM interface, 4 bytes (2 words) per read, up to the end
    category (ETG.1000.6 Table 19: each category is a type word, a size word in words,
    then its data)."""
    words = bytearray()

    def word(w: int) -> int:
        while len(words) < 2 * (w + 1):
            words.extend(bytes(eeprom_read(len(words) // 2))[:4])
        return int.from_bytes(words[2 * w : 2 * w + 2], "little")

    w = _SII_HEADER_WORDS
    while w + 1 < _SII_MAX_WORDS:
        kind = word(w)
        if kind == _SII_END:  # kept with its size word: a category header is two words
            word(w + 1)
            return bytes(words[: 2 * (w + 2)])
        w += 2 + word(w + 1)
    return bytes(words[: 2 * _SII_MAX_WORDS])


_VIEWS: PerObject[BusView] = PerObject("bus_view")


def view(ctl: Controller) -> BusView:
    """The one view of ``ctl`` (its emulated ESCs keep register values between requests)."""
    v = _VIEWS.get(ctl)
    if v is None:
        v = _VIEWS[ctl] = BusView(ctl)
    return v


__all__ = [
    "BusView",
    "al_code_name",
    "check_position",
    "pdo_rows",
    "read_sii",
    "slave_rows",
    "view",
]
