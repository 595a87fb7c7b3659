"""Small RINEX observation writers for tests (RINEX 3.05 Tables A2/A3, RINEX 2.11 Table A1)."""

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
