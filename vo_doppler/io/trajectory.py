"""Trajectory files: TUM rows ``t x y z qx qy qz qw`` and KITTI rows (the 3×4 matrix [R | t]
row-major; KITTI files carry no time, so times come from elsewhere or default to the row index).

TUM times must increase strictly (a repeated or earlier time names its line); KITTI rotations
must be rotations (orthonormal within 1e-3, determinant +1) before they are re-orthonormalised.
"""

from __future__ import annotations

from array import array
from enum import StrEnum
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.choices import checked
from vo_doppler.errors import InputError
from vo_doppler.io.textfile import read_text, text_lines
from vo_doppler.model.trajectory import Trajectory


def _read_numeric_rows(path: Path, n_columns: int, what: str) -> tuple[np.ndarray, np.ndarray]:
    """The rows of ``n_columns`` finite numbers (``#`` comments and blank lines skipped) and
    their line numbers. The numbers are gathered in flat typed arrays (the array shares their
    memory): lists of Python floats took 250 bytes a row, a 30-min ground truth at 100 Hz
    (180,000 rows) 108 MiB at its peak."""
    values_out = array("d")
    numbers = array("q")
    text = read_text(path, f"{what} file")
    for number, line in enumerate(text_lines(text), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        fields = stripped.replace(",", " ").split()
        if len(fields) != n_columns:
            raise InputError(
                f"{what} row has {len(fields)} fields, expected {n_columns}", path, number
            )
        try:
            values = [float(f) for f in fields]
        except ValueError as exc:
            raise InputError(f"{what} row has a non-numeric field ({exc})", path, number) from exc
        if not np.all(np.isfinite(values)):
            raise InputError(f"{what} row has a non-finite value", path, number)
        values_out.extend(values)
        numbers.append(number)
    rows = np.frombuffer(values_out, dtype=float).reshape(-1, n_columns)
    return rows, np.frombuffer(numbers, dtype=np.int64)


def read_tum(path: str | Path) -> Trajectory:
    """Read a TUM trajectory file (``t x y z qx qy qz qw``; ``#`` comments allowed)."""
    path = Path(path)
    data, numbers = _read_numeric_rows(path, 8, "TUM")
    steps = np.diff(data[:, 0])
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0]) + 1
        raise InputError(
            f"TUM time {data[k, 0]:.9f} s is not after the previous row's", path, numbers[k]
        )
    scale = np.abs(data[:, 4:8]).max(axis=1, initial=0.0)
    bad = np.flatnonzero(scale == 0.0)
    if bad.size:
        raise InputError("TUM row has a zero quaternion", path, numbers[bad[0]])
    quats = data[:, 4:8] / scale[:, None]  # scaled first: no overflow or underflow in the norm
    quats /= np.linalg.norm(quats, axis=1)[:, None]
    return Trajectory(data[:, 0], data[:, 1:4], Rotation.from_quat(quats))


def write_tum(path: str | Path, trajectory: Trajectory) -> None:
    """Write a TUM trajectory file with full double precision."""
    quats = trajectory.orientations.as_quat() if len(trajectory) else np.zeros((0, 4))
    data = np.column_stack([trajectory.t, trajectory.positions, quats])
    np.savetxt(path, data, fmt="%.9f", header="t x y z qx qy qz qw")


def read_kitti(path: str | Path, times: np.ndarray | None = None) -> Trajectory:
    """Read a KITTI pose file (3×4 row-major per line); times default to the row index."""
    path = Path(path)
    data, numbers = _read_numeric_rows(path, 12, "KITTI")
    poses = data.reshape(-1, 3, 4)
    if times is None:
        times = np.arange(len(poses), dtype=float)
    elif len(times) != len(poses):
        raise InputError(f"{len(poses)} poses but {len(times)} timestamps", path)
    rotations = poses[:, :, :3]
    gram = np.einsum("nji,njk->nik", rotations, rotations) - np.eye(3)
    bad = np.flatnonzero((np.abs(gram).max(axis=(1, 2)) > 1e-3) | (np.linalg.det(rotations) <= 0))
    if bad.size:
        raise InputError(
            "KITTI pose has no rotation matrix (not orthonormal)", path, numbers[bad[0]]
        )
    u, _, vt = np.linalg.svd(rotations)
    fixed = u @ vt
    return Trajectory(times, poses[:, :, 3], Rotation.from_matrix(fixed))


def write_kitti(path: str | Path, trajectory: Trajectory) -> None:
    """Write a KITTI pose file (no timestamps)."""
    rows = trajectory.matrices[:, :3, :].reshape(-1, 12)
    np.savetxt(path, rows, fmt="%.9e")


class TrajectoryFormat(StrEnum):
    """The ``fmt`` of :func:`read_trajectory` (and of the commands' ``--format``)."""

    AUTO = "auto"
    """By :data:`AUTO_FORMAT_RULE`."""
    TUM = "tum"
    KITTI = "kitti"


AUTO_FORMAT_RULE = "by the number of columns of the first data row, TUM 8, KITTI 12"
"""How ``auto`` tells the format. Not by the extension: TUM and KITTI files are both commonly
``.txt`` (KITTI's ``00.txt``, TUM's ``groundtruth.txt``), while the column counts never
overlap."""


def read_trajectory(
    path: str | Path, fmt: TrajectoryFormat | str = TrajectoryFormat.AUTO, times=None
) -> Trajectory:
    """Read TUM or KITTI; ``auto`` picks :data:`AUTO_FORMAT_RULE`."""
    path = Path(path)
    if trajectory_format(path, fmt) is TrajectoryFormat.TUM:
        return read_tum(path)
    return read_kitti(path, times)


def trajectory_format(
    path: str | Path, fmt: TrajectoryFormat | str = TrajectoryFormat.AUTO
) -> TrajectoryFormat:
    """``fmt`` (a :class:`~vo_doppler.choices.ChoiceError` if it is none), or for "auto" the
    format of ``path`` by the number of columns of its first data row: "tum" (8) or "kitti"
    (12); anything else is an :class:`InputError`."""
    fmt = checked(TrajectoryFormat, fmt, "fmt")
    return _sniff_format(Path(path)) if fmt is TrajectoryFormat.AUTO else fmt


def _sniff_format(path: Path) -> TrajectoryFormat:
    for line in read_text(path, "trajectory file").splitlines():
        stripped = line.strip()
        if stripped and not stripped.startswith("#"):
            n = len(stripped.replace(",", " ").split())
            if n == 8:
                return TrajectoryFormat.TUM
            if n == 12:
                return TrajectoryFormat.KITTI
            raise InputError(
                f"cannot tell the trajectory format: first row has {n} fields "
                "(TUM has 8, KITTI 12)",
                path,
            )
    raise InputError("trajectory file has no data rows", path)
