"""Robust statistics live in ``vo_doppler/robust.py`` only (docs/design.md, "Packages"): a scan
of every other module's code (docstrings and comments aside) fails on a hand-made normalised
MAD — the constant 1.4826, the name ``MAD_TO_SIGMA`` or a ``median(np.abs(`` scale — naming the
file and the line."""

from __future__ import annotations

import ast
import io
import tokenize
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "vo_doppler"
HOME = "robust.py"
MEDIAN_OF_ABS = (["median", "(", "np", ".", "abs", "("], ["nanmedian", "(", "np", ".", "abs", "("])


def hand_made_scales(source: str) -> list[tuple[int, str]]:
    """(line, what) of each robust-scale implementation in ``source``'s code tokens."""
    skipped = {tokenize.STRING, tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE}
    tokens = [
        t for t in tokenize.generate_tokens(io.StringIO(source).readline) if t.type not in skipped
    ]
    found = []
    for i, token in enumerate(tokens):
        if token.type == tokenize.NUMBER and ast.literal_eval(token.string) == 1.4826:
            found.append((token.start[0], "the literal 1.4826"))
        elif token.type == tokenize.NAME and token.string == "MAD_TO_SIGMA":
            found.append((token.start[0], "MAD_TO_SIGMA (use robust.nmad)"))
        elif [t.string for t in tokens[i : i + 6]] in MEDIAN_OF_ABS:
            found.append((token.start[0], "a median(np.abs(…)) scale (use robust.mad or nmad)"))
    return found


def violations(package: Path = PACKAGE) -> list[str]:
    return [
        f"{path.relative_to(package.parent)}:{line}: {what}"
        for path in sorted(package.rglob("*.py"))
        if path.relative_to(package).as_posix() != HOME
        for line, what in hand_made_scales(path.read_text())
    ]


def test_no_robust_scale_is_made_outside_robust_py():
    assert violations() == []


def test_the_scan_sees_code_and_not_prose(tmp_path):
    (tmp_path / "vo_doppler" / "gnss").mkdir(parents=True)
    (tmp_path / "vo_doppler" / "gnss" / "bad.py").write_text(
        '"""k = 1.4826 · median |z| (prose)."""\n'
        "import numpy as np\n"
        "# 1.4826 in a comment\n"
        "s = 1.4826 * np.median(np.abs(z))\n"
        "t = np.nanmedian(np.abs(z), axis=0)\n"
        "from vo_doppler.robust import MAD_TO_SIGMA\n"
    )
    (tmp_path / "vo_doppler" / "robust.py").write_text("MAD_TO_SIGMA = 1.4826\n")
    assert violations(tmp_path / "vo_doppler") == [
        "vo_doppler/gnss/bad.py:4: the literal 1.4826",
        "vo_doppler/gnss/bad.py:4: a median(np.abs(…)) scale (use robust.mad or nmad)",
        "vo_doppler/gnss/bad.py:5: a median(np.abs(…)) scale (use robust.mad or nmad)",
        "vo_doppler/gnss/bad.py:6: MAD_TO_SIGMA (use robust.nmad)",
    ]
