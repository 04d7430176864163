"""The bus configuration a recording was made with, and a replay's check of it.

A replay makes the recorded calls on a bus brought up from the files the session used,
found again by the names it gave them (``GT_Open(eni=...)``, ``GTECAT_ENI``,
``GTECAT_MACHINE``).  A file replaced at the same name between the recording and the
replay would not be noticed until the replay diverged somewhere later, for no reason it
could name.  So every bring-up of a recorded session notes, for its ENI file and its
machine description, the name as given, the SHA-256 of the bytes and a digest of what was
read from them (:func:`noted`; the recording's header keeps them as ``bus_config``), and
the replay compares them before anything runs (:func:`check`): bytes that differ but
describe the same bus (an ENI exported again with other whitespace, attribute order or
XML comments; a machine description with its tables in another order) are the same
configuration; anything else is refused with the file and what to do.  A file given to
the replay with ``--eni`` / ``--machine`` is the user's choice and is not compared (that
is how a session is replayed against a changed file on purpose); a file that is gone is
left to the replay's own check (:func:`gtecat.faults.record._check_files`), which names it.
A recording made before this was kept has no ``bus_config`` and replays as before.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import replace
from pathlib import Path
from typing import Any

from ..errors import ParameterError

#: what each kind of file is called, and the replay's option that gives another
_KINDS = {"eni": ("ENI file", "--eni"), "machine": ("machine description", "--machine")}
#: the digest of what an ENI's bytes describe, by the SHA-256 of the bytes (the model is
#: walked once per content in a process that brings the same bus up again and again)
_MODELS: dict[str, str] = {}


def noted(ctl: Any) -> list[dict[str, str]]:
    """The configuration files of ``ctl``'s bus, just brought up: per file ``what`` (``eni``
    | ``machine``), ``name`` (as the session gave it), ``sha256`` (of its bytes) and
    ``model`` (a digest of what they describe: :func:`model_digest`).  A file that cannot be
    read again now is left out (the bring-up read it; the replay finds out)."""
    files = [("eni", str(ctl.eni_path()))]
    source = getattr(ctl.machine, "source", "")
    if source and isinstance(ctl.options.machine, str | Path):  # (read from a file)
        files.append(("machine", source))
    out = []
    for what, name in files:
        try:
            data = Path(name).read_bytes()
        except OSError:
            continue
        sha = hashlib.sha256(data).hexdigest()
        out.append(
            {"what": what, "name": name, "sha256": sha, "model": model_digest(what, name, data)}
        )
    return out


def model_digest(what: str, name: str, data: bytes) -> str:
    """A digest of what a configuration file's bytes describe, "" when they do not parse:
    an ENI's model as gtecat reads it (slaves, PDOs, InitCmds, cycle time...) without where
    it was read from (the file's name, the slaves' lines); a machine description's TOML
    tables, their keys in order."""
    sha = hashlib.sha256(data).hexdigest()
    key = f"{what}:{sha}"
    got = _MODELS.get(key)
    if got is not None:
        return got
    try:
        if what == "eni":
            from gtecat.eni.reader import read_eni

            config = read_eni(name)
            if hashlib.sha256(Path(name).read_bytes()).hexdigest() != sha:
                return ""  # (changed again while it was read: no digest to stand for it)
            config = replace(
                config, source="", slaves=tuple(replace(s, line=None) for s in config.slaves)
            )
            text = repr(config)
        else:
            import tomllib

            tables = tomllib.loads(data.decode("utf-8"))
            text = json.dumps(tables, sort_keys=True, default=str)
    except Exception:  # (any file that does not parse: no digest, so it matches none)
        return ""
    got = _MODELS[key] = hashlib.sha256(text.encode()).hexdigest()
    return got


def check(recorded: Any, eni: str | None = None, machine: str | None = None) -> None:
    """Refuse a replay whose ENI file or machine description, found by the name the session
    gave it (relative names from the folder the replay runs in: the recorded one), is not
    the one recorded (module docstring); ``eni`` / ``machine``: the files the user gave
    instead, not compared.  ``recorded``: the header's ``bus_config`` (None: an older
    recording, nothing to compare)."""
    if not isinstance(recorded, list):
        return
    given = {"eni": eni, "machine": machine}
    for note in recorded:
        if not isinstance(note, dict) or note.get("what") not in _KINDS or given[note["what"]]:
            continue
        what, name, sha = note["what"], note.get("name"), note.get("sha256")
        if not isinstance(name, str) or not isinstance(sha, str):
            continue
        try:
            data = Path(name).read_bytes()
        except OSError:
            continue  # (gone: the replay's own check names it)
        now = hashlib.sha256(data).hexdigest()
        if now == sha:
            continue
        model = note.get("model")
        if model and model_digest(what, name, data) == model:
            continue  # the same bus, written another way
        words, option = _KINDS[what]
        where = Path(name).resolve()
        raise ParameterError(
            f"the {words} {where} is not the one the session was recorded with: it describes "
            f"another {'bus' if what == 'eni' else 'machine'} (recorded sha256 {sha[:16]}, "
            f"now {now[:16]}), so the replay would diverge where that matters; put the "
            f"recorded file back, or replay against this one on purpose with {option} {where}"
        )
