"""``vo-doppler run`` on damaged copies of a short generated drive: every case names the file
and the problem, keeps what it could compute, and exits 0 (results) or 1 (runtime failure)."""

from __future__ import annotations

import json
import logging
import shutil
from datetime import datetime
from pathlib import Path

import numpy as np
import pytest

from vo_doppler.cli import main
from vo_doppler.io.heading_csv import read_heading_csv
from vo_doppler.io.trajectory import read_tum
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon

OUTPUTS = ("trajectory_vo.tum", "trajectory_corrected.tum", "heading.csv", "summary.json")


@pytest.fixture(scope="module")
def clean(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("bad_input") / "clean"
    simulate_urban_canyon(folder, UrbanCanyonConfig(duration_s=10.0, seed=4, image_size=(320, 180)))
    return folder


@pytest.fixture(scope="module")
def clean_run(clean, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("clean_run")
    assert main(["run", str(clean), "-o", str(out)]) == 0
    return out


def damaged_copy(clean: Path, tmp_path: Path) -> Path:
    folder = tmp_path / "damaged"
    shutil.copytree(clean, folder)
    return folder


def run(folder: Path, tmp_path: Path, caplog) -> tuple[int, Path]:
    out = tmp_path / "out"
    with caplog.at_level(logging.INFO):
        code = main(["run", str(folder), "-o", str(out)])
    return code, out


def assert_full_outputs(out: Path, n_images: int) -> None:
    for name in OUTPUTS:
        assert (out / name).stat().st_size > 0, name
    corrected = read_tum(out / "trajectory_corrected.tum")
    assert len(corrected) == n_images
    assert np.all(np.isfinite(corrected.positions))


def n_images(folder: Path) -> int:
    return len(list((folder / "image_0").iterdir()))


def epoch_seconds(header: str) -> float:
    year, month, day, hour, minute = (int(v) for v in header[1:].split()[:5])
    second = float(header[1:].split()[5])
    return datetime(year, month, day, hour, minute).timestamp() + second


def test_truncated_rinex_keeps_the_epochs_before_the_cut(clean, clean_run, tmp_path, caplog):
    folder = damaged_copy(clean, tmp_path)
    obs = folder / "gnss" / "rover.obs"
    text = obs.read_text()
    cut = int(0.6 * len(text))
    cut = text.index("\n", text.index("\n", cut) + 1) + 7  # inside a satellite line
    obs.write_text(text[:cut])
    code, out = run(folder, tmp_path, caplog)
    assert code == 0
    assert_full_outputs(out, n_images(folder))
    assert "rover.obs:" in caplog.text
    clean_table = read_heading_csv(clean_run / "heading.csv")
    table = read_heading_csv(out / "heading.csv")
    assert 0.5 * len(clean_table) < len(table) < 0.7 * len(clean_table)
    np.testing.assert_array_equal(table.t, clean_table.t[: len(table)])


def test_gnss_outage_leaves_a_gap_without_heading(clean, tmp_path, caplog):
    folder = damaged_copy(clean, tmp_path)
    obs = folder / "gnss" / "rover.obs"
    text = obs.read_text()
    end = text.index("\n", text.index("END OF HEADER")) + 1
    header, body = text[:end], text[end:]
    blocks = ["> " + block for block in body.split("> ") if block]
    start = epoch_seconds(blocks[0])
    kept = [b for b in blocks if not 3.0 <= epoch_seconds(b) - start < 6.0]
    assert len(blocks) - len(kept) == 60  # 3 s at 20 Hz
    obs.write_text(header + "".join(kept))
    code, out = run(folder, tmp_path, caplog)
    assert code == 0
    assert_full_outputs(out, n_images(folder))
    table = read_heading_csv(out / "heading.csv")
    gap = (table.t - table.t[0] >= 3.0) & (table.t - table.t[0] < 6.0)
    assert not np.any(table.tc_available[gap])


def test_short_can_frames_are_skipped_and_named(clean, tmp_path, caplog):
    folder = damaged_copy(clean, tmp_path)
    log_path = folder / "can" / "vehicle.log"
    lines = log_path.read_text().splitlines(keepends=True)
    wheel_lines = [i for i, line in enumerate(lines) if "1A0#" in line][100:103]
    for i in wheel_lines:
        head, payload = lines[i].rstrip("\n").split("#")
        lines[i] = f"{head}#{payload[:8]}\n"
    log_path.write_text("".join(lines))
    code, out = run(folder, tmp_path, caplog)
    assert code == 0
    assert_full_outputs(out, n_images(folder))
    assert "vehicle.log: 3 frames shorter than their DBC length skipped" in caplog.text
    assert "id 0x1A0, 4 of 8 bytes" in caplog.text


def test_unreadable_image_is_flagged_and_bridged(clean, clean_run, tmp_path, caplog):
    folder = damaged_copy(clean, tmp_path)
    image = sorted((folder / "image_0").iterdir())[40]
    image.write_bytes(b"not an image")
    code, out = run(folder, tmp_path, caplog)
    assert code == 0
    assert_full_outputs(out, n_images(folder))
    assert f"{image.name}: cannot decode image" in caplog.text
    summary = json.loads((out / "summary.json").read_text())
    clean_summary = json.loads((clean_run / "summary.json").read_text())
    assert summary["vo_flagged_frames"] > clean_summary["vo_flagged_frames"]


def test_navigation_without_ephemerides_keeps_the_vo_and_fails(clean, tmp_path, caplog, capsys):
    folder = damaged_copy(clean, tmp_path)
    nav = folder / "gnss" / "brdc.nav"
    header, marker, _ = nav.read_text().partition("END OF HEADER")
    nav.write_text(header + marker + "\n")
    code, out = run(folder, tmp_path, caplog)
    assert code == 1
    assert "unavailable at every epoch" in capsys.readouterr().err
    assert "no healthy ephemeris" in caplog.text
    vo = read_tum(out / "trajectory_vo.tum")
    assert len(vo) == n_images(folder) and np.all(np.isfinite(vo.positions))


def test_can_log_ending_early_keeps_the_vo_scale(clean, clean_run, tmp_path, caplog):
    folder = damaged_copy(clean, tmp_path)
    log_path = folder / "can" / "vehicle.log"
    lines = log_path.read_text().splitlines(keepends=True)
    log_path.write_text("".join(lines[: int(0.7 * len(lines))]))
    code, out = run(folder, tmp_path, caplog)
    assert code == 0
    assert_full_outputs(out, n_images(folder))
    assert "outside the speed record" in caplog.text
    summary = json.loads((out / "summary.json").read_text())
    clean_summary = json.loads((clean_run / "summary.json").read_text())
    vo, clean_vo = summary["evaluation"]["vo"], clean_summary["evaluation"]["vo"]
    assert (
        vo["final_position_error_m"]
        < clean_vo["final_position_error_m"] + 0.02 * vo["path_length_m"]
    )


def test_unknown_short_frames_policy_is_named(clean, tmp_path, caplog, capsys):
    folder = damaged_copy(clean, tmp_path)
    manifest = folder / "sequence.yaml"
    manifest.write_text(manifest.read_text().replace("can:\n", "can:\n  short_frames: guess\n"))
    code, _ = run(folder, tmp_path, caplog)
    assert code == 1
    assert "can.short_frames is 'guess'" in capsys.readouterr().err
