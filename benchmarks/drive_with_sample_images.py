"""Give a simulated drive without images (``vo-doppler simulate --no-images``) a camera: the
bundled sample's frames, played forward and back, as hard links at the drive's own image times.

    python benchmarks/drive_with_sample_images.py DRIVE_DIR [--sample DIR]

Rendering a long drive's frames takes hours (0.32 CPU-s a frame: 2.4 CPU-hours for 30 min at
15 Hz); the memory benchmarks need the VO to run on every frame of a long drive, not to see that
drive's own city. The sample's 570 frames are walked 0, 1, …, 569, 568, …, 1, 0, 1, … so the
motion between frames stays continuous (no jump at the turns), and each of the drive's
``times.txt`` rows gets one frame. The drive's manifest gains the sample's ``camera`` section
(its calibration stays the drive's own ``calib.yaml``). The VO's poses are of course not the
drive's: this is for memory and speed, never for accuracy.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np
import yaml

SAMPLE = Path(__file__).resolve().parents[1] / "sample_sequences" / "urban_canyon_small"


def ping_pong(count: int, length: int) -> np.ndarray:
    """Indices 0..length-1 forward, then back, repeated, ``count`` of them."""
    period = 2 * (length - 1)
    phase = np.arange(count) % period
    return np.where(phase < length, phase, period - phase)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("drive", type=Path)
    parser.add_argument("--sample", type=Path, default=SAMPLE)
    args = parser.parse_args(argv)
    manifest_path = args.drive / "sequence.yaml"
    manifest = yaml.safe_load(manifest_path.read_text())
    sample = yaml.safe_load((args.sample / "sequence.yaml").read_text())
    if "camera" in manifest:
        print(f"{args.drive} has a camera already", file=sys.stderr)
        return 1
    camera = dict(sample["camera"])
    times = np.loadtxt(args.drive / camera["times"], ndmin=1)
    frames = sorted((args.sample / camera["images"]).iterdir())
    target = args.drive / camera["images"]
    target.mkdir()
    width = len(str(times.size))
    suffix = frames[0].suffix
    for row, index in enumerate(ping_pong(times.size, len(frames))):
        os.link(frames[index], target / f"{row:0{width}d}{suffix}")
    camera["time_offset_s"] = float(manifest["start_gps_s"]) + (
        float(sample["camera"]["time_offset_s"]) - float(sample["start_gps_s"])
    )
    ordered = {}
    for key, value in manifest.items():
        ordered[key] = value
        if key == "start_gps_s":
            ordered["camera"] = camera
    manifest_path.write_text(yaml.safe_dump(ordered, sort_keys=False))
    print(f"{args.drive}: {times.size} frames linked from {len(frames)} of {args.sample}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
