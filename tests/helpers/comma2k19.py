"""The comma2k19 minute of ../shared/data imported into a temporary sequence folder (skipped
when the recording is absent)."""

from __future__ import annotations

from tests.conftest import require_shared
from vo_doppler.io.comma2k19_import import import_comma2k19
from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.sequence import Sequence

COMMA = "comma2k19_example1"
SP3 = f"{COMMA}/Sta20124_1400_1845.sp3"


def imported_comma2k19(tmp_path_factory) -> Sequence:
    """``vo-doppler import comma2k19`` with its precise orbits, read back."""
    folder = tmp_path_factory.mktemp("comma") / "sequence"
    import_comma2k19(require_shared(COMMA), folder, require_shared(SP3))
    return read_sequence(folder)
