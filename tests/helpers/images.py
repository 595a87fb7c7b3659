"""Checks on decoded pictures shared by the figure and report tests."""

from __future__ import annotations

import numpy as np


def distinct_colours(pixels: np.ndarray) -> int:
    """The number of distinct colours of an image (height, width, channels): 8-bit channels, or
    floats in [0, 1] as matplotlib decodes a PNG, each packed with the others into one integer
    per pixel (a 1-D unique is some 50 times faster than ``np.unique(..., axis=0)`` on rows)."""
    levels = pixels if pixels.dtype == np.uint8 else np.round(pixels * 255.0).astype(np.uint8)
    channels = levels.reshape(-1, levels.shape[-1]).astype(np.uint64)
    packed = np.zeros(len(channels), dtype=np.uint64)
    for index in range(channels.shape[1]):
        packed |= channels[:, index] << np.uint64(8 * index)
    return int(np.unique(packed).size)
