"""What the robot says to a person, in English: one sentence (or question) per outcome, made from the
predicate's sentence template in the lexicon ("pour {Theme} into the {Destination}").

`say(outcome)` takes the structured outcome that `lmcr execute` and `lmcr robot` print as JSON (or a
part of it) and returns the sentence: "I poured the water into the cup." on success, "I tried to pour
the water into the cup, but only 40% of it went in." on a failure, "I can't reach the cup: should I pour
the water into the glass instead?" when the plan is infeasible and another object would do, the
completion's question while it waits for an answer, and a sentence for each error kind
(`error_outcome`). Past tenses come from English's regular rule, or from a predicate's `past` in the
lexicon for an irregular verb; what a learned verb did is said with its motion ("I threw the peel into the
compost bin", `motion_done`): the corpus gives a verb's roles, not its past tense.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from lmcr.frame import Frame
from lmcr.lexicon import Lexicon, load_lexicon
from lmcr.robot.household import MOTIONS, household

_SLOT = re.compile(r"(the )?\{(\w+)\}")
_AUTO_ID = re.compile(r"(.+)#(\d+)")
ORDINALS = ("first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth", "ninth", "tenth")
LEAVE_IT = "I'll leave it."
# household.MOTIONS, tasks.TOOL_MOTIONS and serving, as a person hears them
MOTIONS_SAID = (
    "and put things away, throw them out, hand them over, cook them in a pan or an oven, stir, wipe, cut, cover or "
    "serve with a tool"
)


def past_tense(verb: str, irregular: str | None = None) -> str:
    """The simple past of an English verb: `irregular` when given (the lexicon's `past`), else the regular
    rule: bake -> baked, fry -> fried, dip -> dipped (one syllable ending consonant-vowel-consonant), pour ->
    poured. A verb with a particle ("throw out") inflects its first word (`irregular`: that word's past)."""
    head, _, rest = verb.partition(" ")
    if rest:
        return f"{past_tense(head, irregular)} {rest}"
    if irregular:
        return irregular
    if verb.endswith("e"):
        return verb + "d"
    if len(verb) > 1 and verb[-1] == "y" and verb[-2] not in "aeiou":
        return verb[:-1] + "ied"
    if len(re.findall(r"[aeiou]+", verb)) == 1 and re.search(r"(?:^|[^aeiou])[aeiou][^aeiouwxy]$", verb):
        return verb + verb[-1] + "ed"
    return verb + "ed"


# tasks.TOOL_MOTIONS, in the past tense
TOOL_MOTIONS_SAID = {"stir": "stirred", "wipe": "wiped", "cut": "cut", "cover": "covered"}


def motion_done(
    motion: str | None, roles: Mapping[str, str], built_like: Mapping[str, str] | None = None
) -> str | None:
    """What the robot did, in the past tense of its own motion ("threw the peel into the compost bin",
    "handed the knife to the person", "put the apple on the shelf", "stirred the batter with the spoon");
    None for the paper's predicates, whose own verbs say it. `built_like`: the known object each label the
    robot has no model of is built as (a coffee table like a shelf: "on" it)."""
    if motion in TOOL_MOTIONS_SAID and {"Theme", "Instrument"} <= set(roles):
        return f"{TOOL_MOTIONS_SAID[motion]} the {roles['Theme']} with the {roles['Instrument']}"
    if motion not in (*MOTIONS, "serve") or not {"Theme", "Destination"} <= set(roles):
        return None
    theme, place = roles["Theme"], roles["Destination"]
    if motion == "serve":
        return f"served the {theme} into the {place}" + (
            f" with the {roles['Instrument']}" if "Instrument" in roles else ""
        )
    if motion == "hand over":
        return f"handed the {theme} to the {place}"
    if motion == "dispose":
        return f"threw the {theme} into the {place}"
    found = household().get((built_like or {}).get(place, place))
    return f"put the {theme} {'on' if found and found.surface == 'top' else 'into'} the {place}"


def phrase(frame: Mapping | Frame, lexicon: Lexicon | None = None, tense: str = "base") -> str:
    """The frame as a verb phrase from its predicate's template: "pour the water into the cup" (`tense`
    "base") or "poured the water into the cup" ("past"). Every object gets "the" (they are on the table);
    a role without a filler reads "anything"."""
    lexicon = lexicon or load_lexicon()
    predicate, roles = _parts(frame)
    spec = lexicon.predicates[predicate]

    def filled(match: re.Match) -> str:
        value = roles.get(match.group(2))
        return f"the {value}" if value else "anything"

    text = _SLOT.sub(filled, spec.template(roles))
    if tense == "past":
        verb, _, rest = text.partition(" ")
        text = f"{past_tense(verb, spec.past)} {rest}".strip()
    return text


def spoken(ident: str) -> str:
    """An object's id as a person hears it: "cup" -> "the cup", "cup#2" -> "the second cup" (an id the
    scene assigned), "red cup" -> "the red cup"."""
    match = _AUTO_ID.fullmatch(ident)
    if match is None:
        return f"the {ident}"
    n = int(match.group(2))
    return f"the {ORDINALS[n - 1]} {match.group(1)}" if n <= len(ORDINALS) else f"{match.group(1)} number {n}"


def say(outcome: Mapping, lexicon: Lexicon | None = None) -> str:
    """What the robot says about `outcome`, a mapping with (some of) the fields of `lmcr execute`'s and
    `lmcr robot`'s JSON: `frame` ({"predicate", "roles"} or a Frame), `feasible`, `success`, `checks`,
    `reason`, `out_of_reach`, `unreachable`, `blocker`, `chosen_object`, `suggestion`, `question`, `left`,
    and for an error `error` with `error_kind` ("unknown_predicate", "incomplete" with the parsed `frame`,
    "absent" with the `absent` label, "unfit" with what it was asked, `doing`, and why its tool cannot,
    `reason`; see `error_outcome`)."""
    lexicon = lexicon or load_lexicon()
    if outcome.get("error"):
        return _error(outcome, lexicon)
    if outcome.get("left"):
        return LEAVE_IT
    frame = outcome.get("frame")
    if "feasible" not in outcome:  # completed, not yet acted on: the completion's question, if any
        return outcome.get("question") or (f"I'll {phrase(frame, lexicon)}." if frame else LEAVE_IT)
    if _parts(frame)[0] not in lexicon.predicates:
        return _cannot_do(_parts(frame)[0], lexicon)
    if not outcome["feasible"]:
        return _refusal(outcome, frame, lexicon)
    if outcome.get("success"):
        done = motion_done(outcome.get("motion"), _parts(frame)[1], outcome.get("built_like"))
        return f"I {done or phrase(frame, lexicon, 'past')}."
    return f"I tried to {phrase(frame, lexicon)}, but {_what_failed(outcome.get('checks') or {})}."


def error_outcome(exc: Exception) -> dict:
    """The fields `say` reads from an error: its one-line text and its kind (with what the kind needs)."""
    from lmcr.errors import one_line

    out: dict = {"error": one_line(exc)}
    if getattr(exc, "absent", None):  # a stated object that is not on the table
        out.update(error_kind="absent", absent=exc.absent)
    elif getattr(exc, "frame", None):  # a frame the objects on the table cannot complete
        out.update(error_kind="incomplete", frame=exc.frame)
    elif getattr(exc, "unfit", None):  # a tool that cannot do what the verb's class does with it
        out.update(error_kind="unfit", doing=exc.unfit[0], reason=exc.unfit[1])
    elif getattr(exc, "negated", None):  # asked only not to do something
        out.update(error_kind="negated", predicate=exc.negated)
    elif any(c.__name__ == "NoPredicateError" for c in type(exc).__mro__):  # by name: no spaCy to import
        out["error_kind"] = "unknown_predicate"
        if getattr(exc, "predicate", None):  # understood, but no motion for it
            out["predicate"] = exc.predicate
    return out


def _parts(frame: Mapping | Frame) -> tuple[str, dict]:
    if isinstance(frame, Frame):
        return frame.predicate, frame.role_map
    return frame["predicate"], dict(frame["roles"])


def _error(outcome: Mapping, lexicon: Lexicon) -> str:
    kind = outcome.get("error_kind")
    if kind == "unknown_predicate":
        return _cannot_do(outcome.get("predicate"), lexicon)
    if kind == "negated":
        return f"All right, I won't {outcome['predicate']}."
    if kind == "absent":
        return f"I see no {outcome['absent']} on the table."  # "no" suits a cup and milk alike
    if kind == "unfit":
        return f"Sorry, I can't {outcome['doing']}: {outcome['reason']}."
    if kind == "incomplete" and _parts(outcome["frame"])[0] in lexicon.predicates:
        return f"I can't {phrase(outcome['frame'], lexicon)} here."
    return f"Sorry, I can't do that: {outcome['error']}."


def _cannot_do(predicate: str | None, lexicon: Lexicon) -> str:
    """'Sorry, I don't know how to do that. I can blend, brush, ... or sprinkle things, and put things
    away, throw them out, hand them over, ...' (the paper's predicates' motions, and the learned verbs')"""
    verbs = lexicon.hand_written  # what the robot has motions for
    can = ", ".join(verbs[:-1]) + f" or {verbs[-1]}" if len(verbs) > 1 else "".join(verbs)
    return f"Sorry, I don't know how to {predicate or 'do that'}. I can {can} things, {MOTIONS_SAID}."


def _refusal(outcome: Mapping, frame, lexicon: Lexicon) -> str:
    """Why the robot did not move, and the other object it offers when one would do."""
    # what stands out of reach as the planner names it ("the soup"), else the object the completion chose
    unreachable = (outcome.get("unreachable") or "").removeprefix("the ") or outcome.get("chosen_object")
    if outcome.get("out_of_reach"):
        why = (
            f"I can't reach {spoken(unreachable)}"
            if unreachable
            else f"I can't reach far enough to {phrase(frame, lexicon)}"
        )
    elif outcome.get("blocker"):  # a clash's name: "the pot", "the cup#2"
        blocker = outcome["blocker"]
        why = f"I can't {phrase(frame, lexicon)}: {spoken(blocker.removeprefix('the '))} is in the way"
    else:
        why = f"I can't {phrase(frame, lexicon)} without a mishap"
    suggestion = outcome.get("suggestion")
    if not suggestion:
        return f"{why}."
    predicate, roles = _parts(frame)
    offered = {"predicate": predicate, "roles": {**roles, **suggestion}}
    return f"{why}: should I {phrase(offered, lexicon)} instead?"


def _what_failed(checks: Mapping) -> str:
    """What went wrong, from the per-verb checks, in the words a person would use."""
    said = []
    if checks.get("grasped") is False:
        said.append("I lost my grip")
    for key, where in (("liquid_in_target", "went in"), ("powder_on_target", "landed on it")):
        if isinstance(checks.get(key), (int, float)) and checks.get("verb_check") is False:
            said.append(f"only {checks[key]:.0%} of it {where}")
    if checks.get("in_target") is False:
        said.append("it did not end up in place")
    if checks.get("dipped_below_rim") is False:
        said.append("it did not go in deep enough")
    elif checks.get("lifted_out") is False:
        said.append("I could not lift it back out")
    if checks.get("over_target") is False:
        said.append("I missed the spot")
    if checks.get("knocked"):
        said.append("I bumped into " + _listed([spoken(i) for i in checks["knocked"]]))
    if checks.get("waypoints_within_tolerance") is False and not said:
        said.append("my arm did not get where it should")
    return _listed(said) if said else "it did not work out"


def _listed(items: list[str]) -> str:
    return ", ".join(items[:-1]) + f" and {items[-1]}" if len(items) > 1 else "".join(items)
