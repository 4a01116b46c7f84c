"""What each sentence and clause of an instruction contributes, read before the phrasing rewrites.

People wrap what they ask in talk the grammar has no rule for, and name the doer of a step where the
grammar expects an imperative. On the normalised text (sentences split by ``;``, clauses by ``,``),
a sentence at a time:

- **talk**: greetings, thanks, hesitations and remarks ("hi robot", "thanks so much", "um", "is
  it possible", "just a splash is fine"): a clause that names nothing the scene or the rules know
  (no object, colour, arm, place, direction or action verb) states no goal and is dropped;
- **things left as they are**: "leave the cup alone", "the red one stays where it is", "don't touch
  the fork", "you don't need to move the tray": no goal (what is not moved stays);
- **arms as subjects**: "left arm picks up the block", "the right hand pours", "have the right one
  put it in the tray", "left arm, grab ..." -> the imperative with ``with the left arm``;
- **ordinal steps**: "first ..., second ..., third ...", "after that", "afterwards", "finally" ->
  steps in order; "... first" at a clause's end is dropped (the order is the order said);
- **how, not what**: "at the same time", "one in each hand", "use both hands for that": the
  planner chooses the arms' timing; dropped;
- **direction words**: "further away from you", "farther back", "away from me" -> ``forward``;
  a flat utensil "pointing away from you" / "facing forward" beside a plate is how it is laid
  anyway (dropped).

Every change is recorded as a step (``talk``, ``left as is``, ``arm``, ``order``, ``how``,
``direction``) for ``plan --explain``.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from agentchord.agents.rules import knowledge as kb

#: Words that make a clause say something about the task (else it is talk).
_CONTENT = frozenset("""
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
_OPENERS = re.compile(r"^(?:(?:hi|hello|hey|hiya|yo|ok|okay|alright|so|um+|uh+|hmm+|oh|ah|well|sorry|excuse me|"
                      r"good (?:morning|afternoon|evening)|dear robot|robot|hey robot|hi robot|hello robot)(?: ,)? )+")
_CLOSERS = re.compile(r"(?:^|(?: ,)? )(?:thanks|thank you|thx|ty|cheers)(?: (?:so|very) much| a lot| in advance)?(?: ,)?"
                      r"(?: (?:robot|buddy|friend))?$")
#: A clause that leaves an object as it is: no goal.
_LEFT_AS_IS = [
    re.compile(r"^(?:and )?(?:but )?(?:please )?(?:leave|keep) (?:the |that |this )?[a-z ]+? "
               r"(?:alone|where it is|where they are|as it is|as they are|in place|untouched|where it was|there|on the table)$"),
    re.compile(r"^(?:and )?(?:but )?(?:do not|don't|dont|no need to|you don't need to|you do not need to|you dont need to)"
               r" (?:touch|move|bother with|worry about) [a-z ' ]+$"),
    re.compile(r"^(?:and )?(?:the |that )?[a-z ]+? (?:stays|stay|remains|should stay|can stay) (?:where it is|put|as it is|there)$"),
    re.compile(r"^(?:just |only )?(?:the \w+ )?(?:and )?(?:don't|do not|dont) (?:just )?(?:slide|drag|push) it$"),
]
#: The same inside a clause, after "and" or "but".
_LEFT_AS_IS_INSIDE = re.compile(
    r"(?: ,)? (?:and|but) (?:(?:please )?(?:leave|keep) (?:the |that |this )?[a-z ]+? (?:alone|where it is|where they are|as it is|"
    r"in place|untouched)|(?:do not|don't|dont) (?:touch|move) (?:the |that |this )?[a-z ]+?)(?= ,|$)")
#: How the arms share the work, when the goal says what: the planner chooses it.
_HOW = [
    re.compile(r"\b(?:at (?:the )?same time|simultaneously|together|in one go|in parallel)\b"),
    re.compile(r"(?: ,)? (?:one (?:in|with|per) (?:each|every) (?:hand|arm|gripper)|one per (?:hand|arm|gripper)|"
               r"one (?:for|with) each (?:hand|arm))\b"),
    re.compile(r"(?:^|(?: ,)? )(?:you'll|you will|you'd|you) (?:probably )?need (?:both|two) (?:hands?|arms?)(?: for (?:that|this|it))?$"),
]
#: Arm words a subject may be.
_ARM_SUBJECT = re.compile(
    r"^(?:and )?(?:(?:can|could|will|would|should|let|have|make) )?(?:the |your )?(left|right)(?: (?:arm|hand|gripper|one|side))?"
    r"(?: ,| :)? (?!(?:arm|hand|gripper)\b)(\w+)\b(.*)$")
_BOTH_SUBJECT = re.compile(r"^(?:and )?(?:then )?(?:both (?:of you|arms|hands|grippers)|both|the two arms|the arms) (\w+)\b(.*)$")
#: Ordinal words that open a step.
_ORDINAL = re.compile(r"^(?:and )?(?:first(?:ly)?|second(?:ly)?|third(?:ly)?|fourth|next|after that|afterwards|after this|"
                      r"after(?= (?:put|set|place|lay|stand|move|give|hand|pour|take|grab|pick|carry|bring|fold)\b)|"
                      r"then after that|finally|lastly|last|to finish|and finally|and then|and after that)(?: ,)? ")
_TRAILING_ORDER = re.compile(r" (?:first|afterwards|after that|after it|after them|at the end|in the end|when (?:you(?:'re| are)?|ur|your) done|"
                             r"when finished|after|last|this time|for me)$")
#: Direction phrases that mean "away from the robot".
_AWAY = re.compile(r"\b(?:a (?:little |tiny )?bit |a little |slightly )?(?:further|farther)(?: away)?(?: back)?(?: from (?:me|you|the robot))?"
                   r"(?: than (?:it is|it does|it was)(?: now)?)?\b|\baway from (?:me|you|the robot)\b|\btowards? the (?:back|far side|far end)\b|"
                   r"\bto the back\b(?! of the table| edge| of the)")
#: "a little closer to you", "towards the robot": the robot's side of the table.
_TOWARD_YOU = re.compile(r"\b(?:a (?:little |tiny )?bit |a little |slightly )?(?:closer|nearer) (?:to|towards?) (?:you|me|the robot|yourself)\b|"
                         r"\btowards? (?:you|me|the robot|yourself)\b")
#: "so it's (lying) right next to the plate": what the move is for is where it goes.
_SO_IT = re.compile(r"(?: ,)? so (?:that )?(?:it|they)(?:'s|'re| is| are| ends? up| sits?| lies| lie)?(?: (?:lying|sitting|standing))?"
                    r"(?: (?:right|just|directly))? (?=(?:next to|beside|near|in|inside|into|on|onto|at|to the|behind|in front of)\b)")
#: "next to the plate on the right": on that side of it (not the table's right side).
_BESIDE_ON_SIDE = re.compile(r"\b(?:right |just )?(?:next to|beside|by|near|near to|close to) ((?:the )?[a-z]+(?: [a-z]+)?)(?: ,)? "
                             r"(?:on|to|at) (?:the|its) (left|right)"
                             r"(?: side| hand side)?(?: of it)?(?= ,|$| then\b| and\b| with\b)")
#: "the marked circle on the right": a drawn place, its side only describing it.
_MARKED_ON_SIDE = re.compile(r"\b((?:the )?(?:marked |taped |drawn |painted |target )?(?:circle|area|spot|zone|region|mark|target)) (?:on|to|at) the "
                             r"(?:left|right)(?: side| half)?(?: of the table)?(?= ,|$| then\b| and\b| with\b)")
#: "a bit to the left so it's beside the cup": beside it (the way there is not the side: coming from its
#: right, the bottle ends on the cup's right).
_SIDE_BESIDE = re.compile(r"\b(?:a (?:little |tiny )?bit |a little |slightly )?(?:over )?to the (left|right)(?: ,)? (?:so )?(?:right |just )?"
                          r"(?:beside|next to|by) "
                          r"(the [a-z]+(?: [a-z]+)?)(?= ,|$| then\b| and\b| with\b)")
#: "near to the fork", "close to it": next to it.
_NEAR_TO = re.compile(r"\b(?:near|close)(?: to)? (?=the |it\b|them\b)")
#: "with one hand ... with the other": two arms, the planner's to choose.
_ONE_AND_OTHER = (re.compile(r" with one (?:hand|arm|gripper)\b"), re.compile(r" with the other arm\b"))
#: "and the bottle too", "then the red one as well": the step before, for another object.
_TOO = re.compile(r"^(then |and |and then )?(?:also )?((?:the )?[a-z]+(?: [a-z]+)?|it|them) (?:too|as well|also)$")
#: "do the same with the spoon (on the right)": the step before, for another object (and side).
_SAME = re.compile(r"^(then |and |and then )?(?:do|repeat) (?:the same|that|the same thing|it) (?:with|for|to) ((?:the )?[a-z]+(?: [a-z]+)?)"
                   r"(?: (?:on|to|at) (?:the )?(left|right)(?: side)?(?: of it)?)?$")
#: "a bit closer to the bottle": next to it.
_CLOSER = re.compile(r"\b(?:a (?:little |tiny )?bit |a little |slightly )?(?:closer|nearer) to\b")
_POINTING = re.compile(r"(?: ,)? (?:and )?(?:both |each )?(?:of them )?(?:pointing|facing|oriented|aimed|tips?|handles?)"
                       r" (?:away from (?:me|you|the robot)|forwards?|ahead|straight ahead|to the far side|away|up|north)"
                       r"(?: \( ?tips away from (?:me|you) ?\))?\b")


#: Shorthand people type -> the word.
_SHORTHAND = [(re.compile(r"\b(?:pls|plz|plse)\b"), ""), (re.compile(r"\bw/ ?|\bw (?=the |your |my |both |left |right )"), "with "),
              (re.compile(r"\bur\b"), "your"), (re.compile(r"\bu\b"), "you"), (re.compile(r"\bthx\b"), "thanks"),
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
                r"(?=to |next |beside |onto |on |into |in |,|$)"), r"\1 \2 "),
    (re.compile(r"\b(hand|pass|give) (it|them|the [a-z]+(?: [a-z]+)?) (?:off|across|over) (?=to )"), r"\1 \2 "),
    (re.compile(r"\b(stand|set|put) (it|them|the [a-z]+(?: [a-z]+)?) back up\b"), r"\1 \2 back"),
    (re.compile(r"\b(?:standing|sitting|stood) up\b"), ""),
]
#: An arm named by its side alone, after a hand-over or "with": "to your right", "with the other".
_ARM_ELLIPSIS = [
    (re.compile(r"\b((?:hand|pass|give|transfer)\w* (?:it|them|the [a-z]+(?: [a-z]+)?) (?:over |across |off )?to) (?:the|your|my) "
                r"(left|right)(?: one)?\b(?! (?:arm|hand|gripper|of|side)\b)"), r"\1 the \2 arm"),
    (re.compile(r"\b(with|in|using) (?:the|your|my) (left|right)(?: one)?\b(?! (?:arm|hand|gripper|of|side)\b)"), r"\1 the \2 arm"),
    (re.compile(r"\b(to|with|in|by|from) (?:the )?(left|right) one\b"), r"\1 the \2 arm"),
    (re.compile(r"\bwith (?:the )?(\w+) in (?:your|the) (left|right)(?: hand| arm| gripper| one)?\b"), r"from the \1 with the \2 arm"),
    (re.compile(r"\bin (?:your|the) (left|right)(?: hand| arm| gripper| one)?\b(?! (?:side|of|corner|half|edge)\b)"), r"with the \1 arm"),
    (re.compile(r"\b(hand|pass|give|transfer)(\w*(?: (?:it|them|the [a-z]+))?(?: over| across)?) from (?:the )?(left|right)(?: arm| hand| gripper)?"
                r" to (?:the )?(right|left)(?: arm| hand| gripper| one)?\b"), r"\1\2 from the \3 arm to the \4 arm"),
    # "move the block to the target with a handover, left to right": the hand-over first, then the move.
    (re.compile(r"^(?:move|put|place|bring|get|take) (the [a-z]+(?: [a-z]+)?) (to|onto|on|in|into) ([a-z ]+?) (?:with|via|using|by) (?:a )?handover"
                r"(?: ,)? (?:from )?(?:the )?(left|right)(?: arm| hand)? to (?:the )?(right|left)(?: arm| hand)?\b"),
     r"hand \1 over from the \4 arm to the \5 arm , then put \1 \2 \3"),
    (re.compile(r"\bthe (left|right) one\b(?= (?:put|place|set|pour|take|grab|hold|drop|fill|pick)\b)"), r"the \1 arm"),
    (re.compile(r"\b(left|right) arm (hand|arm|gripper)\b"), r"\1 \2"),
]
#: A fold across the cloth (left onto right), which no rule makes.
_ACROSS = re.compile(r"\b(?:from )?(?:the )?(?:left|right)(?: half| side| edge| corners?)?(?: of it)? (?:to|onto|over|over to|on top of|towards?) "
                     r"(?:the )?(?:right|left)(?: half| side| edge| corners?)?\b|\bside to side\b|\blengthwise\b|\bsideways\b|\bleft-right\b")
#: Where a pour happens, said beside it: the goal is the pour (holding the cup is said by "hold").
_IN_THE_AIR = re.compile(r"(?: ,)? (?:in (?:the )?(?:mid-? ?air|air)|up in the air|off the table|above the table|over the table)\b")
#: How a table setting is meant ("like for dinner", "like a proper place setting", "like at a restaurant").
_SETTING_MANNER = (r"(?:just )?like (?:for (?:dinner|lunch|breakfast|a meal)|(?:a |an )?(?:proper |normal |usual |formal |nice )?"
                   r"(?:place|table|dinner) setting|(?:they do |you'd see |you see |you would see )?(?:at|in) a restaurant)")
#: A table setting's manner said after it: ", like a proper place setting", "like they do at a restaurant".
_LIKE_A_SETTING = re.compile(rf"(?: ,)? {_SETTING_MANNER}(?= ,|$)")


#: Frames that say "the end state is": dropped, the state that follows is read as usual.
_END_STATE = re.compile(r"^(?:(?:the )?end result|result|the goal|goal|in the end|at the end|by the end|when you're done|"
                        r"what i(?:'d| would) like (?:in the end |at the end )?is|what i want (?:in the end |at the end )?is|"
                        r"(?:at the end |in the end )?i (?:just |really )?(?:want|need|would like|'d like)|"
                        r"want|i'd like)(?: ,| :)? (?=the |a |an |there |both |my |water |some water )")
#: "there to be water in the cup", "the cup with water in it", "cup has water in it": a pour into the cup.
_WATER_IN = [
    (re.compile(r"^(?:there (?:to be|is|should be) )?(?:some )?water in (?:the |my )?(\w+)(?: (?:at the end|in the end))?$"), r"pour water into the \1"),
    (re.compile(r"^(?:the |my )?(\w+(?: \w+)?) (?:with|has|should have|to have|having|ends up with|to end up with) (?:some )?water in it"
                r"(?: (?:at the end|in the end))?$"), r"pour water into the \1"),
]
#: Whole sentences or clauses that are talk though they name things: permission, questions about the ask, remarks.
_TALK_SENTENCES = [re.compile(p) for p in (
    r"(?:is it|is that|would that be) (?:possible|ok|okay|alright)",
    r"how you do it is up to you", r"(?:it's|it is) up to you",
    r"i(?:'m| am) (?:done|finished|thirsty|hungry|not sure)\b.*",
    r"(?:and )?(?:i|we) (?:don't|do not|dont) want (?:to|you to|it to)\b.*",
    r"(?:and )?you (?:can|may|could) (?:hold|do|use|take)\b.*(?: if .*)?",
    r"(?:and )?(?:don't|do not|dont) (?:overflow|spill|drop|break)\b.*",
    r"(?:both|all)(?: of them)?(?: (?:vertical|horizontal|straight|too|aligned))?",
    r"(?:just )?once", r"in half",
    r"it(?:'s| is)? (?:quite |very |rather |a bit |so )?(?:long|heavy|big|wide|light|small|wobbly)",
    r"(?:then )?(?:pull|move|bring|take) (?:the |your )?(?:left|right|both) arms? (?:back|away|home)(?: out of the way)?",
    r"(?:the |my )?[a-z ]+ (?:is|are) (?:kind of |sort of |a bit |rather |quite )?(?:in the way|far away|too far(?: away)?|too close)",
    r"(?:just )?(?:next |close )?to it",
    r"(?:the )?(?:cup|bottle|plate|tray|towel|block|capsule)(?: is)? (?:right )?(?:there|here|over there|in front of you)",
    r"(?:and )?(?:both|they|them|each|all)(?: of them)? (?:should |must |need to )?(?:point|face|pointing|facing|be pointing|be facing)"
    r" (?:forwards?|away(?: from (?:me|you))?|ahead|up|the same way)",
    _SETTING_MANNER,
)]
#: "bottle standing back where it was", "the cup back in the same spot": put back.
_BACK_AS_IT_WAS = re.compile(r"^(?:and )?(?:the )?(\w+)(?: and (?:the )?(\w+))?(?: both)?(?: is| are| should be| to be)?(?: both)?"
                             r"(?: standing| sitting| upright| stood)*(?: back)?(?: upright)?(?: again)?"
                             r" (?:about |roughly |more or less |right |exactly |just )?(?:where (?:it|they) (?:was|were|started|stood|is|are)"
                             r"(?: now| before| at the start)?|where you found (?:it|them)|in the same (?:spot|place|position)|"
                             r"in (?:its|their) (?:old |original )?(?:place|places|spot|spots)|back where (?:it|they) (?:was|were|started))$")
#: "(pick up both blocks and) put them in the cup, red first then blue": each, in the order said.
_EACH_IN_ORDER = re.compile(r"^(?:(?:pick up|take|grab|lift) (?:both|the two|the) (\w+?)s and (put|place|drop|set|move) them|"
                            r"(put|place|drop|set|move) (?:both|the two|the) (\w+?)s) (.+?) , (?:the )?(\w+)(?: one)? first"
                            r"(?: ,)?(?: and)?(?: then)? (?:the )?(\w+)(?: one)?$")


def _put_back(m: re.Match[str]) -> str:
    first = "put it back" if m[1] in ("it", "they", "them") else f"put the {m[1]} back"
    return first if m[2] is None else f"{first} , put the {m[2]} back"


def _each_in_order(m: re.Match[str]) -> str:
    noun, verb, where = m[1] or m[4], m[2] or m[3], m[5]
    return f"{verb} the {m[6]} {noun} {where} then {verb} the {m[7]} {noun} {where}"
#: Cleanups once a sentence's clauses are read: states and particles left at a clause's end.
_LAST = [
    (re.compile(r" after (?:it|them|that)(?= with| ,|$)"), "", "order"),
    (re.compile(r"(?:^|(?: ;| ,) )(?:you'll|you will|you'd|you) (?:probably )?need (?:both|two) (?:hands?|arms?)(?: for (?:that|this|it))?(?= ,|$)"),
     "", "how"),
    (re.compile(r"(?: ,)+ ,"), " ,", "shorthand"),
    (re.compile(r"\bgive (?:some )?water (?:from (?:the )?(\w+) )?(?=into|in|to)\b"), r"pour water from the \1 ", "verb"),
    (re.compile(r"\b(hold|lift|take|pick) ([^,]+?) , (?:then )?pour(?= with| ,|$)"), r"\1 \2 , pour into it", "ellipsis"),
    (re.compile(r"^(?:set|lay) (?:up )?the table(?: properly)?(?: for me)? , "), "", "talk"),
    (re.compile(r"(?: ,)? with the folded edge (?:on the side |at the side |on the edge )?(?:nearest|closest|near|towards?)(?: to)? (?:me|you)"),
     "", "cloth part"),
    (re.compile(r"(?: ,)? lying on the (?:top|far) half(?: of where it is(?: now)?)?"), "", "cloth part"),
    (re.compile(r" (?:standing up|sitting up|standing|sitting|lying|upright)(?= ,|$)"), "", "how"),
    (re.compile(r" while it(?:'s| is)?(?= ,|$)"), "", "how"),
    (re.compile(r"\b(fill|lift|hold|pick|take) (the \w+|it|them) up\b"), r"\1 \2", "particle"),
]
#: Which way a fold goes, said of the only fold the rules make (near edge onto far edge).
_FOLD_WAY = re.compile(r"(?:^|(?: ,)? )(?:towards? |to )(?:the )?(?:top|far|back) (?:side|edge|end|half)(?= ,|$)|(?: ,)? forward(?= ,|$)|"
                       r"(?: ,)? (?:from )?(?:near|front|bottom)(?: edge| side)?(?: to| onto| over)? (?:far|back|top)(?: edge| side)?(?= ,|$)")
#: "the capsule should end up in the tray", "the blue one goes in the cup", "the block to end up inside the target".
_SHOULD_BE = re.compile(r"^(?:and )?((?:the |my )?[a-z]+(?: (?!should|must|needs?|has|is|will|to|shall)[a-z]+)?(?: and (?:the |my )?[a-z]+)?) "
                        r"(?:should|must|needs? to|has to|is to|will|to|shall)? ?"
                        r"(?:end up|be|go|goes|sit|sits|stay|get|gets|belong|belongs|land|lands)(?: back)? "
                        r"(in|inside|into|on|onto|at|next to|beside|on top of) ")
#: "both back on table (after)": the two put back.
_BOTH_BACK = re.compile(r"^(?:and )?(?:then )?both (?:of them )?(?:back )?(?:down )?(?:on (?:the )?table)?(?: after(?:wards)?)?$")
#: A sentence that only names what follows ("end result", "the goal").
_TITLE = re.compile(r"(?:the )?(?:end result|result|goal|final state|end state|target state|plan|steps?)")
#: How an arm is asked for: "use your left hand (this time) to pick ...", "use right arm only".
_USE_ARM = re.compile(r"^(?:please )?(?:use|using) (?:your |the )?(left|right|both) (?:arm|hand|gripper)s?(?: (?:only|this time))*"
                      r"(?: (?:to|for|and) (.+))?$")
#: The tray's handles are how it is carried: "by both handles", "using the two handles", "grab both handles" (the tray).
_HANDLES = [
    (re.compile(r"(?: ,)? (?:by|using|with|at) (?:both|its|the two|the|its two|both of its|the) handles?\b"), ""),
    (re.compile(r"\b(grab|take|hold|grasp|pick up) (?:both|the two|the|its) handles?\b"), r"\1 the tray"),
]
#: A cloth's parts, as the rules name them (bottom = near the robot, top = far).
_CLOTH_PARTS = [
    (re.compile(r"\b(?:the )?(?:two )?corners? (?:closest|nearest|nearer|closer) to (?:you|me|the robot)\b"), "the bottom corners"),
    (re.compile(r"\b(?:the )?(?:two )?(?:far|farthest|furthest) ones\b"), "the top corners"),
    (re.compile(r"\b(?:near|front|bottom)[- ](left|right) corner\b"), r"bottom \1 corner"),
    (re.compile(r"\b(?:far|back|top)[- ](left|right) corner\b"), r"top \1 corner"),
    (re.compile(r"\b(?:front|near|nearer|closer) (corners|edge|side|half|end)\b"), r"bottom \1"),
    (re.compile(r"\b(?:back|far|farther|further) (corners|edge|side|half|end)\b"), r"top \1"),
]
#: A whole fold said by its parts: the bottom (near) corners, edge or half brought onto the top ones.
_FOLD_BY_PARTS = re.compile(r"\bbottom (?:corners|edge|side|half|end)\b.*\b(?:top (?:corners|edge|side|half|end)|them)\b|"
                            r"\bthem\b.*\btop (?:corners|edge|side|half)\b")


class NotAGoalError(ValueError):
    """A sentence asks for something the rules recognise but cannot do (the reason is the message)."""


def _lemma_like(word: str) -> bool:
    """Whether ``word`` is a form of an action verb: the stem and an ending (``pours``, ``poured``, ``pouring``)."""
    return any(word == stem or (word.startswith(stem) and word[len(stem):] in _ENDINGS) for stem in _ACTION_STEMS)


_ENDINGS = frozenset({"s", "es", "ed", "d", "ing", "ping", "ped", "ting", "ted", "ling", "led", "ies", "ied", "y", "e", "en", "t"})


def is_talk(clause: str, objects: frozenset[str]) -> bool:
    """Whether a clause names nothing the task is about (no object, colour, arm, place or action verb)."""
    words = clause.replace("'", " ").split()
    if not words:
        return True
    for word in words:
        if word in objects or word in _CONTENT or word in kb.DIRECTION_WORDS or word in kb.TABLE_WORDS:
            return False
        if word.rstrip("s") in objects or _lemma_like(word):
            return False
        if word in _COLOUR_WORDS:
            return False
    return True


_COLOUR_WORDS = frozenset({"red", "blue", "green", "yellow", "orange", "white", "black", "grey", "gray", "brown", "purple", "pink"})


def read_sentences(sentences: list[str], objects: frozenset[str], note: Callable[[str], None],
                   verb: Callable[[str], str | None]) -> list[str]:
    """Each sentence read (:func:`read_sentence`); a sentence that only names an arm ("use the right arm only")
    names the arm of every step after it."""
    out: list[str] = []
    arm: str | None = None
    for k, sentence in enumerate(sentences):
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
        read = read_sentence(sentence, objects, note, verb)
        if out and read == "hand it over" and (placed := _PLACE_STEP.match(out[-1])) is not None and placed[1] != "it":
            obj = placed[1] if placed[1].startswith("the ") else f"the {placed[1]}"
            out[-1] = f"hand {obj} over , then {out[-1]}"  # the sentence before, done by a hand-over
            note("order")
            continue
        out.append(read)
    return out


#: A hand-over said as the way of doing a step: "use a handover", "do it via handover".
_BY_HANDOVER = re.compile(r"^(?:and )?(?:then )?(?:use|using|do it (?:via|with|by|using)|via|with|by|through) (?:a )?handover(?: please)?$")
#: A hand-over with no place of its own ("hand it across", "hand the block over").
_HANDOVER_ALONE = re.compile(r"(?:and )?(?:hand|pass|give) (it|them|the [a-z]+(?: [a-z]+)?) over")  # no "then": the way, not a next step
#: A step that takes an object somewhere ("get the block onto the target").
_PLACE_STEP = re.compile(r"(?:(?:get|put|place|move|bring|take|carry|set) )?((?:the )?[a-z]+(?: [a-z]+)?|it) (?:over )?(?:onto|on|to|into|in|at) ")
#: An end state said with a participle: "the cup moved over to the right", "the capsule put in the tray".
_PARTICIPLE = re.compile(r"^(?:and )?((?:the )?[a-z]+(?: [a-z]+)?) (moved|put|placed|pushed|slid|shifted|set|laid|stacked|dropped) (?!back$)(.+)$")
#: "leave the bottle standing up afterwards": put it back.
_LEAVE_STANDING = re.compile(r"^(?:and )?(?:then )?leave (the \w+|it) (?:standing|upright|standing up|up)(?: (?:afterwards|after|after that|at the end))?$")
#: A step said without its verb: "red into cup", "blue next to the cup on the right".
_VERBLESS = re.compile(r"^(?:and )?(then )?((?:the )?[a-z]+(?: one)?) "
                       r"(into|in|onto|on top of|next to|beside|to the (?:left|right) of|behind|in front of) (.+)$")
#: A sentence that names the job the sentences after it spell out.
_TITLE_SENTENCE = re.compile(r"(?:please )?(?:set|lay) (?:up )?the table(?: properly)?(?: for me)?(?: please)?")
#: Verbs that start a step joined by "and" ("pick up the bottle and pour ...").
_VERB_STARTS = ("pick", "take", "grab", "grasp", "hold", "lift", "put", "place", "set", "lay", "stand", "drop", "pour", "fill",
                "empty", "hand", "pass", "give", "move", "carry", "bring", "push", "slide", "fold", "stack", "insert")
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
    heading = re.match(r"^armheading (left|right|both) , ", s)
    if heading is not None:
        s = s[heading.end():]
    # The rules fold a cloth near edge onto far edge only: a fold across (left onto right) is refused,
    # not read as the fold they know.
    if re.search(r"\bfold", s) and (across := _ACROSS.search(s)) is not None:
        raise NotAGoalError(f"'{across[0].strip()}': the rules fold a cloth in half near edge onto far edge only, "
                            "not across it (left onto right)")
    s = _drop(_OPENERS, s, note, "talk")
    s = _drop(_CLOSERS, s, note, "talk")
    s = _drop(re.compile(r"\b(?:for me|for you|if you can|if possible|if that's ok|if that's easier(?: for you)?|though)\b"), s, note, "talk")
    s = _drop(re.compile(r"(?: ,)? (?:is|would be|'s|will be) (?:fine|good|ok|okay|enough|great|perfect|all)$"), s, note, "talk")
    if re.fullmatch(r"(?:go|do it|start|begin|go ahead|that's all|that is all|done)", s) or any(t.fullmatch(s) for t in _TALK_SENTENCES):
        note("talk")
        return ""
    if not re.search(r"\b(?:pour|fill|empt)", s):  # for a pour, both arms say who holds the cup; else how it is carried
        s = _drop(re.compile(r"(?:^|(?: ,)? )(?:(?:use|using|with) )?(?:both|two|the two) (?:of your )?(?:hands?|arms?|grippers?)"
                             r"(?: for (?:that|this|it))?(?: at the same time)?$"), s, note, "how")
    s = _drop(_LEFT_AS_IS_INSIDE, s, note, "left as is")
    stated = _drop(_END_STATE, s, note, "end state")
    if stated != s:  # "I want water in the cup and the bottle where it was": two end states
        stated = re.sub(r" and (?=(?:the|my|both) )", " , ", stated)
    s = stated
    s = _sub(re.compile(r"\bthe whole thing\b"), "it", s, note, "pronoun")
    s = _drop(re.compile(r"(?: ,)? (?:and )?(?:let go|release it|release them|go)$"), s, note, "talk")
    for pattern, repl in _HANDLES:
        s = _sub(pattern, repl, s, note, "handles")
    if re.search(r"\b(?:towel|cloth|corners?|fold)", s) or ("towel" in objects or "cloth" in objects) and re.search(r"\b(?:edge|side|half)\b", s):
        for pattern, repl in _CLOTH_PARTS:
            s = _sub(pattern, repl, s, note, "cloth part")
        if _FOLD_BY_PARTS.search(s) and not re.search(r"\b(?:left|right) (?:corner|half|side|edge)\b(?!s)", s.replace("bottom left corner", "")
                                                       .replace("bottom right corner", "").replace("top left corner", "").replace("top right corner", "")):
            note("cloth part")
            return "fold the towel"  # the bottom corners (or edge, or half) onto the top ones: the fold

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
    for how in _HOW:
        s = _drop(how, s, note, "how")
    s = _sub(_POINTING, "", s, note, "how")
    s = _drop(_LIKE_A_SETTING, s, note, "how")
    s = _sub(_AWAY, "forward", s, note, "direction")
    s = _sub(_TOWARD_YOU, "closer", s, note, "direction")
    s = _sub(_CLOSER, "next to", s, note, "direction")
    s = _sub(_SO_IT, " ", s, note, "place")
    s = _sub(_BESIDE_ON_SIDE, r"to the \2 of \1", s, note, "place")
    s = _sub(_SIDE_BESIDE, r"next to \2", s, note, "place")
    s = _sub(_NEAR_TO, "next to ", s, note, "place")
    s = _sub(re.compile(r"\bforward(?: ,)? (to the \w+ region)\b"), r"\1", s, note, "direction")
    s = _sub(re.compile(r"\bto (inside|into|onto)\b"), r"\1", s, note, "place")
    s = _drop(re.compile(r" (?:standing|sitting|lying|upright|up)(?= ,|$)"), s, note, "how")

    s = _sub(re.compile(r" ?-> ?"), " ", s, note, "shorthand")
    s = _sub(re.compile(r"\bwith the other(?: one| hand| arm| gripper)?\b"), "with the other arm", s, note, "arm")
    if all(p.search(s) for p in _ONE_AND_OTHER):
        for pattern in _ONE_AND_OTHER:
            s = _drop(pattern, s, note, "how")
    s = _drop(re.compile(r"(?: ,)? while (?:you(?:'re| are)? holding it|it(?:'s| is)? (?:up|held|in the air))(?= ,|$)"), s, note, "how")
    s = _sub(re.compile(r"\bpour (?:me |us |him |her )?(?:a|some) (glass|cup|mug) of water\b"), r"pour water into the \1", s, note, "verb")
    s = _sub(_AMOUNT, " ", s, note, "amount")
    s = _sub(_AMOUNT_TAIL, "", s, note, "amount")
    s = _sub(_IN_THE_AIR, "", s, note, "how")
    s = _sub(re.compile(r"\b(hand|pass|give) (it|them|the [a-z]+(?: [a-z]+)?) (?:across|over)(?= ,|$)"), r"\1 \2 over", s, note, "particle")
    s = _sub(_MARKED_ON_SIDE, r"\1", s, note, "place")
    for pattern, repl in _PARTICLES:
        s = _sub(pattern, repl, s, note, "particle")
    for pattern, repl in _ARM_ELLIPSIS:
        s = _sub(pattern, repl, s, note, "arm")
    # "... while the right one pours into it": a step of its own, by that arm.
    # (A hold said so is left to the phrasing's temporal rewrite: "pour ... while the left arm holds the cup".)
    s = _sub(re.compile(r" while (?:the |your )?(left|right)(?: one| arm| hand| gripper) (?!hold|keep|grip|steady)(\w+)\b([^,]*)"),
             lambda m: f" , {verb(m[2]) or m[2]}{m[3]} with the {m[1]} arm", s, note, "arm")
    s = _sub(re.compile(r"\bso (?:that )?it(?:'s| is)? (?:only )?half (?:as \w+|the size)\b"), "", s, note, "how")
    s = _sub(re.compile(r"\bmake (the \w+) (?:smaller|half as big|half the size) by folding it\b"), r"fold \1", s, note, "verb")
    clauses: list[str] = []
    s = re.sub(r"\s*,(?:\s*,)+", " ,", s)  # a clause dropped inside left two commas
    for clause in s.split(" , "):
        clause = clause.strip(" ,")
        if not clause:
            continue
        if any(p.fullmatch(clause) for p in _LEFT_AS_IS) or any(t.fullmatch(clause) for t in _TALK_SENTENCES):
            note("left as is")
            continue
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
            clause = _again(clause, clauses[-1], objects, note)
        clause = _arm_subject(clause, note, verb)
        for pattern, repl in _WATER_IN:
            clause = _sub(pattern, repl, clause, note, "end state")
        clause = _sub(_BACK_AS_IT_WAS, _put_back, clause, note, "end state")
        clause = _sub(_LEAVE_STANDING, r"put \1 back", clause, note, "end state")
        verbless = _VERBLESS.match(clause)
        if verbless is not None and verb(verbless[2].split()[-1]) is None and verbless[2].split()[-1] not in ("it", "them", "they"):
            thing = verbless[2] if verbless[2].startswith("the ") else f"the {verbless[2]}"
            clause = f"{verbless[1] or ''}put {thing} {verbless[3]} {verbless[4]}"
            note("verb")
        participle = _PARTICIPLE.match(clause)
        if (participle is not None and verb(participle[2]) is not None
                and (participle[1].startswith("the ") or participle[1].split()[-1] in objects)):
            subject = participle[1] if participle[1].startswith("the ") else f"the {participle[1]}"
            clause = f"{verb(participle[2])} {subject} {participle[3].removeprefix('over ')}"
            note("end state")
        clause = _sub(_SHOULD_BE, r"put \1 \2 ", clause, note, "end state")
        clause = _sub(_BOTH_BACK, "put them back", clause, note, "end state")
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
        if heading_arm is not None and not re.search(r"\b(?:left|right|both|other) (?:arm|hand|gripper|one)s?\b", clause):
            # A heading ("Right arm: grab ..., pour ..., set it down") names the arm of every step under it.
            with_arm = "with both arms" if heading_arm == "both" else f"with the {heading_arm} arm"
            steps = re.split(r" (then|and then|and(?= (?:" + "|".join(_VERB_STARTS) + r")\b)) ", clause)
            clause = "".join(f"{part} {with_arm}" if k % 2 == 0 else f" {part} " for k, part in enumerate(steps))
        clauses.append(clause)
    clauses = _handover_first(clauses, note)
    out = " , ".join(clauses).strip(" ,")
    out = _sub(_EACH_IN_ORDER, _each_in_order, out, note, "order")
    for pattern, repl, name in _LAST:
        out = _sub(pattern, repl, out, note, name)
    if re.search(r"\bfold", out) or "towel" in objects:  # "fold it in half, towards the far side": the only fold the rules make
        out = _drop(_FOLD_WAY, out, note, "cloth part")
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


def _again(clause: str, before: str, objects: frozenset[str], note: Callable[[str], None]) -> str:
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
    if same is not None and same[3]:
        other = "left" if same[3] == "right" else "right"
        again = re.sub(rf"\b{other}\b", same[3], again) if re.search(rf"\b{other}\b", again) else again
    note("ellipsis")
    return (lead + again).strip()


def _arm_subject(clause: str, note: Callable[[str], None], verb: Callable[[str], str | None]) -> str:
    """``left arm picks up the block`` -> ``pick up the block with the left arm``."""
    then = clause.startswith("then ")
    body = clause.removeprefix("then ")
    match = _ARM_SUBJECT.match(body)
    if match is not None and verb(match[2]) is not None and not re.search(r"\b(?:left|right|other|while|as)\b", match[3]):
        rest = match[3].strip()
        arm = f"with the {match[1]} arm"
        body = f"{verb(match[2])} {rest} {arm}".strip() if rest else f"{verb(match[2])} {arm}"
        note("arm")
    else:
        match = _BOTH_SUBJECT.match(body)
        if match is not None and verb(match[1]) is not None:
            body = f"{verb(match[1])} {match[2].strip()} with both arms".replace("  ", " ")
            note("arm")
    return ("then " + body) if then else body


def _drop(pattern: re.Pattern[str], text: str, note: Callable[[str], None], name: str) -> str:
    return _sub(pattern, "", text, note, name)


def _sub(pattern: re.Pattern[str], repl: str | Callable[[re.Match[str]], str], text: str, note: Callable[[str], None], name: str) -> str:
    new = re.sub(r"\s+", " ", pattern.sub(repl, text)).strip()
    if new != text.strip():
        note(name)
    return new
