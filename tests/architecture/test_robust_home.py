"""Robust statistics live in ``vo_doppler/robust.py`` only (docs/design.md, "Packages"): a scan
of every other module's code (docstrings and comments aside) fails, naming the file and the
line, on a hand-made normalised MAD — the constant 1.4826, the name ``MAD_TO_SIGMA`` or a
``median(np.abs(`` scale — and on a hand-made robust weight or influence function:

* a Huber weight (R2), ``minimum(1, …/…abs…)``: the literal 1 against a quotient whose divisor
  holds an absolute value, e.g. ``np.minimum(1.0, k / np.abs(u))``;
* a Huber ψ (R2′), ``clip(u, -k, k)``: a symmetric clip whose bound is symbolic and names a
  tuning constant (``k``, ``…_k``, ``k_…`` or ``…huber…``), so that clipping a cosine to
  [-1, 1] or saturating a physical quantity (``-max_rate, max_rate``) passes;
* a Huber-inflated variance (R2″), ``where(a > b, S * a / b, S)`` (or ``a / b * S``, or the
  factor ``where(a > b, a / b, 1)``): the quantity compared with b scales S by a/b beyond it;
* a Cauchy weight (R3), ``… / (1 + (u / c) ** 2)``: one plus a squared quotient, divided by.
"""

from __future__ import annotations

import ast
import io
import tokenize
from collections.abc import Iterator
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "vo_doppler"
HOME = "robust.py"
MEDIAN_OF_ABS = (["median", "(", "np", ".", "abs", "("], ["nanmedian", "(", "np", ".", "abs", "("])
SKIPPED = {
    tokenize.STRING,
    tokenize.COMMENT,
    tokenize.NL,
    tokenize.INDENT,
    tokenize.DEDENT,
    tokenize.ENDMARKER,
}
OPENING, CLOSING, ROUND = set("([{"), set(")]}"), set("()")
HUBER_WEIGHT = "a Huber weight min(1, k/|u|) (use robust.huber_weight)"
HUBER_PSI = "a Huber ψ clip(u, -k, k) (use robust.huber_psi)"
HUBER_VARIANCE = "a Huber-inflated variance S·|u|/k beyond k (use robust.huber_inflated_variance)"
CAUCHY_WEIGHT = "a Cauchy weight 1/(1 + (u/c)²) (use robust.cauchy_weight)"

Tokens = list[tokenize.TokenInfo]


def code_tokens(source: str) -> Tokens:
    """The tokens of ``source``'s code: no strings (docstrings), comments or layout but the
    end of each statement (NEWLINE)."""
    return [
        t for t in tokenize.generate_tokens(io.StringIO(source).readline) if t.type not in SKIPPED
    ]


def closing(tokens: Tokens, opening: int) -> int:
    """The index of the bracket that closes the one at ``opening``."""
    depth = 0
    for i in range(opening, len(tokens)):
        depth += (tokens[i].string in OPENING) - (tokens[i].string in CLOSING)
        if depth == 0:
            return i
    return len(tokens)


def split(tokens: Tokens, separators: set[str]) -> list[Tokens]:
    """``tokens`` split at the separators outside brackets (a call's arguments at ",")."""
    parts: list[Tokens] = [[]]
    depth = 0
    for t in tokens:
        depth += (t.string in OPENING) - (t.string in CLOSING)
        if depth == 0 and t.string in separators:
            parts.append([])
        else:
            parts[-1].append(t)
    return parts


def calls(tokens: Tokens, names: set[str]) -> Iterator[tuple[int, list[Tokens]]]:
    """(index, arguments) of each call of a function or method named in ``names``."""
    for i, t in enumerate(tokens[:-1]):
        if t.type == tokenize.NAME and t.string in names and tokens[i + 1].string == "(":
            yield i, split(tokens[i + 2 : closing(tokens, i + 1)], {","})


def definition(tokens: Tokens, name: str, before: int) -> Tokens | None:
    """The expression last assigned to ``name`` by a statement ``name = …`` before the token
    at ``before``; None without one."""
    for j in range(before - 1, -1, -1):
        statement = j == 0 or tokens[j - 1].type == tokenize.NEWLINE
        if statement and tokens[j].string == name and tokens[j + 1].string == "=":
            end = next(k for k in range(j, len(tokens)) if tokens[k].type == tokenize.NEWLINE)
            return tokens[j + 2 : end]
    return None


def text(tokens: Tokens, brackets: bool = True) -> list[str]:
    """The strings of ``tokens``, round brackets left out unless ``brackets``."""
    return [t.string for t in tokens if brackets or t.string not in ROUND]


def is_literal(tokens: Tokens, value: float) -> bool:
    """Whether ``tokens`` are one number literal equal to ``value`` (1 and 1.0 alike)."""
    return (
        len(tokens) == 1
        and tokens[0].type == tokenize.NUMBER
        and ast.literal_eval(tokens[0].string) == value
    )


def is_tuning_constant(name: str) -> bool:
    """Whether ``name`` reads as a robust tuning constant (Huber's k)."""
    return name == "k" or name.endswith("_k") or name.startswith("k_") or "huber" in name.lower()


def huber_weights(tokens: Tokens) -> Iterator[int]:
    """Indices of min(1, x / …abs…) (R2), either argument order."""
    for i, arguments in calls(tokens, {"min", "minimum", "fmin"}):
        if len(arguments) != 2 or not any(is_literal(a, 1) for a in arguments):
            continue
        other = text(arguments[1] if is_literal(arguments[0], 1) else arguments[0])
        if "/" in other and "abs" in other[other.index("/") :]:
            yield i


def huber_psis(tokens: Tokens) -> Iterator[int]:
    """Indices of clip(u, -b, b) (R2′) with b symbolic and naming a tuning constant."""
    for i, arguments in calls(tokens, {"clip"}):
        if len(arguments) < 2:
            continue
        low, high = arguments[-2:]
        names = [t.string for t in high if t.type == tokenize.NAME]
        if text(low) == ["-", *text(high)] and any(is_tuning_constant(n) for n in names):
            yield i


def huber_variances(tokens: Tokens) -> Iterator[int]:
    """Indices of where(a > b, S * a / b, S), where(a > b, a / b * S, S) and
    where(a > b, a / b, 1) (R2″), round brackets aside; the condition may be a name assigned
    a > b before."""
    for i, arguments in calls(tokens, {"where"}):
        if len(arguments) != 3:
            continue
        condition, inflated, plain = arguments
        if len(condition) == 1 and condition[0].type == tokenize.NAME:
            condition = definition(tokens, condition[0].string, i) or condition
        compared = split(condition, {">", ">="})
        if len(compared) != 2:
            continue
        ratio = [*text(compared[0], False), "/", *text(compared[1], False)]
        variance = text(plain, False)
        inflations = ([*variance, "*", *ratio], [*ratio, "*", *variance])
        if text(inflated, False) in inflations or (
            is_literal(plain, 1) and text(inflated, False) == ratio
        ):
            yield i


def cauchy_weights(tokens: Tokens) -> Iterator[int]:
    """Indices of … / (1 + (u / c) ** 2) (R3), either order of the sum, round brackets aside."""
    for i, t in enumerate(tokens[:-1]):
        if t.string != "/" or tokens[i + 1].string != "(":
            continue
        terms = split(tokens[i + 2 : closing(tokens, i + 1)], {"+"})
        if len(terms) != 2 or not any(is_literal(term, 1) for term in terms):
            continue
        other = [
            u for u in (terms[1] if is_literal(terms[0], 1) else terms[0]) if u.string not in ROUND
        ]
        squared = len(other) > 2 and other[-2].string == "**" and is_literal(other[-1:], 2)
        if squared and "/" in text(other) and len(split(other, {"-"})) == 1:
            yield i


def hand_made_robust(source: str) -> list[tuple[int, str]]:
    """(line, what) of each robust scale, weight or ψ implemented in ``source``'s code."""
    tokens = code_tokens(source)
    found = []
    for i, token in enumerate(tokens):
        if token.type == tokenize.NUMBER and ast.literal_eval(token.string) == 1.4826:
            found.append((token.start[0], "the literal 1.4826"))
        elif token.type == tokenize.NAME and token.string == "MAD_TO_SIGMA":
            found.append((token.start[0], "MAD_TO_SIGMA (use robust.nmad)"))
        elif [t.string for t in tokens[i : i + 6]] in MEDIAN_OF_ABS:
            found.append((token.start[0], "a median(np.abs(…)) scale (use robust.mad or nmad)"))
    for rule, what in (
        (huber_weights, HUBER_WEIGHT),
        (huber_psis, HUBER_PSI),
        (huber_variances, HUBER_VARIANCE),
        (cauchy_weights, CAUCHY_WEIGHT),
    ):
        found.extend((tokens[i].start[0], what) for i in rule(tokens))
    return sorted(found, key=lambda hit: hit[0])


def violations(package: Path = PACKAGE) -> list[str]:
    return [
        f"{path.relative_to(package.parent)}:{line}: {what}"
        for path in sorted(package.rglob("*.py"))
        if path.relative_to(package).as_posix() != HOME
        for line, what in hand_made_robust(path.read_text())
    ]


def test_no_robust_scale_or_weight_is_made_outside_robust_py():
    assert violations() == []


def test_robust_py_holds_what_the_scan_looks_for():
    kinds = {what for _, what in hand_made_robust((PACKAGE / HOME).read_text())}
    assert {HUBER_WEIGHT, HUBER_PSI, HUBER_VARIANCE, CAUCHY_WEIGHT} <= kinds


def test_the_scan_sees_code_and_not_prose(tmp_path):
    (tmp_path / "vo_doppler" / "gnss").mkdir(parents=True)
    (tmp_path / "vo_doppler" / "gnss" / "bad.py").write_text(
        '"""k = 1.4826 · median |z| (prose); w = np.minimum(1.0, k / np.abs(u)) in prose."""\n'
        "import numpy as np\n"
        "# 1.4826 in a comment, and np.clip(u, -k, k) in another\n"
        "s = 1.4826 * np.median(np.abs(z))\n"
        "t = np.nanmedian(np.abs(z), axis=0)\n"
        "from vo_doppler.robust import MAD_TO_SIGMA\n"
        "w = np.minimum(1.0, k / np.abs(u))\n"
        "w = np.minimum(1, k * s / np.maximum(np.abs(r), eps))\n"
        "w = min(huber_k / abs(u), 1)\n"
        "w = np.minimum(1.0, np.abs(x) / limit)\n"
        "w = np.minimum(1.0, distance / horizon) * np.minimum(2, k / np.abs(u))\n"
        "psi = np.clip(u, -k, k)\n"
        "psi = np.clip(innovation, -config.huber_k, config.huber_k)\n"
        "psi = u.clip(-self.k_outer * s, self.k_outer * s)\n"
        "c = np.clip(cosine, -1.0, 1.0) + np.clip(rate, -max_rate, max_rate)\n"
        "c = np.clip(u, -k, 2 * k) + np.clip(u, 0, k)\n"
        "gain = P / np.where(size > huber_k, S * size / huber_k, S)\n"
        "S = np.where(np.abs(u) >= k, np.abs(u) / k * S, S)\n"
        "S = S * np.where(size > k, (size / k), 1.0)\n"
        "S = np.where(size > k, S * size / limit, S) + np.where(v > top, v - top, v)\n"
        "beyond = size > huber_k\n"
        "gain = P / np.where(beyond, S * size / huber_k, S)\n"
        "mask = size > k\n"
        "S = np.where(mask, S * v / k, S) + np.where(ok, S * size / k, S)\n"
        "w = 1 / (1 + (u / c) ** 2)\n"
        "w = prior / (1.0 + u**2 / c**2) + 1.0 / ((u / cauchy_c) ** 2 + 1.0)\n"
        "d = 1 / (1 + x**2) + 1 / (1 + np.exp(-x)) + 1 / (1 - (u / c) ** 2)\n"
        "d = np.sqrt(1 + (a / b) ** 2) + 1 / (2 + (u / c) ** 2)\n"
    )
    (tmp_path / "vo_doppler" / "robust.py").write_text(
        "MAD_TO_SIGMA = 1.4826\nw = np.minimum(1.0, k / np.abs(u))\npsi = np.clip(u, -k, k)\n"
    )
    path = "vo_doppler/gnss/bad.py"
    assert violations(tmp_path / "vo_doppler") == [
        f"{path}:4: the literal 1.4826",
        f"{path}:4: a median(np.abs(…)) scale (use robust.mad or nmad)",
        f"{path}:5: a median(np.abs(…)) scale (use robust.mad or nmad)",
        f"{path}:6: MAD_TO_SIGMA (use robust.nmad)",
        f"{path}:7: {HUBER_WEIGHT}",
        f"{path}:8: {HUBER_WEIGHT}",
        f"{path}:9: {HUBER_WEIGHT}",
        f"{path}:12: {HUBER_PSI}",
        f"{path}:13: {HUBER_PSI}",
        f"{path}:14: {HUBER_PSI}",
        f"{path}:17: {HUBER_VARIANCE}",
        f"{path}:18: {HUBER_VARIANCE}",
        f"{path}:19: {HUBER_VARIANCE}",
        f"{path}:22: {HUBER_VARIANCE}",
        f"{path}:25: {CAUCHY_WEIGHT}",
        f"{path}:26: {CAUCHY_WEIGHT}",
        f"{path}:26: {CAUCHY_WEIGHT}",
    ]
