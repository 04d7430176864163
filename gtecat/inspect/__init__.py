"""Seeing and touching a running machine: inspection endpoints, attaching to them, the panel.

Every running gtecat (a Python application after ``GT_Open``, a ``gtecat controller``)
publishes an endpoint (:mod:`.endpoint`) in a per-user runtime folder (:mod:`.runtime`);
``gtecat ps`` lists them, the bus verbs attach to one (:mod:`.client`) and ``gtecat panel``
shows one in a browser (:mod:`.panel`).  The endpoint reads what the master and the
controller already hold; it keeps no model of the machine of its own.
"""

import os as _os


def enabled() -> bool:
    """Whether this process publishes its endpoints (``GTECAT_INSPECT``, on unless 0, no,
    off or false): asked before the endpoint's module is loaded, which a process that
    publishes nothing (a replay) never needs."""
    return _os.environ.get("GTECAT_INSPECT", "1").strip().lower() not in ("0", "no", "off", "false")
