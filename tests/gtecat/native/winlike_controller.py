"""`gtecat controller` in a Python that lacks what Python on Windows lacks: fcntl, AF_UNIX,
epoll and poll, os.getuid, a native socketpair (a smoke of the controller's pure-Python path)."""

import os
import select
import socket
import sys

sys.modules["fcntl"] = None  # import fcntl -> ImportError, as on Windows
for mod, names in (
    (socket, ("AF_UNIX",)),
    (select, ("epoll", "poll")),
    (os, ("getuid", "sched_getaffinity")),
):
    for n in names:
        if hasattr(mod, n):
            delattr(mod, n)


def _tcp_socketpair(*_args):  # Windows' socket.socketpair: two TCP sockets on loopback
    with socket.socket() as lsock:
        lsock.bind(("127.0.0.1", 0))
        lsock.listen(1)
        a = socket.create_connection(lsock.getsockname())
        b, _ = lsock.accept()
    return a, b


socket.socketpair = _tcp_socketpair
from gtecat.cli.main import main  # noqa: E402

sys.exit(main(["controller", *sys.argv[1:]]))
