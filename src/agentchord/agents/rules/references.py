"""What a noun phrase names in the scene: the offline composer's references.

Objects by name, category word or synonym, colour, size or position among several of a kind
(``the tall bottle``, ``the left block``, ``the red one``: of the kind last named), pronouns for
the last one mentioned, groups (``the cutlery``), a cloth's parts; the table and its regions;
places relative to objects; arms. :class:`Context` holds what the clauses of one instruction
share while they are read (:mod:`agentchord.agents.rules.instructions`).
"""

from __future__ import annotations

import difflib

from agentchord.agents.exceptions import InstructionNotGroundedError
from agentchord.agents.observe import COLOURS
from agentchord.agents.scene import Scene
from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.language import NounPhrase
from agentchord.robot.aloha import other_arm

#: Size words: the candidate with the largest (True) or smallest (False) measure.
SIZE_WORDS = {
    "tall": ("height", True), "taller": ("height", True), "tallest": ("height", True), "high": ("height", True),
    "short": ("height", False), "shorter": ("height", False), "low": ("height", False),
    "big": ("volume", True), "bigger": ("volume", True), "biggest": ("volume", True), "large": ("volume", True),
    "larger": ("volume", True), "largest": ("volume", True), "wide": ("volume", True),
    "small": ("volume", False), "smaller": ("volume", False), "smallest": ("volume", False), "little": ("volume", False),
    "tiny": ("volume", False),
}
#: Words a noun phrase may carry that name nothing (``the bottle of water``, ``the empty cup``).
FILLER_WORDS = frozenset({"water", "empty", "full", "coffee", "object", "thing", "item", "same", "original", "two"})
#: Words for a group of scene objects (``the cutlery``): the category words they stand for.
GROUP_WORDS = {"cutlery": {"fork", "spoon", "knife"}, "utensils": {"fork", "spoon", "knife"}, "silverware": {"fork", "spoon", "knife"},
           "flatware": {"fork", "spoon", "knife"}}
#: Position words among several candidates: (axis, largest) -> the one furthest that way.
POSITION_WORDS = {"left": (0, False), "right": (0, True), "front": (1, False), "near": (1, False), "nearer": (1, False),
                   "closer": (1, False), "back": (1, True), "far": (1, True), "farther": (1, True), "rear": (1, True)}
#: Words for a part of a cloth (``the bottom corners of the towel``, ``its far edge``).
CLOTH_PART_WORDS = frozenset({"corner", "corners", "edge", "edges", "side", "end", "half", "hem"})
CLOTH_SIDE_WORDS = frozenset({"bottom", "top", "near", "far", "front", "back", "lower", "upper", "two", "both", "left", "right", "closest", "furthest"})



def lemma_noun(word: str) -> str:
    """The singular of a plural noun (``blocks`` -> ``block``), or the word."""
    if word.endswith("ies") and len(word) > 4:
        return word[:-3] + "y"
    if word.endswith("es") and word[:-2].endswith(("ss", "sh", "ch", "x")):
        return word[:-2]
    if word.endswith("s") and not word.endswith("ss") and len(word) > 3:
        return word[:-1]
    return word


#: Words for a place drawn or taped on the table (a scene's region).
MARK_WORDS = frozenset({"marked", "mark", "circle", "circled", "taped", "drawn", "outlined", "painted"})
#: Words for a bowl, and the depth / width of a container they may name when the scene has no bowl.
BOWL_WORDS = frozenset({"bowl", "basin", "dish"})
BOWL_DEPTH = (0.3, 1.0)


class Context:
    """What the clauses of one instruction share: the scene, the objects named so far, who holds what.

    It decides what each noun phrase names (:meth:`resolve` and its kin): objects, the table and its
    regions, places relative to objects, arms.
    """

    def __init__(self, scene: Scene, instruction: str) -> None:
        self.scene = scene
        self.instruction = instruction
        self.objects = {o.name: o for o in scene.objects}
        self.cloths = kb.cloth_names(self.objects)
        self.corners = {f"{c}_{k}" for c in self.cloths for k in kb.CLOTH_CORNERS}
        self.mentioned: list[str] = []
        self.held_by: dict[str, str] = {}
        # The arm a pour said holds each vessel: only "both of you put them down" reads it.
        self.pour_arms: dict[str, str] = {}
        #: Objects picked up, poured from or handed over and not yet put down, last taken last:
        #: what ``put it down`` puts down.
        self.in_hand: list[str] = []
        #: Objects taken, moved or placed so far: a put-back of any other is already done (it never left its place).
        self.touched: set[str] = set()
        #: The head noun last named (``block``): what ``the big one`` is one of.
        self.last_kind: str | None = None
        #: How each phrase was read, for ``plan --explain``.
        self.read: list[tuple[str, str, str]] = []
        #: A cloth whose part was taken (``take the near corners of the towel``): a place of it on its other part folds it.
        self.cloth_taken: str | None = None
        #: The side (``left``, ``right``) each anchor last had something put beside it: "the other side" is the other.
        self.sides: dict[str, str] = {}
        #: The object last placed beside (``on the right`` later in the instruction is its right).
        self.last_anchor: str | None = None
        #: The container each object was put into so far: beside it is beside its container ("put the red block in
        #: the cup and the blue one beside the red one": the red one is in the cup, so beside the cup).
        self.inside: dict[str, str] = {}

    def note(self, words: str, role: str, what: str) -> None:
        if (words, role, what) not in self.read:
            self.read.append((words, role, what))

    def error(self, words: str, problem: str) -> InstructionNotGroundedError:
        return InstructionNotGroundedError(self.instruction, f"{words.strip()!r} {problem}")

    def take(self, name: str) -> None:
        self.touched.add(name)
        if name in self.in_hand:
            self.in_hand.remove(name)
        self.in_hand.append(name)

    def resolve_put_down(self, np: NounPhrase) -> list[str]:
        """What a place clause names: ``it`` is the object last taken in hand, else as :meth:`resolve_all`."""
        if np.pronoun == "it" and self.in_hand:
            self.note(np.text, "object", self.in_hand[-1])
            return [self.mention(self.in_hand[-1])]
        return self.resolve_all(np)

    def mention(self, name: str) -> str:
        if name in self.mentioned:
            self.mentioned.remove(name)
        self.mentioned.append(name)
        return name

    # --- noun phrases -------------------------------------------------------------------
    def resolve_all(self, np: NounPhrase) -> list[str]:
        """Scene objects a noun phrase names: one, or several for ``both``, ``them``, ``all``."""
        if np.pronoun in ("all", "them", "they"):
            if not self.mentioned:
                raise self.error(np.text, "has nothing to refer to (name the objects)")
            group = list(self.mentioned) if np.pronoun == "all" else self.mentioned[-2:]
            return sorted(group, key=self.mentioned.index)
        if group := self.group(np):
            return group
        return [self.resolve(np)]

    def group(self, np: NounPhrase) -> list[str]:
        """The objects a plural or collective noun names (``both blocks``, ``the cutlery``), else none."""
        if not np.words or np.of is not None:
            return []
        head = np.words[-1]
        kinds = GROUP_WORDS.get(head) or ({lemma_noun(head)} if lemma_noun(head) != head else set())
        if not kinds:
            return []
        modifiers = [w for w in np.words[:-1] if w not in ("both", "all", "two", "the")]
        pool = [o for o in self.scene.objects if o.name not in self.corners and kb.words(o) & {kb.SYNONYMS.get(k, k) for k in kinds}
                and all(w in kb.words(o) for w in modifiers)]
        if len(pool) < 2:
            return []
        names = [self.mention(o.name) for o in sorted(pool, key=lambda o: o.pos[0])]
        self.note(np.text, "object", " and ".join(names))
        return names

    def resolve(self, np: NounPhrase, exclude: tuple[str, ...] = ()) -> str:
        """The one scene object a noun phrase names (a pronoun: the last one mentioned, not in ``exclude``)."""
        if np.pronoun:
            if np.pronoun in ("all", "them", "they"):
                raise self.error(np.text, "names several objects where one is wanted")
            earlier = [m for m in self.mentioned if m not in exclude]
            only = [o.name for o in self.scene.objects if o.name not in self.corners and o.name not in exclude]
            if not earlier and len(only) == 1:
                # "grab it, give it to the right arm" in a scene with one object: "it" can only be that one.
                earlier = only
            if not earlier:
                raise self.error(np.text, "has nothing to refer to (no object was named before it)")
            if earlier[-1] in self.corners:
                # After a fold, "pick it up" is the whole cloth, which no skill moves (not the corner named last).
                raise self.error(np.text, "is the cloth: the rules fold a cloth, they do not move it")
            self.note(np.text, "object", earlier[-1])
            return earlier[-1]
        if len(np.words) > 1 and np.words[-1] in ("back", "down"):  # "put the bottle back" read as one phrase
            np = NounPhrase(words=np.words[:-1], of=np.of)
        # A synonym ("mug" for the cup) only where the scene has nothing the word itself names (a scene may have a mug).
        named = {w for o in self.scene.objects for w in kb.words(o)}
        words = [w if w in named else kb.SYNONYMS.get(w, w) for w in np.words if w not in FILLER_WORDS] or list(np.words)
        if words[-1] == "one":
            if self.last_kind is None:
                # "the blue one" said first: the one object its other words (a colour) name, if just one.
                rest = [w for w in words[:-1] if w not in ("the", "a", "an")]
                named = [o for o in self.scene.objects if o.name not in self.corners and rest and all(w in kb.words(o) for w in rest)]
                if len(named) != 1:
                    raise self.error(np.text, "has nothing to refer to (name the object)")
                self.note(np.text, "object", named[0].name)
                return self.mention(named[0].name)
            words[-1] = self.last_kind
        if np.of is not None and not words:
            return self.resolve(np.of)
        joined = "_".join(np.words)
        if joined in self.objects:
            if sum(np.words[-1] in kb.words(o) for o in self.scene.objects) > 1:  # a kind with several members: "the red one"
                self.last_kind = np.words[-1]
            self.note(np.text, "object", joined)
            return self.mention(joined)
        sizes = [w for w in words if w in SIZE_WORDS]
        pool = [o for o in self.scene.objects if o.name not in self.corners and o.name not in exclude]
        # A position word picks among several of a kind ("the left block"); of one object it is no modifier.
        positions = [w for w in words if w in POSITION_WORDS and not any(w in kb.words(o) for o in pool)]
        plain = [w for w in words if w not in SIZE_WORDS and w not in positions]
        candidates = [o for o in pool if all(w in kb.words(o) for w in plain)]
        for word in positions:
            if len(candidates) > 1:
                axis, largest = POSITION_WORDS[word]
                candidates = [(max if largest else min)(candidates, key=lambda o, axis=axis: o.pos[axis])]
        if not candidates and plain:
            # The head noun alone may still be unique ("coffee capsule" -> capsule); a colour that
            # does not match is a contradiction, not a modifier to ignore.
            head = [o for o in pool if plain[-1] in kb.words(o)]
            if not head and plain[-1] in BOWL_WORDS:
                # "The bowl" for the scene's one bowl-shaped container: open, about as deep as it is wide
                # (an open cup, not a tall drinking cup or a flat tray).
                head = [o for o in pool if kb.is_container(o) and BOWL_DEPTH[0] <= o.extent[2] / max(o.extent[:2]) <= BOWL_DEPTH[1]]
            # A colour the one object of that kind has ("the white bowl" for the white cup) still describes it.
            if len(head) == 1 and all(c in kb.words(head[0]) for c in set(plain[:-1]) & set(COLOURS)):
                candidates = head
            # Another object's word before the head ("the fork n spoon", "the cup bottle") is a second object the
            # phrase names: reading the head alone would silently drop it.
            others = sorted({o.name for o in pool for w in plain[:-1] if w in kb.words(o) and o not in candidates})
            if candidates and others:
                raise self.error(np.text, f"names {', '.join(others)} as well as the {candidates[0].name}: "
                                          "join two objects with 'and' (the fork and the spoon)")
        for word in sizes:
            if len(candidates) > 1:
                measure, largest = SIZE_WORDS[word]
                key = (lambda o: o.extent[2]) if measure == "height" else (lambda o: o.extent[0] * o.extent[1] * o.extent[2])
                candidates = [(max if largest else min)(candidates, key=key)]
        if not candidates:
            known = sorted({w for o in pool for w in kb.words(o)} | set(self.objects))
            close = difflib.get_close_matches(plain[-1] if plain else np.text, known, n=2, cutoff=0.6)
            hint = f"; did you mean {' or '.join(map(repr, close))}?" if close else ""
            scene_objects = ", ".join(o.name for o in self.scene.objects if o.name not in self.corners) or "no objects"
            raise self.error(np.text, f"names no scene object (the scene has {scene_objects}){hint}")
        if len(candidates) > 1:
            names = ", ".join(o.name for o in candidates)
            raise self.error(np.text, f"is ambiguous: it could be {names}; name one by colour, size or name")
        if plain:
            self.last_kind = plain[-1]
        self.note(np.text, "object", candidates[0].name)
        return self.mention(candidates[0].name)

    def table_place(self, np: NounPhrase) -> tuple[float, float] | None | bool:
        """``False`` when ``np`` is not the table or a region of it; ``None`` for the table itself; else a point."""
        words = list(np.words) + (list(np.of.words) if np.of is not None else [])
        of_table = np.of is not None and set(np.of.words) & kb.TABLE_WORDS
        if set(np.words) <= kb.TABLE_WORDS and np.words and np.of is None:
            return None
        region_words = set(words) & (kb.PART_WORDS | set(kb.DIRECTION_WORDS))
        if not of_table and not set(words) & (set(kb.DIRECTION_WORDS) | kb.TABLE_WORDS | {"center", "middle"}):
            return False  # "the spot", "the area": a part of nothing said; not the table
        if of_table and set(np.words) - kb.PART_WORDS - set(kb.DIRECTION_WORDS) - kb.TABLE_WORDS - FILLER_WORDS - set(POSITION_WORDS) \
                - {"center", "middle", "very", "far", "near", "top", "bottom", "other"}:
            return False  # "the rite side of the table": a word that names no part of it (not the table itself)
        if of_table or (np.of is None and np.words and set(np.words) <= kb.PART_WORDS | set(kb.DIRECTION_WORDS) | kb.TABLE_WORDS and region_words):
            return kb.table_point(words) or (kb.TABLE_CENTER if set(words) & {"center", "middle"} else None)
        return False

    def region(self, np: NounPhrase) -> str | None:
        """The scene region a noun phrase names (``the target region``, ``the target``), if any."""
        words = [w for w in np.words if w not in ("region", "area", "zone", "spot", "position", "place")]
        if not words:
            return None
        if len(self.scene.regions) == 1 and set(words) & MARK_WORDS:
            # "the marked area", "the circle": a place drawn on the table, and the scene has one.
            region = self.scene.regions[0]
            vocabulary = set(region.name.lower().replace("_", " ").split()) | set(region.description.lower().split())
            if all(w in MARK_WORDS or w in vocabulary for w in words):
                return region.name
        for region in self.scene.regions:
            vocabulary = set(region.name.lower().replace("_", " ").split()) | set(region.description.lower().split())
            if region.name.lower() in words or (all(w in vocabulary for w in words) and set(np.words) & {"region", "area", "zone"}):
                return region.name
        return None

    def other_arm(self, obj: str | None) -> str | None:
        """The arm ``the other one|arm|hand`` names: not the one holding ``obj``, else not the one holding what else
        is in hand ("pick up the cup with the left hand, pour the bottle into it with the other one": the right); None
        where what else is in hand has no arm said (the planner gives the free arm).

        Raises:
            InstructionNotGroundedError: Nothing says which arm the other one is not (it is never dropped).
        """
        if obj in self.held_by:
            return other_arm(self.held_by[obj])
        busy = {self.held_by[n] for n in self.in_hand if n != obj and n in self.held_by}
        if len(busy) == 1:
            return other_arm(busy.pop())
        if any(n != obj for n in self.in_hand):
            return None  # what else is in hand is held by an arm the planner chooses: it uses the free one
        raise self.error("the other arm", "says which arm only by the other one, and no arm holds anything yet (say left or right)")

    def arm_of(self, said: str | None, obj: str | None = None) -> str | None:
        if said in ("left", "right"):
            return said
        if said == "other":
            return self.other_arm(obj)
        if said == "both" and obj:  # "both of you set them down": each arm what it holds
            return self.held_by.get(obj) or self.pour_arms.get(obj)
        return self.held_by.get(obj) if obj else None


# --- clauses -> goals ---------------------------------------------------------------------
