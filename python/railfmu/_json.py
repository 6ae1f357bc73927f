"""Descriptions given as Python values (dicts, lists, NumPy numbers) made the JSON text the
master reads, with a message naming the entry JSON cannot hold."""

from __future__ import annotations

import json
import math
import os
from typing import Any, List, Optional

import numpy as np

from . import _railfmu


def _python(value: Any) -> Any:
    """A NumPy number or array, a pandas Series or Index as the Python number or list JSON
    writes; anything else as it is."""
    if isinstance(value, np.generic):
        return value.item()
    if not isinstance(value, (dict, list, tuple, str)) and callable(getattr(value, "tolist", None)):
        return value.tolist()
    return value


def _plain(value: Any) -> Any:
    """What ``json.dumps`` cannot write by itself: NumPy and pandas values as :func:`_python`
    reads them, ranges as lists, paths as their text; anything else is a TypeError naming its
    type."""
    converted = _python(value)
    if converted is not value:
        return converted
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, range):
        return list(value)
    shown = repr(value)
    shown = shown if len(shown) <= 60 else shown[:57] + "..."
    raise TypeError(f"{type(value).__name__} {shown} is not a value JSON holds (a number, text, list or dict)")


def _first_bad(value: Any, path: List[str]) -> Optional[str]:
    """Where in ``value`` the first number JSON has no form for (NaN, an infinity) is, and what
    it is; None if there is none."""
    value = _python(value)
    if isinstance(value, float) and not math.isfinite(value):
        return f"{'.'.join(path) or 'the value'}: {value} (JSON has no such number)"
    if isinstance(value, dict):
        for k, v in value.items():
            bad = _first_bad(v, path + [str(k)])
            if bad:
                return bad
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            bad = _first_bad(v, path[:-1] + [f"{path[-1]}[{i}]"] if path else [f"[{i}]"])
            if bad:
                return bad
    return None


def description_json(value: Any, what: str) -> str:
    """``value`` as JSON text; SystemDescriptionError naming the entry that JSON cannot hold."""
    try:
        return json.dumps(value, default=_plain, allow_nan=False)
    except TypeError as e:
        raise _railfmu.SystemDescriptionError(f"{what}: {e}") from None
    except ValueError as e:
        # a NaN or an infinity (looked for only then, and named by its place), or a circular
        # reference, which the search must not walk into
        bad = None if "ircular" in str(e) else _first_bad(value, [])
        raise _railfmu.SystemDescriptionError(f"{what}: {bad or e}") from None
