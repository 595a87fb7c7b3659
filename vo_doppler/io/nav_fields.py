"""Fields laid one after another over a navigation message's data bits, as the ICDs' bit
allocation tables list them (the Galileo OS SIS ICD's I/NAV words, the BDS-SIS-ICD-B1I's D1
subframes with their parity bits removed).

A field is ``(name, bits, signed, scale)``: ``name`` None for a reserved or spare field, a signed
field in two's complement, ``scale`` its least significant bit in SI units (radians for the
angles, semicircles times the ICDs' π = 3.1415926535898).
"""

from __future__ import annotations

from collections.abc import Sequence

ICD_PI = 3.1415926535898
"""π as the GPS, Galileo and BeiDou ICDs define it to turn semicircles into radians."""

Field = tuple[str | None, int, bool, float]


def read_fields(bits: int, n_bits: int, fields: Sequence[Field]) -> dict[str, float]:
    """The named fields of ``bits`` (an integer of ``n_bits`` bits, the first sent the most
    significant), the first field starting at its most significant bit."""
    out: dict[str, float] = {}
    end = n_bits
    for name, width, signed, scale in fields:
        end -= width
        if end < 0:
            raise ValueError(f"fields of {n_bits - end} bits in {n_bits}")
        value = (bits >> end) & ((1 << width) - 1)
        if signed and value >> (width - 1):
            value -= 1 << width
        if name is not None:
            out[name] = value * scale
    return out
