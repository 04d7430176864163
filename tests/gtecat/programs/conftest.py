"""Motion-program tests: compile and run programs on a bare runtime (no controller)."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from gtecat.programs.compiler import compile_source
from gtecat.programs.threads import ProgramRuntime

MS = 1_000_000


class Host:
    """A runtime with a recording GT caller and a lockstep millisecond clock."""

    def __init__(self, source: str, speed: float = 100.0, answers=None) -> None:
        self.calls: list[tuple[str, tuple]] = []
        self.answers: dict[str, Callable[[tuple], int]] = answers or {}
        self.program = compile_source(source, "test.c")
        self.rt = ProgramRuntime(self.call, speed)
        self.rt.download(self.program)
        self.now = 0

    def call(self, name: str, args: tuple) -> tuple[int, str]:
        self.calls.append((name, args))
        answer = self.answers.get(name)
        rc = answer(args) if answer is not None else 0
        return rc, ("refused" if rc else "")

    def start(self, thread: int = 0, function: str | None = None, page: int | None = None):
        f = self.program.function(function) if function else self.program.functions[0]
        assert f is not None
        self.rt.bind(thread, f.id, thread if page is None else page)
        self.rt.run(thread)

    def ms(self, n: int = 1) -> int:
        done = 0
        for _ in range(n):
            done += self.rt.step(self.now, MS)
            self.now += MS
        return done

    def until_idle(self, limit_ms: int = 10_000) -> int:
        """Milliseconds until no thread runs (the cycle in which the last one ended + 1)."""
        for k in range(limit_ms):
            if not any(self.rt.status(t).run == 1 for t in range(32)):
                return k
            self.ms()
        raise AssertionError("threads still running")

    def g(self, name: str) -> int:
        v = self.program.global_var(name)
        assert v is not None
        return self.rt.globals[v.address]

    def garr(self, name: str) -> list[int]:
        v = self.program.global_var(name)
        assert v is not None
        return self.rt.globals[v.address : v.address + v.size]

    def set_g(self, name: str, word: int, k: int = 0) -> None:
        v = self.program.global_var(name)
        assert v is not None
        self.rt.globals[v.address + k] = word


@pytest.fixture
def host():
    return Host
