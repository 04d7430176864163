"""The vendor constants (macros) the GT functions take, with the values the manual gives.

Where the manual names a macro and its value ("该宏定义为 N") the value is the
manual's; the ``MC_*`` resource types and ``PT_MODE_*`` are named by the
manual (GT_LmtsOn/Off, the ``#define MC_GPO 12`` of 10.4.3, GT_PrfPt in
examples 7-3/7-4) and take the vendor header's values, which the manual's own
example (MC_GPO = 12) confirms.
"""

from __future__ import annotations

# resource types (vendor header; MC_LIMIT_* : GT_LmtsOn / GT_LmtsOff, chapter 13)
MC_NONE = -1
MC_LIMIT_POSITIVE = 0
MC_LIMIT_NEGATIVE = 1
MC_ALARM = 2
MC_HOME = 3
MC_GPI = 4
MC_ARRIVE = 5
MC_MPG = 6
MC_ENABLE = 10
MC_CLEAR = 11
MC_GPO = 12
MC_DAC = 20
MC_STEP = 21
MC_PULSE = 22
MC_ENCODER = 23
MC_ADC = 24
MC_AXIS = 30
MC_PROFILE = 31
MC_CONTROL = 32

# PT mode (7.4): FIFO mode and segment types (GT_PtData)
PT_MODE_STATIC = 0
PT_MODE_DYNAMIC = 1
PT_SEGMENT_NORMAL = 0
PT_SEGMENT_EVEN = 1
PT_SEGMENT_STOP = 2

# electronic gear (7.5): master type (GT_SetGearMaster)
GEAR_MASTER_ENCODER = 1
GEAR_MASTER_PROFILE = 2
GEAR_MASTER_AXIS = 3

# Follow (7.6): master type, start event, segment type
FOLLOW_MASTER_ENCODER = 1
FOLLOW_MASTER_PROFILE = 2
FOLLOW_MASTER_AXIS = 3
FOLLOW_EVENT_START = 1
FOLLOW_EVENT_PASS = 2
FOLLOW_SEGMENT_NORMAL = 0
FOLLOW_SEGMENT_EVEN = 1
FOLLOW_SEGMENT_STOP = 2
FOLLOW_SEGMENT_CONTINUE = 3

# --- GT_Open channels ------------------------------------------------------------------------
#: GT_Open(CHANNEL_PCI_ECATCH) as in manual example 5-5.  The vendor header's value is not
#: public; the emulator ignores the channel, so any value opens the (emulated) controller.
CHANNEL_PCI_ECATCH = 1

# --- capture and smart home (GTS vendor header; gts-header-facts "Smart home") --------------
CAPTURE_HOME = 1
CAPTURE_INDEX = 2
CAPTURE_PROBE = 3

HOME_MODE_LIMIT = 10
HOME_MODE_LIMIT_HOME = 11
HOME_MODE_LIMIT_INDEX = 12
HOME_MODE_LIMIT_HOME_INDEX = 13
HOME_MODE_HOME = 20
HOME_MODE_HOME_INDEX = 22
HOME_MODE_INDEX = 30
HOME_MODE_FORCED_HOME = 40
HOME_MODE_FORCED_HOME_INDEX = 41

HOME_STAGE_IDLE = 0
HOME_STAGE_START = 1
HOME_STAGE_SEARCH_LIMIT = 10
HOME_STAGE_SEARCH_LIMIT_STOP = 11
HOME_STAGE_SEARCH_LIMIT_ESCAPE = 13
HOME_STAGE_SEARCH_LIMIT_RETURN = 15
HOME_STAGE_SEARCH_LIMIT_RETURN_STOP = 16
HOME_STAGE_SEARCH_HOME = 20
HOME_STAGE_SEARCH_HOME_RETURN = 25
HOME_STAGE_SEARCH_INDEX = 30
HOME_STAGE_SEARCH_GPI = 40
HOME_STAGE_SEARCH_GPI_RETURN = 45
HOME_STAGE_GO_HOME = 80
HOME_STAGE_END = 100

HOME_ERROR_NONE = 0
HOME_ERROR_NOT_TRAP_MODE = 1
HOME_ERROR_DISABLE = 2
HOME_ERROR_ALARM = 3
HOME_ERROR_STOP = 4
HOME_ERROR_STAGE = 5
HOME_ERROR_HOME_MODE = 6
HOME_ERROR_SET_CAPTURE_HOME = 7
HOME_ERROR_NO_HOME = 8
HOME_ERROR_SET_CAPTURE_INDEX = 9
HOME_ERROR_NO_INDEX = 10
