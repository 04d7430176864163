"""Read a ``Gecat.eni`` of either family, told apart by content (DESIGN.md "Configuration files").

* ETG.2100 ENI XML: root element ``EtherCATConfig`` (:mod:`gtecat.eni.xml_reader`);
* Googol's INI-style file: ``[CommonInfo]`` / ``[SlaveStart]`` sections
  (:mod:`gtecat.eni.googol_reader`);
* ``EncryptedEtherCATConfig`` (TwinCAT's encrypted ENI) is refused: its
  content cannot be read without the vendor's key.

Both file names and extensions are meaningless here (the real controller calls
both ``Gecat.eni``); only the bytes decide.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import re
from dataclasses import replace
from pathlib import Path
from typing import Any

from .errors import EniError
from .model import EniConfig

_GOOGOL = re.compile(rb"^\s*\[\s*(CommonInfo|SlaveStart|SlaveIndex|MasterInfo)\s*\]", re.I | re.M)
_ROOT = re.compile(rb"<\s*(?:[A-Za-z_][\w.-]*:)?([A-Za-z_][\w.-]*)")


def _head_bytes(data: bytes | str) -> bytes:
    if isinstance(data, str):
        return data[:8192].encode("utf-8", "replace")
    head = data[:8192]
    for bom, codec, width in (
        (b"\x00\x00\xfe\xff", "utf-32-be", 4),
        (b"\xff\xfe\x00\x00", "utf-32-le", 4),
        (b"\xff\xfe", "utf-16-le", 2),
        (b"\xfe\xff", "utf-16-be", 2),
    ):
        if head.startswith(bom):
            # decode whole code units only (the cut may fall inside a character)
            part = data[len(bom) : len(bom) + 4096 * width]
            return part.decode(codec, "replace").encode("utf-8", "replace")[:8192]
    return head


def _root_tag(head: bytes) -> bytes | None:
    """Name of the first element, skipping the declaration, comments and PIs."""
    i = 0
    n = len(head)
    while i < n:
        j = head.find(b"<", i)
        if j < 0:
            return None
        if head.startswith(b"<?", j):
            k = head.find(b"?>", j)
            i = n if k < 0 else k + 2
            continue
        if head.startswith(b"<!--", j):
            k = head.find(b"-->", j)
            i = n if k < 0 else k + 3
            continue
        if head.startswith(b"<!", j):  # DOCTYPE: let the parser refuse it with its line
            k = head.find(b">", j)
            i = n if k < 0 else k + 1
            continue
        m = _ROOT.match(head, j)
        return m.group(1) if m else None
    return None


def detect_format(data: bytes | str) -> str:
    """``"xml"``, ``"googol"``, ``"encrypted"`` or ``"unknown"``."""
    head = _head_bytes(data)
    stripped = head.lstrip(b"\xef\xbb\xbf \t\r\n")
    if stripped.startswith(b"<"):
        tag = _root_tag(stripped)
        if tag == b"EncryptedEtherCATConfig":
            return "encrypted"
        if tag == b"EtherCATConfig":
            return "xml"
        if tag is None and b"EtherCATConfig" in stripped:
            return "xml"
        return "unknown"
    if _GOOGOL.search(head):
        return "googol"
    return "unknown"


#: the register InitCmds (the master's and each slave's): the reader builds the bus from the
#: rest, so their elements (most of a TwinCAT file's) are checked by expat but not kept
_NOT_READ = frozenset({("Master", "InitCmds"), ("Slave", "InitCmds")})
# The readers and the XML parser are imported at the first parse: a process whose model
# comes from the cache folder (read_eni), as a replay's does, needs none of them (~5 ms of its
# start).


def parse_xml(
    data: bytes | str,
    source: str,
    skip: frozenset[tuple[str, str]] = frozenset(),
    share: frozenset[tuple[str, str]] = frozenset(),
) -> Any:
    """:func:`gtecat.eni.xmltree.parse_xml`."""
    from .xmltree import parse_xml

    return parse_xml(data, source, skip, share)


def read_xml(root: Any, source: str) -> EniConfig:
    """:func:`gtecat.eni.xml_reader.read_xml`."""
    from .xml_reader import read_xml

    return read_xml(root, source)


def read_googol(text: str | bytes, source: str) -> EniConfig:
    """:func:`gtecat.eni.googol_reader.read_googol`."""
    from .googol_reader import read_googol

    return read_googol(text, source)


#: the subtrees a bus of like slaves repeats byte for byte: read once (see parse_xml)
_SHARED = frozenset({("Slave", "Mailbox"), ("ProcessData", "RxPdo"), ("ProcessData", "TxPdo")})


def parse_eni(text: str | bytes, source: str = "<string>") -> EniConfig:
    """Parse configuration text/bytes; ``source`` names it in error messages."""
    fmt = detect_format(text)
    if fmt == "xml":
        root = parse_xml(text, source, _NOT_READ, _SHARED)
        if root.tag == "EncryptedEtherCATConfig":
            fmt = "encrypted"
        elif root.tag != "EtherCATConfig":
            raise EniError(
                f"root element is <{root.tag}>, not <EtherCATConfig>", file=source, line=root.line
            )
        else:
            try:
                return read_xml(root, source)
            except EniError:
                # the message's line may be that of a shared subtree's first occurrence:
                # the same error from a tree with the line of every element
                del root
                return read_xml(parse_xml(text, source, _NOT_READ), source)
    if fmt == "encrypted":
        raise EniError(
            "this is an EncryptedEtherCATConfig (an encrypted ENI); export it unencrypted "
            "from the configuration tool",
            file=source,
        )
    if fmt == "googol":
        return read_googol(text, source)
    raise EniError(
        "not an ENI: neither ETG.2100 XML (<EtherCATConfig>) nor a Googol INI Gecat.eni "
        "([CommonInfo]/[SlaveStart] sections)",
        file=source,
    )


def read_eni(
    path: str | os.PathLike[str], cache_dir: str | os.PathLike[str] | None = None
) -> EniConfig:
    """Read and parse a configuration file (either family).

    ``cache_dir``: a folder where the model of each file content is kept between processes
    (see :func:`_load_cached`): a program, test or CI job that opens the same ENI in every
    run parses it once."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise EniError(f"cannot read the file: {exc.strerror or exc}", file=str(p)) from None
    if not data.strip():
        raise EniError("the file is empty", file=str(p))
    digest = hashlib.sha256(data).digest()
    key = (digest, str(p))
    config = _PARSED.get(key)
    if config is None:
        stored = _cache_file(cache_dir, digest) if cache_dir is not None else None
        config = _load_cached(stored, str(p)) if stored is not None else None
        if config is None:
            config = parse_eni(data, str(p))
            if stored is not None:
                _store(stored, config)
        if len(_PARSED) >= _PARSED_MAX:
            _PARSED.pop(next(iter(_PARSED)))
        _PARSED[key] = config
    return config


#: one parse per file content: the model is immutable (frozen dataclasses of tuples), so a
#: program or a test suite that opens the same ENI again gets the same object; a file that
#: changed is a new key, and one that fails raises each time (errors are not cached).  The
#: key is the content's digest, not the content (a 1,000-axis ENI is 20 MB).
_PARSED: dict[tuple[bytes, str], EniConfig] = {}
_PARSED_MAX = 32

_READER_DIGEST: list[str] = []


def _reader_digest() -> str:
    """The digest of this package's source: a model stored by other reader code is not read."""
    if not _READER_DIGEST:
        h = hashlib.sha256()
        for f in sorted(Path(__file__).parent.glob("*.py")):
            h.update(f.name.encode())
            h.update(f.read_bytes())
        _READER_DIGEST.append(h.hexdigest()[:16])
    return _READER_DIGEST[0]


def _cache_file(cache_dir: str | os.PathLike[str], digest: bytes) -> Path:
    return Path(cache_dir) / _reader_digest() / f"{digest.hex()[:40]}.pickle"


def _load_cached(file: Path, source: str) -> EniConfig | None:
    """The model stored for this content (its ``source`` made this file's), or None.

    The folder is the user's own cache (mode 0700 where it is made, like the compiled
    bytecode beside it); a file that is unreadable, cut short or of another kind is ignored
    and parsed again."""
    try:
        with file.open("rb") as f:
            config = pickle.load(f)
    except Exception:  # absent, partial, foreign: parse the file instead
        return None
    if not isinstance(config, EniConfig):
        return None
    return config if config.source == source else replace(config, source=source)


def _store(file: Path, config: EniConfig) -> None:
    """Keep ``config`` for the next process (atomically; a failure only costs the speed)."""
    try:
        file.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        tmp = file.with_name(f"{file.name}.{os.getpid()}.tmp")
        with tmp.open("wb") as f:
            pickle.dump(config, f, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, file)
        _prune(file.parent)
    except (OSError, pickle.PicklingError, RecursionError):
        pass


#: models kept per reader version: the least recently stored go first
_CACHE_FILES = 32


def _prune(folder: Path) -> None:
    files = sorted(folder.glob("*.pickle"), key=lambda f: f.stat().st_mtime)
    for f in files[:-_CACHE_FILES]:
        f.unlink(missing_ok=True)
