"""What each sentence and clause of an instruction contributes, read before the phrasing rewrites.

People wrap what they ask in talk the grammar has no rule for, and name the doer of a step where the
grammar expects an imperative. On the normalised text (sentences split by ``;``, clauses by ``,``),
a sentence at a time:

- **talk** (:mod:`~agentchord.agents.rules.talk`): greetings, thanks, hesitations and remarks ("hi
  robot", "thanks so much", "um", "is it possible", "just a splash is fine"): a clause that names nothing
  the scene or the rules know states no goal and is dropped; a remark still says what a later ``it`` is;
- **things left as they are**: "leave the cup alone", "the red one stays where it is", "don't touch
  the fork", "you don't need to move the tray", a negated step ("don't pour anything"): no goal;
- **arms as subjects**: "left arm picks up the block", "the right hand pours", "have the right one
  put it in the tray", "left arm, grab ..." -> the imperative with ``with the left arm``;
- **ordinal steps**: "first ..., second ..., third ...", "after that", "afterwards", "finally" ->
  steps in order; "... first" at a clause's end is dropped (the order is the order said);
- **how, not what**: "at the same time", "one in each hand", "use both hands for that": the
  planner chooses the arms' timing; dropped;
- a flat utensil "pointing away from you" / "facing forward" beside a plate is how it is laid
  anyway (dropped).

A kind of phrasing with rules of its own is read by its module, called from here in this order:
a swap and the verbs' frames (:mod:`~agentchord.agents.rules.verbs`), the cloth's parts
(:mod:`~agentchord.agents.rules.cloth_parts`), an arm for each object and arms named without
``with the ... arm`` (:mod:`~agentchord.agents.rules.arm_words`), places and directions
(:mod:`~agentchord.agents.rules.places`), end states and verbless steps, a clause at a time
(:mod:`~agentchord.agents.rules.end_states`), the order objects are done in
(:mod:`~agentchord.agents.rules.ordinals`); across sentences, a pour said to be done holding the
vessel (:mod:`~agentchord.agents.rules.held_pour`).

Every change is recorded as a step (``talk``, ``left as is``, ``arm``, ``order``, ``how``,
``direction``) for ``plan --explain``.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from agentchord.agents.rules.arm_words import each_arm, not_this_arm, read_arms
from agentchord.agents.rules.cloth_parts import FOLD, drop_fold_way, read_cloth_parts, refuse_fold_across
from agentchord.agents.rules.ellipsis import again, is_again
from agentchord.agents.rules.end_states import END_STATE, read_end_state
from agentchord.agents.rules.ordinals import ANY_ORDER, each_in_order, each_of_list, first_before, first_of_both
from agentchord.agents.rules.held_pour import hold_before_pour, take_conditions
from agentchord.agents.rules.places import read_places, restates, there_is_last_place
from agentchord.agents.rules.talk import (
    CLOSERS,
    HEDGES,
    OPENERS,
    SETTING_MANNER,
    TALK_SENTENCES,
    is_talk,
    it_is_topic,
    named_again,
    topic_of,
)
from agentchord.agents.rules.verbs import read_swap, read_verbs
from agentchord.agents.rules.rewrite_steps import NotAGoalError, drop as _drop, sub as _sub

#: A clause that leaves an object as it is: no goal.
_LEFT_AS_IS = [
    re.compile(r"^(?:and )?(?:but )?(?:please )?(?:leave|keep) (?:the |that |this )?[a-z ]+? "
               r"(?:alone|where it is|where they are|as it is|as they are|in place|untouched|where it was|there|on the table)$"),
    re.compile(r"^(?:and )?(?:but )?(?:do not|don't|dont|no need to|you don't need to|you do not need to|you dont need to)"
               r" (?:touch|move|bother with|bother|worry about) [a-z ' ]+$"),
    # a negated step ("don't pour anything", "never drop it") states no goal; "don't forget to ..." does
    # (never one that names an arm: "don't use your left arm" says who does the work, it is read or refused, not dropped)
    re.compile(r"^(?:and )?(?:but )?(?:please )?(?:do not|don't|dont|never) (?!forget\b|fail\b)(?![a-z ' ]*\b(?:arm|hand|gripper)s?\b)[a-z ' ]+$"),
    re.compile(r"^(?:and )?(?:the |that )?[a-z ]+? (?:stays|stay|remains|should stay|can stay) (?:where it is|put|as it is|there)$"),
    re.compile(r"^(?:just |only )?(?:the \w+ )?(?:and )?(?:don't|do not|dont) (?:just )?(?:slide|drag|push) it$"),
]
#: The same inside a clause, after "and" or "but".
_LEFT_AS_IS_INSIDE = re.compile(
    r"(?: ,)? (?:and|but) (?:(?:please )?(?:leave|keep) (?:the |that |this )?[a-z ]+? (?:alone|where it is|where they are|as it is|"
    r"in place|untouched)|(?:do not|don't|dont) (?:touch|move) (?:the |that |this )?[a-z ]+?)(?= ,|$)")
#: How the arms share the work, when the goal says what: the planner chooses it.
_HOW = [
    re.compile(r"\b(?:at (?:the )?same time|simultaneously|together|in one go|in parallel|(?:both |all )?at once)\b"),
    # "fold it once": one time, the adverb (not "once S", a condition: that has a clause after it).
    re.compile(r"(?<=[a-z]) (?:just )?once(?= ,|$| so\b| with\b| and\b| then\b| in half\b| only\b)"),
    re.compile(r"(?: ,)? (?:just )?(?:like|as|the way) (?:it|they) (?:is|are|was|were|stands?|stand)(?: now| right now| at the moment)?(?= ,|$)"),
    re.compile(r"(?: ,)? (?:one (?:in|with|per) (?:each|every) (?:hand|arm|gripper)|one per (?:hand|arm|gripper)|"
               r"one (?:for|with) each (?:hand|arm)|one (?:on|at|to) (?:each|either) side(?: of (?:it|them|the [a-z]+))?)\b"),
    re.compile(r"(?:^|(?: ,)? )(?:you'll|you will|you'd|you) (?:probably )?need (?:both|two) (?:hands?|arms?)(?: for (?:that|this|it))?$"),
    # "try to keep it standing (up)": how it is carried (a placed object stands anyway); the manner word may be gone already.
    re.compile(r"(?:^|(?: ,)? )(?:and )?try (?:to|and) keep (?:it|them|the [a-z]+)(?: (?:standing|upright|steady|level|vertical|straight)(?: up)?)?"
               r"(?: (?:if you can|if possible))?$"),
]
#: Arm words a subject may be.
_ARM_SUBJECT = re.compile(
    r"^(?:and )?(?:(?:can|could|will|would|should|let|have|make) )?(?:the |your )?(left|right)(?: (?:arm|hand|gripper|one|side))?"
    r"(?: ,| :)? (?!(?:arm|hand|gripper)\b)(\w+)\b(.*)$")
_BOTH_SUBJECT = re.compile(r"^(?:and )?(?:then )?(?:both (?:of you|arms?|hands?|grippers?)|both|(?:the )?two (?:arms|hands|grippers)|the arms|"
                           r"(?:the )?left and (?:the )?right(?: (?:arms?|hands?|grippers?|ones?))?|"
                           r"(?:the )?right and (?:the )?left(?: (?:arms?|hands?|grippers?|ones?))?) (\w+)\b(.*)$")
#: Ordinal words that open a step.
_ORDINAL = re.compile(r"^(?:and )?(?:first(?:ly)?|second(?:ly)?|third(?:ly)?|fourth|next|after that|afterwards|after this|"
                      r"after(?= (?:(?:both|(?:the )?two) (?:(?:arms?|hands?) )?)?"
                      r"(?:put|set|place|lay|stand|move|give|hand|pour|take|grab|pick|carry|bring|fold|lift)\b)|"
                      r"then after that|finally|lastly|last|to finish|and finally|and then|and after that)(?: ,)? ")
_TRAILING_ORDER = re.compile(r" (?:first|afterwards|after that|after it|after them|at the end|in the end|when (?:you(?:'re| are)?|ur|your) done|"
                             r"when finished|after|last|this time|for me)$")
#: "the marked circle on the right": a drawn place, its side only describing it.
_MARKED_ON_SIDE = re.compile(r"\b((?:the )?(?:marked |taped |drawn |painted |target )?(?:circle|area|spot|zone|region|mark|target)) (?:on|to|at) the "
                             r"(?:left|right)(?: side| half)?(?: of the table)?(?= ,|$| then\b| and\b| with\b)")
#: "with one hand ... with the other": two arms, the planner's to choose.
_ONE_AND_OTHER = (re.compile(r" with one (?:hand|arm|gripper)\b"), re.compile(r" with the other arm\b"))
_POINTING = re.compile(r"(?: ,)? (?:and )?(?:both |each )?(?:of them )?"
                       r"(?:(?:with )?(?:the )?handles? (?:towards?|facing|nearest|closest to|to) (?:you|me|the robot)|"
                       r"(?:pointing|facing|oriented|aimed|tips?|handles?)"
                       r" (?:away from (?:me|you|the robot)|forwards?|ahead|straight ahead|to the far side|away|up|north)"
                       r"(?: \( ?tips away from (?:me|you) ?\))?)\b")


#: "both lying up-and-down instead of sideways (like they are now)": pointing away from the robot, how a utensil beside a
#: plate is laid anyway (never "sideways" or "across": those stay, and are not read).
_UP_AND_DOWN = re.compile(r"(?: ,)? (?:and )?(?:both |each |all )?(?:of them )?(?:lying|pointing|facing|oriented|turned|laid|placed|set) "
                          r"(?:up-and-down|up and down|front-to-back|front to back|vertically|vertical)"
                          r"(?: instead of (?:sideways|across|left-right|left to right|horizontally|horizontal)"
                          r"(?: like (?:they|it) (?:are|is|were|was)(?: now| right now)?)?)?(?= ,|$)")


#: Shorthand people type -> the word.
_SHORTHAND = [(re.compile(r"\b(?:pls|plz|plse|ple+a+s+e+)\b"), ""), (re.compile(r"\bw/ ?|\bw (?=the |your |my |both |left |right )"), "with "),
              (re.compile(r"\bur\b"), "your"), (re.compile(r"\bu\b"), "you"), (re.compile(r"\bthx\b"), "thanks"),
              (re.compile(r"\bem\b"), "them"), (re.compile(r"\bfwd\b"), "forward"),
              (re.compile(r"\bl (?=arm|hand|gripper)\b"), "left "), (re.compile(r"\br (?=arm|hand|gripper)\b"), "right ")]
#: Vague amounts and distances: the goal has none (a pour is a pour; a nudge is the rules' nudge).
_AMOUNT = re.compile(r"(?: ,)? (?:just |only |maybe )?(?:like )?(?:a (?:little|tiny|small|wee) (?:bit )?(?:of )?|a bit(?: more)?(?: of)? |"
                     r"some |a splash of |a drop of |a little more |a few centimet(?:er|re)s |about \w+ (?:cm|centimet(?:er|re)s|mm)(?: or so)? |"
                     r"(?:roughly |about |around )?\d+ ?(?:cm|centimet(?:er|re)s)(?: or so)? )(?=water\b|with\b|$| ,| then\b| and\b)")
_AMOUNT_TAIL = re.compile(r"(?: ,)? (?:just |only |maybe )?(?:like )?(?:a (?:little|tiny|small) bit|a bit|a little|slightly|somewhat|"
                          r"(?:roughly |about |around )?(?:\d+|ten|five|a few) ?(?:cm|centimet(?:er|re)s)(?: or so)?)(?= ,|$| then\b| and\b)")
#: Particles of phrasal verbs that add nothing to the goal.
_PARTICLES = [
    (re.compile(r"\b(pick|lift|take|hold|raise|stand|set|get) (it|them|the [a-z]+(?: [a-z]+)?) (?:back )?up\b"), r"\1 \2"),
    (re.compile(r"\b(hold|lift|raise|pick|take|fill) up (?=the |it\b|them\b|my )"), r"\1 "),
    (re.compile(r"\bmy (?=\w+\b)"), "the "),
    (re.compile(r"\b(move|slide|bring|shift|carry|push|put|set) (it|them|the [a-z]+(?: [a-z]+)?) over "
                r"(?=to |next |beside |by |near |close |onto |on |into |in |,|$)"), r"\1 \2 "),
    (re.compile(r"\b(hand|pass|give) (it|them|the [a-z]+(?: [a-z]+)?) (?:off|across|over) (?=to )"), r"\1 \2 "),
    (re.compile(r"\b(stand|set|put) (it|them|the [a-z]+(?: [a-z]+)?) back up\b"), r"\1 \2 back"),
    (re.compile(r"\bleave (the \w+|it) standing up\b"), r"leave \1 standing"),  # put back, below
    (re.compile(r"\b(?:standing|sitting|stood) up\b"), ""),
    # "keep it in the air" (the place dropped already), "keep the cup up": holding it, as a step.
    (re.compile(r"\bkeep (it|them|the [a-z]+(?: [a-z]+)?)(?: (?:held|lifted|raised|up|aloft))*(?= ,|$| and\b| then\b| while\b)"), r"hold \1"),
]
#: Where a pour happens, said beside it: the goal is the pour (holding the cup is said by "hold").
_IN_THE_AIR = re.compile(r"(?: ,)? (?:in (?:the )?(?:mid-? ?air|air)|up in the air|off the table|above the table|over the table)\b")
#: A table setting's manner said after it: ", like a proper place setting", "like they do at a restaurant".
_LIKE_A_SETTING = re.compile(rf"(?: ,)? {SETTING_MANNER}(?= ,|$)")


#: Cleanups once a sentence's clauses are read: states and particles left at a clause's end.
_LAST = [
    (re.compile(r" after (?:it|them|that)(?= with| ,|$)"), "", "order"),
    (re.compile(r"(?:^|(?: ;| ,) )(?:you'll|you will|you'd|you) (?:probably )?need (?:both|two) (?:hands?|arms?)(?: for (?:that|this|it))?(?= ,|$)"),
     "", "how"),
    (re.compile(r"(?: ,)+ ,"), " ,", "shorthand"),
    (re.compile(r"\bgive (?:some )?water (?:from (?:the )?(\w+) )?(?=into|in|to)\b"), r"pour water from the \1 ", "verb"),
    (re.compile(r"\b(hold|lift|take|pick) ([^,]+?) , (?:then )?pour(?= with| ,|$)"), r"\1 \2 , pour into it", "ellipsis"),
    (re.compile(r"^(?:set|lay) (?:up )?the table(?: properly)?(?: for me)? , "), "", "talk"),
    (re.compile(r"(?: ,)? with the (?:folded edge|fold|crease|fold line|folded side) (?:on the side |at the side |on the edge )?"
                r"(?:nearest|closest|near|nearer|closer|towards?|facing)(?: to)? (?:me|you|the robot)"), "", "cloth part"),
    (re.compile(r"(?: ,)? lying on the (?:top|far) half(?: of where it is(?: now)?)?"), "", "cloth part"),
    (re.compile(r" (?:standing up|sitting up|standing|sitting|lying|upright)(?= ,|$)"), "", "how"),
    (re.compile(r" while it(?:'s| is)?(?= ,|$)"), "", "how"),
    (re.compile(r"\b(fill|lift|hold|pick|take) (the \w+|it|them) up\b"), r"\1 \2", "particle"),
]
#: A sentence that only names what follows ("end result", "the goal").
_TITLE = re.compile(r"(?:the )?(?:end result|result|goal|final state|end state|target state|plan|steps?)")
#: How an arm is asked for: "use your left hand (this time) to pick ...", "use right arm only".
_USE_ARM = re.compile(r"^(?:please )?(?:use|using) (?:your |the )?(left|right|both) (?:arm|hand|gripper)s?(?: (?:only|this time))*"
                      r"(?: (?:to|for|and) (.+))?$")
#: The tray's handles are how it is carried: "by both handles", "using the two handles", "grab both handles" (the tray).
_HANDLES = [
    (re.compile(r"(?: ,)? (?:by|using|with|at) (?:both|its|the two|the|its two|both of its|the) handles?\b"), ""),
    # "lift the tray by the two ends", "hold it at both sides": where it is gripped, not where it goes.
    (re.compile(r"(?: ,)? (?:by|at|from) (?:both|the two|its two|both of its|either|each|its|the) (?:ends?|sides?)(?= ,|$| and\b| then\b)"), ""),
    (re.compile(r"\b(grab|take|hold|grasp|pick up) (?:both|the two|the|its) handles?\b"), r"\1 the tray"),
]




#: A sentence that only names the action ("Bimanual pour:"), the verb of a verbless step after it ("bottle into cup").
_ACTION_TITLE = re.compile(r"(?:(?:bimanual(?:ly)?|two-?handed|one-?handed|single-?arm|dual-?arm) )?(?:pour|pouring|stack|stacking|fold|folding)"
                           r"(?: task| job)?")
_VERBLESS_START = re.compile(r"^(?:the )?[a-z]+(?: [a-z]+)? (?:into|in|onto|on|over) ")


def _titled(sentences: list[str], note: Callable[[str], None]) -> list[str]:
    """``bimanual pour ; bottle into cup`` -> ``bimanual pour bottle into cup``: the title's verb is the step's."""
    out: list[str] = []
    for sentence in sentences:
        if out and _ACTION_TITLE.fullmatch(out[-1].strip()) and _VERBLESS_START.match(sentence.strip()):
            out[-1] = f"{out[-1].strip()} {sentence.strip()}"
            note("verb")
            continue
        out.append(sentence)
    return out


def read_sentences(sentences: list[str], objects: frozenset[str], note: Callable[[str], None],
                   verb: Callable[[str], str | None]) -> list[str]:
    """Each sentence read (:func:`read_sentence`); a sentence that only names an arm ("use the right arm only")
    names the arm of every step after it."""
    sentences = each_of_list(sentences, note)
    sentences = there_is_last_place(sentences, note)
    sentences = _titled(sentences, note)
    if len(sentences) > 1 and _ARM_ALONE.fullmatch(sentences[-1].strip()):
        sentences = [sentences[-1], *sentences[:-1]]  # "Put the block in the cup. Use your left hand.": the arm of the steps before
    out: list[str] = []
    arm: str | None = None
    held: list[tuple[str, str]] = []  # what a pour is said to be done holding, and by which arm ("hold it up while you pour")
    topic: str | None = None  # an object a remark names ("the blue one is in the way"), for an "it" after it
    for k, sentence in enumerate(sentences):
        sentence, holds = take_conditions(sentence, note)
        held += holds
        if not sentence:
            continue
        if k < len(sentences) - 1 and _TITLE_SENTENCE.fullmatch(sentence.strip()):
            note("talk")  # "Can you set the table? The fork ...": the sentences after it say how
            continue
        alone = _ARM_ALONE.fullmatch(sentence.strip())
        if alone is not None:
            arm = alone[1]
            note("arm")
            continue
        if arm is not None and not re.match(r"^armheading ", sentence) and not re.search(r"\b(?:left|right|both) (?:arm|hand|gripper)", sentence):
            sentence = f"armheading {arm} , {sentence}"
        if out and restates(sentence, out[-1]):
            note("place")  # "Move the cup next to the bottle. Like right beside it."
            continue
        heading = re.match(r"^(?:armheading (left|right|both)|(left|right|both) (?:arm|hand|gripper)s?) , ", sentence)
        bare = sentence[heading.end():] if heading else sentence
        if out and is_again(bare):
            said = again(bare, re.split(r" , | then ", out[-1])[-1], objects, note)
            if said != bare:  # "Put the red block in the cup. Then the blue one as well."
                if heading is not None:  # "Right arm, do the same with the spoon": the step again, by the arm addressed
                    said = re.sub(r" with the (?:left|right|both) arms?\b", "", said) + f" with the {heading[1] or heading[2]} arm"
                out.append(said if said.startswith("then ") else f"then {said}")
                continue
        if out and (ordered := first_of_both(out[-1], sentence)) is not None:
            out[-1] = ordered  # "Put both blocks in the cup. Red one first, then the blue one."
            note("order")
            continue
        read = read_sentence(sentence, objects, note, verb)
        if not read:
            topic = topic_of(sentence, objects) or topic  # "The fork is too far away. Can you move it ...": what "it" is
            continue
        if topic is not None:
            read = it_is_topic(read, topic, objects, note)
            topic = None
        if out and named_again(read, " ".join(out), objects):
            note("talk")  # "... move the fork next to the plate. Just the fork.": said again, to insist
            continue
        if k < len(sentences) - 1 and _TITLE_SENTENCE.fullmatch(read):
            note("talk")  # "Could you set up the coffee tray? The capsule goes ...": the sentences after it say how
            continue
        if out and read == "hand it over" and (placed := _PLACE_STEP.match(out[-1])) is not None and placed[1] != "it":
            obj = placed[1] if placed[1].startswith("the ") else f"the {placed[1]}"
            out[-1] = f"hand {obj} over , then {out[-1]}"  # the sentence before, done by a hand-over
            note("order")
            continue
        out.append(read)
    if held:
        with_hold = hold_before_pour(out, held)
        if with_hold is None:
            raise NotAGoalError(f"'{held[0][0]}' is to be held while pouring, but no pour is said")
        out = with_hold
    return out


#: A hand-over said as the way of doing a step: "use a handover", "do it via handover".
_BY_HANDOVER = re.compile(r"^(?:and )?(?:then )?(?:use|using|do it (?:via|with|by|using)|via|with|by|through) (?:a )?handover(?: please)?$")
#: A hand-over with no place of its own ("hand it across", "hand the block over").
_HANDOVER_ALONE = re.compile(r"(?:and )?(?:hand|pass|give) (it|them|the [a-z]+(?: [a-z]+)?) over")  # no "then": the way, not a next step
#: A step that takes an object somewhere ("get the block onto the target").
_PLACE_STEP = re.compile(r"(?:(?:get|put|place|move|bring|take|carry|set) )?((?:the )?[a-z]+(?: [a-z]+)?|it) (?:over )?(?:onto|on|to|into|in|at) ")
#: A sentence that names the job the sentences after it spell out.
_TITLE_SENTENCE = re.compile(r"(?:(?:could|can|would|will) you |please )*(?:set|lay) (?:up )?the table(?: properly)?(?: for me)?(?: please)?|"
                             r"(?:(?:could|can|would|will) you |please )*(?:(?:set up|prepare) (?:the |my )?[a-z]+(?: [a-z]+)?|"
                             r"get (?:the |my )?[a-z]+(?: [a-z]+)? (?:ready|set up)|"
                             r"(?:arrange|rearrange|set out|lay out|sort out|organi[sz]e|tidy(?: up)?) (?:the |my )?[a-z]+(?: [a-z]+)?)")
#: Verbs that start a step joined by "and" ("pick up the bottle and pour ...").
_VERB_STARTS = ("pick", "take", "grab", "grasp", "hold", "lift", "put", "place", "set", "lay", "stand", "drop", "pour", "fill",
                "empty", "hand", "pass", "give", "move", "carry", "bring", "push", "slide", "fold", "stack", "insert")
#: A put-back with no place of its own: by the arm that holds the object, not the arm "use ... to" asks for.
_PUT_BACK = re.compile(r"(?:then )?(?:put|set|place|stand|leave) (?:it|them|both|the [a-z]+(?: [a-z]+)?) (?:back|down)(?: down)?"
                       r"(?: where (?:it|they) (?:was|were)(?: before)?| in (?:its|their) place)?")
#: A sentence that only says which arm does the work.
_ARM_ALONE = re.compile(r"(?:please )?(?:(?:use|using|with) )?(?:only )?(?:your |the )?(left|right|both) (?:arm|hand|gripper)s?(?: only)?(?: please)?")


def read_sentence(sentence: str, objects: frozenset[str], note: Callable[[str], None], verb: Callable[[str], str | None]) -> str:
    """The sentence with its talk, things left as they are and how-clauses dropped, arms as subjects moved
    into ``with the ... arm`` and ordinal steps as ``then``.

    Args:
        sentence: One normalised sentence (clauses separated by `` , ``).
        objects: The words naming scene objects.
        note: Records a step's name (for ``--explain``).
        verb: The verb a word is a form of (``picks`` -> ``pick``), or None when it is not one the rules read.

    Raises:
        NotAGoalError: A fold across the cloth (left onto right), which no rule makes.
    """
    s = sentence
    for pattern, repl in _SHORTHAND:
        s = _sub(pattern, repl, s, note, "shorthand")
    s = read_swap(s, note)
    heading = re.match(r"^armheading (left|right|both) , ", s)
    if heading is not None:
        s = s[heading.end():]
    refuse_fold_across(s)
    s = _drop(OPENERS, s, note, "talk")
    s = _drop(CLOSERS, s, note, "talk")
    s = _drop(HEDGES, s, note, "talk")
    s = not_this_arm(s, note)
    s = _drop(re.compile(r"\b(?:for me|for you|if you can|if possible|if that's ok|if it(?:'s| is)? no (?:trouble|bother|problem)|"
                         r"if you don't mind|if that's easier(?: for you)?|though)\b"), s, note, "talk")
    s = _drop(re.compile(r"(?: ,)? (?:is|would be|'s|will be) (?:fine|good|ok|okay|enough|great|perfect|all)(?= ,|$)"), s, note, "talk")
    if re.fullmatch(r"(?:go|do it|start|begin|go ahead|that's all|that is all|done)", s) or any(t.fullmatch(s) for t in TALK_SENTENCES):
        note("talk")
        return ""
    if not re.search(r"\b(?:pour|fill|empt)", s):  # for a pour, both arms say who holds the cup; else how it is carried
        s = _drop(re.compile(r"(?:^|(?: ,)? )(?:(?:use|using|with) )?(?:both|two|the two) (?:of your )?(?:hands?|arms?|grippers?)"
                             r"(?: for (?:that|this|it|the [a-z]+))?(?: at the same time)?$"), s, note, "how")
    s = _drop(_LEFT_AS_IS_INSIDE, s, note, "left as is")
    s = _drop(ANY_ORDER, s, note, "order")
    stated = _drop(END_STATE, s, note, "end state")
    if stated != s:  # "I want water in the cup and the bottle where it was": two end states
        stated = re.sub(r" and (?=(?:the|my|both) )", " , ", stated)
    s = stated
    s = _sub(re.compile(r"\bthe whole thing\b"), "it", s, note, "pronoun")
    s = _drop(re.compile(r"(?: ,)? (?:and )?(?:let go|release it|release them|go)$"), s, note, "talk")
    for pattern, repl in _HANDLES:
        s = _sub(pattern, repl, s, note, "handles")
    s = read_cloth_parts(s, objects, note)
    if s == FOLD:
        return s

    s = each_arm(s, note)
    used = _USE_ARM.match(s)
    if used is not None and used[2] and heading is None:
        heading_arm: str | None = used[1]  # "use your left hand to pick up ... and pour ...": every step's arm
        s = used[2]
        note("arm")
    else:
        heading_arm = heading[1] if heading is not None else None

    # An arm called by name before its step: "left hand, put ..." -> "put ... with the left arm".
    called = re.match(r"^(?:the |your )?(left|right) (?:arm|hand|gripper) , (.+)$", s)
    if called is not None:
        first, sep, rest = called[2].partition(" , ")
        s = f"{first} with the {called[1]} arm{sep}{rest}"
        note("arm")
    s = read_verbs(s, note, verb)
    for how in _HOW:
        s = _drop(how, s, note, "how")
    s = _sub(_POINTING, "", s, note, "how")
    s = _sub(_UP_AND_DOWN, "", s, note, "how")
    s = _drop(_LIKE_A_SETTING, s, note, "how")
    s = read_places(s, note)
    s = _drop(re.compile(r" (?:standing|sitting|lying|upright|up)(?= ,|$)"), s, note, "how")

    # "capsule -> tray": the arrow is where it goes.
    s = _sub(re.compile(r"(?:^|(?<=, ))(?:the )?([a-z]+(?: [a-z]+)?) ?-> ?(?=[a-z])"), r"put the \1 to ", s, note, "shorthand")
    s = _sub(re.compile(r" ?-> ?"), " ", s, note, "shorthand")
    s = _sub(re.compile(r"\bwith the other(?: one| hand| arm| gripper)?\b"), "with the other arm", s, note, "arm")
    if all(p.search(s) for p in _ONE_AND_OTHER):
        for pattern in _ONE_AND_OTHER:
            s = _drop(pattern, s, note, "how")
    s = _drop(re.compile(r"(?: ,)? while (?:you(?:'re| are)? holding it|it(?:'s| is)? (?:held )?(?:up|held|in the air|off the table))(?= ,|$)"), s, note, "how")
    s = _sub(re.compile(r"\bpour (?:me |us |him |her )?(?:a|some) (glass|cup|mug) of water\b"), r"pour water into the \1", s, note, "verb")
    # "tray back a bit": an amount after "back" makes it a way to move (farther back: away from you), not a put-back.
    s = _sub(re.compile(r"\bback(?= (?:just )?(?:a (?:little |tiny |wee )?bit|a little|slightly|a touch|a tad)(?= ,|$| then\b| and\b))"),
             "farther back", s, note, "direction")
    s = _sub(_AMOUNT, " ", s, note, "amount")
    s = _sub(_AMOUNT_TAIL, "", s, note, "amount")
    s = _sub(_IN_THE_AIR, "", s, note, "how")
    s = _sub(re.compile(r"\b(hand|pass|give) (it|them|the [a-z]+(?: [a-z]+)?) (?:across|over)(?= ,|$)"), r"\1 \2 over", s, note, "particle")
    s = _sub(_MARKED_ON_SIDE, r"\1", s, note, "place")
    for pattern, repl in _PARTICLES:
        s = _sub(pattern, repl, s, note, "particle")
    s = read_arms(s, note)
    # "... while the right one pours into it": a step of its own, by that arm.
    # (A hold said so is left to the phrasing's temporal rewrite: "pour ... while the left arm holds the cup".)
    s = _sub(re.compile(r" while (?:the |your )?(left|right)(?: one| arm| hand| gripper) (?!hold|keep|grip|steady)(\w+)\b([^,]*)"),
             lambda m: f" , {verb(m[2]) or m[2]}{m[3]} with the {m[1]} arm", s, note, "arm")
    s = _sub(re.compile(r"\bso (?:that )?it(?:'s| is)? (?:only )?half (?:as \w+|the size)\b"), "", s, note, "how")
    s = _sub(re.compile(r"\bmake (the \w+) (?:smaller|half as big|half the size) by folding it\b"), r"fold \1", s, note, "verb")
    clauses: list[str] = []
    s = re.sub(r"\s*,(?:\s*,)+", " ,", s)  # a clause dropped inside left two commas
    s = each_in_order(s, note)
    s = first_before(s, note)
    s = re.sub(r"(?:^|(?<= , ))(?:and )?(after|afterwards|after that|then|next|finally|lastly) , ", r"\1 ", s)  # "after, put ..."
    s = re.sub(r"\band , (?=(?:" + "|".join(_VERB_STARTS) + r"|tip)\b)", "and ", s)  # a clause dropped after "and"
    # "push the tray forward , with the capsule in it": what is in it belongs to the clause before.
    s = re.sub(r" , (with the [a-z ]+? (?:sitting |lying |resting |standing )?(?:in|inside|on) (?:it|there))(?= ,|$)", r" \1", s)
    for clause in s.split(" , "):
        clause = clause.strip(" ,")
        if not clause:
            continue
        if any(p.fullmatch(clause) for p in _LEFT_AS_IS) or any(t.fullmatch(clause) for t in TALK_SENTENCES):
            note("left as is")
            continue
        if clauses and restates(clause, clauses[-1]):
            note("place")
            continue
        clause = re.sub(r"^but (?:then )?", "", clause)  # "I'm not sure how to say it, but ...": what follows is the ask
        ordinal = _ORDINAL.match(clause)
        if ordinal and clauses:
            note("order")
            clause = "then " + clause[ordinal.end():]
        elif ordinal:
            note("order")
            clause = clause[ordinal.end():]
        clause = _drop(_TRAILING_ORDER, clause, note, "order")
        clause = _sub(_BY_HANDOVER, "hand it over", clause, note, "order")
        if clauses:
            clause = again(clause, clauses[-1], objects, note)
        clause = _arm_subject(clause, note, verb)
        clause = read_end_state(clause, objects, note, verb)
        if _TITLE.fullmatch(clause):
            note("talk")
            continue
        if is_talk(clause.removeprefix("then "), objects):
            note("talk")
            continue
        if heading_arm is not None and re.search(r"\b(?:hand|pass|give|transfer)\w*\b.*\bto (?:the )?(?:left|right|other) (?:arm|hand|gripper|one)\b", clause):
            heading_arm = None  # handed over: the arm that took it does the steps after, not the heading's
            clauses.append(clause)
            continue
        if used is not None and heading_arm is not None and _PUT_BACK.fullmatch(clause.removeprefix("then ").removeprefix("and ")):
            clauses.append(clause)  # "use the left arm to pour ..., and put the bottle back": the put-back is the arm that holds it
            continue
        if heading_arm is not None and not re.search(r"\b(?:left|right|both|other) (?:arm|hand|gripper|one)s?\b", clause):
            # A heading ("Right arm: grab ..., pour ..., set it down") names the arm of every step under it.
            with_arm = "with both arms" if heading_arm == "both" else f"with the {heading_arm} arm"
            steps = re.split(r" (then|and then|and(?= (?:" + "|".join(_VERB_STARTS) + r")\b)) ", clause)
            clause = "".join(f"{part} {with_arm}" if k % 2 == 0 else f" {part} " for k, part in enumerate(steps))
        clauses.append(clause)
    clauses = _handover_first(clauses, note)
    out = " , ".join(clauses).strip(" ,")
    for pattern, repl, name in _LAST:
        out = _sub(pattern, repl, out, note, name)
    out = drop_fold_way(out, objects, note)
    return out.strip(" ,")


def _handover_first(clauses: list[str], note: Callable[[str], None]) -> list[str]:
    """"get the block onto the target , hand it across": the hand-over is how it gets there, so it comes first."""
    out = list(clauses)
    for k in range(1, len(out)):
        handed = _HANDOVER_ALONE.fullmatch(out[k])
        placed = _PLACE_STEP.match(out[k - 1].removeprefix("then "))
        if handed is None or placed is None:
            continue
        obj = placed[1] if handed[1] in ("it", "them") else handed[1]
        obj = obj if obj in ("it", "them") or obj.startswith("the ") else f"the {obj}"
        out[k - 1], out[k] = f"hand {obj} over", "then " + out[k - 1].removeprefix("then ")
        note("order")
    return out


def _arm_subject(clause: str, note: Callable[[str], None], verb: Callable[[str], str | None]) -> str:
    """``left arm picks up the block`` -> ``pick up the block with the left arm``."""
    then = clause.startswith("then ")
    body = clause.removeprefix("then ")
    match = _ARM_SUBJECT.match(body)
    if match is not None and verb(match[2]) is not None and not re.search(r"\b(?:left|right|other|while|as)\b", match[3]):
        rest = match[3].strip()
        arm = f"with the {match[1]} arm"
        # "right one grabs the bottle and pours": the arm of each of its verbs, as a heading's.
        steps = re.split(r" (then|and then|and(?= (?:" + "|".join(_VERB_STARTS) + r")\b)) ", f"{verb(match[2])} {rest}".strip())
        body = "".join(f"{part} {arm}" if k % 2 == 0 else f" {part} " for k, part in enumerate(steps))
        note("arm")
    else:
        match = _BOTH_SUBJECT.match(body)
        if match is not None and verb(match[1]) is not None:
            body = f"{verb(match[1])} {match[2].strip()} with both arms".replace("  ", " ")
            note("arm")
    return ("then " + body) if then else body


