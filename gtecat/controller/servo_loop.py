"""The servo loop of a GTS card as an application sees it: PID sets, output modes, DAC and ADC.

The emulated amplifiers follow the plan (:mod:`gtecat.master.card`); nothing here changes
how an axis moves.  What is kept is what the vendor's functions read back and what a
scenario observes, decided where the vendor is silent:

* **PID.**  Each control (one per axis) has two parameter sets (``index`` 1..2, the
  vendor's ``GT_SetControlFilter`` selects one); before any ``GT_SetPid`` a set reads
  ``kp`` 1, ``ki`` = ``kd`` = ``kvff`` = ``kaff`` 0, ``integralLimit`` =
  ``derivativeLimit`` = ``limit`` = 32767.  Stored and read back; the emulated loop is a
  well-tuned one whatever the numbers.
* **Output modes.**  ``GT_CtrlMode(axis, 0)`` makes the axis an analog one (its DAC
  carries the command), ``1`` a pulse one (the card's axes start as pulse axes);
  ``GT_StepDir`` / ``GT_StepPulse`` choose the pulse format of a step channel (0 / 1, the
  vendor's ``STEP_DIR`` / ``STEP_PULSE``; default step/dir).
* **DAC.**  Channel ``n`` is axis ``n``'s analog output (1..axes).  On an analog axis whose
  servo is on, the control loop drives it: ``GT_GetDac`` reads the loop's command,
  ``kp`` x following error (pulses) + ``kvff`` x planned velocity (pulse/ms), rounded and
  clipped to +-``limit`` of the active set, and ``GT_SetDac`` returns 1.  Otherwise the
  channel is a free analog output: ``GT_SetDac`` writes -32768..32767 (+-10 V) and
  ``GT_GetDac`` reads it back; ``GT_Reset`` sets them to 0.
* **ADC.**  Eight analog inputs (1..8) at 0 V until the field side sets them
  (``GTE_SetAdc`` / :meth:`ServoLoop.set_adc`); ``GT_GetAdcValue`` gives
  ``round(volts / 10 x 32767)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .._attrs import PerObject
from ..errors import ParameterError

PID_SETS = 2
ADC_CHANNELS = 8
ADC_VOLTS = 10.0
_SHORT = 32767


@dataclass
class PidSet:
    kp: float = 1.0
    ki: float = 0.0
    kd: float = 0.0
    kvff: float = 0.0
    kaff: float = 0.0
    integralLimit: int = _SHORT  # noqa: N815 - the vendor's TPid field names
    derivativeLimit: int = _SHORT  # noqa: N815
    limit: int = _SHORT


@dataclass
class ServoLoop:
    """The loop settings and analog channels of one controller."""

    pid: dict[tuple[int, int], PidSet] = field(default_factory=dict)
    #: the active set of each control (GT_SetControlFilter; 1 by default)
    active_set: dict[int, int] = field(default_factory=dict)
    #: axis -> 0 analog, 1 pulse (absent: pulse)
    ctrl_mode: dict[int, int] = field(default_factory=dict)
    #: step channel -> 0 step/dir, 1 pulse (CW/CCW)
    step_mode: dict[int, int] = field(default_factory=dict)
    dac: dict[int, int] = field(default_factory=dict)
    adc: list[float] = field(default_factory=lambda: [0.0] * ADC_CHANNELS)
    #: GT_SetSoftLimitMode per axis (0: stop after the limit, the only one emulated)
    soft_limit_mode: dict[int, int] = field(default_factory=dict)
    #: soft limits put aside by GT_LmtsOffEx(..., limitMode=1): axis -> (positive, negative)
    soft_stash: dict[int, tuple[int, int]] = field(default_factory=dict)

    def pid_set(self, control: int, index: int) -> PidSet:
        return self.pid.setdefault((control, index), PidSet())

    def analog(self, axis: int) -> bool:
        return self.ctrl_mode.get(axis, 1) == 0

    def set_adc(self, adc: int, volts: float) -> None:
        """The field side: the voltage on analog input ``adc`` (1..8), clipped to +-10 V."""
        if not 1 <= int(adc) <= ADC_CHANNELS:
            raise ParameterError(f"adc={adc}: the card has analog inputs 1..{ADC_CHANNELS}")
        self.adc[int(adc) - 1] = min(max(float(volts), -ADC_VOLTS), ADC_VOLTS)

    def reset(self) -> None:
        """GT_Reset: free analog outputs to 0 V; settings and inputs stay."""
        self.dac.clear()


_LOOPS: PerObject[ServoLoop] = PerObject("servo_loop")


def servo_loop(ctl: Any) -> ServoLoop:
    """The loop state of controller ``ctl`` (made on first use)."""
    base = getattr(ctl, "_base", ctl)
    loop = _LOOPS.get(base)
    if loop is None:
        loop = _LOOPS[base] = ServoLoop()
        base.on_reset.append(lambda c: loop.reset())
    return loop


__all__ = ["ADC_CHANNELS", "PID_SETS", "PidSet", "ServoLoop", "servo_loop"]
