"""The legal range of every number a configuration file holds, checked at the reader.

Both readers (ETG.2100 XML and Googol's INI ``Gecat.eni``) take each number they
use through :meth:`Limit.parse` or :meth:`Limit.check` with its limit from the
table below, and turn the :class:`RangeError` into an :class:`~gtecat.eni.errors.EniError`
with the file and line; :func:`gtecat.eni.check.check_config` applies the same limits
to the whole model, whichever reader or builder made it.  A hostile value
(negative, 2**64, four thousand digits, ``1e999``) is refused with the field and
its range, never a traceback and never a silently wrong value.

Where a range comes from:

* object index 16 bits, subindex 8 bits (CiA 301); vendor id, product code,
  revision and serial number 32 bits (ETG.1000.6 identity object 0x1018);
* station (``PhysAddr``) and auto-increment addresses: 16-bit ADP (ETG.1000.4);
  an auto-increment address may be spelled signed (``-1``) or unsigned (``65535``);
* sync managers 0..15 (an ESC has 16, registers 0x0800..0x087F);
* a PDO entry fits one sync manager, whose length register is 16 bits:
  1..524280 bits;
* the logical images live in the 32-bit logical address space (ETG.1000.4):
  at most 2**32 bytes, every bit offset and area end inside it;
* counts in the Googol INI (PDOs of a sync manager, entries of a PDO) are 8-bit
  sub-index counts; a Googol slave has at most 8 CiA-402 channels (``nservo``);
* the bus cycle is 31.25 us .. 1 s (:data:`CYCLE_NS`): shorter than the fastest
  EtherCAT cycle is no real configuration and makes bring-up crawl, longer is no
  control loop.
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal, InvalidOperation

from .datatypes import MAX_CHANNELS
from .numbers import TooLong, parse_int, shown


class RangeError(ValueError):
    """A number outside its field's legal range; the message names the field and the range."""


@dataclass(frozen=True, slots=True)
class Limit:
    """An inclusive range ``lo..hi`` and why it is that (shown in every error)."""

    lo: int
    hi: int
    why: str
    hex: bool = False

    def _fmt(self, v: int) -> str:
        if self.hex and v >= 0:
            return f"0x{v:X}"
        return str(v)

    def __str__(self) -> str:
        return f"{self._fmt(self.lo)}..{self._fmt(self.hi)} ({self.why})"

    def __contains__(self, value: object) -> bool:
        return isinstance(value, int) and self.lo <= value <= self.hi

    def error(self, field: str, value: int | str) -> RangeError:
        text = shown(value, quote=False) if isinstance(value, str) else self._show_int(value)
        return RangeError(f"{field} {text} is out of range: legal is {self}")

    def _show_int(self, value: int) -> str:
        return shown(self._fmt(value) if abs(value) < 1 << 128 else f"{value:#x}", quote=False)

    def check(self, value: int, field: str, text: str | None = None) -> int:
        """``value`` when it lies in the range, else :class:`RangeError` (``text`` as written)."""
        if isinstance(value, int) and self.lo <= value <= self.hi:  # (value in self, inline)
            return value
        raise self.error(field, text if text is not None else value)

    def parse(self, text: str | int, field: str) -> int:
        """Parse an integer as :func:`gtecat.eni.numbers.parse_int` spells it and check it."""
        try:
            value = parse_int(text)
        except TooLong:  # more digits than any range holds
            raise self.error(field, str(text)) from None
        if self.lo <= value <= self.hi:  # parse_int gives an int: check()'s test, inline
            return value
        raise self.error(field, text if isinstance(text, str) else value)


# --- object dictionary and identity --------------------------------------------------------
INDEX = Limit(0, 0xFFFF, "a 16-bit object index", hex=True)
SUBINDEX = Limit(0, 0xFF, "an 8-bit subindex")
IDENTITY = Limit(0, 0xFFFF_FFFF, "32 bits, identity object 0x1018", hex=True)
#: the byte size of a start SDO (Googol ``startitem``): an expedited value of 1..8 bytes
SDO_SIZE = Limit(1, 8, "bytes of an expedited start SDO")
#: ETG.2100 ``InitCmd/Ccs``
CCS = Limit(1, 2, "1 download, 2 upload")
#: ETG.2100 ``InitCmd/Timeout`` in ms (xs:int, not negative)
TIMEOUT_MS = Limit(0, 2**31 - 1, "milliseconds")


def sdo_value(size: int) -> Limit:
    """A start SDO value of ``size`` bytes, spelled signed or unsigned."""
    unit = "byte" if size == 1 else "bytes"
    return Limit(
        -(1 << (8 * size - 1)), (1 << (8 * size)) - 1, f"{size} {unit}, signed or unsigned"
    )


# --- addresses and sync managers -----------------------------------------------------------
PHYS_ADDR = Limit(0, 0xFFFF, "a 16-bit station address")
AUTO_INC_ADDR = Limit(-0x8000, 0xFFFF, "a 16-bit auto-increment address, signed or unsigned")
SM = Limit(0, 15, "an ESC has 16 sync managers")
ESC_ADDRESS = Limit(0, 0xFFFF, "a 16-bit ESC memory address")
SM_LENGTH = Limit(0, 0xFFFF, "bytes: a 16-bit sync manager length")
SM_CONTROL = Limit(0, 0xFF, "an 8-bit sync manager control byte")
#: a PDO entry fits one sync manager (16-bit length register, ETG.1000.4)
ENTRY_BITS = Limit(1, 0xFFFF * 8, "bits: an entry fits one sync manager of at most 65535 bytes")
PDO_COUNT = Limit(0, 255, "an 8-bit sub-index count")

# --- the logical process image (32-bit logical address space) ------------------------------
IMAGE_BYTES = Limit(0, 1 << 32, "bytes: the 32-bit logical address space")
IMAGE_BITS = 8 << 32
BIT_OFFSET = Limit(0, IMAGE_BITS - 1, "a bit of the 32-bit logical address space")
BIT_LENGTH = Limit(0, IMAGE_BITS, "bits of the 32-bit logical address space")


def check_span(start: int, length: int, field: str) -> None:
    """``start + length`` must end inside the logical address space."""
    if start + length > IMAGE_BITS:
        raise RangeError(
            f"{field} bits {start}+{length} end at bit {start + length}, beyond the 32-bit "
            f"logical address space (legal ends are 0..{IMAGE_BITS})"
        )


# --- Googol INI counts and hints -----------------------------------------------------------
SLAVE_COUNT = Limit(0, 0xFFFF, "a bus has at most 65535 slaves")
POSITION = Limit(0, 0xFFFE, "a 0-based bus position")
SERVO_TYPE = Limit(0, 1, "0 IO, 1 servo")
NSERVO = Limit(0, MAX_CHANNELS, "CiA-402 channels of one slave")
ENABLED = Limit(0, 1, "0 disabled, 1 enabled")
SYNC_DIR = Limit(1, 2, "1 outputs, 2 inputs")
#: the position of a PDO's first entry in its ``slave_syncN_PDO_entry`` list
ENTRY_POS = Limit(0, 0xFFFF, "a position in the entry list")

# --- the bus cycle -------------------------------------------------------------------------
CYCLE_NS = Limit(31_250, 1_000_000_000, "ns: a positive cycle of 31.25 us to 1 s")
_CYCLE_US = (Decimal("31.25"), Decimal(1_000_000))
CYCLE_US_TEXT = "31.25..1000000 us (a positive cycle of 31.25 us to 1 s)"


def cycle_ns_from_us(text: str | int | float, field: str) -> int:
    """A cycle time in microseconds as a file or a topology writes it -> nanoseconds.

    Integers (``1000``, ``#x3E8``), decimals (``62.5``) and exponents (``1e3``)
    are read; the legal range is 31.25 us .. 1 s (:data:`CYCLE_NS`), so a 1 ns
    or a ``1e999`` cycle is a :class:`RangeError` and 0 is one too (a reader for
    which 0 means "not given" says so before calling this).
    """
    if isinstance(text, bool):
        raise RangeError(f"{field} {text!r} is not a number: legal is {CYCLE_US_TEXT}")
    if isinstance(text, int | float):
        us, raw = Decimal(text), repr(text)
    else:
        raw = text.strip()
        try:
            if raw.lower().lstrip("+-").startswith(("0x", "#x")):
                us = Decimal(parse_int(raw))
            else:
                us = Decimal(raw.replace("_", ""))
        except (ValueError, InvalidOperation):
            raise RangeError(
                f"{field} {shown(raw)} is not a number of microseconds: legal is {CYCLE_US_TEXT}"
            ) from None
    if not us.is_finite() or not _CYCLE_US[0] <= us <= _CYCLE_US[1]:
        raise RangeError(
            f"{field} {shown(raw, quote=False)} us is out of range: legal is {CYCLE_US_TEXT}"
        )
    return int((us * 1000).to_integral_value())
