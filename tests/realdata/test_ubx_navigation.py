"""A u-blox F9P's own measurements and broadcast ephemerides as the UBX log it would have written
(issue 31): the Hong Kong static F9P's first minute (its RINEX observations as RXM-RAWX, the
day's GPS, Galileo and BeiDou records as RXM-SFRBX subframes and pages) gives the same
single-point fixes as the RINEX files, with the Galileo and BeiDou satellites in them: before
issue 31 the log's Galileo and BeiDou navigation data were counted, not decoded, and those
satellites were lost."""

from __future__ import annotations

import logging
from dataclasses import replace

import numpy as np
import pytest
from pyubx2 import UBXMessage

from tests.conftest import require_shared
from tests.helpers import beidou_d1 as bds
from tests.helpers import galileo_inav as gal
from tests.helpers import lnav
from vo_doppler.gnss.spp import solve_spp
from vo_doppler.io.gps_lnav import URA_METERS
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.ubx import read_ubx
from vo_doppler.model.navigation import Navigation

pytestmark = [pytest.mark.shared_data, pytest.mark.slow]

STATIC = "hk_tst_static_f9p/"
W = 604800.0
EPOCHS = 60
GNSS_ID = {"G": 0, "E": 2, "C": 3}
PSEUDORANGE = {"G": "C1C", "E": "C1C", "C": "C1I"}
"""The F9P's L1 C/A, E1 C and B1I pseudoranges (RINEX 3.02 names B1I 'C1I'); RXM-RAWX gives them
as signal 0 of each system (B1I as RINEX 3.04's 'C2I')."""
B1I_NAMES = {f"{kind}1I": f"{kind}2I" for kind in "CLDS"}
"""RINEX 3.02's B1I observables by RINEX 3.03's names, which the GNSS stage gives TGD1 (it reads
a 3.02 'C1I' as no B1I and applies no group delay: up to 7.6 m on this day's records)."""


def _rawx(t: float, rows: list[tuple[str, int, float, float]]) -> bytes:
    fields: dict[str, float] = {}
    for k, (system, prn, pseudorange, cn0) in enumerate(rows, start=1):
        s = f"_{k:02d}"
        fields |= {f"gnssId{s}": GNSS_ID[system], f"svId{s}": prn, f"sigId{s}": 0}
        fields |= {f"prMes{s}": pseudorange, f"prValid{s}": 1, f"cno{s}": round(cn0)}
        fields |= {f"locktime{s}": 20000, f"prStd{s}": 4, f"doStd{s}": 5, f"halfCyc{s}": 1}
    week, tow = divmod(t, W)
    return UBXMessage(
        "RXM", "RXM-RAWX", 0, rcvTow=tow, week=int(week), leapS=18, numMeas=len(rows),
        version=1, **fields,
    ).serialize()  # fmt: skip


def _navigation_data(nav: Navigation, chosen: list[int]) -> bytes:
    """Each chosen record as its satellite sends it: GPS LNAV subframes, Galileo I/NAV pages,
    BeiDou D1 subframes, sent 10 min before toe."""
    kepler, out = nav.kepler, b""
    for k in chosen:
        system, prn = str(kepler.system[k]), int(kepler.prn[k])
        eph = {name: float(values[k]) for name, values in kepler.params.items()}
        sent = float(kepler["toe"][k]) - 600.0
        if system == "G":
            ura = next(i for i, v in enumerate(URA_METERS) if v >= eph["accuracy"])
            eph |= {"toc_sow": float(kepler.toc[k] % W), "ura_index": ura}
            words = lnav.encode_ephemeris(eph, int(sent % W) // 6)
            out += b"".join(lnav.sfrbx(prn, w) for w in words)
        elif system == "E":
            eph["toc_sow"] = float(kepler.toc[k] % W)
            words = gal.encode_ephemeris(prn, eph, sent)
            out += b"".join(gal.ubx_sfrbx(prn, gal.sfrbx_words(w)) for w in words)
        else:
            eph["toc_sow"] = float((kepler.toc[k] - 14.0) % W)
            bdt = sent - 14.0 - 1356 * W
            subframes = bds.encode_subframes(eph, int(bdt // W), int(bdt % W) // 6 * 6)
            out += b"".join(bds.ubx_sfrbx(prn, words) for words in subframes)
    return out


def _chosen_records(nav: Navigation, t0: float, satellites: set[tuple[str, int]]) -> list[int]:
    """Per observed satellite, its healthy record nearest ``t0`` (BeiDou GEO, which sends D2,
    left out)."""
    kepler = nav.kepler
    chosen = []
    for system, prn in sorted(satellites):
        if system == "C" and (prn <= 5 or prn >= 59):
            continue
        rows = np.flatnonzero(
            (kepler.system == system) & (kepler.prn == prn) & (kepler["health"] == 0)
        )
        if rows.size:
            chosen.append(int(rows[np.argmin(np.abs(kepler["toe"][rows] - t0))]))
    return chosen


def test_an_f9p_log_gives_the_fixes_of_its_rinex_files_with_galileo_and_beidou(tmp_path):
    obs = read_obs(require_shared(STATIC + "2020_06_03_TST_03.obs"))
    obs = obs.subset(obs.time <= obs.epoch_time[EPOCHS - 1])
    obs = replace(  # the first minute, started from the Earth's centre as the UBX log is
        obs,
        epoch_time=obs.epoch_time[:EPOCHS],
        epoch_flag=obs.epoch_flag[:EPOCHS],
        header=replace(obs.header, approx_position=None),
    )
    b1i = replace(obs, codes=tuple(B1I_NAMES.get(c, c) for c in obs.codes))
    nav = read_nav([require_shared(STATIC + f"hksc155c.20{x}") for x in "nlb"])
    t0 = float(obs.epoch_time[0])
    observed = set()
    epochs = []
    for t in obs.epoch_time[:EPOCHS]:
        rows = []
        for system, code in PSEUDORANGE.items():
            here = obs.subset((obs.time == t) & obs.mask(system, code))
            strength = obs.subset((obs.time == t) & obs.mask(system, "S" + code[1:]))
            cn0 = dict(zip(strength.prn.tolist(), strength.value.tolist(), strict=True))
            for prn, value in zip(here.prn.tolist(), here.value.tolist(), strict=True):
                if np.isfinite(value) and prn in cn0:
                    rows.append((system, prn, value, cn0[prn]))
                    observed.add((system, prn))
        epochs.append(_rawx(float(t), rows))
    chosen = _chosen_records(nav, t0, observed)
    path = tmp_path / "f9p.ubx"
    path.write_bytes(_navigation_data(nav, chosen) + b"".join(epochs))
    recording = read_ubx(path)
    decoded = recording.navigation.kepler
    assert sorted(zip(decoded.system.tolist(), decoded.prn.tolist(), strict=True)) == sorted(
        (str(nav.kepler.system[k]), int(nav.kepler.prn[k])) for k in chosen
    )
    systems = {s: int((decoded.system == s).sum()) for s in "GEC"}
    assert systems == {"G": 8, "E": 3, "C": 6}  # the satellites the F9P tracked in the canyon
    source = Navigation(nav.kepler.subset(chosen), nav.glonass)  # the same records, no Klobuchar
    logging.disable(logging.WARNING)
    try:
        from_ubx = solve_spp(recording.observations, recording.navigation, "GEC")
        from_rinex = solve_spp(b1i, source, "GEC")
        gps_only = solve_spp(recording.observations, recording.navigation, "G")
    finally:
        logging.disable(logging.NOTSET)
    np.testing.assert_array_equal(from_ubx.t, from_rinex.t)
    np.testing.assert_array_equal(from_ubx.valid, from_rinex.valid)
    np.testing.assert_array_equal(from_ubx.n_sat, from_rinex.n_sat)
    both = from_ubx.valid
    assert both.sum() >= EPOCHS // 2
    gap = np.linalg.norm(from_ubx.position_ecef[both] - from_rinex.position_ecef[both], axis=1)
    # measured: 60 of 60 fixes valid and the same to 1.8e-5 m; 5–6 GPS satellites used, 13–14
    # with Galileo and BeiDou
    assert gap.max() <= 1e-3
    assert np.all(from_ubx.n_sat[both] >= gps_only.n_sat[both] + 7)
