"""The keyword checks every ``check_*`` function of the public API shares (projector, frames, unprojector).

One place for what a keyword must be, so the three entry points refuse the same bad value with the same
line: a flag that is not a bool (``allow_vacuous="no"`` is truthy and would let nothing pass), a timeout
that is not a finite number of seconds within the candidate limit.
"""

from __future__ import annotations

import math
import numbers

import numpy as np
from wirecheck.core.limits import MAX_CANDIDATE_TIMEOUT_S

from .reports.fmt import short_repr

__all__ = ["checked_flag", "checked_seconds"]


def checked_flag(value, name: str, extra: str = "") -> bool:
    """``value`` as a bool (numpy's bool too); TypeError naming ``name`` otherwise."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} {short_repr(value)}: expected True or False{' ' + extra if extra else ''}")
    return bool(value)


def checked_seconds(timeout_s, name: str = "timeout_s") -> float:
    """``timeout_s`` as a finite float in (0, MAX_CANDIDATE_TIMEOUT_S]; TypeError/ValueError naming it otherwise."""
    if isinstance(timeout_s, bool) or not isinstance(timeout_s, numbers.Real):
        raise TypeError(f"{name} {short_repr(timeout_s)}: expected a number of seconds > 0")
    seconds = float(timeout_s)
    if not (math.isfinite(seconds) and 0 < seconds <= MAX_CANDIDATE_TIMEOUT_S):
        raise ValueError(
            f"{name} {timeout_s!r}: expected a finite number of seconds > 0 and at most "
            f"{MAX_CANDIDATE_TIMEOUT_S:g} (one day)"
        )
    return seconds
