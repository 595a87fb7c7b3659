"""``report.html`` in a real headless browser (Chromium): it renders offline, its script runs
(the map's scale bar is drawn), no console message at all, and a screenshot is taken. Skips,
saying why, where no Chromium is installed (``apt-get install chromium``)."""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tests.helpers.images import distinct_colours

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("short_drive")]

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
WIDTH, HEIGHT = 1280, 4000


@pytest.fixture(scope="session")
def browser() -> str:
    found = next((path for path in map(shutil.which, BROWSERS) if path), None)
    if found is None:
        pytest.skip(f"no headless browser installed (looked for {', '.join(BROWSERS)})")
    return found


def headless(browser: str, profile: Path, page: Path, *options: str) -> subprocess.CompletedProcess:
    """Run the browser headless on ``page`` offline (every host name fails to resolve), with
    its console messages logged to stderr.

    The browser runs detached (its shell exits at once, so init reaps it): its memory never
    counts among this process's children (``RUSAGE_CHILDREN``), which other tests measure."""
    command = [
        browser,
        "--headless",
        "--disable-gpu",
        f"--user-data-dir={profile}",
        "--host-resolver-rules=MAP * ~NOTFOUND",
        "--enable-logging=stderr",
        "--v=0",
        "--virtual-time-budget=3000",
        *(["--no-sandbox"] if os.geteuid() == 0 else []),
        *options,
        page.as_uri(),
    ]
    out, err, code = (profile.parent / f"browser.{name}" for name in ("out", "err", "rc"))
    code.unlink(missing_ok=True)
    detached = f"({shlex.join(command)} >{shlex.quote(str(out))} 2>{shlex.quote(str(err))}; "
    detached += f"echo $? >{shlex.quote(str(code))}.tmp; mv {shlex.quote(str(code))}.tmp "
    detached += f"{shlex.quote(str(code))}) &"
    subprocess.run(["sh", "-c", detached], check=True)
    deadline = time.monotonic() + 180.0
    while not code.exists():
        assert time.monotonic() < deadline, "the browser did not finish within 180 s"
        time.sleep(0.2)
    return subprocess.CompletedProcess(
        command, int(code.read_text()), out.read_text(), err.read_text()
    )


def console_messages(stderr: str) -> list[str]:
    """The page's console lines Chromium logged (``…:CONSOLE…] "message", source: …``)."""
    return [line for line in stderr.splitlines() if ":CONSOLE" in line]


def test_report_renders_offline_without_console_messages(browser, run_report, tmp_path):
    shot = tmp_path / "report.png"
    result = headless(
        browser,
        tmp_path / "profile",
        run_report / "report.html",
        f"--screenshot={shot}",
        f"--window-size={WIDTH},{HEIGHT}",
        "--hide-scrollbars",
    )
    assert shot.is_file(), result.stderr[-2000:]
    assert console_messages(result.stderr) == []
    image = np.asarray(Image.open(shot).convert("RGB"))
    assert image.shape == (HEIGHT, WIDTH, 3)
    # Not a blank page: text, tables and figures give many distinct colours.
    assert distinct_colours(image) > 500


def test_report_script_draws_the_map_controls_and_fetches_no_tile(browser, run_report, tmp_path):
    result = headless(browser, tmp_path / "profile", run_report / "report.html", "--dump-dom")
    dom = result.stdout
    assert '<svg id="map"' in dom
    scale = re.search(
        r'<span id="scale" class="scalebar" style="width: ([\d.]+)px;">([^<]+)</span>', dom
    )
    assert scale is not None, "the map script did not run"
    assert float(scale.group(1)) > 0 and re.fullmatch(r"[\d.]+ k?m", scale.group(2))
    assert "<image" not in dom
    assert console_messages(result.stderr) == []


def test_ticking_the_background_adds_openstreetmap_tiles_over_the_view(
    browser, run_report, tmp_path
):
    page = tmp_path / "report.html"
    html = (run_report / "report.html").read_text()
    page.write_text(
        html.replace("</body>", "<script>document.getElementById('osm').click()</script></body>")
    )
    dom = headless(browser, tmp_path / "profile", page, "--dump-dom").stdout
    tiles = re.findall(r'href="https://tile\.openstreetmap\.org/(\d+)/(\d+)/(\d+)\.png"', dom)
    assert tiles, "no tile after ticking the box"
    zoom = {int(z) for z, _, _ in tiles}
    assert len(zoom) == 1 and 1 <= zoom.pop() <= 19
    # The drive is near 35.69 N, 139.70 E: the tiles' x, y must be that place's.
    z, x, y = map(int, tiles[0])
    n = 2**z
    lon = x / n * 360.0 - 180.0
    lat = np.degrees(np.arctan(np.sinh(np.pi * (1 - 2 * y / n))))
    assert abs(lon - 139.70) < 0.05 and abs(lat - 35.69) < 0.05
