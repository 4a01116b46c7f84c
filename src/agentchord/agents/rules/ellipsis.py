"""Ellipsis: a step said again for another object ("and the bottle too", "do the same with the spoon on the right",
"same thing with the spoon on the other side").

Used by :mod:`~agentchord.agents.rules.discourse`, a clause or a sentence at a time: the step before, with the object
named in its object's place (and the side named, or the other side of the one said before, in its side's place).
"""

from __future__ import annotations

import re
from collections.abc import Callable

#: "and the bottle too", "then the red one as well": the step before, for another object.
_TOO = re.compile(r"^(then |and |and then )?(?:also )?((?:the )?[a-z]+(?: [a-z]+)?|it|them) (?:too|as well|also)$")
#: "do the same with the spoon (on the right)": the step before, for another object (and side).
_SAME = re.compile(r"^(then |and |and then )?(?:(?:do|repeat) (?:the same|that|the same thing|it)|(?:the )?same(?: thing)?(?: again)?) (?:with|for|to) "
                   r"((?:the )?[a-z]+(?: [a-z]+)?)(?: (?:on|to|at) (?:the )?(left|right|other)(?: side)?(?: of it)?)?$")


def is_again(clause: str) -> bool:
    """Whether a clause only says the step before again, for another object."""
    return bool(_TOO.match(clause) or _SAME.match(clause))


def again(clause: str, before: str, objects: frozenset[str], note: Callable[[str], None]) -> str:
    """``the bottle too`` / ``do the same with the spoon on the right`` after a step: that step again, for the
    object named (and on the side named)."""
    too, same = _TOO.match(clause), _SAME.match(clause)
    match = too or same
    if match is None:
        return clause
    lead, new = match[1] or "", match[2]
    if new not in ("it", "them") and not new.startswith("the "):
        new = "the " + new
    if not any(w in objects or w == "one" for w in new.split()[1:]) and new not in ("it", "them"):
        return clause
    step = before.removeprefix("then ")
    names = "|".join(sorted((re.escape(w) for w in objects), key=len, reverse=True)) or "(?!)"
    found = re.search(rf"\bthe (?:[a-z]+ )*?(?:{names}|one)\b|\b(?:it|them)\b", step)
    if found is None:
        return clause
    again = step[: found.start()] + new + step[found.end():]
    if same is not None and same[3] == "other":  # "on the other side": the side said before, flipped; unsaid, refused
        flip = {"left": "right", "right": "left"}
        if not re.search(r"\b(?:left|right)\b", again):
            return clause
        again = re.sub(r"\b(left|right)\b", lambda m: flip[m[1]], again)
    elif same is not None and same[3]:
        other = "left" if same[3] == "right" else "right"
        again = re.sub(rf"\b{other}\b", same[3], again) if re.search(rf"\b{other}\b", again) else again
    note("ellipsis")
    return (lead + again).strip()
