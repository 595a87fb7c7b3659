"""JSON as the toolkit writes it: valid for strict readers, whatever the numbers."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from vo_doppler.report.json_text import json_text, plain


def test_non_finite_numbers_become_null_and_numpy_plain_values():
    value = {
        "nan": float("nan"),
        "inf": [float("inf"), -np.inf],
        "numpy": (np.float64(np.nan), np.float32(1.5), np.int64(3), np.bool_(True)),
        "array": np.array([1.0, np.nan]),
        "nested": {"ok": 2.25, "text": "NaN"},
    }
    assert plain(value) == {
        "nan": None,
        "inf": [None, None],
        "numpy": [None, 1.5, 3, True],
        "array": [1.0, None],
        "nested": {"ok": 2.25, "text": "NaN"},
    }
    text = json_text(value, indent=2)
    assert "NaN," not in text and "Infinity" not in text
    assert json.loads(text, parse_constant=lambda word: 1 / 0) == plain(value)


def test_default_serialises_other_objects():
    assert json_text({"path": Path("a/b")}, default=str) == '{"path": "a/b"}'
