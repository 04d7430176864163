"""The bus as the inspection verbs see it: opened the way ``GT_Open`` would, or a running
controller's, one slave at a time by ``-p POSITION``.

``--eni`` (or ``GTECAT_ENI``, else ``./Gecat.eni``), ``--machine``, ``--backend`` and
``--iface`` mean what they mean for ``GT_Open``. On the emulated bus every command starts a
fresh bus and stops it when done; ``--backend pysoem --iface NIC`` talks to a real one;
``--controller ADDR`` (or ``GTECAT_CONTROLLER``) reads and changes a running controller's
bus; ``--attach ID`` (or, with no file named, the only gtecat running: a Python application
after ``GT_Open``, a ``gtecat controller``) reads and changes that one's, as IgH's
``ethercat`` tool reads the running master. What a verb asks of the bus is
:class:`gtecat.controller.inspect.BusView` either way.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gtecat.drives.machine import MachineError

from ..errors import BusError, ConfigMismatch, ParameterError
from . import output

if TYPE_CHECKING:  # the controller (numpy, drives) loads when a verb opens a bus
    from ..controller.core import Controller


def add_bus_options(p: argparse.ArgumentParser, *, position: bool = True) -> None:
    p.add_argument("--eni", help="configuration file (default: $GTECAT_ENI or ./Gecat.eni)")
    p.add_argument("--machine", help="machine description TOML ($GTECAT_MACHINE)")
    p.add_argument("--backend", choices=("emulated", "pysoem"), help="($GTECAT_BACKEND)")
    p.add_argument("--iface", help="network interface for pysoem ($GTECAT_IFACE)")
    if position:
        output.add_position(p)
    output.add_json(p)
    add_controller(p)
    p.add_argument(
        "--attach",
        metavar="ID",
        help="show the bus of this running gtecat (`gtecat ps` lists them; default: the only "
        "one running, unless a configuration file is named)",
    )


def add_controller(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--controller",
        metavar="ADDR",
        help="show the bus of a running controller (unix:/path of `gtecat controller`; "
        "default $GTECAT_CONTROLLER unless a configuration file is named) instead of "
        "opening one",
    )


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
        from ..controller.core import folder_message

        raise ParameterError(folder_message(Path(eni), "give the file, e.g. --eni"))
    return eni


def open_bus(args: argparse.Namespace) -> Controller:
    """Bring the bus up as GT_Open + GT_InitEcatComm would (lockstep; realtime on pysoem)."""
    from ..controller.core import Controller, Options

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
    except BaseException:
        ctl.close()
        raise
    return ctl


def controller_address(args: argparse.Namespace) -> str | None:
    """The running controller a verb reads: ``--controller``; else ``GTECAT_CONTROLLER``
    unless a configuration file was named on the command line (or it says ``local``)."""
    if getattr(args, "controller", None):
        return str(args.controller)
    if getattr(args, "eni", None) or getattr(args, "file", None):
        return None
    env = os.environ.get("GTECAT_CONTROLLER", "").strip()
    return env if env and env != "local" else None


def attach(args: argparse.Namespace) -> Any:
    """The running gtecat a verb reads (``--attach ID``, else the only one running when no
    configuration file is named and ``GTECAT_INSPECT`` is not 0), as a view whose methods
    are :class:`~gtecat.controller.inspect.BusView`'s; None: the verb opens a bus of its own
    (and says so in one line when it looked for a running one)."""
    wanted = getattr(args, "attach", None)
    if not wanted:
        if getattr(args, "eni", None) or getattr(args, "file", None):
            return None
        if getattr(args, "backend", None) or getattr(args, "iface", None):
            return None
        from ..inspect.endpoint import enabled

        if not enabled():
            return None
    from ..inspect import client

    found = client.connect(wanted)
    if found is None:
        print(
            "note: no running gtecat to attach to (`gtecat ps`); this command opens a bus "
            "of its own",
            file=sys.stderr,
        )
        return None
    if not wanted:  # found by itself: say which one, so nobody mistakes it for their file
        info = found[0]
        print(
            f"note: attached to the running gtecat {info.id} ({info.kind}, "
            f"{info.eni or 'no ENI'}; `gtecat ps`); --eni FILE opens a bus of its own",
            file=sys.stderr,
        )
    return client.attach_view(found[1])


@contextlib.contextmanager
def bus_view(args: argparse.Namespace) -> Iterator[Any]:
    """``with bus_view(args) as bus:`` the bus a verb shows: a bus of its own (a
    :class:`~gtecat.controller.inspect.BusView`, closed afterwards) or a running controller
    (a :class:`~gtecat.native.client.Field`, whose methods are the view's, run there)."""
    address = controller_address(args)
    if address:
        from ..native.client import Field

        with Field.connect(address) as f:
            yield f
        return
    attached = attach(args)
    if attached is not None:
        with attached as f:
            yield f
        return
    from ..controller.inspect import view

    ctl = open_bus(args)
    try:
        yield view(ctl)
    finally:
        ctl.close()
