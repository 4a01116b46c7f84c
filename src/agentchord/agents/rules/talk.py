"""Talk: what people say around an instruction that states no goal, and what a remark still names.

Used by :mod:`~agentchord.agents.rules.discourse`, a sentence at a time. Greetings, thanks,
hesitations, permission, remarks about the scene ("hi robot", "thanks so much", "um", "is it
possible", "I'm done eating", "it's quite long") state no goal and are dropped; a clause that names
nothing the scene or the rules know (no object, colour, arm, place, direction or action verb) is talk
(:func:`is_talk`). A remark may still say what the next sentence's ``it`` is ("The blue one is in the
way. Move it to the right": :func:`topic_of`, :func:`it_is_topic`), and a sentence that only names an
object already named insists on it ("... Just the fork.": :func:`named_again`). A likeness with a subject ("like when
we are eating dinner", "the way we do at home") says how it should look, not what goes where (:func:`drop_likeness`),
unless it names a scene object.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from agentchord.agents.rules import knowledge as kb

#: Words that make a clause say something about the task (else it is talk).
CONTENT_WORDS = frozenset("""
left right both arm arms hand hands gripper grippers one ones it them they it's its
table corner corners edge edges half halves side sides top bottom near far front back forward forwards behind
center middle target region spot area place there here beside next on onto in into inside under over between
water upright down up away closer nearer
once done when while after before until then and
handover hand-over transfer pour fold swap
""".split())
#: Verbs of the actions the rules know, in any form people write (a clause with one is not talk).
_ACTION_STEMS = ("pour", "empt", "fill", "pick", "grab", "grasp", "take", "took", "hold", "held", "lift", "put", "place",
                 "set", "lay", "laid", "stand", "stood", "drop", "insert", "hand", "pass", "transfer", "give", "gave", "fold",
                 "move", "push", "slide", "shift", "carry", "bring", "brought", "stack", "arrange", "swap", "switch",
                 "return", "get", "go", "went", "leave", "left", "keep", "sit", "lie", "rest", "tip", "decant", "load",
                 "pop", "stick", "nudge", "drag", "turn", "rotate", "spread", "line", "pile", "collect", "fetch",
                 "deposit", "toss", "plop", "release", "let", "pinch", "clean", "tidy", "clear")
#: Interjections and courtesies that open or close a sentence.
OPENERS = re.compile(r"^(?:(?:(?:hi|hello|hey) there|hi|hello|hey|hiya|yo|ok|okay|alright|so|actually|um+|uh+|hmm+|oh|ah|well|sorry|excuse me|"
                      r"good (?:morning|afternoon|evening)|dear robot|robot|hey robot|hi robot|hello robot)(?: ,)?(?: |$))+")
CLOSERS = re.compile(r"(?:^|(?: ,)? )(?:thanks|thank you|thx|ty|cheers)(?: (?:so|very) much| a lot| a bunch| a ton| heaps| in advance)?(?: ,)?"
                      r"(?: (?:robot|buddy|friend))?$")
#: Hesitations anywhere ("and uh pour it") and tags that end a clause ("... a bit yeah", "... lol", "and that's it").
HEDGES = re.compile(r"\b(?:uh+|um+|uhm+|erm+|er)\b(?: ,)?|(?: ,)? (?:yeah|yep|yup|lol|haha|you know|ok\?|and that(?:'s| is) (?:it|all)|"
                    r"that(?:'s| is) (?:it|all)|and that (?:it|all)|if you would|this time|for now|for the moment|for the time being)(?= ,|$)|"
                    # "then you can just put it back": a permission or a question that is the step itself.
                    r"(?:(?<=then )|(?<=and )|(?<=, ))(?:you can|you could|can you|could you|would you) "
                    r"(?!(?:hold|do|use|take)\b)(?=[a-z]+ (?:the|it|them|both|your)\b)")  # "you can hold ...": permission (TALK_SENTENCES)
#: How a table setting is meant ("like for dinner", "like a proper place setting", "like at a restaurant").
SETTING_MANNER = (r"(?:just )?like (?:for (?:dinner|lunch|breakfast|a meal)|(?:a |an )?(?:proper |normal |usual |formal |nice )?"
                   r"(?:place|table|dinner) setting|(?:they do |you'd see |you see |you would see )?(?:at|in) a restaurant)")
#: A likeness said after a step: "like when we are eating dinner", "the way you'd do it at home", "as if you were
#: serving guests": how it should look, never what goes where (a clause with a subject, up to the clause's end).
_LIKENESS = re.compile(r"(?: ,)? (?:just )?(?:like|as if|as though|the way) (?:when |how )?(?:we|you|i|people|they|someone|one|"
                       r"(?:my|our|your|the|his|her) [a-z]+)"
                       r"(?:'re|'d|'m| are| am| were| was| would| do| did| usually)? [a-z' ]+?(?= ,| ;|$)|"
                       # "fold the towel like a sandwich", "like a book": a likeness of a thing (not "i'd like a ...").
                       r"(?<!'d)(?<!\bwould)(?<!\bi)(?<!\bwe)(?<!\byou) (?:just )?like (?:a|an) (?:[a-z]+ )?[a-z]+(?= ,| ;|$)")
#: A purpose said after a step ("so i can eat my soup", "so it's smaller", "so that we have room"): why, never what goes
#: where (a place said in it, "so it's on the left", keeps it: it may be the step's place, and the grammar refuses it).
_PURPOSE = re.compile(r"(?: ,)? (?:so|so that|in order that) (?:i|we|you|it|they|there|he|she)(?:'s|'re|'ll| is| are| can| could| will| have| has"
                      r"| won't| don't| doesn't| takes?| looks?)?(?P<rest>(?: [a-z']+)+?)(?= ,| ;|$)")


def drop_purpose(text: str, objects: frozenset[str], note: Callable[[str], None]) -> str:
    """``text`` without its purposes (:data:`_PURPOSE`) that name nothing the task is about (:func:`is_talk`)."""
    def keep(m: re.Match[str]) -> str:
        if not is_talk(m["rest"].strip(), objects):
            return m[0]
        note("talk")
        return ""
    return re.sub(r"\s+", " ", _PURPOSE.sub(keep, text)).strip()


def drop_likeness(text: str, objects: frozenset[str], note: Callable[[str], None]) -> str:
    """``text`` without its likenesses (:data:`_LIKENESS`); one that names a scene object ("like you did with the fork")
    may say what to do, so it stays (and the grammar refuses it rather than drop it)."""
    def keep(m: re.Match[str]) -> str:
        if any(w in objects or w.rstrip("s") in objects for w in m[0].split()):
            return m[0]
        note("how")
        return ""
    return re.sub(r"\s+", " ", _LIKENESS.sub(keep, text)).strip()


#: Whole sentences or clauses that are talk though they name things: permission, questions about the ask, remarks.
TALK_SENTENCES = [re.compile(p) for p in (
    r"(?:is it|is that|would that be) (?:possible|ok|okay|alright)",
    r"how you do it is up to you", r"(?:it's|it is) up to you",
    r"i(?:'m| am) (?:done|finished|thirsty|hungry|not sure)\b(?:(?! , (?:but|so) ).)*",
    r"(?:and )?(?:i|we) (?:don't|do not|dont) want (?:to|you to|it to)\b.*",
    r"(?:and )?you (?:can|may|could) (?:hold|do|use|take)\b.*(?: if .*)?",
    r"(?:and )?(?:don't|do not|dont) (?:overflow|spill|drop|break)\b.*",
    r"(?:both|all)(?: of them)?(?: (?:vertical|horizontal|straight|too|aligned))?",
    r"(?:just )?once", r"in half",
    r"(?:so |ok |okay )?here(?: is)? (?:the deal|the plan|the task|what i (?:want|need)(?: you to do)?|what to do|how it goes)",
    r"(?:could you |can you |please )?(?:make|get) (?:it|the table|everything|things|this) (?:look )?" + SETTING_MANNER,
    r"(?:and )?(?:we|you|i)(?: can| could| will|'ll| might| shall) [a-z ]+ (?:later|another time|afterwards)",
    r"it(?:'s| is)? (?:quite |very |rather |a bit |so )?(?:long|heavy|big|wide|light|small|wobbly)",
    r"(?:then )?(?:pull|move|bring|take) (?:the |your )?(?:left|right|both) arms? (?:back|away|home)(?: out of the way)?",
    r"(?:the |my )?[a-z ]+ (?:is|are) (?:kind of |sort of |a bit |a little |rather |quite |way |much )*(?:in the way|far away|too far(?: away)?|"
    r"too close|too near|in a bad spot|in the wrong place|not where i want it)(?: (?:to|from) (?:the |me\b|you\b)[a-z ]*)?",
    r"(?:just )?(?:next |close )?to it",
    r"(?:the )?(?:cup|bottle|plate|tray|towel|block|capsule)(?: is)? (?:right )?(?:there|here|over there|in front of you)",
    r"(?:and )?(?:both|they|them|each|all)(?: of them)? (?:should |must |need to )?(?:point|face|pointing|facing|be pointing|be facing)"
    r" (?:forwards?|away(?: from (?:me|you))?|ahead|up|the same way)",
    SETTING_MANNER,
    r"(?:hi|hello|hey|hiya)(?: there| robot| everyone| all| buddy| friend)?",
    # "nothing knocked over", "without spilling anything": what must not happen, which no planned step does.
    r"(?:and )?(?:with )?(?:nothing|none of it|no water) (?:else )?(?:knocked over|spilled|broken|dropped|falling over|fallen over|tipped over|"
    r"on the floor)",
)]


def _lemma_like(word: str) -> bool:
    """Whether ``word`` is a form of an action verb: the stem and an ending (``pours``, ``poured``, ``pouring``)."""
    return any(word == stem or (word.startswith(stem) and word[len(stem):] in _ENDINGS) for stem in _ACTION_STEMS)


_ENDINGS = frozenset({"s", "es", "ed", "d", "ing", "ping", "ped", "ting", "ted", "ling", "led", "ies", "ied", "y", "e", "en", "t"})
#: A remark about the speaker: "i'm so thirsty", "we were busy all day", "i feel tired".
_REMARK = re.compile(r"^(?:and |but |so )?(?:i|we)(?:'m| am|'re| are| was| were| feel| felt|'ve been| have been| had)\b")


def is_talk(clause: str, objects: frozenset[str]) -> bool:
    """Whether a clause names nothing the task is about (no object, colour, arm, place or action verb)."""
    words = clause.replace("'", " ").split()
    if not words:
        return True
    if _REMARK.match(clause):
        # "i'm so thirsty after that meeting": about the speaker; only an object, a colour or an action makes it a task.
        return not any(w in objects or w.rstrip("s") in objects or w in _COLOUR_WORDS or _lemma_like(w) for w in words)
    for word in words:
        if word in objects or word in CONTENT_WORDS or word in kb.DIRECTION_WORDS or word in kb.TABLE_WORDS:
            return False
        if word.rstrip("s") in objects or _lemma_like(word):
            return False
        if word in _COLOUR_WORDS:
            return False
    return True


_COLOUR_WORDS = frozenset({"red", "blue", "green", "yellow", "orange", "white", "black", "grey", "gray", "brown", "purple", "pink"})


def topic_of(sentence: str, objects: frozenset[str]) -> str | None:
    """The object a remark is about: its first noun phrase naming one ("the blue one is kind of in the way")."""
    names = "|".join(sorted((re.escape(w) for w in objects), key=len, reverse=True)) or "(?!)"
    m = re.search(rf"\bthe (?:[a-z]+ )?(?:{names}|one)\b", sentence)
    return m[0] if m is not None else None


def it_is_topic(read: str, topic: str, objects: frozenset[str], note: Callable[[str], None]) -> str:
    """``move it to the right`` after a remark about the blue one: ``move the blue one to the right`` (only where ``it``
    comes before any object is named)."""
    it = re.search(r"\bit\b", read)
    if it is None or any(w in objects or w == "one" for w in read[: it.start()].split()):
        return read
    note("pronoun")
    return read[: it.start()] + topic + read[it.end():]


def named_again(read: str, before: str, objects: frozenset[str]) -> bool:
    """Whether a sentence only names an object already named ("just the fork")."""
    m = re.fullmatch(r"(?:only |just )?(?:the )?([a-z]+)(?: only)?", read.strip())
    return m is not None and m[1] in objects and re.search(rf"\b{m[1]}\b", before) is not None
