"""Where a controller listens and how a client reaches it.

Two transports carry the same protocol (:mod:`gtecat.native.protocol`):

* ``unix:/path`` (or ``/path``, or ``unix:@name`` for the Linux abstract namespace): a Unix
  socket; the file system's permissions say who may connect.
* ``tcp:HOST:PORT`` (also ``tcp://HOST:PORT``, ``tcp:PORT`` for 127.0.0.1, ``tcp:[::1]:PORT``):
  a TCP socket, for a Windows ``gts.dll`` or a client on another machine.  Anyone who can
  reach the port may connect, so every connection presents a token in its hello; the
  controller compares it in constant time and drops a connection that does not.

The token of a TCP controller: ``--token-file FILE`` when given, else ``GTECAT_TOKEN``, else
a random one made at start and written to :func:`default_token_file` (readable by its owner
only).  A client takes ``GTECAT_TOKEN``, else the file ``GTECAT_TOKEN_FILE`` names, else the
default token file when it exists (a client of the same user on the same machine needs
nothing set).
"""

from __future__ import annotations

import contextlib
import hmac
import os
import secrets
import socket
import stat
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

#: one record per message where the system has them (Linux), a byte stream elsewhere
SOCKET_TYPE = socket.SOCK_SEQPACKET if sys.platform.startswith("linux") else socket.SOCK_STREAM


def socket_path(address: str) -> str:
    """``unix:/path``, ``/path`` or ``unix:@name`` (Linux abstract) -> the AF_UNIX address."""
    addr = address[5:] if address.startswith("unix:") else address
    if not addr:
        raise ValueError(f"controller address {address!r} names no socket")
    if addr.startswith("@"):
        return "\0" + addr[1:]
    return addr


#: the port the documentation and ``gtecat.ini`` examples use
DEFAULT_TCP_PORT = 7701
#: the longest token a hello may carry
MAX_TOKEN = 256


class AddressError(ValueError):
    """A controller address that is neither ``unix:/path`` nor ``tcp:HOST:PORT``."""


@dataclass(frozen=True, slots=True)
class Address:
    kind: str  #: "unix" or "tcp"
    path: str = ""  #: AF_UNIX address (abstract names start with NUL)
    host: str = ""
    port: int = 0

    @property
    def tcp(self) -> bool:
        return self.kind == "tcp"

    def __str__(self) -> str:
        if self.tcp:
            host = f"[{self.host}]" if ":" in self.host else self.host
            return f"tcp:{host}:{self.port}"
        return "unix:" + ("@" + self.path[1:] if self.path.startswith("\0") else self.path)


def parse(address: str) -> Address:
    """``unix:/path``, ``/path``, ``unix:@name``, ``tcp:HOST:PORT``, ``tcp://HOST:PORT`` or
    ``tcp:PORT`` (127.0.0.1) -> :class:`Address` (:class:`AddressError` otherwise)."""
    text = address.strip()
    if text.startswith("tcp:"):
        rest = text[4:]
        if rest.startswith("//"):
            rest = rest[2:]
        rest = rest.rstrip("/")
        if rest.isdigit():
            host, port_text = "127.0.0.1", rest
        elif rest.startswith("["):
            host, sep, port_text = rest[1:].partition("]:")
            if not sep:
                raise AddressError(f"{address!r}: write an IPv6 address as tcp:[::1]:PORT")
        else:
            host, sep, port_text = rest.rpartition(":")
            if not sep or not host:
                raise AddressError(f"{address!r}: write tcp:HOST:PORT, e.g. tcp:127.0.0.1:7701")
        if not port_text.isdigit() or not 0 <= int(port_text) <= 65535:
            raise AddressError(f"{address!r}: the port must be a number from 0 to 65535")
        return Address("tcp", host=host, port=int(port_text))
    if "://" in text or (":" in text.split("/", 1)[0] and not text.startswith("unix:")):
        raise AddressError(
            f"{address!r}: a controller address is unix:/path or tcp:HOST:PORT "
            f"(e.g. tcp:127.0.0.1:{DEFAULT_TCP_PORT})"
        )
    try:
        return Address("unix", path=socket_path(text))
    except ValueError as e:
        raise AddressError(str(e)) from None


def runtime_dir() -> Path:
    """This user's folder for the default socket and token file (not created here)."""
    base = os.environ.get("XDG_RUNTIME_DIR") or tempfile.gettempdir()
    who = os.getuid() if hasattr(os, "getuid") else os.environ.get("USERNAME", "user")
    return Path(base) / f"gtecat-{who}"


def private_dir(path: Path) -> Path:
    """``path`` made (0700) when missing, and checked: a folder of this user's that no one
    else may enter, else ValueError with the reason (another user who made it first could
    take the socket's address over)."""
    with contextlib.suppress(FileExistsError):
        path.mkdir(mode=0o700, parents=True)
    st = path.lstat()
    if not stat.S_ISDIR(st.st_mode):
        raise ValueError(f"{path} is not a folder; remove it (gtecat keeps its sockets there)")
    if hasattr(os, "getuid") and st.st_uid != os.getuid():
        raise ValueError(
            f"{path} belongs to uid {st.st_uid}, not to you: gtecat will not put its socket "
            "there (remove it, or set XDG_RUNTIME_DIR)"
        )
    if st.st_mode & 0o077:
        raise ValueError(
            f"{path} is open to other users (mode {stat.S_IMODE(st.st_mode):04o}): "
            "chmod 700 it, or remove it"
        )
    return path


def default_token_file(port: int) -> Path:
    """The token file of the controller listening on ``port`` (one file per port: two
    controllers of one user never take each other's)."""
    return runtime_dir() / f"controller-{int(port)}.token"


def make_token() -> str:
    return secrets.token_hex(16)


def read_token_file(path: str | os.PathLike[str]) -> str:
    """The token in a file (its first line, blanks stripped); ValueError when it has none."""
    try:
        text = Path(path).read_text(encoding="utf-8", errors="replace")
    except OSError as e:
        raise ValueError(f"cannot read the token file {path}: {e.strerror or e}") from None
    token = text.strip().splitlines()[0].strip() if text.strip() else ""
    check_token(token, f"the token file {path}")
    return token


def check_token(token: str, where: str) -> None:
    if not token:
        raise ValueError(f"{where} holds no token")
    if len(token.encode()) > MAX_TOKEN:
        raise ValueError(f"{where}: a token has at most {MAX_TOKEN} bytes")


def write_token_file(path: str | os.PathLike[str], token: str) -> None:
    """Write ``token`` to ``path`` so that only its owner can read it (mode 0600; its folder
    is made 0700 when missing)."""
    p = Path(path)
    p.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    flags = os.O_WRONLY | os.O_CREAT | os.O_TRUNC | getattr(os, "O_NOFOLLOW", 0)
    fd = os.open(p, flags, 0o600)
    try:
        with contextlib.suppress(AttributeError, OSError):
            os.fchmod(fd, 0o600)  # an older file of wider mode
        os.write(fd, (token + "\n").encode())
    finally:
        os.close(fd)


def client_token(port: int) -> str:
    """The token a client of the controller on ``port`` presents: ``GTECAT_TOKEN``, else
    the file ``GTECAT_TOKEN_FILE`` names, else that port's default token file when it
    exists, else ""."""
    token = os.environ.get("GTECAT_TOKEN", "").strip()
    if token:
        return token
    named = os.environ.get("GTECAT_TOKEN_FILE", "").strip()
    if named:
        return read_token_file(named)
    with contextlib.suppress(ValueError):
        if default_token_file(port).is_file():
            return read_token_file(default_token_file(port))
    return ""


def tokens_equal(given: bytes, expected: bytes) -> bool:
    """Constant-time comparison (the time does not tell how much of a guess was right)."""
    return hmac.compare_digest(given, expected)


def listen(addr: Address, backlog: int = 128) -> socket.socket:
    """A listening, non-blocking socket at ``addr`` (a stale Unix socket is replaced; one
    that still answers is an error)."""
    if addr.tcp:
        infos = socket.getaddrinfo(addr.host, addr.port, type=socket.SOCK_STREAM)
        family, _, _, _, sockaddr = infos[0]
        s = socket.socket(family, socket.SOCK_STREAM)
        try:
            if sys.platform != "win32":  # on Windows it would let a second server steal the port
                s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            s.bind(sockaddr)
            s.listen(backlog)
        except OSError:
            s.close()
            raise
        s.setblocking(False)
        return s
    path = addr.path
    s = socket.socket(socket.AF_UNIX, SOCKET_TYPE)
    if not path.startswith("\0") and os.path.exists(path):
        probe = socket.socket(socket.AF_UNIX, SOCKET_TYPE)
        try:
            probe.connect(path)
        except OSError:
            os.unlink(path)  # a stale socket of a controller that died
        else:
            s.close()
            raise OSError(f"a controller already listens at {addr}")
        finally:
            probe.close()
    s.bind(path)
    if not path.startswith("\0"):
        os.chmod(path, 0o600)  # its folder guards it too; the socket is the owner's alone
    s.listen(backlog)
    s.setblocking(False)
    return s


def bound(addr: Address, sock: socket.socket) -> Address:
    """``addr`` with the port the system chose (``tcp:HOST:0``)."""
    if addr.tcp and addr.port == 0:
        return Address("tcp", host=addr.host, port=sock.getsockname()[1])
    return addr


def tune(sock: socket.socket) -> None:
    """Small requests and replies: no Nagle delay on TCP."""
    if sock.family in (socket.AF_INET, socket.AF_INET6):
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)


def connect(addr: Address, timeout_s: float) -> socket.socket:
    """A connected (blocking, ``timeout_s``) socket to ``addr``."""
    if addr.tcp:
        sock = socket.create_connection((addr.host, addr.port), timeout=timeout_s)
        tune(sock)
        return sock
    sock = socket.socket(socket.AF_UNIX, SOCKET_TYPE)
    sock.settimeout(timeout_s)
    try:
        sock.connect(addr.path)
    except OSError:
        sock.close()
        raise
    return sock


def peer_name(sock: socket.socket, fallback: str) -> str:
    try:
        peer = sock.getpeername()
    except OSError:
        return fallback
    if isinstance(peer, tuple):
        return f"{peer[0]}:{peer[1]}"
    return fallback


__all__ = [
    "DEFAULT_TCP_PORT",
    "MAX_TOKEN",
    "Address",
    "AddressError",
    "bound",
    "check_token",
    "client_token",
    "connect",
    "default_token_file",
    "listen",
    "make_token",
    "parse",
    "peer_name",
    "read_token_file",
    "runtime_dir",
    "tokens_equal",
    "tune",
    "write_token_file",
]
