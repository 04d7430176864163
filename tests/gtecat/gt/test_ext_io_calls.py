"""Extension IO modules as applications drive them: GTS ExtMdl, the ``*Gts`` forms, the GTN cores'
modules and gLink-II, against modules of the machine description driven from the field side.

Facts: the vendor's GTS header and ExtMdl manual (module ``mdl`` 0..15, ``index`` 0..15,
``GT_GetStsExtMdl`` reads 0 when the module communicates and 1 otherwise, the mode is set
after ``GT_LoadExtConfig``), the multi-card C# wrappers (``cardNum`` first), the GTN header
(``GTN_ExtModuleInit(core, method=1)``, terminals from 1, 32 per word) and ``gtgl500.h``.
The call sequences are those of field applications (open, reset, load, then bits; outputs
written as ``!on`` on the active-low GTS modules).
"""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_ushort

import pytest

from gtecat import gt
from gtecat.drives.machine import MachineError, machine_from_dict

from .conftest import bring_up

MACHINE = {
    "ext": {
        "0": {"di": 16, "do": 16},
        "1": {"di": 8, "do": 8},
        "2": {"di": 0, "do": 0, "ai": 2, "ao": 2, "ai_range": [0, 10]},
    },
    "glink": {"0": {"di": 16, "do": 16}, "3": {"di": 8, "do": 8}},
}


@pytest.fixture
def card(tmp_path, monkeypatch):
    """A GTS card with the modules, the working folder holding the vendor's ExtModule.cfg."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "ExtModule.cfg").write_text("[mdl0]\n", encoding="utf-8")
    m = machine_from_dict(MACHINE, "machine.toml")
    assert gt.GT_Open(card="gts:2", machine=m, clock="lockstep", log="") == 0
    return tmp_path


def u16(fn, *args) -> int:
    v = c_ushort()
    assert fn(*args, byref(v)) == 0, gt.GTE_GetLastError()
    return v.value


def test_the_field_bring_up_sequence_and_active_low_bits(card):
    # a C# application's bring-up: GT_OpenExtMdlGts(0, "gts.dll"), reset, load, reset
    assert gt.GT_OpenExtMdlGts(0, "gts.dll") == 0
    assert gt.GT_ResetExtMdlGts(0) == 0
    assert gt.GT_LoadExtConfigGts(0, "ExtModule.cfg") == 0, gt.GTE_GetLastError()
    assert gt.GT_ResetExtMdlGts(0) == 0
    mdl0 = gt.GTE_ExtModule(0)
    assert u16(gt.GT_GetExtDoValue, 0) == 0xFFFF  # every output off: all levels high
    on = True
    assert gt.GT_SetExtIoBitGts(0, 0, 3, int(not on)) == 0  # written as !on, as applications do
    assert mdl0.output(3) and not mdl0.output(2)
    assert u16(gt.GT_GetExtDoValue, 0) == 0xFFF7
    mdl0.set_input(5, True)  # a sensor on input 5 of module 0
    assert u16(gt.GT_GetExtIoValueGts, 0, 0) == 0xFFDF
    assert u16(gt.GT_GetExtIoBit, 0, 5) == 0 and u16(gt.GT_GetExtIoBit, 0, 4) == 1
    assert gt.GTE_SetExtDi(0, 5, 0) == 0 and u16(gt.GT_GetExtIoBit, 0, 5) == 1
    assert gt.GT_SetExtIoValue(1, 0xFFF0) == 0  # module 1: outputs 0..3 on
    assert [gt.GTE_ExtModule(1).output(i) for i in range(5)] == [True] * 4 + [False]
    assert u16(gt.GT_GetStsExtMdlGts, 0, 1, 0) == 0
    assert gt.GT_CloseExtMdlGts(0) == 0
    assert mdl0.output(3)  # closing the access leaves the outputs as they are


def test_the_access_and_the_modules_refuse_clearly(card):
    assert gt.GT_SetExtIoBit(0, 1, 0) == 1
    assert "GT_OpenExtMdl first" in gt.GTE_GetLastError()
    assert gt.GT_OpenExtMdl(None) == 0
    assert gt.GT_GetExtIoValue(0, byref(c_ushort())) == 1
    assert "GT_LoadExtConfig first" in gt.GTE_GetLastError()
    assert gt.GT_LoadExtConfig("missing.cfg") == 1 and "missing.cfg" in gt.GTE_GetLastError()
    assert gt.GT_LoadExtConfig(r"D:\cfg\ExtModule.cfg") == 0  # found by its name here
    assert gt.GT_SetExtIoBit(5, 0, 0) == 1 and "[ext.0], [ext.1]" in gt.GTE_GetLastError()
    assert gt.GT_SetExtIoBit(16, 0, 0) == 7  # the vendor's range 0..15
    assert gt.GT_SetExtIoBit(1, 8, 0) == 7 and "8 output(s)" in gt.GTE_GetLastError()
    assert gt.GT_SetExtIoBit(0, 1, 2) == 7  # a level is 0 or 1
    assert gt.GT_SetExtIoBitGts(1, 0, 1, 0) == -1 and "card 1 is not open" in gt.GTE_GetLastError()
    assert gt.GT_SetExtIoBitGts(16, 0, 1, 0) == 7  # cards 0..15
    assert u16(gt.GT_GetStsExtMdl, 5, 0) == 1  # absent: status 1, the call itself succeeds
    gt.GTE_ExtModule(1).online = False  # the module's cable pulled
    assert u16(gt.GT_GetStsExtMdl, 1, 0) == 1
    assert gt.GT_SetExtIoValue(1, 0) == 1 and "does not answer" in gt.GTE_GetLastError()
    assert gt.GT_ResetExtMdl() == 1 and "[1]" in gt.GTE_GetLastError()
    gt.GTE_ExtModule(1).online = True
    assert gt.GT_SetExtMdlMode(1) == 0 and u16(gt.GT_GetExtMdlMode) == 1
    assert gt.GT_SwitchtoCardNoExtMdl(0) == 0 and gt.GT_SwitchtoCardNoExtMdl(16) == 7
    assert gt.GT_SwitchtoCardNoExtMdl(2) == 1 and "GT_SetCardNo(2)" in gt.GTE_GetLastError()


def test_reset_switches_the_module_outputs_off_and_gt_reset_does_not(card):
    assert gt.GT_OpenExtMdl("gts.dll") == 0 and gt.GT_LoadExtConfig("ExtModule.cfg") == 0
    assert gt.GT_SetExtIoValue(0, 0x0000) == 0
    assert gt.GT_Reset() == 0
    assert gt.GTE_ExtModule(0).output(15)
    assert gt.GT_ResetExtMdl() == 0
    assert not any(gt.GTE_ExtModule(0).output(i) for i in range(16))


def test_analog_channels_in_volts_and_in_raw_values(card):
    assert gt.GT_OpenExtMdl() == 0 and gt.GT_LoadExtConfig("ExtModule.cfg") == 0
    assert gt.GTE_SetExtAdVoltage(2, 1, 2.5) == 0
    v = c_double()
    assert gt.GT_GetExtAdVoltage(2, 1, byref(v)) == 0 and v.value == 2.5
    assert u16(gt.GT_GetExtAdValue, 2, 1) == round(2.5 / 10 * 65535)  # range [0, 10] V
    assert gt.GT_SetExtDaVoltage(2, 0, -5.0) == 0
    assert gt.GTE_ExtModule(2).ao_voltage(0) == -5.0
    assert gt.GT_SetExtDaValue(2, 1, 65535) == 0 and gt.GTE_ExtModule(2).ao_voltage(1) == 10.0
    assert gt.GT_SetExtDaVoltage(2, 0, 11.0) == 7  # beyond the default range [-10, 10] V
    assert gt.GT_GetExtAdVoltage(2, 2, byref(v)) == 7  # two channels
    assert u16(gt.GT_GetStsExtMdl, 2, 1) == 0 and u16(gt.GT_GetStsExtMdl, 2, 3) == 1
    assert gt.GT_GetExtAdVoltageGts(0, 2, 1, byref(v)) == 0 and v.value == 2.5


def test_the_gtn_core_numbers_the_chain_from_1():
    machine = machine_from_dict(MACHINE)
    bring_up(clock="lockstep", machine=machine)
    assert gt.GTN_SetExtDoBit(1, 1, 1) == 1 and "GTN_ExtModuleInit" in gt.GTE_GetLastError()
    assert gt.GTN_ExtModuleInit(1, 1) == 0
    # GTN modules are active high: 1 = on; terminal 17 is module 1's output 0
    assert gt.GTN_SetExtDoBit(1, 17, 1) == 0 and gt.GTE_ExtModule(1).output(0)
    assert gt.GTN_SetExtDo(1, 1, 0x0003_0005, 0x0003_000F) == 0
    outs = [gt.GTE_ExtModule(0).output(i) for i in range(4)]
    assert outs == [True, False, True, False]
    assert gt.GTE_ExtModule(1).output(0) and gt.GTE_ExtModule(1).output(1)
    do = c_long()
    assert gt.GTN_GetExtDo(1, 1, byref(do)) == 0 and do.value == 0x0003_0005
    gt.GTE_ExtModule(1).set_input(2, True)
    di, bit = c_long(), c_short()
    assert gt.GTN_GetExtDi(1, 1, byref(di)) == 0 and di.value == 1 << 18
    assert gt.GTN_GetExtDiBit(1, 19, byref(bit)) == 0 and bit.value == 1
    assert gt.GTN_GetExtDiBit(1, 25, byref(bit)) == 7  # 24 inputs on the chain
    gt.GTE_ExtModule(2).set_voltage(0, 5.0)
    ai = (c_double * 2)()
    assert gt.GTN_GetExtAi(1, 1, ai, 2) == 0 and list(ai) == [5.0, 0.0]
    raw = (c_short * 1)()
    assert gt.GTN_GetExtAiValue(1, 1, raw, 1) == 0 and raw[0] == 16384  # 5 V of +-10 V
    assert gt.GTN_SetExtAo(1, 2, byref(c_double(3.5)), 1) == 0
    assert gt.GTE_ExtModule(2).ao_voltage(1) == 3.5
    assert gt.GTN_GetExtAo(1, 3, (c_double * 1)(), 1) == 7


def test_gtn_init_without_modules_is_an_error():
    bring_up(clock="lockstep")
    assert gt.GTN_ExtModuleInit(1) == 1 and "no [ext.N]" in gt.GTE_GetLastError()


def test_glink_slaves(card):
    assert gt.GT_SetGLinkDoBit(0, 1, 1) == 1 and "GT_GLinkInit" in gt.GTE_GetLastError()
    assert gt.GT_GLinkInit(0) == 0
    n = c_ubyte()
    assert gt.GT_GetGLinkOnlineSlaveNum(byref(n)) == 0 and n.value == 2
    assert gt.GT_SetGLinkDoBit(0, 9, 1) == 0 and gt.GTE_GLinkSlave(0).output(9)
    buf = (c_ubyte * 2)()
    assert gt.GT_GetGLinkDo(0, 0, buf, 2) == 0 and list(buf) == [0, 2]
    assert gt.GT_SetGLinkDo(3, 0, (c_ubyte * 1)(0x81), 1) == 0
    assert gt.GTE_GLinkSlave(3).output(7) and not gt.GTE_GLinkSlave(3).output(6)
    assert gt.GTE_SetGLinkDi(3, 2, 1) == 0
    b = c_ubyte()
    assert gt.GT_GetGLinkDiBit(3, 2, byref(b)) == 0 and b.value == 1
    assert gt.GT_GetGLinkDi(3, 0, buf, 1) == 0 and buf[0] == 4
    assert gt.GT_GetGLinkDi(3, 0, buf, 2) == 7  # slave 3 has one input byte
    assert gt.GT_GetGLinkDiBit(1, 0, byref(b)) == 1  # no slave 1


@pytest.mark.parametrize(
    ("table", "words"),
    [
        ({"ext": {"16": {}}}, "numbered 0..15"),
        ({"ext": {"0": {"di": 40}}}, "di must be an integer 0..32"),
        ({"ext": {"0": {"dio": 4}}}, "unknown key(s) dio"),
        ({"ext": {"0": {"ai_range": [5, 0]}}}, "low < high"),
        ({"ext": {"0": {"active_low": 1}}}, "true or false"),
        ({"glink": {"64": {}}}, "numbered 0..63"),
        ({"glink": {"0": {"ai": 2}}}, "unknown key(s) ai"),
    ],
)
def test_bad_module_tables_name_the_key(table, words):
    with pytest.raises(MachineError, match=r"\[(ext|glink)\.\d+\]") as e:
        machine_from_dict(table, "m.toml")
    assert words in str(e.value)


def test_active_low_overrides_the_family_wiring(card):
    gt.GT_Close()
    m = machine_from_dict({"ext": {"0": {"active_low": False}}})
    assert gt.GT_Open(card="gts:1", machine=m, clock="lockstep", log="") == 0
    assert gt.GT_OpenExtMdl() == 0 and gt.GT_LoadExtConfig("ExtModule.cfg") == 0
    assert gt.GT_SetExtIoBit(0, 0, 1) == 0 and gt.GTE_ExtModule(0).output(0)


def test_the_multi_card_forms_act_on_the_same_modules(card):
    """The ``...Gts`` forms of the multi-card wrappers (``cardNum`` first, card 0 here) read and
    write the modules the single-card forms do: levels, raw analog values and volts."""
    assert gt.GT_OpenExtMdlGts(0, "gts.dll") == 0
    assert gt.GT_LoadExtConfigGts(0, "ExtModule.cfg") == 0
    assert gt.GT_SwitchtoCardNoExtMdlGts(0, 0) == 0
    assert gt.GT_SwitchtoCardNoExtMdlGts(0, 2) == 1
    assert gt.GT_SetExtIoValueGts(0, 1, 0xFFF0) == 0  # module 1: outputs 0..3 on (active low)
    assert u16(gt.GT_GetExtDoValueGts, 0, 1) == 0xFFF0 == u16(gt.GT_GetExtDoValue, 1)
    assert gt.GTE_ExtModule(1).output(0) and not gt.GTE_ExtModule(1).output(4)
    gt.GTE_ExtModule(0).set_input(5, True)  # on = low level
    assert u16(gt.GT_GetExtIoBitGts, 0, 0, 5) == 0 and u16(gt.GT_GetExtIoBitGts, 0, 0, 4) == 1
    assert gt.GT_SetExtDaVoltageGts(0, 2, 0, -5.0) == 0
    assert gt.GTE_ExtModule(2).ao_voltage(0) == -5.0
    assert gt.GT_SetExtDaValueGts(0, 2, 1, 65535) == 0
    assert gt.GTE_ExtModule(2).ao_voltage(1) == 10.0
    assert gt.GTE_SetExtAdVoltage(2, 0, 5.0) == 0
    assert u16(gt.GT_GetExtAdValueGts, 0, 2, 0) == round(5.0 / 10 * 65535)  # range [0, 10] V
    assert gt.GT_SetExtIoValueGts(1, 1, 0) == -1 and "card 1 is not open" in gt.GTE_GetLastError()


def test_the_gtn_core_reads_an_output_back_and_writes_raw_analog_values():
    bring_up(clock="lockstep", machine=machine_from_dict(MACHINE))
    assert gt.GTN_ExtModuleInit(1, 1) == 0
    assert gt.GTN_SetExtDoBit(1, 18, 1) == 0  # module 1's output 1
    bit = c_short()
    assert gt.GTN_GetExtDoBit(1, 18, byref(bit)) == 0 and bit.value == 1
    assert gt.GTN_GetExtDoBit(1, 17, byref(bit)) == 0 and bit.value == 0
    assert gt.GTN_GetExtDoBit(1, 25, byref(bit)) == 7  # 24 outputs on the chain
    # +-32767 is +-10 V (the default range); AO 2 of the chain is module 2's channel 1
    assert gt.GTN_SetExtAoValue(1, 2, (c_short * 1)(-16384), 1) == 0
    assert abs(gt.GTE_ExtModule(2).ao_voltage(1) - (-16384 / 32767 * 10)) < 1e-9
    assert gt.GT_SetExtAoValue(1, byref(c_short(32767)), 1) == 0  # the GT_ form is core 1
    assert gt.GTE_ExtModule(2).ao_voltage(0) == 10.0


def test_the_gts_forms_address_each_cards_own_modules(card):
    """A station of two cards, each with its own modules (card 1: an identical controller):
    the ``*Gts`` forms name the card; the current card stays 0."""
    assert gt.GT_SetCardNo(1) == 0 and gt.GT_Open() == 0
    assert gt.GT_SetCardNo(0) == 0
    for n in (0, 1):
        assert gt.GT_OpenExtMdlGts(n, "gts.dll") == 0
        assert gt.GT_LoadExtConfigGts(n, "ExtModule.cfg") == 0, gt.GTE_GetLastError()
    assert gt.GT_SetExtIoBitGts(1, 0, 3, 0) == 0  # card 1, module 0, output 3 on (active low)
    assert gt.GTE_ExtModule(0).output(3) is False  # card 0's module is untouched
    assert u16(gt.GT_GetExtDoValueGts, 0, 0) == 0xFFFF
    assert u16(gt.GT_GetExtDoValueGts, 1, 0) == 0xFFF7
    assert gt.GT_SetCardNo(1) == 0
    assert gt.GTE_ExtModule(0).output(3) is True and u16(gt.GT_GetExtDoValue, 0) == 0xFFF7
    assert gt.GT_SwitchtoCardNoExtMdl(1) == 0  # the current card
