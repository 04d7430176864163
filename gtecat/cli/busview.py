"""The bus as the inspection verbs see it: opened the way ``GT_Open`` would, one slave at a
time by ``-p POSITION``, with what each backend can show (object dictionary, ESC registers,
SII).

``--eni`` (or ``GTECAT_ENI``, else ``./Gecat.eni``), ``--machine``, ``--backend`` and
``--iface`` mean what they mean for ``GT_Open``. On the emulated bus every command starts a
fresh bus and stops it when done; ``--backend pysoem --iface NIC`` talks to a real one.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from drives.machine import MachineError

from ..controller.core import Controller, Options
from ..errors import BusError, ConfigMismatch, NoSlavesError, ParameterError
from . import output


def add_bus_options(p: argparse.ArgumentParser, *, position: bool = True) -> None:
    p.add_argument("--eni", help="configuration file (default: $GTECAT_ENI or ./Gecat.eni)")
    p.add_argument("--machine", help="machine description TOML ($GTECAT_MACHINE)")
    p.add_argument("--backend", choices=("emulated", "pysoem"), help="($GTECAT_BACKEND)")
    p.add_argument("--iface", help="network interface for pysoem ($GTECAT_IFACE)")
    if position:
        output.add_position(p)
    output.add_json(p)


def check_toml_kind(path: str | os.PathLike[str] | None, want: str) -> None:
    """Refuse a topology given as a machine description and the other way round."""
    if not path or not Path(path).is_file() or Path(path).suffix.lower() != ".toml":
        return
    import tomllib

    try:
        data = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return  # the reader itself says what is wrong
    if want == "machine" and "slave" in data and "axis" not in data:
        raise ParameterError(
            f"{path} is a topology ([[slave]] tables: a bus for `gtecat eni new`), not a machine "
            "description ([axis.N] tables: switches, index, probe marks)"
        )
    if want == "topology" and "axis" in data and "slave" not in data:
        raise ParameterError(
            f"{path} is a machine description ([axis.N] tables, for --machine), not a topology "
            "([[slave]] tables, what `gtecat eni new` writes an ENI from)"
        )


def eni_argument(args: argparse.Namespace) -> str | None:
    eni = getattr(args, "eni", None) or getattr(args, "file", None)
    if eni and Path(eni).is_dir():
        inside = sorted(p.name for p in Path(eni).iterdir() if p.suffix.lower() == ".eni")
        hint = f" (it holds {', '.join(inside)})" if inside else ""
        raise ParameterError(
            f"{eni} is a folder, not an ENI file{hint}: give the file, e.g. --eni "
            f"{Path(eni) / (inside[0] if inside else 'Gecat.eni')}"
        )
    return eni


def open_bus(args: argparse.Namespace) -> Controller:
    """Bring the bus up as GT_Open + GT_InitEcatComm would (lockstep; realtime on pysoem)."""
    backend = args.backend or os.environ.get("GTECAT_BACKEND") or "emulated"
    eni = eni_argument(args)
    check_toml_kind(args.machine, "machine")
    try:
        ctl = Controller(
            Options(
                eni=eni,
                machine=args.machine,
                # a real bus must cycle on the wall clock (docs/hardware.md)
                clock="realtime" if backend == "pysoem" else "lockstep",
                backend=args.backend,
                iface=args.iface,
                log="",
            )
        )
    except MachineError as e:
        raise MachineError(f"{e} (--machine FILE or GTECAT_MACHINE; or leave it out)") from None
    try:
        ctl.init_ecat()
        if not ctl.clock.run_until(lambda: ctl.ready, 2000):
            err = ctl.master.error if ctl.master else ""
            raise BusError(f"the bus did not reach OP{': ' + err if err else ''}")
    except ConfigMismatch as e:
        ctl.close()
        if "export" in str(e):  # the master already says what to do
            raise
        raise ConfigMismatch(
            f"{e}; the ENI does not describe this bus: export it again from the "
            "configuration tool for this machine, or check the cabling order"
        ) from None
    except NoSlavesError:
        ctl.close()
        if backend != "emulated":
            raise
        path = ctl.eni_path()
        raise NoSlavesError(
            f"{path} describes no slaves, so the emulated bus is empty: use the ENI your "
            "configuration tool exported for the machine (`gtecat map FILE` shows its slaves)"
        ) from None
    except BaseException:
        ctl.close()
        raise
    return ctl


class Bus:
    """``with Bus(args) as bus:`` an opened bus, closed afterwards."""

    def __init__(self, args: argparse.Namespace) -> None:
        self.args = args
        self.ctl = open_bus(args)
        self.master = self.ctl.master
        self.layout = self.master.layout
        self._escs: dict[int, Any] = {}

    def __enter__(self) -> Bus:
        return self

    def __exit__(self, *exc: object) -> None:
        self.ctl.close()

    @property
    def count(self) -> int:
        return len(self.layout.slaves)

    def check(self, position: int) -> int:
        if not 0 <= position < self.count:
            raise ParameterError(
                f"no slave {position}: the bus has slaves 0..{self.count - 1}"
                if self.count
                else f"no slave {position}: the bus has none"
            )
        return position

    def positions(self) -> list[int]:
        """``-p POSITION`` or every slave."""
        p = getattr(self.args, "position", None)
        return [self.check(p)] if p is not None else list(range(self.count))

    # --- what the backend can show ------------------------------------------------------------
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

    def pysoem_slave(self, position: int) -> Any:
        m = getattr(self.ctl.backend, "master", None)
        if m is None:
            raise BusError("the pysoem master is not open")
        return m.slaves[self.check(position)]

    def od(self, position: int) -> Any:
        """The object dictionary of ``position`` (the emulated slave's own)."""
        slave = self.virtual(position, "listing the object dictionary")
        od = getattr(slave, "od", None)
        if od is None:
            raise BusError(f"slave {position} ({slave.name}) has no CoE object dictionary")
        return od

    def esc(self, position: int) -> Any:
        """The emulated slave's EtherCAT slave controller: registers and SII EEPROM."""
        if position not in self._escs:
            from drives.esc.registers import Esc
            from drives.esc.sii import build_sii, sii_info_for

            slave = self.virtual(position, "ESC registers and the SII")
            self._escs[position] = Esc(
                slave, build_sii(sii_info_for(slave)), position=position, chain_length=self.count
            )
        esc = self._escs[position]
        esc.sync_al()
        return esc

    def reg_read(self, position: int, address: int, size: int) -> bytes:
        if self.emulated:
            data = self.esc(position).read(address, size)
            if data is None:
                raise BusError(f"slave {position}: 0x{address:04X}+{size} is not readable")
            return bytes(data)
        s = self.pysoem_slave(position)
        return bytes(s._fprd(address, size))

    def reg_write(self, position: int, address: int, data: bytes) -> None:
        if self.emulated:
            if not self.esc(position).write(address, data):
                raise BusError(f"slave {position}: 0x{address:04X}+{len(data)} is not writable")
            return
        self.pysoem_slave(position)._fpwr(address, data)

    def sii(self, position: int) -> bytes:
        if self.emulated:
            return bytes(self.esc(position).sii)
        s = self.pysoem_slave(position)
        words = []
        for w in range(0, 2048, 2):  # 4 KiB at most; stop at the end category
            chunk = bytes(s.eeprom_read(w))
            words.append(chunk)
            if w >= 0x40 and chunk[:2] == b"\xff\xff":
                break
        return b"".join(words)
