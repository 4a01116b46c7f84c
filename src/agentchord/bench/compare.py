"""Two sweeps' records, episode by episode: what changed besides the clock.

A refactor must leave every episode as it was. Wall time and measured compute differ from run to
run; everything else a record holds (success, steps, robot time, path, failures, the modelled
reasoning) is a function of the code and the seed. Pure functions: records in, differences out.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from dataclasses import dataclass, field

#: Fields that differ between two runs of the same code: the machine's clock.
VOLATILE = frozenset({"wall_s", "compute_s", "exec_time_s"})
#: Execution time less measured compute and reasoning must agree within this (s): it is robot time.
ROBOT_TOLERANCE_S = 2e-3


@dataclass
class Comparison:
    """What differs between two sweeps on the episodes both ran.

    Attributes:
        compared: Episodes in both.
        only_before: Episode ids only the first holds.
        only_after: Episode ids only the second holds.
        changed: Episode id -> the fields that differ (volatile ones left out).
        by_method: Method -> field -> how many of its episodes differ in it.
    """

    compared: int = 0
    only_before: list[str] = field(default_factory=list)
    only_after: list[str] = field(default_factory=list)
    changed: dict[str, list[str]] = field(default_factory=dict)
    by_method: dict[str, Counter] = field(default_factory=lambda: defaultdict(Counter))

    @property
    def identical(self) -> bool:
        """Whether every episode both ran is the same, field for field."""
        return not self.changed


def compare_records(before: list[dict], after: list[dict]) -> Comparison:
    """Compare two sweeps' records by episode id, every field but the volatile ones."""
    first = {r["id"]: r for r in before}
    second = {r["id"]: r for r in after}
    out = Comparison(only_before=sorted(set(first) - set(second)), only_after=sorted(set(second) - set(first)))
    for key in sorted(set(first) & set(second)):
        a, b = first[key], second[key]
        out.compared += 1
        fields = sorted(f for f in set(a) | set(b) if f not in VOLATILE and a.get(f) != b.get(f))
        if all(f in a and f in b for f in ("exec_time_s", "compute_s", "reasoning_s")):
            rest_a = a["exec_time_s"] - a["compute_s"] - a["reasoning_s"]
            rest_b = b["exec_time_s"] - b["compute_s"] - b["reasoning_s"]
            if abs(rest_a - rest_b) > ROBOT_TOLERANCE_S:
                fields.append("exec_time_s - compute_s - reasoning_s")
        if fields:
            out.changed[key] = fields
            for name in fields:
                out.by_method[a.get("method", "?")][name] += 1
    return out


def comparison_markdown(comparison: Comparison) -> str:
    """The comparison as Markdown: a line of totals, and a row per method with differences."""
    lines = [f"{comparison.compared} episodes in both; {len(comparison.changed)} differ "
             f"(wall time and measured compute left out); {len(comparison.only_before)} only before, "
             f"{len(comparison.only_after)} only after."]
    if comparison.changed:
        lines += ["", "| Method | Field | Episodes |", "|---|---|---|"]
        for method in sorted(comparison.by_method):
            for name, count in sorted(comparison.by_method[method].items()):
                lines.append(f"| {method} | {name} | {count} |")
    return "\n".join(lines) + "\n"
