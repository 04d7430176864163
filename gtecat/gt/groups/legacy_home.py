"""The older homing calls of GTS cards: a search with the home (and index) capture armed.

Implemented by :mod:`gtecat.gt.legacy_home_calls` over the smart homing of
:mod:`gtecat.controller.smart_home`.
"""

NAME = "legacy_home"
TITLE = "legacy capture homing (GTS)"

PROTOTYPES = r"""
short GT_HomeInit();  // header (GTS)
short GT_Home(short axis, long pos, double vel, double acc, long offset);  // header (GTS)
short GT_Index(short axis, long pos, long offset);  // header (GTS)
short GT_HomeStop(short axis, long pos, double vel, double acc);  // header (GTS)
short GT_HomeSts(short axis, unsigned short *pStatus);  // header (GTS)
"""
