"""Progress reporting: a tqdm bar when tqdm is installed, else a line on stderr."""

from __future__ import annotations

import contextlib
import sys
from typing import Any, Callable, Iterator, Optional


class _TextBar:
    def __init__(self, unit: str):
        self.unit = unit
        self.last = -1

    def __call__(self, done: int, total: int, *_: Any) -> None:
        pct = 100 * done // max(total, 1)
        if pct != self.last and (pct % 10 == 0 or done == total):
            self.last = pct
            sys.stderr.write(f"\r{done}/{total} {self.unit} ({pct} %)")
            if done == total:
                sys.stderr.write("\n")
            sys.stderr.flush()


def check_progress(progress: Any) -> None:
    """Refuses a ``progress`` that is none of None, True, False or a callable (a number would
    otherwise pass as True)."""
    if not (progress is None or isinstance(progress, bool) or callable(progress)):
        raise TypeError(
            f"progress must be True, False, None or a callable f(done, total, ...), "
            f"not {type(progress).__name__} {progress!r}"
        )


@contextlib.contextmanager
def bar(progress: Any, unit: str) -> Iterator[Optional[Callable[..., Any]]]:
    """The callback for ``progress``: None/False -> None, a callable -> itself, True -> a bar
    ``f(done, total, ...)`` closed on exit."""
    check_progress(progress)
    if progress is None or progress is False:
        yield None
        return
    if callable(progress):
        yield progress
        return
    try:
        from tqdm import tqdm
    except ImportError:
        yield _TextBar(unit)
        return
    t = tqdm(unit=unit, file=sys.stderr)

    def update(done: int, total: int, *_: Any) -> None:
        if t.total != total:
            t.total = total
        t.n = done
        t.refresh()

    try:
        yield update
    finally:
        t.close()
