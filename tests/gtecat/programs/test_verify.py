"""Program images checked entry by entry at GT_Download (gtecat/programs/verify.py).

A ``.bin`` with a valid CRC may still be wrong (written by hand, by another tool, or
corrupted and checksummed again): an index beyond its variable, a jump out of its function,
a call with too few arguments.  GT_Download refuses it with 7 and a reason (manual entry 10
gives 7 for a parameter the controller cannot use); no later GT call fails because of it.
"""

from __future__ import annotations

import os
import random
from ctypes import byref, c_short, c_ulong
from dataclasses import replace

import pytest

from gtecat import gt
from gtecat.programs import image
from gtecat.programs.compiler import compile_source
from gtecat.programs.model import Instr, Kind, Op, Operand
from gtecat.programs.verify import ImageInvalid, verify

SOURCE = """\
int arr[4];
double pos[2];
int k;
int clk;
int f(int n)
{
    int i;
    int cc;
    int t;
    i = 0;
loop:
    cc = i >= n;
    if (cc) goto done;
    t = i * 2;
    arr[i] = arr[i] + t;
    k = k - arr[i];
    i = i + 1;
    goto loop;
done:
    GT_GetPrfPos(1, &pos[0], 1, &clk);
    GT_Delay(1);
    return k;
}
int g()
{
    k = 7;
    return k;
}
"""
#: a few hundred mutations by default, GTECAT_LONG=N runs N x 100 times more
MUTATIONS = 300 * (100 * int(os.environ.get("GTECAT_LONG", "0") or 0) or 1)


@pytest.fixture(scope="module")
def program():
    return compile_source(SOURCE, "prog.c")


def test_a_compiled_program_passes(program):
    verify(program)


def _with(program, pc, **changes):
    code = list(program.code)
    code[pc] = replace(code[pc], **changes)
    return replace(program, code=tuple(code))


def _mov_ops(program):
    return program.code[_first(program, Op.MOV)].operands


def _first(program, op):
    return next(pc for pc, ins in enumerate(program.code) if ins.op is op)


@pytest.mark.parametrize(
    "mutate, words",
    [
        (lambda p: _with(p, _first(p, Op.JUMP), target=len(p.code) + 5), "jumps to"),
        (lambda p: _with(p, _first(p, Op.JUMP), target=p.functions[1].entry), "outside its"),
        (lambda p: _with(p, _first(p, Op.CALL), target=99), "calls string 99"),
        (lambda p: _with(p, _first(p, Op.CALL), operands=()), "arguments"),
        (lambda p: _with(p, _first(p, Op.BINARY), sub=99), "binary operator 99"),
        (lambda p: _with(p, _first(p, Op.MOV), operands=(Operand.const(0, 1),) * 2), "constant"),
        (
            lambda p: _with(p, _first(p, Op.MOV), operands=(Operand(Kind.GLOBAL, value=5000),) * 2),
            "outside the area",
        ),
        (
            lambda p: _with(
                p,
                _first(p, Op.MOV),
                operands=(Operand(Kind.GLOBAL, size=4, index_kind=Kind.CONST, index=9),) * 2,
            ),
            "index 9",
        ),
        (lambda p: replace(p, functions=(replace(p.functions[0], end=10**6),)), "outside"),
        (lambda p: replace(p, global_init=((4000, 1),)), "global word 4000"),
        (
            lambda p: replace(p, code=(*p.code[:-1], Instr(Op.MOV, 1, operands=_mov_ops(p)))),
            "neither returns nor jumps",
        ),
    ],
)
def test_a_wrong_entry_is_named(program, mutate, words):
    with pytest.raises(ImageInvalid, match=words):
        verify(mutate(program))


def _mutant(program, rng: random.Random):
    """One entry of ``program`` changed to a random value its ``.bin`` field can hold."""
    code = list(program.code)
    pc = rng.randrange(len(code))
    ins = code[pc]
    what = rng.choice(["target", "sub", "operand", "drop", "function", "init"])
    if what == "target":
        code[pc] = replace(ins, target=rng.choice([-1, len(code), rng.randrange(-(2**31), 2**31)]))
    elif what == "sub":
        code[pc] = replace(ins, sub=rng.randrange(256))
    elif what == "operand" and ins.operands:
        k = rng.randrange(len(ins.operands))
        o = ins.operands[k]
        field = rng.choice(["value", "size", "index", "index_kind", "kind"])
        value = {
            "value": rng.choice([-1, 1023, 1024, 2**31 - 1, rng.randrange(-(2**31), 2**31)]),
            "size": rng.choice([0, 1, 2000, 65535]),
            "index": rng.choice([-1, 4, 1024, rng.randrange(-(2**31), 2**31)]),
            "index_kind": rng.choice(list(Kind)),
            "kind": rng.choice(list(Kind)),
        }[field]
        ops = list(ins.operands)
        ops[k] = replace(o, **{field: value})
        code[pc] = replace(ins, operands=tuple(ops))
    elif what == "drop" and ins.operands:
        code[pc] = replace(ins, operands=ins.operands[:-1])
    elif what == "function":
        f = rng.choice(program.functions)
        changed = replace(f, **{rng.choice(["entry", "end"]): rng.randrange(0, len(code) + 3)})
        return replace(
            program, functions=tuple(changed if x is f else x for x in program.functions)
        )
    else:
        return replace(program, global_init=((rng.randrange(65536), rng.randrange(-9, 9)),))
    return replace(program, code=tuple(code))


def test_mutated_images_are_refused_at_download_or_run_without_escaping(program, tmp_path):
    """Random single-entry mutations with a valid CRC: GT_Download says 0 or 7 (never -7);
    what it accepts runs its threads without an exception reaching a later GT call."""
    assert gt.GT_Open(clock="lockstep", log="", mram=str(tmp_path / "m.mram")) == 0
    rng = random.Random(26)
    seen = {0: 0, 7: 0}
    try:
        for n in range(MUTATIONS):
            mutant = _mutant(program, rng)
            # (each image to new files: a file truncated and written again costs ext4 a
            # forced allocation at its close, 5 times the write)
            for ext in (".bin", ".ini"):
                (tmp_path / "m").with_suffix(ext).unlink(missing_ok=True)
            try:
                bin_path, _ = image.write(mutant, tmp_path / "m.c")
            except Exception:  # a value the .bin field cannot hold: not an image at all
                continue
            rc = gt.GT_Download(str(bin_path))
            assert rc in (0, 7, 2008), (n, rc, gt.GTE_GetLastError())
            seen[rc] = seen.get(rc, 0) + 1
            if rc != 0:
                assert "cannot run" in gt.GTE_GetLastError() or rc == 2008
                continue
            fid = c_short()
            for name in ("f", "g"):
                if gt.GT_GetFunId(name, byref(fid)) == 0:
                    gt.GT_Bind(0 if name == "f" else 1, fid.value, 0 if name == "f" else 1)
                    gt.GT_RunThread(0 if name == "f" else 1)
            for _ in range(3):
                assert gt.GTE_Wait(2) in (0, 1), gt.GTE_GetLastError()
                clk = c_ulong()
                assert gt.GT_GetClock(byref(clk)) == 0, gt.GTE_GetLastError()
    finally:
        gt.GT_Close()
    assert seen[7] > MUTATIONS // 10 and seen[0] > 0, seen
