"""The names an expression may use: the language's functions, and a task's objects and arms."""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

from agentchord.expr.library import LIBRARY, Function
from agentchord.expr.templates import TEMPLATE_FUNCTIONS
from agentchord.features.frame import ARMS, FeatureFrame

#: Every callable of the language (library, then templates), by name.
CALLABLES: MappingProxyType[str, Function] = MappingProxyType({**LIBRARY, **TEMPLATE_FUNCTIONS})
#: Callable name -> one-line description with its signature (for prompts and messages).
FUNCTIONS: MappingProxyType[str, str] = MappingProxyType({n: f.description for n, f in CALLABLES.items()})


@dataclass(frozen=True)
class Vocabulary:
    """The names an expression may use.

    Attributes:
        objects: Object names of the task (``bottle``, ``cup``).
        arms: Arm names of the robot.
    """

    objects: frozenset[str]
    arms: frozenset[str] = frozenset(ARMS)

    def __post_init__(self) -> None:
        # Accept any iterable of names, but keep the dataclass hashable and immutable.
        for field_name in ("objects", "arms"):
            names = getattr(self, field_name)
            if isinstance(names, str):
                raise TypeError(f"Vocabulary.{field_name} must be a collection of names, not the string {names!r}")
            names = frozenset(names)
            for name in names:
                if not isinstance(name, str) or not name.isidentifier() or is_dunder(name):
                    raise ValueError(
                        f"Vocabulary.{field_name}: {name!r} cannot be used in expressions "
                        "(names must be identifiers that neither start nor end with '__')"
                    )
            object.__setattr__(self, field_name, names)
        if clash := self.objects & self.arms:
            raise ValueError(f"Vocabulary: {', '.join(sorted(clash))} named both an object and an arm")

    @classmethod
    def from_frame(cls, frame: FeatureFrame) -> Vocabulary:
        """The objects and arms present in ``frame``."""
        return cls(objects=frozenset(frame.objects), arms=frozenset(frame.arms))

    def describe(self) -> str:
        """``objects: bottle, cup; arms: left, right`` (for messages)."""
        objects = ", ".join(sorted(self.objects)) or "none"
        return f"objects: {objects}; arms: {', '.join(sorted(self.arms)) or 'none'}"


def is_dunder(name: str | None) -> bool:
    """Whether ``name`` starts or ends with ``__`` (never readable in an expression)."""
    return name is not None and (name.startswith("__") or name.endswith("__"))
