"""The one way the toolkit writes JSON: valid JSON (RFC 8259) whatever the numbers.

Python's ``json`` writes a NaN or an infinity as the bare words ``NaN`` and ``Infinity``, which
no strict reader (a browser's ``JSON.parse``, ``jq``) accepts. Here they become ``null`` — the
figure is not available — and NumPy scalars and arrays become plain numbers and lists.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from typing import Any

import numpy as np


def plain(value: Any) -> Any:
    """``value`` with every non-finite float replaced by None, NumPy scalars and arrays turned
    into Python numbers and lists, tuples into lists (dictionaries and lists walked through)."""
    if isinstance(value, dict):
        return {key: plain(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [plain(item) for item in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, np.generic):
        return plain(value.item())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def json_text(
    value: Any, indent: int | None = None, default: Callable[[Any], Any] | None = None
) -> str:
    """``value`` as JSON text, NaN and infinities as ``null`` (see :func:`plain`); ``default``
    as for :func:`json.dumps` (e.g. ``str`` for paths)."""
    return json.dumps(plain(value), indent=indent, default=default, allow_nan=False)
