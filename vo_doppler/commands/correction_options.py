"""The heading-correction options of ``correct``, ``run`` and ``batch`` (one definition), with
the check that refuses an option the chosen method ignores."""

from __future__ import annotations

import argparse

from vo_doppler.choices import values
from vo_doppler.commands.arg_types import positive_float
from vo_doppler.fusion.correction import CorrectionConfig, CorrectionMethod
from vo_doppler.fusion.heading_blend import BlendConfig
from vo_doppler.fusion.heading_correction import HeadingReference


def add_correction_options(parser: argparse.ArgumentParser, window_s: bool = False) -> None:
    """``--correction``, ``--causal`` and ``--reference`` (and ``--window-s`` when
    ``window_s``), with :func:`ignored_correction_option` as a usage check."""
    parser.add_argument(
        "--correction",
        choices=values(CorrectionMethod),
        default=CorrectionConfig().method.value,
        help="heading correction: window (the window method of [TK18], Takeyama & Kojima 2018, "
        "Eq. 11-13) or kalman (adaptive blend: filter and smoother on the VO heading offset)",
    )
    parser.add_argument(
        "--causal",
        action="store_true",
        help="kalman: forward filter only (each pose uses the headings up to its time; the "
        "window method has no smoother to turn off)",
    )
    if window_s:
        # None when not given, so that a --window-s the Kalman blend would ignore is refused.
        parser.add_argument(
            "--window-s",
            type=positive_float,
            help="window method's W (s), [TK18] Eq. 11-13 "
            f"(default: {CorrectionConfig().window_s:g})",
        )
    parser.add_argument(
        "--reference",
        choices=values(HeadingReference),
        default=CorrectionConfig().reference.value,
        help="compare the absolute heading with the VO's direction of travel (course) or with "
        "its orientation yaw (orientation: [TK18] sec. 3.6 as the paper writes it)",
    )
    parser.add_check(ignored_correction_option)


def ignored_correction_option(args: argparse.Namespace) -> str | None:
    """The problem when an option has no effect with the chosen ``--correction``: ``--causal``
    with the window method (which has no smoother), ``--window-s`` with the Kalman blend
    (which has no window)."""
    if args.correction == "window" and args.causal:
        return (
            "--causal applies to --correction kalman only: the window method has no smoother "
            "to turn off (drop --causal)"
        )
    if args.correction == "kalman" and getattr(args, "window_s", None) is not None:
        return (
            "--window-s applies to --correction window only: --correction kalman has no "
            "window (drop --window-s, or give --correction window)"
        )
    return None


def correction_config(args: argparse.Namespace, **blend) -> CorrectionConfig:
    """The :class:`CorrectionConfig` of :func:`add_correction_options`' options; ``blend``:
    further :class:`BlendConfig` settings (e.g. ``max_gap_s``)."""
    window_s = getattr(args, "window_s", None)
    return CorrectionConfig(
        method=args.correction,
        reference=args.reference,
        window_s=CorrectionConfig().window_s if window_s is None else window_s,
        blend=BlendConfig(smooth=not args.causal, **blend),
    )
