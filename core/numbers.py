"""Number syntax accepted from users: plain ASCII decimals, as a C ``strtod``/``strtol`` reads them.

Python's ``int`` and ``float`` also accept digit-group underscores (``4_000``)
and any Unicode decimal digit (``'٤'`` is 4): another tool reading the same
scene file or command line would disagree, or refuse. These refuse both, with
``ValueError`` like ``int``/``float`` (argparse names the option and value).
"""

from __future__ import annotations


def _check(text: str, kind: str) -> str:
    if not text.isascii() or "_" in text:
        raise ValueError(f"invalid {kind} literal: {text!r} (expected ASCII digits, no '_')")
    return text


def plain_int(text: str) -> int:
    """``int(text)`` for ASCII decimal text without underscores; ValueError otherwise."""
    return int(_check(text, "int"))


def plain_float(text: str) -> float:
    """``float(text)`` for ASCII text without underscores; ValueError otherwise."""
    return float(_check(text, "float"))


plain_int.__name__ = "int"  # argparse's message: "invalid int value: '4_000'"
plain_float.__name__ = "float"
