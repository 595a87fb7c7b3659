"""Option values outside their physical domain are usage errors (exit 2) naming the option,
caught by argparse before any file is read: the QA report's cases, which exited 1 or 3 or
were accepted."""

from __future__ import annotations

import pytest

from vo_doppler.cli import main

GNSS = ["gnss", "velocity", "r.obs", "--nav", "r.nav", "-o", "v.csv"]
HEADING = ["heading", "r.obs", "--nav", "r.nav", "--speed-csv", "s.csv", "-o", "h.csv"]
HEADING += ["--yaw-rate-csv", "y.csv"]
DEADRECKON = ["deadreckon", "--gyro1", "a.csv", "--gyro2", "b.csv", "--gps", "g.csv", "-o", "d"]
SIMULATE = ["simulate", "--no-images", "-o", "sim"]
CORRECT = ["correct", "t.tum", "--heading", "h.csv", "-o", "c.tum"]
RUN = ["run", "seq", "-o", "out"]
VO = ["vo", "images", "--calib", "c.yaml", "-o", "out"]
BATCH = ["batch", "seq", "-o", "out"]


@pytest.mark.parametrize(
    ("argv", "option"),
    [
        ([*GNSS, "--elev-mask", "95"], "--elev-mask"),
        ([*GNSS, "--elev-mask", "nan"], "--elev-mask"),
        ([*GNSS, "--elev-mask", "-10"], "--elev-mask"),
        ([*GNSS, "--bands", "x"], "--bands"),
        ([*HEADING, "--window-s", "-1"], "--window-s"),
        ([*HEADING, "--window-s", "0"], "--window-s"),
        ([*HEADING, "--wheel-scale", "-1"], "--wheel-scale"),
        ([*HEADING, "--gyro-bias", "nan"], "--gyro-bias"),
        ([*HEADING, "--systems", "XZ"], "--systems"),
        ([*DEADRECKON, "--cluster-m", "-1"], "--cluster-m"),
        ([*DEADRECKON, "--threshold", "-1"], "--threshold"),
        ([*DEADRECKON, "--tau", "-5"], "--tau"),
        ([*DEADRECKON, "--straight", "nan,5"], "--straight"),
        ([*SIMULATE, "--duration", "1e9"], "--duration"),
        ([*SIMULATE, "--duration", "-5"], "--duration"),
        ([*SIMULATE, "--duration", "nan"], "--duration"),
        ([*SIMULATE, "--max-speed", "-3"], "--max-speed"),
        ([*SIMULATE, "--gnss-rate", "0"], "--gnss-rate"),
        ([*SIMULATE, "--systems", "XZ"], "--systems"),
        ([*SIMULATE, "--fps", "1e9"], "--fps"),
        ([*SIMULATE, "--fps", "0"], "--fps"),
        ([*SIMULATE, "--start", "2025-13-01"], "--start"),
        ([*CORRECT, "--window-s", "0"], "--window-s"),
        ([*CORRECT, "--max-gap-s", "0"], "--max-gap-s"),
        ([*RUN, "--elev-mask", "nan"], "--elev-mask"),
        ([*RUN, "--elev-mask", "90"], "--elev-mask"),
        ([*RUN, "--systems", "X"], "--systems"),
        ([*BATCH, "--elev-mask", "-1"], "--elev-mask"),
        ([*VO, "--fps", "nan"], "--fps"),
        ([*VO, "--fps", "inf"], "--fps"),
        ([*VO, "--fps", "0"], "--fps"),
        ([*VO, "--fps", "1e6"], "--fps"),
    ],
)
def test_out_of_domain_option_is_exit_2_naming_it(argv, option, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    assert f"argument {option}" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
