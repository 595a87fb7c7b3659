"""``vo-doppler eval gnss``: the table, the JSON, and the exit codes (0 scored, 1 inputs that do
not overlap or cannot be read, 2 usage); ``eval EST GT`` unchanged beside it."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.conftest import require_shared
from tests.helpers.heading_table import plain_heading_table
from tests.helpers.velocity import velocity_solution
from vo_doppler.cli import main
from vo_doppler.errors import EXIT_FAILURE, EXIT_OK, EXIT_USAGE
from vo_doppler.geo import EnuFrame, course_to_yaw, ecef_to_geodetic
from vo_doppler.io.gnss_csv import write_spp_csv, write_velocity_csv
from vo_doppler.io.heading_csv import write_heading_csv
from vo_doppler.io.trajectory import write_tum
from vo_doppler.io.truth_csv import read_ground_truth
from vo_doppler.model.gnss_solutions import SppSolution
from vo_doppler.model.trajectory import Trajectory

T0 = 1.24e9
ORIGIN = EnuFrame(np.radians(22.3), np.radians(114.18), 5.0)
COURSE_DEG = 60.0


def drive(t: np.ndarray) -> np.ndarray:
    """ENU positions of a straight drive at 10 m/s along COURSE_DEG."""
    c = np.radians(COURSE_DEG)
    d = 10.0 * (t - t[0])
    return np.column_stack([d * np.sin(c), d * np.cos(c), np.zeros(t.size)])


def velocities(n: int, course_deg: float, speed: float = 10.0) -> np.ndarray:
    c = np.radians(course_deg)
    return np.tile([speed * np.sin(c), speed * np.cos(c), 0.0], (n, 1))


@pytest.fixture
def files(tmp_path):
    """A 60-s truth (lat/lon CSV with gps_time_s, and the same as TUM), vel.csv with a 2°
    course offset, heading.csv with a 1° offset, pos.csv 5 m east of the truth."""
    t = T0 + np.arange(61.0)
    enu = drive(t)
    lat, lon, h = ecef_to_geodetic(ORIGIN.enu_to_ecef(enu))
    lat, lon = np.degrees(lat), np.degrees(lon)
    truth = tmp_path / "truth.csv"
    rows = [f"{a:.3f},{b:.10f},{c:.10f},{d:.4f}" for a, b, c, d in zip(t, lat, lon, h, strict=True)]
    truth.write_text("gps_time_s,lat_deg,lon_deg,height_m\n" + "\n".join(rows) + "\n")
    tum = tmp_path / "truth.tum"
    write_tum(tum, Trajectory(t, enu, Rotation.identity(t.size)))
    epochs = t[:-1] + 0.5
    vel = tmp_path / "vel.csv"
    write_velocity_csv(vel, _solution(epochs, velocities(epochs.size, COURSE_DEG + 2.0)))
    heading = tmp_path / "heading.csv"
    yaw = np.full(epochs.size, course_to_yaw(np.radians(COURSE_DEG - 1.0)))
    write_heading_csv(heading, plain_heading_table(epochs, yaw_tc=yaw, yaw_conv=yaw))
    pos = tmp_path / "pos.csv"
    ecef = ORIGIN.enu_to_ecef(drive(np.r_[t[0], epochs])[1:] + np.array([5.0, 0.0, 0.0]))
    n = epochs.size
    ones = np.ones(n, dtype=bool)
    write_spp_csv(
        pos,
        SppSolution(
            epochs,
            ecef,
            {},
            np.full(n, 8),
            np.ones(n),
            np.ones(n),
            ones,
            0,
            ones,
            np.ones(n),
            np.ones(n),
        ),
    )
    return {"truth": truth, "tum": tum, "vel": vel, "heading": heading, "pos": pos}


def _solution(t, enu):
    n = t.size
    return velocity_solution(
        t,
        enu,
        verified=np.ones(n, dtype=bool),
        speed_sigma_mps=np.full(n, 0.1),
        course_sigma_rad=np.full(n, 0.01),
    )


def test_scores_every_output_and_writes_json(files, tmp_path, capsys):
    out = tmp_path / "scores" / "gnss.json"
    code = main(
        ["eval", "gnss", "--truth", str(files["truth"]), "--vel", str(files["vel"]),
         "--heading", str(files["heading"]), "--pos", str(files["pos"]), "--json", str(out)]
    )  # fmt: skip
    assert code == EXIT_OK
    printed = capsys.readouterr().out
    assert "course error" in printed and "tight, reliable" in printed and "vel.csv" in printed
    figures = json.loads(out.read_text())
    course = figures["velocity"]["course_error_deg"]
    assert course["median"] == pytest.approx(2.0, abs=1e-3)
    assert course["max"] == pytest.approx(2.0, abs=1e-3)
    assert course["beyond_5"] == 0 and figures["velocity"]["availability"] == 1.0
    assert figures["heading"]["tight"]["error_deg"]["p95"] == pytest.approx(1.0, abs=1e-3)
    assert figures["positions"]["horizontal_error_m"]["median"] == pytest.approx(5.0, abs=1e-3)
    assert figures["velocity"]["coverage"]["scored"] == 60
    assert figures["files"]["velocity"] == str(files["vel"])
    assert figures["thresholds"]["moving_mps"] == 3.0


def test_tum_truth_with_an_origin_scores_positions(files, tmp_path):
    out = tmp_path / "gnss.json"
    origin = "22.3,114.18,5.0"
    args = ["eval", "gnss", "--truth", str(files["tum"]), "--pos", str(files["pos"])]
    assert main([*args, "--origin", origin, "--json", str(out)]) == EXIT_OK
    horizontal = json.loads(out.read_text())["positions"]["horizontal_error_m"]
    assert horizontal["p95"] == pytest.approx(5.0, abs=1e-3)
    assert main(args) == EXIT_FAILURE  # no origin: positions cannot be compared


def test_truth_and_origin_from_a_sequence_folder(files, tmp_path):
    folder = tmp_path / "seq"
    folder.mkdir()
    (folder / "gt.tum").write_bytes(files["tum"].read_bytes())
    (folder / "sequence.yaml").write_text(
        "format: vo-doppler-sequence/1\n"
        "origin: {lat_deg: 22.3, lon_deg: 114.18, height_m: 5.0}\n"
        "ground_truth: {trajectory: gt.tum}\n"
    )
    out = tmp_path / "gnss.json"
    args = ["eval", "gnss", "--sequence", str(folder), "--pos", str(files["pos"])]
    assert main([*args, "--json", str(out)]) == EXIT_OK
    assert json.loads(out.read_text())["truth"]["source"] == "TUM"


def test_outputs_outside_the_truth_exit_1_naming_the_file(files, tmp_path, capsys):
    later = tmp_path / "later_vel.csv"
    t = T0 + 1000.0 + np.arange(10.0)
    write_velocity_csv(later, _solution(t, velocities(10, COURSE_DEG)))
    code = main(["eval", "gnss", "--truth", str(files["truth"]), "--vel", str(later)])
    assert code == EXIT_FAILURE
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "later_vel.csv" in err and "none of its 10 epochs" in err and "span" in err


def test_unreadable_inputs_exit_1_naming_the_file(files, tmp_path, capsys):
    missing = tmp_path / "missing.csv"
    assert main(["eval", "gnss", "--truth", str(missing), "--vel", str(files["vel"])]) == 1
    assert "missing.csv" in capsys.readouterr().err
    bad = tmp_path / "bad_vel.csv"
    bad.write_text("gps_time_s,ve,vn,vu,valid\n1,x,0,0,1\n")
    assert main(["eval", "gnss", "--truth", str(files["truth"]), "--vel", str(bad)]) == 1
    assert "bad_vel.csv:2" in capsys.readouterr().err


@pytest.mark.parametrize(
    "args",
    [
        ["--truth", "T"],  # no output to score
        ["--vel", "V"],  # no truth
        ["--truth", "T", "--vel", "V", "--standstill-mps", "4", "--moving-mps", "3"],
        ["--truth", "T", "--vel", "V", "--origin", "95,0,0"],
        ["--truth", "T", "--vel", "V", "--origin", "1,2,3", "--sequence", "S"],
        ["--truth", "T", "--vel", "V", "--moving-mps", "-1"],
        ["--truth", "T", "--vel", "V", "extra"],
    ],
)
def test_usage_errors_exit_2(args, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["eval", "gnss", *args])
    assert stop.value.code == EXIT_USAGE
    assert "usage: vo-doppler eval gnss" in capsys.readouterr().err


def test_help_of_both_modes(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["eval", "gnss", "--help"])
    assert stop.value.code == EXIT_OK
    text = capsys.readouterr().out
    assert "--truth" in text and "--standstill-mps" in text and "(default: 3.0)" in text
    with pytest.raises(SystemExit):
        main(["eval", "--help"])
    assert "eval gnss" in capsys.readouterr().out


def test_the_trajectory_evaluation_is_unchanged(files, capsys):
    assert main(["eval", str(files["tum"]), str(files["tum"]), "--json"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out)["ate_rmse_m"] == pytest.approx(0.0, abs=1e-9)


def test_hong_kong_truth_against_its_own_velocity_turned_two_degrees(tmp_path):
    """The real 1 Hz canyon truth: a vel.csv made of the truth's own central-difference
    velocity turned by 2° at the truth's epochs scores 2.0° on every moving epoch."""
    path = require_shared("hk_tst_canyon_drive/groundTruth_TST_first_half.csv")
    truth = read_ground_truth(path)
    velocity = np.gradient(truth.enu, truth.t, axis=0)
    turn = np.radians(2.0)
    rotated = velocity.copy()  # clockwise by 2°: the course grows by 2°
    rotated[:, 0] = velocity[:, 0] * np.cos(turn) + velocity[:, 1] * np.sin(turn)
    rotated[:, 1] = -velocity[:, 0] * np.sin(turn) + velocity[:, 1] * np.cos(turn)
    vel = tmp_path / "vel.csv"
    write_velocity_csv(vel, _solution(truth.t, rotated))
    out = tmp_path / "gnss.json"
    assert main(["eval", "gnss", "--truth", str(path), "--vel", str(vel), "--json", str(out)]) == 0
    figures = json.loads(out.read_text())["velocity"]
    assert figures["coverage"]["scored"] == len(truth)
    assert figures["coverage"]["moving"] > 100
    course = figures["course_error_deg"]
    assert course["median"] == pytest.approx(2.0, abs=0.01)
    assert course["max"] == pytest.approx(2.0, abs=0.01)
    assert figures["speed_error_mps"]["max"] < 0.01


def test_every_gnss_option_has_help_and_its_default():
    from tests.cli.test_help import _options
    from vo_doppler.commands.eval_command import gnss_parser
    from vo_doppler.commands.help_format import has_default, shown_default

    parser = gnss_parser("vo-doppler eval gnss")
    for action in _options(parser):
        assert action.help, action.option_strings
        rendered = parser._get_formatter()._expand_help(action)
        if has_default(action):
            assert rendered.count(f"(default: {shown_default(action.default)})") == 1


def test_the_json_may_not_replace_an_input(files, capsys):
    args = ["eval", "gnss", "--truth", str(files["truth"]), "--vel", str(files["vel"])]
    assert main([*args, "--json", str(files["vel"])]) == EXIT_FAILURE
    assert "would destroy the input" in capsys.readouterr().err
    assert files["vel"].read_text().startswith("gps_time_s,")
