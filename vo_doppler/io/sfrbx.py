"""u-blox RXM-SFRBX broadcast navigation data → ephemerides: the one decoder behind the UBX log
reader (:mod:`vo_doppler.io.ubx`) and the ROS bag reader's ublox_msgs ``RxmSFRBX``
(:mod:`vo_doppler.io.rosbag_gnss`).

Per message (u-blox interface description, "Broadcast navigation data"), by gnssId:

- 0 GPS and 5 QZSS, sigId 0 (L1 C/A), 10 words: an LNAV subframe, each word's data bits in
  bits 29…6 and its parity bits in 5…0; a subframe failing the parity check is refused (named),
  subframes 1–3 decoded (:mod:`vo_doppler.io.gps_lnav`, QZSS as J01–J10); their 10-bit week
  needs a full GPS week from the recording.
- 2 Galileo, sigId 0/1 (E1-B) or 5 (E5b-I), 8 words: an I/NAV page, CRC-checked, words 1–5
  decoded (:mod:`vo_doppler.io.galileo_inav`).
- 3 BeiDou, 10 words: a D1 subframe of a MEO/IGSO satellite, BCH-checked, subframes 1–3 decoded
  (:mod:`vo_doppler.io.beidou_d1d2`); GEO satellites' D2 subframes are counted, not decoded.
- 6 GLONASS: a string (the first three words, ``svId`` the slot, ``freqId`` − 7 the frequency
  number), strings 1–4 decoded (:mod:`vo_doppler.io.glonass_strings`) on the day of the
  recording's GPS time.
- Every other system or signal (SBAS, NavIC, GPS L2C/L5 CNAV, Galileo F/NAV …): counted.

Problems are (where, text): ``where`` the byte offset or message index of the message named, or
None for a count over the whole stream; each reader words them with its file or topic.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from vo_doppler.io.beidou_d1d2 import D1Assembler, is_geo
from vo_doppler.io.galileo_inav import SIGNALS, InavAssembler
from vo_doppler.io.glonass_strings import GlonassAssembler, sfrbx_string
from vo_doppler.io.gps_lnav import LnavAssembler, parity_error, subframe_id
from vo_doppler.io.rinex_common import prn_in_range
from vo_doppler.model.navigation import NavRecords, concat_records

SYSTEMS = {0: "G", 1: "S", 2: "E", 3: "C", 5: "J", 6: "R", 7: "I"}
"""u-blox gnssId → RINEX system letter."""
NAMES = {
    "G": "GPS",
    "S": "SBAS",
    "E": "Galileo",
    "C": "BeiDou",
    "J": "QZSS",
    "R": "GLONASS",
    "I": "NavIC",
}
NO_EPHEMERIS_HINT = (
    "those satellites have no ephemeris in the sequence, so their measurements are not used; "
    "add a RINEX navigation file of the day for them"
)


@dataclass(frozen=True)
class SfrbxMessage:
    """One RXM-SFRBX message: ``where`` its byte offset or message index, the u-blox gnssId,
    svId, sigId (0 in a message without one) and freqId, and its data words."""

    where: int
    gnss: int
    sv: int
    signal: int
    freq: int
    words: tuple[int, ...]


@dataclass(frozen=True)
class SfrbxNavigation:
    """The ephemerides of a stream of RXM-SFRBX messages and its problems (module docstring)."""

    kepler: NavRecords
    glonass: NavRecords
    problems: tuple[tuple[int | None, str], ...]


class _Decoder:
    def __init__(self, week: int | None, reference: float | None) -> None:
        self.week, self.reference = week, reference
        self.lnav = {"G": LnavAssembler.new("G"), "J": LnavAssembler.new("J")}
        self.inav = InavAssembler()
        self.d1 = D1Assembler()
        self.glonass = GlonassAssembler(float("nan") if reference is None else reference)
        self.problems: list[tuple[int | None, str]] = []
        self.not_decoded: dict[str, int] = {}
        self.no_ephemeris: dict[str, int] = {}
        self.first_lnav: int | None = None
        self.first_string: int | None = None

    def count(self, table: dict[str, int], what: str) -> None:
        table[what] = table.get(what, 0) + 1

    def add(self, m: SfrbxMessage) -> None:
        system = SYSTEMS.get(m.gnss, "")
        if system in ("G", "J") and len(m.words) == 10 and m.signal == 0:
            self.lnav_subframe(system, m)
        elif system == "E" and len(m.words) >= 8 and m.signal in SIGNALS:
            if prn_in_range("E", m.sv):
                self.inav.add(m.sv, SIGNALS[m.signal], list(m.words), m.where)
            else:
                self.count(self.not_decoded, "Galileo pages of an unknown satellite")
        elif system == "C" and len(m.words) == 10 and prn_in_range("C", m.sv):
            if is_geo(m.sv):
                self.count(self.no_ephemeris, "BeiDou GEO (D2) subframes")
            else:
                self.d1.add(m.sv, list(m.words), m.where)
        elif system == "R" and len(m.words) >= 3:
            self.glonass_string(m)
        elif system in ("G", "J", "E", "C", "R"):
            self.count(self.not_decoded, f"{NAMES[system]} messages of other signals or lengths")
        else:
            self.count(self.no_ephemeris, f"{NAMES.get(system, f'gnssId {m.gnss}')} messages")

    def lnav_subframe(self, system: str, m: SfrbxMessage) -> None:
        name = NAMES[system]
        words30 = tuple(w & 0x3FFFFFFF for w in m.words)
        word = parity_error(words30)
        if word is not None or not prn_in_range(system, m.sv):
            why = f"word {word} fails the LNAV parity check" if word else f"no {name} satellite"
            self.problems.append((m.where, f"{name} subframe of SV {m.sv}: {why}"))
            return
        words = tuple(w >> 6 for w in words30)
        if subframe_id(words) not in (1, 2, 3):
            self.count(self.not_decoded, f"{name} subframes 4-5 or without preamble")
        elif self.week is None:
            self.first_lnav = m.where if self.first_lnav is None else self.first_lnav
        else:
            self.lnav[system].add(m.sv, words, self.week, m.where)

    def glonass_string(self, m: SfrbxMessage) -> None:
        if not prn_in_range("R", m.sv):
            self.count(self.not_decoded, "GLONASS strings of an unknown slot")
        elif self.reference is None:
            self.first_string = m.where if self.first_string is None else self.first_string
        else:
            string = sfrbx_string(list(m.words[:3]))
            self.glonass.add(m.sv, m.freq - 7, string, m.where, m.signal)

    def result(self) -> SfrbxNavigation:
        if self.first_lnav is not None:
            self.problems.append((self.first_lnav, "GPS subframes without a week: not decoded"))
        if self.first_string is not None:
            text = "GLONASS strings without a GPS time: not decoded"
            self.problems.append((self.first_string, text))
        for system, assembler in self.lnav.items():
            name = NAMES[system]
            for where, prn, why in assembler.rejected:
                text = f"{name} ephemeris of {system}{prn:02d} off any {name} orbit: {why}"
                self.problems.append((where, text))
        for what, system, rejected in (
            ("GLONASS strings or ephemerides", "R", self.glonass.rejected),
            ("Galileo pages or ephemerides", "E", self.inav.rejected),
            ("BeiDou subframes or ephemerides", "C", self.d1.rejected),
        ):
            if rejected:
                where, prn, why = rejected[0]
                text = f"{len(rejected)} {what} refused (the first: {system}{prn:02d}, {why})"
                self.problems.append((where, text))
        if self.inav.n_alert:
            self.not_decoded["Galileo alert pages"] = self.inav.n_alert
        if self.d1.n_almanac:
            self.not_decoded["BeiDou almanac subframes 4-5"] = self.d1.n_almanac
        if self.not_decoded:
            counts = ", ".join(f"{n} {what}" for what, n in sorted(self.not_decoded.items()))
            self.problems.append((None, f"not decoded: {counts}"))
        if self.no_ephemeris:
            counts = ", ".join(f"{n} {what}" for what, n in sorted(self.no_ephemeris.items()))
            text = f"navigation data not decoded ({counts}): {NO_EPHEMERIS_HINT}"
            self.problems.append((None, text))
        kepler = self.lnav["G"].navrecords()
        for records in (self.lnav["J"].navrecords(), self.inav.navrecords()):
            kepler = concat_records(kepler, records)
        kepler = concat_records(kepler, self.d1.navrecords())
        return SfrbxNavigation(kepler, self.glonass.navrecords(), tuple(self.problems))


def decode_sfrbx(
    messages: Iterable[SfrbxMessage], week: int | None, reference: float | None
) -> SfrbxNavigation:
    """Ephemerides of the messages in stream order (module docstring): ``week`` a full GPS week
    of the recording (for GPS and QZSS subframes), ``reference`` a GPS time in it (for GLONASS
    strings); each None when the recording has none."""
    decoder = _Decoder(week, reference)
    for message in messages:
        decoder.add(message)
    return decoder.result()
