"""The FMUs' and the master's messages, forwarded to Python's logging as logger ``railfmu``
(the native module keeps them instead of printing them to the process's stderr, which a
notebook's user does not see). Its level decides which are kept: WARNING unless set, e.g.
``logging.getLogger("railfmu").setLevel(logging.INFO)`` for an FMU's informational messages."""

from __future__ import annotations

import contextlib
import logging
from typing import Iterator

from . import _railfmu

logger = logging.getLogger("railfmu")


def emit() -> None:
    """Logs the messages kept since the last call."""
    messages, dropped = _railfmu.take_log()
    if dropped:
        logger.warning("%d earlier messages were dropped (the newest 10000 are kept between two calls)", dropped)
    for level, text in messages:
        logger.log(level, text)


@contextlib.contextmanager
def forwarded() -> Iterator[None]:
    """Around a call into the native module: its messages at the logger's level, logged when
    it returns (or raises)."""
    _railfmu.set_log_level(logger.getEffectiveLevel())
    try:
        yield
    finally:
        emit()
