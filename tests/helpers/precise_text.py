"""Small SP3-d and RINEX clock writers for tests (formats as in vo_doppler.io.sp3 / rinex_clock)."""

from __future__ import annotations

import numpy as np

from vo_doppler.model.gpstime import SECONDS_PER_DAY, days_from_civil

GPS_DAY0 = int(days_from_civil(1980, 1, 6))


def calendar(t: float) -> tuple[int, int, int, int, int, float]:
    """GPS seconds → (year, month, day, hour, minute, second) by searching the day count."""
    days, second_of_day = divmod(t, SECONDS_PER_DAY)
    target = GPS_DAY0 + int(days)
    year = 1980 + int(days // 365.25)
    while days_from_civil(year + 1, 1, 1) <= target:
        year += 1
    while days_from_civil(year, 1, 1) > target:
        year -= 1
    month = 1
    while month < 12 and days_from_civil(year, month + 1, 1) <= target:
        month += 1
    day = target - int(days_from_civil(year, month, 1)) + 1
    hour, rest = divmod(second_of_day, 3600.0)
    minute, second = divmod(rest, 60.0)
    return year, month, day, int(hour), int(minute), second


def sp3_text(
    t: np.ndarray,
    sat_ids: list[str],
    position_m: np.ndarray,
    clock_s: np.ndarray,
    time_system: str = "GPS",
    newline: str = "\n",
) -> str:
    """An SP3-d file: ``position_m`` (E, N, 3) (NaN → 0.000000), ``clock_s`` (E, N)."""
    y, mo, d, h, mi, s = calendar(t[0])
    lines = [
        f"#dP{y:4d} {mo:2d} {d:2d} {h:2d} {mi:2d} {s:11.8f} {len(t):7d} ORBIT IGS14 FIT  TST",
        f"## 2012 396000.00000000 {np.median(np.diff(t)) if len(t) > 1 else 900.0:14.8f} "
        "58332 0.0000000000000",
    ]
    n_lines = max(5, -(-len(sat_ids) // 17))
    padded = sat_ids + ["  0"] * (17 * n_lines - len(sat_ids))
    for k in range(n_lines):
        chunk = "".join(padded[17 * k : 17 * k + 17])
        lines.append(f"+  {len(sat_ids):3d}   {chunk}" if k == 0 else f"+        {chunk}")
    lines += [
        f"%c M  cc {time_system} ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc",
        "%c cc cc ccc ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc",
        "/* synthetic test orbit",
    ]
    for k, epoch in enumerate(t):
        y, mo, d, h, mi, s = calendar(epoch)
        lines.append(f"*  {y:4d} {mo:2d} {d:2d} {h:2d} {mi:2d} {s:11.8f}")
        for j, sat in enumerate(sat_ids):
            xyz = np.nan_to_num(position_m[k, j] / 1000.0, nan=0.0)
            clock = 999999.999999 if np.isnan(clock_s[k, j]) else clock_s[k, j] * 1e6
            lines.append(f"P{sat}{xyz[0]:14.6f}{xyz[1]:14.6f}{xyz[2]:14.6f}{clock:14.6f}")
            lines.append(f"V{sat}{0.0:14.6f}{0.0:14.6f}{0.0:14.6f}{0.0:14.6f}")
    lines.append("EOF")
    return newline.join(lines) + newline


def clock_text(
    t: np.ndarray,
    sat_ids: list[str],
    bias_s: np.ndarray,
    version: str = "3.04",
    newline: str = "\n",
) -> str:
    """A RINEX clock file with AS records (4 values, so a continuation line each) and one AR;
    the header in the layout of ``version``: up to 3.02 ``F9.2,11X,A1,19X,A1`` and labels from
    column 61, from 3.04 on ``F4.2,17X,A1,20X,A1`` and labels from column 66."""
    if version >= "3.04":
        first, width = f"{version:4}{'':17}C{'':20}G", 65
    else:
        first, width = f"{version:>9}{'':11}C{'':19}G", 60
    header = [
        f"{first:{width}}RINEX VERSION / TYPE",
        f"{'GPS':>6}".ljust(width) + "TIME SYSTEM ID",
        f"{'':{width}}END OF HEADER",
    ]
    name_width = 9 if version >= "3.04" else 4
    body = []
    for k, epoch in enumerate(t):
        y, mo, d, h, mi, s = calendar(epoch)
        stamp = f"{y:4d} {mo:02d} {d:02d} {h:02d} {mi:02d} {s:9.6f}"
        body.append(f"AR {'ABCD'.ljust(name_width)} {stamp}  1   1.000000000000E-09")
        for j, sat in enumerate(sat_ids):
            if np.isnan(bias_s[k, j]):
                continue
            body.append(f"AS {sat.ljust(name_width)} {stamp}  4   {bias_s[k, j]:19.12E}  1.0E-11")
            body.append(f"   {0.0:19.12E}  {0.0:19.12E}")
    return newline.join(header + body) + newline
