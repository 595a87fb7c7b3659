"""The bound-checking fuzz additions: the array container round-trips, every array and UBX
frame mutation changes its seed (and a UBX frame keeps a valid checksum), out-of-range numbers
reach integers too, and the stricter checks flag what they are meant to."""

from __future__ import annotations

import random

import numpy as np

from tests.fuzz.bound_families import (
    ARRAY_MUTATIONS,
    UBX_MUTATIONS,
    _frames,
    check_ubx_bounds,
    out_of_range_number,
    pack_arrays,
    synthetic_segment,
    unpack_arrays,
)
from tests.fuzz.families import FAMILIES
from tests.io.test_ubx import TOW, pvt, rawx
from vo_doppler.io.ubx import checksum, read_ubx


def test_the_container_round_trips_and_a_cut_one_keeps_what_is_there():
    entries = [("a/t", b"\x93NUMPY 1"), ("b/value", b"x\ny\n" * 5)]
    data = pack_arrays(entries)
    assert unpack_arrays(data) == entries
    assert unpack_arrays(data[:-3]) == [entries[0], ("b/value", entries[1][1][:-3])]
    assert unpack_arrays(b"garbage" + data) == []


def test_every_array_mutation_changes_the_segment():
    seed = synthetic_segment()
    for name, mutation in ARRAY_MUTATIONS.items():
        changed = [mutation(seed, random.Random(k)) != seed for k in range(5)]
        assert any(changed), name


def test_ubx_frame_mutations_keep_valid_checksums():
    seed = rawx(TOW) + pvt() + rawx(TOW + 1.0)
    for name, mutation in UBX_MUTATIONS.items():
        results = [mutation(seed, random.Random(k)) for k in range(8)]
        if name not in ("ubx_subframe_bit",):  # no RXM-SFRBX in this stream
            assert any(r != seed for r in results), name
        for data in results:
            for start, end in _frames(data):
                assert checksum(data[start + 2 : end - 2]) == data[end - 2 : end]


def test_out_of_range_numbers_replace_integers_and_decimals():
    text = b"t,n_sat,sigma\n1000.000,8,0.5\n"
    seen = {out_of_range_number(text, random.Random(k)) for k in range(40)}
    assert any(b",8," not in s for s in seen) and any(b",0.5" not in s for s in seen)


def test_the_ubx_bound_check_flags_a_fix_faster_than_any_vehicle(tmp_path):
    path = tmp_path / "log.ubx"
    path.write_bytes(pvt())
    recording = read_ubx(path)
    assert check_ubx_bounds(recording, path) == []
    fast = recording.solution.velocity_ned * 1e5
    object.__setattr__(recording.solution, "velocity_ned", fast)
    assert any("NAV-PVT velocity" in b for b in check_ubx_bounds(recording, path))


def test_the_families_are_registered_with_their_mutations():
    family = FAMILIES["comma2k19-import"]
    assert set(ARRAY_MUTATIONS) <= set(family.mutations)
    assert np.all([name.startswith("array_") for name in family.mutations])
