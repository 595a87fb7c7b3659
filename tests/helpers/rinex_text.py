"""Small RINEX writers for tests (RINEX 3.05 Tables A2/A3, RINEX 2.11 Table A1; RINEX 4.01 and
3.05 navigation rewrites)."""

from __future__ import annotations


def header_line(content: str, label: str) -> str:
    return f"{content:<60}{label:<20}\n"


def field(value: float | None, lli: int | None = None, ssi: int | None = None) -> str:
    if value is None:
        return " " * 16
    text = f"{value:14.3f}"
    return text + (" " if lli is None else str(lli)) + (" " if ssi is None else str(ssi))


def rinex3_header(obs_types: dict[str, list[str]], time_system: str = "GPS") -> str:
    lines = [header_line("     3.04           OBSERVATION DATA    M", "RINEX VERSION / TYPE")]
    lines.append(header_line(" -3817680.9841  3562840.0688  3650158.4543", "APPROX POSITION XYZ"))
    for system, types in obs_types.items():
        chunks = [types[i : i + 13] for i in range(0, len(types), 13)]
        for k, chunk in enumerate(chunks):
            start = f"{system}  {len(types):3d}" if k == 0 else " " * 6
            lines.append(
                header_line(start + "".join(f" {c}" for c in chunk), "SYS / # / OBS TYPES")
            )
    lines.append(header_line("     1.000", "INTERVAL"))
    lines.append(
        header_line(
            f"  2024     6    24     8    20    0.0000000     {time_system}", "TIME OF FIRST OBS"
        )
    )
    lines.append(header_line("", "END OF HEADER"))
    return "".join(lines)


def rinex3_epoch(date: str, records: list[tuple[str, list[str]]], flag: int = 0) -> str:
    """date 'yyyy mm dd hh mm ss.sssssss'; records (sat id, formatted 16-char fields)."""
    out = [f"> {date}  {flag}{len(records):3d}\n"]
    out.extend(f"{sat}{''.join(fields)}".rstrip() + "\n" for sat, fields in records)
    return "".join(out)


def rinex2_header(types: list[str], system: str = "G") -> str:
    lines = [
        header_line(f"     2.11           OBSERVATION DATA    {system}", "RINEX VERSION / TYPE")
    ]
    for i in range(0, len(types), 9):
        chunk = types[i : i + 9]
        start = f"{len(types):6d}" if i == 0 else " " * 6
        lines.append(header_line(start + "".join(f"{c:>6}" for c in chunk), "# / TYPES OF OBSERV"))
    lines.append(
        header_line("  2010     1     6     5    57    3.0000000     GPS", "TIME OF FIRST OBS")
    )
    lines.append(header_line("", "END OF HEADER"))
    return "".join(lines)


def rinex2_epoch(date: str, records: list[tuple[str, list[str]]], flag: int = 0) -> str:
    """date 'yy mm dd hh mm ss.sssssss' (26 chars with leading space)."""
    sats = [sat for sat, _ in records]
    lines = []
    for i in range(0, max(len(sats), 1), 12):
        start = f"{date}  {flag}{len(sats):3d}" if i == 0 else " " * 32
        lines.append(start + "".join(sats[i : i + 12]))
    for _, fields in records:
        for i in range(0, len(fields), 5):
            lines.append("".join(fields[i : i + 5]).rstrip())
    return "".join(line + "\n" for line in lines)


def as_rinex4(v3: bytes) -> bytes:
    """A RINEX 3 navigation file rewritten as RINEX 4.01: each record behind its '> EPH' line,
    plus records of types the reader skips (a CNAV ephemeris, STO, ION)."""
    lines = v3.split(b"\n")
    end = next(i for i, line in enumerate(lines) if b"END OF HEADER" in line)
    header = [b"     4.01           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE"]
    header += [line for line in lines[1:end] if b"IONOSPHERIC CORR" not in line]
    out = [*header, lines[end]]
    message = {"G": b"LNAV", "J": b"LNAV", "E": b"INAV", "C": b"D1", "R": b"FDMA", "S": b"SBAS"}
    for line in lines[end + 1 :]:
        if line[:1].isalpha():
            out.append(b"> EPH " + line[:3] + b" " + message.get(line[:1].decode(), b"LNAV"))
        out.append(line)
    extra = [
        b"> EPH G05 CNAV",
        *(
            [b"G05 2024 06 24 10 00 00" + b" 0.000000000000E+00" * 3]
            + [b"    " + b" 0.0E+00" * 4] * 8
        ),
        b"> STO G01 LNAV",
        b"    2024 06 24 10 00 00 GPUT        UTC(USNO)",
        b"     1.000000000000E+00 0.000000000000E+00 0.000000000000E+00",
        b"> ION G01 LNAV",
        b"    2024 06 24 10 00 00 1.862645149231E-08 2.235174179077E-08-1.192092895508E-07",
        b"    -5.960464477539E-08 1.290240000000E+05 1.638400000000E+05-1.966080000000E+05",
        b"    -2.621440000000E+05 1.000000000000E+00",
    ]
    return b"\n".join(out[:-1] + extra + out[-1:])


def with_glonass_status_lines(v3: bytes, status: bytes) -> bytes:
    """A RINEX 3.04 navigation file as 3.05: each GLONASS record gets its fourth broadcast-orbit
    line (status flags, L1/L2 group delay difference, URAI, health flags)."""
    lines = v3.split(b"\n")
    lines[0] = b"     3.05" + lines[0][9:]
    out = []
    for k, line in enumerate(lines):
        out.append(line)
        if k >= 3 and lines[k - 3][:1] == b"R" and line[:4] == b"    ":
            out.append(status)
    return b"\n".join(out)
