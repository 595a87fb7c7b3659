"""No input of any size is read past its bound before it is refused (issue 30): sparse files of
8 GB (no disk used) whose first bytes are a valid RINEX header or UBX frame, and files under
the bound whose text or frames end in NUL bytes (a logger's reserved space), are refused or cut
after reading only their first MiB. Bytes read are the kernel's count (``rchar``)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tests.helpers.rinex_text import field, rinex3_epoch, rinex3_header
from tests.io.test_ubx import TOW, pvt, rawx
from vo_doppler.errors import InputError
from vo_doppler.io.receiver_file import read_observation_file
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.sp3 import read_sp3
from vo_doppler.io.ubx import MAX_GAP, read_ubx

GIB = 1 << 30
MIB = 1 << 20

pytestmark = pytest.mark.skipif(not Path("/proc/self/io").exists(), reason="Linux /proc only")


def bytes_read() -> int:
    """What this process has read so far, by the kernel's count (``read`` calls included)."""
    with open("/proc/self/io") as io:
        return next(int(line.split()[1]) for line in io if line.startswith("rchar:"))


def sparse(path: Path, head: bytes, size: int) -> Path:
    """``head`` followed by NUL bytes up to ``size``, without writing them (a sparse file)."""
    path.write_bytes(head)
    os.truncate(path, size)
    return path


def rinex_text(n_epochs: int = 3) -> bytes:
    text = rinex3_header({"G": ["C1C", "D1C"]})
    for k in range(n_epochs):
        records = [(s, [field(2.0e7 + k), field(-1000.0 - k)]) for s in ("G05", "G07", "G09")]
        text += rinex3_epoch(f"2024 06 24 08 20 {k:2d}.0000000", records)
    return text.encode()


def test_an_8_gb_rinex_is_refused_before_it_is_read(tmp_path):
    path = sparse(tmp_path / "huge.obs", rinex_text(), 8 * GIB)
    before = bytes_read()
    with pytest.raises(InputError, match="larger than the 1024 MiB"):
        read_observation_file(path)
    assert bytes_read() - before < MIB


def test_a_8_gb_ubx_is_refused_before_it_is_read(tmp_path):
    path = sparse(tmp_path / "huge.ubx", rawx(TOW) + pvt(), 8 * GIB)
    before = bytes_read()
    with pytest.raises(InputError, match="more than the 1024 MiB"):
        read_observation_file(path)
    assert bytes_read() - before < MIB


def test_rinex_text_ends_at_its_first_nul_byte_and_nothing_after_is_read(tmp_path):
    text = rinex_text()
    path = sparse(tmp_path / "reserved.obs", text, 900 * MIB)
    before = bytes_read()
    obs = read_obs(path)
    assert bytes_read() - before < 2 * MIB
    assert obs.epoch_time.size == 3
    lines = text.count(b"\n")
    assert any(
        p.startswith(f"{path}:{lines + 1}: NUL bytes where a line should be") for p in obs.problems
    )


def test_a_ubx_log_is_read_a_chunk_at_a_time_and_not_past_a_long_gap(tmp_path):
    frames = rawx(TOW) + pvt() + rawx(TOW + 1.0)
    path = sparse(tmp_path / "reserved.ubx", frames, 900 * MIB)
    before = bytes_read()
    recording = read_ubx(path)
    assert bytes_read() - before < MAX_GAP + 2 * MIB
    assert recording.observations.epoch_time.size == 2
    assert any("no UBX frame in the 16 MiB before" in p for p in recording.problems)


def test_frames_across_read_chunks_are_all_found(tmp_path):
    """Frames after a gap of NMEA-like bytes longer than a read chunk, one frame straddling
    the chunk boundary: the same epochs as the frames alone."""
    filler = b"$GPGGA,,,,,,0,,,,,,,,*66\r\n" * (MIB // 26 + 7)
    path = tmp_path / "chunks.ubx"
    path.write_bytes(rawx(TOW) + filler + rawx(TOW + 1.0) + pvt() + filler[:1000])
    recording = read_ubx(path)
    assert recording.observations.epoch_time.size == 2
    assert len(recording.solution) == 1
    skipped = [p for p in recording.problems if "bytes outside UBX frames skipped" in p]
    assert skipped == [f"{path}, byte 0: {len(filler) + 1000} bytes outside UBX frames skipped"]


def test_an_sp3_with_nul_bytes_is_refused_naming_the_line(tmp_path):
    path = sparse(tmp_path / "orbits.sp3", b"#dP2024  6 24  0  0  0.00000000\n", 10 * MIB)
    with pytest.raises(InputError, match=r"orbits\.sp3:2: NUL bytes"):
        read_sp3(path)
