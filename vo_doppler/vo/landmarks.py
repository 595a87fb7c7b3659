"""The VO map: 3-D landmarks keyed by track id, kept in sorted parallel arrays.

Look-ups of a whole feature set are one ``searchsorted`` (O(n log N)) instead of a dictionary
access per feature.
"""

from __future__ import annotations

import numpy as np


class LandmarkMap:
    """World points ``xyz`` (N, 3) of tracks ``ids`` (N,), ``ids`` strictly increasing."""

    def __init__(self) -> None:
        self.ids = np.zeros(0, dtype=np.int64)
        self.xyz = np.zeros((0, 3))

    def __len__(self) -> int:
        return len(self.ids)

    def rows(self, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For each track id: whether it has a landmark, and its row (valid where it has)."""
        ids = np.asarray(ids, dtype=np.int64)
        if not len(self.ids):
            return np.zeros(len(ids), bool), np.zeros(len(ids), dtype=np.int64)
        rows = np.minimum(np.searchsorted(self.ids, ids), len(self.ids) - 1)
        return self.ids[rows] == ids, rows

    def contains(self, ids: np.ndarray) -> np.ndarray:
        return self.rows(ids)[0]

    def lookup(self, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mask of the ids that have a landmark, and those landmarks' points (mask.sum(), 3)."""
        found, rows = self.rows(ids)
        return found, self.xyz[rows[found]]

    def set(self, ids: np.ndarray, xyz: np.ndarray) -> None:
        """Insert or overwrite the landmarks of unique track ``ids``."""
        ids = np.asarray(ids, dtype=np.int64)
        xyz = np.asarray(xyz, dtype=float).reshape(-1, 3)
        found, rows = self.rows(ids)
        self.xyz[rows[found]] = xyz[found]
        if not found.all():
            all_ids = np.concatenate([self.ids, ids[~found]])
            all_xyz = np.vstack([self.xyz, xyz[~found]])
            order = np.argsort(all_ids, kind="stable")
            self.ids, self.xyz = all_ids[order], all_xyz[order]

    def remove(self, ids: np.ndarray) -> None:
        keep = ~np.isin(self.ids, ids)
        self.ids, self.xyz = self.ids[keep], self.xyz[keep]

    def retain(self, ids: np.ndarray) -> None:
        """Drop every landmark whose track is not in ``ids``."""
        keep = np.isin(self.ids, ids)
        self.ids, self.xyz = self.ids[keep], self.xyz[keep]

    def clear(self) -> None:
        self.ids = np.zeros(0, dtype=np.int64)
        self.xyz = np.zeros((0, 3))
