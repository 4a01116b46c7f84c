"""Finite numbers: the one rule for every number that enters a graph, a goal or a reply.

NaN passes every comparison test (``nan > 0`` and ``nan <= 0`` are both false), so a
NaN argument or margin is never caught by a range check and fails much later, inside a
solver or the simulator; infinity and absurd magnitudes overflow there too. JSON has no
NaN either: a graph holding one cannot be written back.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterator
from typing import Annotated, Any

from pydantic import Field

from agentchord.guard.exceptions import NonFiniteNumberError

#: Largest magnitude of any number in an action's arguments or a goal (metres, degrees,
#: fractions): far beyond any workspace, small enough that products stay finite.
MAX_MAGNITUDE = 1e6

#: A float field that refuses NaN and infinities (pydantic's own check, with its own message).
FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]


def non_finite(value: Any, max_abs: float = math.inf, where: str = "") -> Iterator[tuple[str, float]]:
    """Every number in a JSON-like value that is NaN, infinite or larger than ``max_abs``.

    Args:
        value: Scalars, mappings, lists and tuples, nested (walked iteratively).
        max_abs: Largest magnitude accepted.
        where: Path prefix of ``value``.

    Yields:
        ``(path, number)``, paths such as ``offset[1]`` or ``args.pos[0]``.
    """
    # Paths are built only for offenders: a large graph has hundreds of thousands of values.
    stack: list[tuple[Any, Any]] = [(value, None)]
    while stack:
        item, link = stack.pop()
        kind = type(item)
        if kind is str or kind is bool or item is None:
            continue
        if kind is float or kind is int:
            if not -max_abs <= item <= max_abs or (kind is float and not math.isfinite(item)):  # NaN fails both
                yield _path(link, where), _as_float(item)
        elif kind is dict or isinstance(item, dict):
            stack += [(v, (link, k, False)) for k, v in item.items()]
        elif kind is list or kind is tuple or isinstance(item, (list, tuple)):
            stack += [(v, (link, i, True)) for i, v in enumerate(item)]
        elif isinstance(item, (int, float)) and not isinstance(item, bool):
            number = float(item)
            if not (math.isfinite(number) and -max_abs <= number <= max_abs):
                yield _path(link, where), number
        elif type(item).__module__ == "numpy" and hasattr(item, "__float__") and getattr(item, "ndim", 0) == 0:
            number = float(item)
            if not (math.isfinite(number) and -max_abs <= number <= max_abs):
                yield _path(link, where), number


def _as_float(number: int | float) -> float:
    # float() of an int past 1e308 overflows: report the largest float instead.
    if isinstance(number, int) and abs(number) > sys.float_info.max:
        return sys.float_info.max if number > 0 else -sys.float_info.max
    return float(number)


def _path(link: Any, where: str) -> str:
    parts = []
    while link is not None:
        link, key, index = link
        parts.append(f"[{key}]" if index else f".{key}")
    text = where + "".join(reversed(parts))
    return text[1:] if text.startswith(".") else text


def describe(number: float, max_abs: float = math.inf) -> str:
    """Why ``number`` is refused, in words."""
    if math.isnan(number):
        return "NaN is not a number: give a finite value"
    if math.isinf(number):
        return f"{'-' if number < 0 else ''}infinity is not allowed: give a finite value"
    return f"{number:g} is out of range: numbers here are at most {max_abs:g} in magnitude"


def check_finite(value: Any, max_abs: float = math.inf, where: str = "") -> Any:
    """``value`` unchanged if every number in it is finite and within ``max_abs``.

    Raises:
        NonFiniteNumberError: The first offending number, with its path.
    """
    for path, number in non_finite(value, max_abs, where):
        raise NonFiniteNumberError(path, number, describe(number, max_abs))
    return value
