"""The in-process controller (``GTECAT_INPROCESS``): a C program's GT calls answered by the
controller server's dispatcher inside the program, and the controller process instead
where the Python runtime cannot be loaded."""

from __future__ import annotations

import os
import socket
import stat
import sys

import pytest

from gtecat.native import inprocess
from gtecat.native.protocol import FRAME, HELLO, PROTOCOL_VERSION, table_digest
from gtecat.native.transport import SOCKET_TYPE

from .conftest import compile_client, native_env, needs_cc, run_client

#: a Python built without a shared runtime (no --enable-shared, and none installed beside a
#: statically linked one) cannot be loaded into a program: libgts starts the process instead
needs_runtime = pytest.mark.skipif(
    not inprocess.ask()["libs"],
    reason="this Python has no shared runtime library (libpython) to load into a program; "
    "programs get the controller process (tested below)",
)


# (the default run: the in-process controller is the default, which test_c_clients's
# test_vendor_gtn_sequence_from_c runs the same program with; GTECAT_INPROCESS=1 taken
# without the reason on stderr in test_ctrl_c_still_ends_... and the forked child below)
@needs_cc
@needs_runtime
@pytest.mark.long("the vendor sequence with GTECAT_INPROCESS=1 set")
def test_a_c_program_runs_its_controller_in_process(gtn_sequence, tmp_path):
    """The vendor sequence as with the controller process: bring-up, the wall floor over a
    usleep, a move, the reasons of refused calls; no controller process is started."""
    r, v = run_client(gtn_sequence, env=native_env(GTECAT_INPROCESS="1"), cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "in-process controller is not used" not in r.stderr, r.stderr
    assert v["done"] == "1", r.stdout + r.stderr
    assert (v["open"], v["init"], v["ready"], v["start"]) == ("0", "0", "1", "0")
    assert v["open_twice"] == "-6" and "already open" in v["open_twice_reason"]
    assert int(v["slept_ms"]) >= 200
    assert v["prfpos"] == "20000"
    assert v["null_required"] == "7" and "pSts is NULL" in v["null_required_reason"]
    assert (v["close"], v["after_close"], v["reopen"], v["reopen_sts"]) == ("0", "-1", "0", "0")


@needs_cc
def test_inprocess_0_starts_the_controller_process(gtn_sequence_on_its_controller_process):
    """The controller process, as a program gets it where the runtime cannot be loaded (the
    run test_c_clients checks the controller's end of)."""
    r, v, _ = gtn_sequence_on_its_controller_process
    assert r.returncode == 0 and v["done"] == "1", r.stdout + r.stderr
    assert (v["open"], v["ready"], v["prfpos"]) == ("0", "1", "20000")
    assert int(v["slept_ms"]) >= 200


@needs_cc
def test_without_a_runtime_to_load_the_controller_process_is_started(gtn_sequence, tmp_path):
    """An interpreter without a shared runtime (built without --enable-shared): the program
    runs as before, on the controller process, and says why on stderr."""
    fake = tmp_path / "python"
    fake.write_text(
        "#!/bin/sh\n"
        'if [ "$2" = gtecat.native.inprocess ]; then printf "\\n/nowhere\\n3.11\\n\\n{}\\n"; '
        "exit 0; fi\n"
        f'exec {sys.executable} "$@"\n'
    )
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    env = native_env(GTECAT_INPROCESS="1", GTECAT_PYTHON=str(fake))
    r, v = run_client(gtn_sequence, env=env, cwd=tmp_path)
    assert "has no shared Python library" in r.stderr, r.stderr
    assert v["done"] == "1" and v["open"] == "0", r.stdout + r.stderr


def test_ask_names_the_runtime_and_the_folder_gtecat_is_in():
    a = inprocess.ask()
    assert a["version"] == f"{sys.version_info[0]}.{sys.version_info[1]}"
    assert os.path.isfile(os.path.join(str(a["root"]), "gtecat", "__init__.py"))
    assert a["path"][0] == a["root"]  # type: ignore[index]


@pytest.mark.skipif(not hasattr(socket, "AF_UNIX"), reason="a Unix socket")
def test_the_host_answers_frames_and_listens(tmp_path):
    """Host.call answers the frames libgts sends (the server's own dispatcher); a frame
    whose length is wrong is refused with b""; the socket takes other clients."""
    address = f"unix:{tmp_path}/controller.sock"
    host = inprocess.start(address)
    try:
        body = HELLO.pack(1, PROTOCOL_VERSION, 8, table_digest().encode())
        reply = host.call(FRAME.pack(len(body)) + body)
        assert reply[4:6] == b"\0\0"  # status 0: greeted
        assert host.call(b"\x09\0\0\0" + body) == b""
        with socket.socket(socket.AF_UNIX, SOCKET_TYPE) as s:
            s.connect(str(tmp_path / "controller.sock"))
    finally:
        host.stop()
    assert not (tmp_path / "controller.sock").exists()


_CTRL_C = r"""
#include <signal.h>
#include <stdio.h>
#include "gts.h"
int main(void)
{
    /* the program's own disposition: the default (a test run started in the background
       inherits SIGINT ignored, and then an ignored Ctrl-C is what the program asked for) */
    signal(SIGINT, SIG_DFL);
    short rc = GT_Open(0, 1);
    printf("open %d\n", rc);
    fflush(stdout);
    raise(SIGINT); /* Ctrl-C: a C program's default ends it */
    printf("survived\n");
    return 0;
}
"""


@needs_cc
@needs_runtime
def test_ctrl_c_still_ends_a_program_whose_controller_runs_in_it(tmp_path):
    """Python's signal module takes SIGINT when first imported, even in a runtime started
    without signal handlers: the library gives the program its own back (a Ctrl-C that did
    nothing, or failed the GT call running, was the defect)."""
    import signal

    src = tmp_path / "ctrl_c.c"
    src.write_text(_CTRL_C)
    exe = compile_client(src, tmp_path / "ctrl_c", "gcc")
    r, v = run_client(exe, env=native_env(GTECAT_INPROCESS="1"), cwd=tmp_path, timeout=120)
    assert v.get("open") == "0", r.stdout + r.stderr
    assert "in-process controller is not used" not in r.stderr, r.stderr
    assert "survived" not in r.stdout
    assert r.returncode == -signal.SIGINT, (r.returncode, r.stdout, r.stderr)


_FORK = r"""
#include <stdio.h>
#include <sys/wait.h>
#include <unistd.h>
#include "gts.h"
int main(void)
{
    long sts = 0;
    char why[256] = "";
    printf("open %d\n", GT_Open(0, 1));
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        short rc = GT_GetSts(1, &sts, 1, NULL);
        GTE_GetLastError(why, sizeof why);
        printf("child_before_open %d %s\n", rc, why);
        printf("child_open %d\n", GT_Open(0, 1));
        printf("child_sts %d\n", GT_GetSts(1, &sts, 1, NULL));
        fflush(stdout);
        _exit(0);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    printf("parent_sts %d\n", GT_GetSts(1, &sts, 1, NULL));
    return 0;
}
"""


@pytest.fixture(scope="module")
def fork_program(libgts, tmp_path_factory):
    """_FORK compiled once for both of its runs."""
    d = tmp_path_factory.mktemp("fork")
    (d / "fork.c").write_text(_FORK)
    return compile_client(d / "fork.c", d / "fork", "gcc")


@needs_cc
@pytest.mark.parametrize("inproc", ["1", "0"])
def test_a_forked_child_reaches_the_controller_once_it_opens(fork_program, tmp_path, inproc):
    """A child of the program reconnects over the controller's socket (the reconnection
    read its address from the buffer it was writing: it never connected); until its own
    GT_Open, the controller's reason says to open."""
    env = native_env(GTECAT_INPROCESS=inproc)
    r, v = run_client(fork_program, env=env, cwd=tmp_path, timeout=120)
    assert v.get("open") == "0", r.stdout + r.stderr
    assert (
        v["child_before_open"].startswith("-1 ") and "has not opened" in v["child_before_open"]
    ), r.stdout
    assert v["child_open"] == "0", r.stdout
    # (the bus is not started: both get the controller's own answer, not -1)
    assert v["child_sts"] == v["parent_sts"] != "-1", r.stdout
