"""What a new user tries: the wrong file for an option, an output that is a file, images that
do not decode, navigation without ephemerides. Each is exit 1 with a message naming the file."""

from __future__ import annotations

from pathlib import Path

import pytest

from vo_doppler.cli import main
from vo_doppler.errors import EXIT_FAILURE

SAMPLE = Path(__file__).resolve().parents[2] / "sample_sequences" / "urban_canyon_small"
OBS, NAV = SAMPLE / "gnss" / "rover.obs", SAMPLE / "gnss" / "brdc.nav"
IMAGES, CALIB, TIMES = SAMPLE / "image_0", SAMPLE / "calib.yaml", SAMPLE / "times.txt"
CAN, DBC = SAMPLE / "can" / "vehicle.log", SAMPLE / "can" / "vehicle.dbc"
TRUTH = SAMPLE / "ground_truth.tum"


@pytest.fixture
def png(tmp_path) -> Path:
    path = tmp_path / "picture.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(256))
    return path


def fails_naming(args: list[str], capsys, *words: str) -> None:
    code = main(args)
    err = capsys.readouterr().err
    assert code == EXIT_FAILURE, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    for word in words:
        assert word in err


CASES = {
    "vo --calib": lambda p, o: ["vo", str(IMAGES), "--calib", p, "--times", str(TIMES), "-o", o],
    "vo --times": lambda p, o: ["vo", str(IMAGES), "--calib", str(CALIB), "--times", p, "-o", o],
    "vo --speed": lambda p, o: [
        "vo",
        str(IMAGES),
        "--calib",
        str(CALIB),
        "--times",
        str(TIMES),
        "--speed",
        p,
        "-o",
        o,
    ],
    "eval estimate": lambda p, o: ["eval", p, str(TRUTH)],
    "eval truth": lambda p, o: ["eval", str(TRUTH), p],
    "correct trajectory": lambda p, o: ["correct", p, "--heading", p, "-o", o + ".tum"],
    "heading --yaw-rate-csv": lambda p, o: [
        "heading",
        str(OBS),
        "--nav",
        str(NAV),
        "--yaw-rate-csv",
        p,
        "--speed-csv",
        p,
        "-o",
        o,
    ],
    "heading --dbc": lambda p, o: [
        "heading",
        str(OBS),
        "--nav",
        str(NAV),
        "--can",
        str(CAN),
        "--dbc",
        p,
        "--yaw-rate",
        "VEHICLE_DYNAMICS.YAW_RATE",
        "--wheel-speed",
        "WHEEL_SPEEDS.WHEEL_SPEED_RL",
        "-o",
        o,
    ],
    "run sequence.yaml": lambda p, o: ["run", p, "-o", o],
}


@pytest.mark.parametrize("case", CASES)
def test_a_png_for_a_text_input_is_named(case, png, tmp_path, capsys):
    args = CASES[case](str(png), str(tmp_path / "out"))
    fails_naming(args, capsys, "picture.png", "PNG image")


def test_correct_heading_png_is_named(png, tmp_path, capsys):
    fails_naming(
        ["correct", str(TRUTH), "--heading", str(png), "-o", str(tmp_path / "c.tum")],
        capsys,
        "picture.png: heading CSV is a PNG image",
    )


def test_simulate_into_an_existing_file_is_refused_at_once(tmp_path, capsys):
    target = tmp_path / "taken"
    target.write_text("keep me")
    fails_naming(
        ["simulate", "--duration", "1", "-o", str(target)], capsys, "the output exists and is not"
    )
    assert target.read_text() == "keep me"


def test_vo_on_images_that_do_not_decode_is_exit_1(tmp_path, capsys):
    images = tmp_path / "images"
    images.mkdir()
    for k in range(5):
        (images / f"{k:06d}.png").write_bytes(b"not an image")
    (tmp_path / "times.txt").write_text("".join(f"{0.1 * k}\n" for k in range(5)))
    fails_naming(
        [
            "vo",
            str(images),
            "--calib",
            str(CALIB),
            "--times",
            str(tmp_path / "times.txt"),
            "-o",
            str(tmp_path / "out"),
        ],
        capsys,
        "only 0 of the 5 images could be decoded",
    )
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("action", ["velocity", "spp"])
def test_gnss_without_a_valid_epoch_is_exit_1(action, tmp_path, capsys):
    nav = tmp_path / "empty.nav"
    header, marker, _ = NAV.read_text().partition("END OF HEADER")
    nav.write_text(header + marker + "\n")
    fails_naming(
        ["gnss", action, str(OBS), "--nav", str(nav), "-o", str(tmp_path / "g.csv")],
        capsys,
        "the navigation file",
        "empty.nav: no ephemeris of the systems 'GREJC'",
        "rover.obs run 2025-03-14 02:10:00",
    )
    assert not (tmp_path / "g.csv").exists()
