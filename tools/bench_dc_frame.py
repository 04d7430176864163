"""Micro-benchmark: the ESC chain's processing of a master's cyclic frame, with and without DC.

    python tools/bench_dc_frame.py [--eni examples/twelve_axes.eni] [--frames 20000]

No network: the chain ``gtecat serve`` builds from the ENI is brought to OP in-process with
SOEM's register writes (station addresses, mailbox and process-data sync managers, FMMUs,
the DC set-up of ``ec_configdc``: receive-time latch, offsets, delays), then the cyclic frame
is processed ``--frames`` times, a slave step between frames as ``gtecat serve`` does it. Only
:meth:`Chain.process` is timed (what ``serve`` reports as ``processing``). Shapes:

* ``lrw``: one LRW of the whole image (a master without DC);
* ``lrw+frmw``: the LRW and an FRMW of the reference clock's system time 0910h (what SOEM's
  ``ec_send_processdata`` sends once ``ec_configdc`` found DC slaves: ec_sample's frame);
* ``lrw+armw``: the LRW and an ARMW of 0910h (TwinCAT's and IgH's drift compensation);
* ``lrw+brd``: the LRW and a BRD of 0910h (a master reading the system time of the line).

Prints JSON: per shape the p50/p90/p99/max processing time in microseconds.
"""

from __future__ import annotations

import argparse
import gc
import json
import struct
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from gtecat.drives.esc import Chain, Command, Datagram, decode_frame, encode_frame  # noqa: E402

_SM = struct.Struct("<HHBBBB")
_FMMU = struct.Struct("<IHBBHBBB3x")
MBX_OUT, MBX_IN, MBX_SIZE = 0x1000, 0x1080, 128
PD_OUT, PD_IN = 0x1100, 0x1400
REF = 0x1001  #: the first slave's station address: SOEM's reference clock


def _x(chain: Chain, datagrams: list[Datagram]) -> list[Datagram]:
    raw = chain.exchange(encode_frame(datagrams))
    if raw is None:
        raise SystemExit("a configuration frame was dropped")
    chain.service()
    return decode_frame(raw).datagrams


def _state(chain: Chain, station: int, state: int) -> None:
    _x(chain, [Datagram(Command.FPWR, station, 0x0120, struct.pack("<H", state))])
    got = _x(chain, [Datagram(Command.FPRD, station, 0x0130, bytes(6))])[0].data
    if got[0] != state:
        raise SystemExit(
            f"slave {station - REF} did not reach state {state}: AL status {got[0]:#x}, "
            f"code {struct.unpack_from('<H', got, 4)[0]:#06x}"
        )


def bring_up(chain: Chain, dc: bool = True) -> tuple[int, int]:
    """SOEM's bring-up in miniature; (image bytes, expected WKC of the LRW)."""
    n = len(chain)
    for pos in range(n):
        _x(chain, [Datagram(Command.APWR, (-pos) & 0xFFFF, 0x0010, struct.pack("<H", REF + pos))])
    outs, ins = [], []
    for pos, esc in enumerate(chain.escs):
        station = REF + pos
        if esc.slave.has_mailbox:
            sms = _SM.pack(MBX_OUT, MBX_SIZE, 0x26, 0, 1, 0) + _SM.pack(
                MBX_IN, MBX_SIZE, 0x22, 0, 1, 0
            )
            _x(chain, [Datagram(Command.FPWR, station, 0x0800, sms)])
        _state(chain, station, 2)
        rx_bits, tx_bits = esc.slave.pdo_sizes()
        outs.append((rx_bits + 7) // 8)
        ins.append((tx_bits + 7) // 8)
    out_total = sum(outs)
    laddr_out, laddr_in, wkc = 0, out_total, 0
    for pos in range(n):
        station = REF + pos
        sms, fmmus = b"", b""
        if outs[pos]:
            sms += _SM.pack(PD_OUT, outs[pos], 0x64, 0, 1, 0)
            fmmus += _FMMU.pack(laddr_out, outs[pos], 0, 7, PD_OUT, 0, 2, 1)
            laddr_out += outs[pos]
            wkc += 2
        if ins[pos]:
            sms += _SM.pack(PD_IN, ins[pos], 0x20, 0, 1, 0)
            fmmus += _FMMU.pack(laddr_in, ins[pos], 0, 7, PD_IN, 0, 1, 1)
            laddr_in += ins[pos]
            wkc += 1
        if sms:
            _x(chain, [Datagram(Command.FPWR, station, 0x0810, sms)])
            _x(chain, [Datagram(Command.FPWR, station, 0x0600, fmmus)])
        _state(chain, station, 4)
    if dc:
        configure_dc(chain)
    for pos in range(n):
        _state(chain, REF + pos, 8)
    return laddr_in, wkc


def configure_dc(chain: Chain, master_time_ns: int = 800_000_000_000_000_000) -> None:
    """``ec_configdc`` on a line: latch the receive times (BWR 0900h), set every slave's offset
    (0920h) so that its system time starts at the master's time, and its propagation delay
    (0928h) from the reference clock: half the difference of the loop times port 0 -> port 1
    of the reference and of the slave (ETG.1000.4 9.1, what SOEM computes)."""
    _x(chain, [Datagram(Command.BWR, 0, 0x0900, bytes(4))])
    loops = []
    for pos in range(len(chain)):
        station = REF + pos
        raw = _x(chain, [Datagram(Command.FPRD, station, 0x0900, bytes(8))])[0].data
        t_a, t_b = struct.unpack("<II", raw)
        loops.append((t_b - t_a) & 0xFFFFFFFF if t_b else 0)
        local = _x(chain, [Datagram(Command.FPRD, station, 0x0918, bytes(8))])[0].data
        offset = (master_time_ns - struct.unpack("<Q", local)[0]) & 0xFFFFFFFFFFFFFFFF
        _x(chain, [Datagram(Command.FPWR, station, 0x0920, struct.pack("<Q", offset))])
        delay = (loops[0] - loops[pos]) // 2
        _x(chain, [Datagram(Command.FPWR, station, 0x0928, struct.pack("<I", delay))])


SHAPES = ("lrw", "lrw+frmw", "lrw+armw", "lrw+brd")


def frame_for(shape: str, image: int) -> bytes:
    datagrams = [Datagram.logical(Command.LRW, 0, bytes(image))]
    if shape == "lrw+frmw":
        datagrams.append(Datagram(Command.FRMW, REF, 0x0910, bytes(8)))
    elif shape == "lrw+armw":
        datagrams.append(Datagram(Command.ARMW, 0, 0x0910, bytes(8)))
    elif shape == "lrw+brd":
        datagrams.append(Datagram(Command.BRD, 0, 0x0910, bytes(8)))
    return encode_frame(datagrams)


def run_shape(eni: Path, shape: str, frames: int) -> dict[str, object]:
    from gtecat.cli.serve_cmd import build_chain

    chain, _config = build_chain(eni)
    image, wkc = bring_up(chain, dc=shape != "lrw")
    template = frame_for(shape, image)
    expected = [wkc] + ([len(chain)] if shape != "lrw" else [])
    clock = time.perf_counter_ns
    samples: list[int] = []
    t = time.monotonic_ns()
    gc.collect()
    gc.disable()
    try:
        for i in range(frames):
            buf = bytearray(template)
            buf[17] = i & 0xFF  # the datagram index a master counts
            t += 1_000_000
            t0 = clock()
            ok = chain.process(buf, len(buf), t)
            t1 = clock()
            samples.append(t1 - t0)
            if not ok:
                raise SystemExit(f"{shape}: frame {i} dropped")
            if i < 3 or i == frames - 1:
                got = [d.wkc for d in decode_frame(bytes(buf)).datagrams]
                if got != expected:
                    raise SystemExit(f"{shape}: working counters {got}, expected {expected}")
            chain.service()
            chain.step(t, 1_000_000)
            if i % 1000 == 999:
                gc.collect(0)
    finally:
        gc.enable()
    data = sorted(samples[frames // 10 :])  # the first tenth warms up
    n = len(data)

    def pct(p: float) -> float:
        return round(data[min(n - 1, int(p * n))] / 1000, 2)

    return {
        "slaves": len(chain),
        "image_bytes": image,
        "frames": frames,
        "p50_us": pct(0.5),
        "p90_us": pct(0.9),
        "p99_us": pct(0.99),
        "max_us": round(data[-1] / 1000, 2),
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--eni", type=Path, default=ROOT / "examples" / "twelve_axes.eni")
    p.add_argument("--frames", type=int, default=20000)
    p.add_argument("--shape", choices=SHAPES, action="append", help="default: all")
    args = p.parse_args(argv)
    result: dict[str, object] = {"eni": str(args.eni)}
    for shape in args.shape or SHAPES:
        result[shape] = run_shape(args.eni, shape, args.frames)
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
