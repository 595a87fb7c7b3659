"""What decoding a CAN log found (:class:`CanDecodeReport`) and what is done with frames shorter
than their DBC length (:class:`ShortFrames`), apart from the decoder (:mod:`vo_doppler.io.can`):
the report travels with a sequence read in a child process (:func:`vo_doppler.job.run_recording`),
and the process that receives it needs neither python-can nor cantools (8 MiB resident)."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from vo_doppler.io.time_order import TimeOrderReport


@dataclass
class CanDecodeReport:
    """What happened to the frames: used, short (skipped or zero-padded), undecodable (by id),
    ignored."""

    n_frames: int = 0
    n_decoded: int = 0
    n_short_skipped: int = 0
    n_padded: int = 0
    n_undecodable: int = 0
    n_unreadable_lines: int = 0
    undecodable_by_id: dict[int, int] = field(default_factory=dict)
    time_order: dict[str, TimeOrderReport] = field(default_factory=dict)
    """Per decoded message, what its time order needed."""
    dbc_units: dict[str, str] = field(default_factory=dict)
    """Unit string the DBC declares for each decoded ``MESSAGE.SIGNAL``."""
    out_of_range: dict[str, str] = field(default_factory=dict)
    """Per ``MESSAGE.SIGNAL``, what was skipped as beyond a vehicle's range (a sentence)."""

    def summary(self) -> str:
        ids = ", ".join(f"0x{k:X}×{v}" for k, v in sorted(self.undecodable_by_id.items()))
        return (
            f"{self.n_frames} frames, {self.n_decoded} decoded, "
            f"{self.n_short_skipped} short skipped, {self.n_padded} short zero-padded, "
            f"{self.n_undecodable} undecodable{f' ({ids})' if ids else ''}, "
            f"{self.n_unreadable_lines} unreadable log lines"
        )

    def problems(self) -> list[str]:
        """Sentences for the warnings of a run: the samples skipped as out of range."""
        return list(self.out_of_range.values())


class ShortFrames(StrEnum):
    """What is done with frames shorter than their DBC length (module docstring)."""

    SKIP = "skip"
    PAD = "pad"
    """Zero-padded, for logs known to drop trailing zero bytes."""
