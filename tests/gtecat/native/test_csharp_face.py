"""The C# face of the table (gts.cs), the Mono dllmap and the Windows-long build they use:
generated text checked without Mono (test_csharp.py runs them under Mono)."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import pytest

from gtecat.gt.table import FUNCTIONS
from gtecat.native import build, csharp, llp64


@pytest.mark.long
def test_gts_cs_declares_the_whole_table_in_the_vendor_style():
    """Every table function and its GTN twin; C long is int, unsigned long uint; counted
    outputs have an out and an array overload; bytes are arrays; structures unrolled as the
    vendor's C# wrappers write them (profile1..8, pad1_1..3)."""
    text = csharp.render()
    for name, proto in FUNCTIONS.items():
        assert f" {name}(" in text, name
        if proto.gtn:
            assert f" GTN_{name[3:]}(" in text, name
    assert text.count('[DllImport("gts.dll")]') >= sum(1 + bool(p.gtn) for p in FUNCTIONS.values())
    assert "GT_GetSts(short axis, out int pSts, short count, out uint pClock)" in text
    assert "GT_GetSts(short axis, [Out] int[] pSts, short count, out uint pClock)" in text
    assert "GT_SetTrapPrm(short profile, ref TTrapPrm pPrm)" in text
    assert "GT_GetTrapPrm(short profile, out TTrapPrm pPrm)" in text
    assert "GT_LoadConfig(string pFile)" in text
    assert "GT_GetEcatRawData(ushort offset, ushort size, [Out] byte[] pValue)" in text
    assert "GT_SetPos(short profile, int pos)" in text
    assert "GTN_Open(short channel = 5, short param = 1)" in text
    assert "GT_Open(short channel = 0, short param = 1)" in text
    assert "public short pad1_3;" in text and "public int pad3_2;" in text
    assert "public short profile8;" in text and "public int originPos8;" in text
    assert "public const short MC_LIMIT_POSITIVE = 0;" in text
    # no C# long (64 bits) but for a C long long (GTN_RN_GetAbsEncPosEx's 64-bit count)
    wide = {n for n, p in FUNCTIONS.items() if any(q.ctype == "long long" for q in p.params)}
    assert "GTN_RN_GetAbsEncPosEx" in wide
    wide |= {"GTN_" + n[3:] for n in wide if n.startswith("GT_") and FUNCTIONS[n].gtn}
    for line in text.split("namespace gts", 1)[1].splitlines():
        if re.search(r"\blong\b", line):
            assert any(f" {n}(" in line for n in wide), line


def test_the_llp64_build_spells_long_as_int_and_keeps_long_long():
    assert llp64.to_llp64("short GT_X(long a, unsigned long *b, long long c)") == (
        "short GT_X(int a, unsigned int *b, long long c)"
    )
    files = llp64.llp64_sources(build.sources("python3"))
    protos = [line for line in files["gts.h"].splitlines() if line.startswith("short ")]
    assert protos and not any(re.search(r"\blong\b", p.replace("long long", "")) for p in protos)
    assert any("long long *pEncPos" in p for p in protos)  # 64 bits stay 64 bits
    stubs = files["gts_stubs.c"]
    assert "sizeof(long)" not in stubs and "sizeof(int)" in stubs
    assert "(long long)" in stubs  # the argument packing keeps its 64-bit slot


def test_the_mono_config_maps_the_vendor_names_and_keeps_monos_own(tmp_path):
    system = tmp_path / "config"
    system.write_text('<configuration><dllmap dll="libc" target="libc.so.6"/></configuration>')
    maps = csharp.system_maps(system)
    assert maps == ['<dllmap dll="libc" target="libc.so.6" />']
    text = csharp.mono_config("/lib/libgts-llp64.so")
    for dll in csharp.DLL_NAMES:
        assert f'<dllmap dll="i:{dll}" target="/lib/libgts-llp64.so" os="!windows"/>' in text
    assert ET.fromstring(text).tag == "configuration"  # well-formed (a valid comment too)


def test_the_multicard_llp64_layer_spells_long_as_int():
    """libgts_mc-llp64.so's layer and the header it includes take int for long (a C#
    multi-card wrapper's ``out int pSts``), long long stays."""
    files = llp64.multicard_sources()
    layer = files["gts_multicard.c"]
    assert re.search(r"short gte_mc_GetSts\(short cardNum, short axis, int \*pSts,", layer)
    assert "short gte_mc_SetPos(short cardNum, short profile, int pos)" in layer
    assert "long" not in layer.replace("long long", "")
    assert "short GT_GetSts(short axis, int *pSts" in files["gts_sc.h"]


def test_lib_csharp_refuses_the_multicard_abi(capsys):
    """gts.cs is the one-card API: --abi gts-multicard --csharp says so instead of writing it."""
    import argparse

    from gtecat.cli import lib_cmd

    parser = argparse.ArgumentParser()
    lib_cmd.add_parser(parser.add_subparsers())  # the lib verb alone: no other verb imported
    args = parser.parse_args(["lib", "--abi", "gts-multicard", "--csharp"])
    assert args.func(args) == 1
    out = capsys.readouterr().out
    assert out.startswith("error: --csharp writes gts.cs for the one-card API only")
    assert "--abi gts-multicard --mono-config" in out
