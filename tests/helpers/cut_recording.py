"""A simulated sequence with its vehicle signals as CSV files, and the same recording cut to a
time span as text (rows, epochs, images outside it left out), independently of
:mod:`vo_doppler.model.time_span`: what ``--start`` / ``--end`` results are compared with."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import yaml

from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.sensor_csv import FORWARD_ACCELERATION_COLUMN, SPEED_COLUMN, YAW_RATE_COLUMN
from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.series import SensorSeries

VEHICLE_FILES = {
    "yaw_rate": ("vehicle/yaw_rate.csv", YAW_RATE_COLUMN),
    "wheel_speed": ("vehicle/wheel_speed.csv", SPEED_COLUMN),
    "forward_acceleration": ("imu/forward_acceleration.csv", FORWARD_ACCELERATION_COLUMN),
}


def _write_series(path: Path, column: str, series: SensorSeries) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    rows = "".join(
        f"{t!r},{v!r}\n" for t, v in zip(series.t.tolist(), series.value.tolist(), strict=True)
    )
    path.write_text(f"t,{column}\n{rows}")


def csv_sequence(simulated: Path, folder: Path) -> Path:
    """``simulated`` (a ``vo-doppler simulate`` folder, CAN log) as a sequence whose yaw rate,
    wheel speed and forward acceleration are CSV files on GPS time (images hard-linked)."""
    sequence = read_sequence(simulated)
    manifest = yaml.safe_load((simulated / "sequence.yaml").read_text())
    folder.mkdir(parents=True)
    shutil.copytree(simulated / "image_0", folder / "image_0", copy_function=os.link)
    for name in ("times.txt", "calib.yaml", "ground_truth.tum"):
        shutil.copy(simulated / name, folder / name)
    shutil.copytree(simulated / "gnss", folder / "gnss")
    for key, (relative, column) in VEHICLE_FILES.items():
        _write_series(folder / relative, column, getattr(sequence, key))
    del manifest["can"]
    manifest["vehicle"] = {
        "yaw_rate": VEHICLE_FILES["yaw_rate"][0],
        "wheel_speed": VEHICLE_FILES["wheel_speed"][0],
    }
    manifest["imu"] = {"forward_acceleration": VEHICLE_FILES["forward_acceleration"][0]}
    (folder / "sequence.yaml").write_text(yaml.safe_dump(manifest, sort_keys=False))
    return folder


def _inside(t: float, begin: float, end: float) -> bool:
    return begin <= t <= end


def _cut_rows(source: Path, target: Path, begin: float, end: float, header: int = 1) -> None:
    """A CSV or TUM file's rows whose first field lies in [begin, end] (comments kept)."""
    lines = source.read_text().splitlines(keepends=True)
    kept = [
        line
        for number, line in enumerate(lines)
        if number < header
        or line.startswith("#")
        or _inside(float(line.replace(",", " ").split()[0]), begin, end)
    ]
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text("".join(kept))


def cut_rinex_obs(source: Path, target: Path, begin: float, end: float) -> None:
    """A RINEX 3 observation file with the epoch records outside [begin, end] left out (the
    records' GPS times taken in order from the reader's epoch list)."""
    lines = source.read_text().splitlines(keepends=True)
    body = next(i for i, line in enumerate(lines) if "END OF HEADER" in line) + 1
    starts = [i for i in range(body, len(lines)) if lines[i].startswith(">")]
    epochs = read_obs(source).epoch_time
    assert len(epochs) == len(starts)
    kept = lines[:body]
    for t, first, last in zip(epochs, starts, [*starts[1:], len(lines)], strict=True):
        if _inside(float(t), begin, end):
            kept += lines[first:last]
    target.write_text("".join(kept))


def cut_copy(full: Path, folder: Path, begin: float, end: float) -> Path:
    """The sequence ``full`` (from :func:`csv_sequence`) cut to the GPS times [begin, end]."""
    manifest = yaml.safe_load((full / "sequence.yaml").read_text())
    folder.mkdir(parents=True)
    offset = float(manifest["camera"]["time_offset_s"])
    images = sorted((full / "image_0").iterdir())
    times = (full / "times.txt").read_text().split()
    (folder / "image_0").mkdir()
    kept_times = []
    for image, text in zip(images, times, strict=True):
        if _inside(float(text) + offset, begin, end):
            os.link(image, folder / "image_0" / image.name)
            kept_times.append(text)
    (folder / "times.txt").write_text("".join(f"{t}\n" for t in kept_times))
    shutil.copy(full / "calib.yaml", folder / "calib.yaml")
    shutil.copytree(full / "gnss", folder / "gnss")
    cut_rinex_obs(full / "gnss" / "rover.obs", folder / "gnss" / "rover.obs", begin, end)
    _cut_rows(full / "ground_truth.tum", folder / "ground_truth.tum", begin, end, header=0)
    for relative, _ in VEHICLE_FILES.values():
        _cut_rows(full / relative, folder / relative, begin, end)
    shutil.copy(full / "sequence.yaml", folder / "sequence.yaml")
    return folder
