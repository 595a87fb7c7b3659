"""``vo-doppler run`` on damaged copies of a short generated drive: every case names the file
(and line or key) and the problem, keeps what it could compute, and exits 0 (results, with the
warning in summary.json) or 1 (bad input or failed processing) — never a traceback or a silently
wrong number."""

from __future__ import annotations

import gzip
import json
import logging
import re
import resource
import shutil
from datetime import datetime
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.helpers.staging import cut_off_staging
from vo_doppler.cli import main
from vo_doppler.errors import EXIT_FAILURE, EXIT_OK
from vo_doppler.io.heading_csv import read_heading_csv
from vo_doppler.io.output_folder import RUN, begin_staging, mark_output
from vo_doppler.io.trajectory import read_tum

pytestmark = pytest.mark.xdist_group("short_drive")

OUTPUTS = ("trajectory_vo.tum", "trajectory_corrected.tum", "heading.csv", "summary.json")


@pytest.fixture(scope="module")
def clean(short_drive_folder) -> Path:
    return short_drive_folder


@pytest.fixture(scope="module")
def clean_run(short_drive_run) -> Path:
    return short_drive_run


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


@pytest.mark.slow
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


@pytest.mark.slow
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


@pytest.mark.slow
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


@pytest.mark.slow
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


@pytest.mark.slow
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


@pytest.mark.slow
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


def edit_manifest(folder: Path, section: str | None, key: str, value) -> None:
    path = folder / "sequence.yaml"
    manifest = yaml.safe_load(path.read_text())
    (manifest if section is None else manifest[section])[key] = value
    path.write_text(yaml.safe_dump(manifest))


def failing_run(folder: Path, tmp_path: Path, capsys, *extra: str) -> str:
    """Run, expect exit 1 with one error line and nothing written; the error line."""
    out = tmp_path / "out"
    code = main(["run", str(folder), "-o", str(out), *extra])
    err = capsys.readouterr().err
    assert code == EXIT_FAILURE, err
    assert "Traceback" not in err and not out.exists()
    return err


@pytest.mark.parametrize(
    ("section", "key", "value", "message"),
    [
        ("gnss", "nav", [], "gnss.nav: is an empty list"),
        ("can", "time_offset_s", float("nan"), "can.time_offset_s: nan is not a finite number"),
        ("can", "yaw_rate_sign", 2, "can.yaw_rate_sign: 2 is not +1 or -1"),
        ("origin", "lat_deg", 135.69, "origin.lat_deg: 135.69 is outside [-90, 90]"),
        ("origin", "lon_deg", 200.0, "origin.lon_deg: 200 is outside [-180, 180]"),
        ("origin", "lat_deg", "north", "origin.lat_deg: 'north' is not a number"),
        ("camera", "time_offset_s", "0.5", "camera.time_offset_s: '0.5' is not a number"),
        ("can", "log", ["a.log", "b.log"], "can.log: ['a.log', 'b.log'] is not a path string"),
        ("can", "yaw_rate", ["X.Y"], "can.yaw_rate: ['X.Y'] is not a non-empty string"),
        ("can", "short_frames", "guess", "can.short_frames is 'guess'"),
        ("camera", "times", "/etc/passwd", "camera.times: absolute paths are refused"),
        ("camera", "times", "../../etc/passwd", "camera.times: the path leaves the sequence"),
        ("gnss", "obs", "/dev/zero", "gnss.obs: absolute paths are refused"),
        ("camera", "calib", "image_0", "camera.calib: "),
        ("camera", "calib", "missing.yaml", "camera.calib: "),
    ],
)
def test_bad_manifest_values_name_the_key(clean, tmp_path, capsys, section, key, value, message):
    folder = damaged_copy(clean, tmp_path)
    edit_manifest(folder, section, key, value)
    err = failing_run(folder, tmp_path, capsys)
    assert message in err and "sequence.yaml" in err
    assert "root:" not in err  # never the content of the file a path points at


def test_devices_are_refused_even_when_outside_paths_are_allowed(clean, tmp_path, capsys):
    folder = damaged_copy(clean, tmp_path)
    edit_manifest(folder, "gnss", "obs", "/dev/zero")
    err = failing_run(folder, tmp_path, capsys, "--allow-outside-paths")
    assert "gnss.obs: " in err and "/dev/zero" in err and "not a regular file" in err


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (
            "format: vo-doppler-sequence/1\nname: caf\xe9\n".encode("latin-1"),
            ":2: the sequence manifest is not UTF-8 text (byte 0xE9)",
        ),
        (
            b"a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
            b"c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\n",
            "aliases (*name) are not accepted",
        ),
        (b"\x89PNG\r\n\x1a\n" + bytes(100), "the sequence manifest is a PNG image"),
    ],
)
def test_unreadable_manifests_are_named(clean, tmp_path, capsys, content, message):
    folder = damaged_copy(clean, tmp_path)
    (folder / "sequence.yaml").write_bytes(content)
    err = failing_run(folder, tmp_path, capsys)
    assert "sequence.yaml" in err and message in err


def test_dbc_declaring_rad_s_for_deg_s_data_is_an_error_with_a_hint(clean, tmp_path, capsys):
    folder = damaged_copy(clean, tmp_path)
    dbc = folder / "can" / "vehicle.dbc"
    dbc.write_text(dbc.read_text().replace('[-327.68|327.67] "deg/s"', '[-327.68|327.67] "rad/s"'))
    err = failing_run(folder, tmp_path, capsys)
    assert (
        "CAN signal VEHICLE_DYNAMICS.YAW_RATE (can.yaw_rate): implausibly large for a moving" in err
    )
    assert "the values look like deg/s: the DBC declares the signal in rad/s: fix the unit" in err


def test_block_of_can_frames_five_seconds_early_is_an_error(clean, tmp_path, capsys):
    folder = damaged_copy(clean, tmp_path)
    log_path = folder / "can" / "vehicle.log"
    lines = log_path.read_text().splitlines(keepends=True)
    for i in range(1000, 1200):
        stamp, rest = lines[i][1:].split(")", 1)
        lines[i] = f"({float(stamp) - 5.0:.6f}){rest}"
    log_path.write_text("".join(lines))
    err = failing_run(folder, tmp_path, capsys)
    assert re.search(
        r"vehicle\.log:100[12]: time goes backwards by 4\.9\d* s in the CAN message", err
    )


@pytest.mark.parametrize(
    ("calib", "message"),
    [
        ((r"fx: ([0-9.]+)", r"fx: -\1"), "focal lengths must be positive"),
        ((r"- - 0.0\n  - 0.0\n  - 1.0", "- - 0.0\n  - 0.0\n  - 2.0"), "not a rigid transform"),
    ],
)
def test_impossible_calibration_is_an_error(clean, tmp_path, capsys, calib, message):
    folder = damaged_copy(clean, tmp_path)
    path = folder / "calib.yaml"
    pattern, replacement = calib
    text = path.read_text()
    damaged = re.sub(pattern, replacement, text, count=1)
    assert damaged != text
    path.write_text(damaged)
    err = failing_run(folder, tmp_path, capsys)
    assert "calib.yaml: " in err and message in err


def test_output_that_is_a_file_fails_before_any_work(tmp_path, capsys):
    target = tmp_path / "results"
    target.write_text("a file")
    code = main(["run", str(tmp_path / "no_such_sequence"), "-o", str(target)])
    err = capsys.readouterr().err
    assert code == EXIT_FAILURE
    assert "results: the output exists and is not a folder" in err  # before reading the input
    assert target.read_text() == "a file"


def tree(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` with its bytes (to see that nothing was touched)."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


@pytest.mark.parametrize(
    ("output", "cwd", "message"),
    [
        ("par/seq", ".", "par/seq: the output folder is the input par/seq"),
        ("par", ".", "par: the output folder contains the input par/seq"),
        ("par/seq/gnss", ".", "par/seq/gnss: the output folder contains the input par/seq/gnss"),
        ("par/seq/out", ".", "par/seq/out: the output folder is inside the input folder par/seq"),
        ("orbits", ".", "orbits: the output folder contains the input par/seq/../../orbits/x.sp3"),
        (
            "other",
            ".",
            "other: the output folder is not empty and was not written by 'vo-doppler "
            "run' or 'vo-doppler batch'; choose a new or empty folder",
        ),
        (".", "empty", ".: the output folder is the current directory or contains it"),
        ("..", "empty", "..: the output folder contains the input ../par/seq"),
    ],
)
def test_run_refuses_its_inputs_the_current_directory_and_a_folder_it_did_not_write(
    tmp_path, capsys, monkeypatch, output, cwd, message
):
    """The QA report's cases (`run selfrun -o selfrun`, `run par/seq -o par`, `-o other` with
    notes in it, `-o .`), the manifest's inputs and a folder inside the sequence's (issue 30:
    `run par/seq -o par/seq/out` was accepted), refused before any reading with nothing
    touched."""
    sequence = tmp_path / "par" / "seq"
    (sequence / "gnss").mkdir(parents=True)
    (sequence / "gnss" / "rover.obs").write_text("observations")
    (tmp_path / "orbits").mkdir()
    (tmp_path / "orbits" / "x.sp3").write_text("orbits")
    (sequence / "sequence.yaml").write_text(
        "format: vo-doppler-sequence/1\ngnss: {obs: gnss/rover.obs, orbits: ../../orbits/x.sp3}\n"
    )
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "notes.txt").write_text("precious")
    (tmp_path / "empty").mkdir()
    before = tree(tmp_path)
    monkeypatch.chdir(tmp_path / cwd)
    seq = "par/seq" if cwd == "." else "../par/seq"
    code = main(["run", seq, "-o", output, "--allow-outside-paths"])
    err = capsys.readouterr().err
    assert code == EXIT_FAILURE
    assert f"vo-doppler run: error: {message}" in err
    assert tree(tmp_path) == before
    assert sorted(p.name for p in (tmp_path / "empty").iterdir()) == []


@pytest.mark.slow
def test_failed_run_keeps_the_previous_results_and_says_so(clean, clean_run, tmp_path, caplog):
    folder = damaged_copy(clean, tmp_path)
    edit_manifest(folder, "can", "time_offset_s", float("inf"))
    out = tmp_path / "previous"
    shutil.copytree(clean_run, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    with caplog.at_level(logging.INFO):
        assert main(["run", str(folder), "-o", str(out)]) == EXIT_FAILURE
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert f"nothing written: {out} left as it was" in caplog.text
    assert not [p for p in tmp_path.iterdir() if ".partial-" in p.name]


@pytest.mark.slow
def test_duplicated_can_frames_and_a_distant_origin_are_warned_and_stale_files_go(
    clean, clean_run, tmp_path, caplog
):
    """Stale files go: an earlier run's figure in the output, and the staging folder of a run
    into it that was killed (while that of a run still writing stays)."""
    folder = damaged_copy(clean, tmp_path)
    log_path = folder / "can" / "vehicle.log"
    lines = log_path.read_text().splitlines(keepends=True)
    wheel = [i for i, line in enumerate(lines) if "1A0#" in line][200:210]
    for i in reversed(wheel):
        head, payload = lines[i].rstrip("\n").split("#")
        lines.insert(i + 1, f"{head}#{payload[:-2]}{(int(payload[-2:], 16) ^ 0xFF):02X}\n")
    log_path.write_text("".join(lines))
    manifest = yaml.safe_load((folder / "sequence.yaml").read_text())
    edit_manifest(folder, "origin", "lat_deg", manifest["origin"]["lat_deg"] + 0.2)  # 22 km
    out = tmp_path / "out"
    shutil.copytree(clean_run, out)
    (out / "stale_figure.png").write_bytes(b"old")
    mark_output(out, RUN)  # an earlier run wrote it
    killed, writing = cut_off_staging(out), begin_staging(out, RUN)
    with caplog.at_level(logging.INFO):
        assert main(["run", str(folder), "-o", str(out)]) == EXIT_OK
    assert not (out / "stale_figure.png").exists()
    assert not killed.exists() and writing.is_dir()
    assert_full_outputs(out, n_images(folder))
    summary = json.loads((out / "summary.json").read_text())
    counts = summary["time_order"]["CAN message WHEEL_SPEEDS"]
    assert counts["conflicting_duplicates"] == 10 and counts["out_of_order"] == 0
    assert any(
        "CAN message WHEEL_SPEEDS: 10 duplicate timestamps with different values" in w
        for w in summary["warnings"]
    )
    assert (
        summary["can_clock_residual_offset_s"] is None
        or abs(summary["can_clock_residual_offset_s"]) < 0.2
    )


def rinex_case(clean: Path, tmp_path: Path, damage) -> Path:
    folder = damaged_copy(clean, tmp_path)
    obs = folder / "gnss" / "rover.obs"
    text = obs.read_text()
    end = text.index("\n", text.index("END OF HEADER")) + 1
    header, body = text[:end], text[end:]
    blocks = ["> " + block for block in body.split("> ") if block]
    obs.write_text(damage(header, blocks))
    return folder


def _swap_epochs(header, blocks):
    blocks[50], blocks[60] = blocks[60], blocks[50]
    return header + "".join(blocks)


def _duplicate_epochs(header, blocks):
    return header + "".join(blocks[:80] + blocks[60:80] + blocks[80:])


def _no_satellites(header, blocks):
    return header + "".join(b.splitlines()[0][:-3] + "  0\n" for b in blocks)


@pytest.mark.parametrize("damage", [_swap_epochs, _duplicate_epochs, _no_satellites])
def test_damaged_rinex_content_is_exit_1_naming_the_file(clean, tmp_path, capsys, damage):
    folder = rinex_case(clean, tmp_path, damage)
    code = main(["run", str(folder), "-o", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == EXIT_FAILURE and "rover.obs" in err and "Traceback" not in err


def _month_13(header, blocks):
    blocks[40] = blocks[40].replace("> 2025 03 14", "> 2025 13 14", 1)
    return header + "".join(blocks)


def _garbage_glonass_slot(header, blocks):
    line = f"{'  9 R01 @@ R02 xx':60}GLONASS SLOT / FRQ #\n"
    at = header.index(f"{'':60}END OF HEADER")
    return header[:at] + line + header[at:] + "".join(blocks)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("damage", "warning"),
    [
        (_month_13, r"rover\.obs:\d+: epoch date unusable \(month 13\): skipped"),
        (
            _garbage_glonass_slot,
            r"rover\.obs:\d+: unreadable GLONASS slot/channel 'R01 @@ R02 xx' ignored",
        ),
    ],
)
def test_one_unusable_rinex_record_is_skipped_and_warned_in_the_summary(
    clean, tmp_path, caplog, damage, warning
):
    """Policy: a record the reader cannot use (an epoch with an impossible calendar value, a
    header line it cannot read) is skipped, the run goes on without it (exit 0) and the warning,
    naming the file and line, is in the log and in summary.json."""
    folder = rinex_case(clean, tmp_path, damage)
    code, out = run(folder, tmp_path, caplog)
    assert code == EXIT_OK
    assert_full_outputs(out, n_images(folder))
    assert re.search(warning, caplog.text)
    summary = json.loads((out / "summary.json").read_text())
    assert any(re.search(warning, w) for w in summary["warnings"]), summary["warnings"]


def test_gzip_bomb_as_the_observation_file_is_exit_1_without_filling_memory(
    clean, tmp_path, capsys
):
    """2 MB of gzip (50 members of 40 MB of zeros: 2 GB expanded) refused after 80 MB."""
    folder = damaged_copy(clean, tmp_path)
    member = gzip.compress(b"0" * 40_000_000, compresslevel=9)
    bomb = folder / "gnss" / "rover.obs.gz"
    bomb.write_bytes(member * (2_000_000 // len(member)))
    edit_manifest(folder, "gnss", "obs", "gnss/rover.obs.gz")
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    err = failing_run(folder, tmp_path, capsys)
    assert "rover.obs.gz" in err and "decompressed data exceed" in err
    assert (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024 < 500


def test_can_times_missing_the_gnss_epochs_are_an_error_before_any_work(clean, tmp_path, capsys):
    folder = damaged_copy(clean, tmp_path)
    edit_manifest(folder, "can", "time_offset_s", 0.0)  # the log's own clock
    err = failing_run(folder, tmp_path, capsys)
    assert "error: the CAN wheel-speed times (" in err
    assert "do not overlap the GNSS epochs" in err and "the manifest's time_offset_s" in err


@pytest.mark.slow
def test_can_clock_off_by_most_of_a_second_is_warned_with_the_fix(tmp_path, caplog):
    folder = tmp_path / "drive"
    simulate = ["simulate", "--duration", "30", "--seed", "1", "--no-images", "-o", str(folder)]
    assert main(simulate) == EXIT_OK  # with reflected signals (default)
    offset = yaml.safe_load((folder / "sequence.yaml").read_text())["can"]["time_offset_s"]
    edit_manifest(folder, "can", "time_offset_s", offset + 0.8)
    code, out = run(folder, tmp_path, caplog)
    assert code == EXIT_OK
    summary = json.loads((out / "summary.json").read_text())
    assert summary["can_clock_residual_offset_s"] == pytest.approx(-0.8, abs=0.1)
    warning = next(w for w in summary["warnings"] if w.startswith("CAN clock"))
    suggested = float(re.search(r"should be about (-?[\d.]+) s", warning).group(1))
    assert suggested == pytest.approx(offset, abs=0.1)


@pytest.fixture(scope="module")
def turning(turning_drive_folder) -> Path:
    """20 s without images, with one left turn of 90° (the QA report's ``s1``); tests damage a
    copy."""
    return turning_drive_folder


@pytest.mark.slow
def test_a_yaw_rate_sign_flipped_in_the_manifest_is_an_error_naming_the_setting(
    turning, tmp_path, capsys
):
    folder = damaged_copy(turning, tmp_path)
    edit_manifest(folder, "can", "yaw_rate_sign", -1)
    err = failing_run(folder, tmp_path, capsys)
    assert "CAN signal VEHICLE_DYNAMICS.YAW_RATE (can.yaw_rate): wrong sign: over 1 turn(s)" in err
    assert f"set can.yaw_rate_sign in {folder / 'sequence.yaml'} to 1 (it is -1)" in err
