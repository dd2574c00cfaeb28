"""The robot in conversation: an instruction, the robot's question when it is unsure, the person's answer,
then the action.

Turns come from anywhere (typed lines, a scripted file, transcribed WAVs). The robot completes each
instruction against the objects on the table; when the completion asks ("Should I pour the milk into
the bowl or the glass?") it waits for an answer and reads it: an object on the table ("the glass",
"into the mug please"), "yes" (the first choice), "no, the other one" (the second of two choices).
An answer naming something not on the table, or nothing it can use, gets a re-ask; after three such
answers the robot says "I'll leave it." and waits for the next instruction. What the robot says about
each outcome is `lmcr.robot.reply.say`'s sentence ("I poured the water into the glass."), kept as the
outcome's `reply`.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from lmcr.complete import Completion, CompletionConfig, complete
from lmcr.errors import LMCRError
from lmcr.robot.budget import Budget
from lmcr.robot.execute import execute
from lmcr.robot.reply import error_outcome
from lmcr.robot.reply import say as sentence
from lmcr.robot.scene import Scene
from lmcr.srl.parser import FrameParser

MAX_TRIES = 3
YES = frozenset({"yes", "yeah", "yep", "sure", "ok", "okay", "right", "correct", "exactly"})
NO = frozenset({"no", "nope", "nah"})
OTHER = frozenset({"other", "another", "second", "else"})


@dataclass(frozen=True)
class Reading:
    """What an answer says: the object chosen, or why it cannot be used (then the robot re-asks)."""

    choice: str | None
    problem: str | None = None


def read_answer(answer: str, choices: list[str], on_table: list[str], vocabulary: tuple[str, ...]) -> Reading:
    """Read one answer to a question offering `choices` (best first)."""
    text = " ".join(re.findall(r"[a-z]+", answer.lower()))
    words = set(text.split())
    named = [
        label
        for label in sorted(set(vocabulary) | set(on_table), key=len, reverse=True)
        if re.search(rf"\b{re.escape(label)}(?:e?s)?\b", text)
    ]
    for label in named:
        if label in on_table:
            return Reading(label)
    if named:
        return Reading(None, f"I don't see {_a(named[0])} {named[0]} on the table.")
    if words & OTHER and len(choices) == 2:
        return Reading(choices[1])
    if words & OTHER:
        return Reading(None, "Which one do you mean?")
    if words & YES and not words & NO:
        return Reading(choices[0])
    if words & NO:
        return Reading(None, "Which one should I use then?")
    return Reading(None, "Sorry, I did not understand.")


def _a(word: str) -> str:
    return "an" if word[:1] in "aeiou" else "a"


def converse(
    turns: Iterator[str],
    scene: Scene,
    parser: FrameParser,
    scorer: Callable,
    config: CompletionConfig,
    cache_dir: Path,
    say: Callable[[str], None],
    budget: Budget | None = None,
) -> list[dict]:
    """Run the conversation until the turns run out; each instruction's outcome is one dict (executed
    result, left, or error) with what the robot said about it (`reply`); each instruction's planning search
    has the `budget`."""
    outcomes = []
    on_table = [o.label for o in scene.objects]

    def done(outcome: dict) -> None:
        outcome["reply"] = sentence(outcome, parser.lex)
        say(f"robot: {outcome['reply']}")
        outcomes.append(outcome)

    for instruction in turns:
        say(f"you: {instruction}")
        try:  # an instruction the robot cannot parse, complete or carry out is answered; the talk goes on
            completion = complete(parser, scorer, instruction, on_table, config)
            answer = None
            if completion.question:
                answer = _ask(completion, turns, on_table, parser.lex.objects, say)
                if answer is None:
                    done({"instruction": instruction, "left": True, "question": completion.question})
                    continue
            result = execute(instruction, scene, parser, scorer, config, cache_dir, answer=answer, budget=budget)
            if not result["feasible"] and result.get("suggestion"):  # "I can't reach the cup: should I ...?"
                answer = _offer(result, turns, on_table, parser.lex.objects, say)
                if answer is None:
                    done({"instruction": instruction, **result, "left": True})
                    continue
                result = execute(instruction, scene, parser, scorer, config, cache_dir, answer=answer, budget=budget)
        except LMCRError as exc:
            done({"instruction": instruction, **error_outcome(exc)})
            continue
        done({"instruction": instruction, **({"answer": answer} if answer else {}), **result})
    return outcomes


def _offer(
    result: dict, turns: Iterator[str], on_table: list[str], vocabulary: tuple[str, ...], say: Callable[[str], None]
) -> dict[str, str] | None:
    """Offer the feasible alternative the robot found; yes (or naming it) takes it, anything else leaves it."""
    role, offered = next(iter(result["suggestion"].items()))
    say(f"robot: {result['question']}")
    reply = next(turns, None)
    if reply is None:
        return None
    say(f"you: {reply}")
    reading = read_answer(reply, [offered, result["chosen_object"]], on_table, vocabulary)
    if reading.choice != offered:
        return None
    return {role: offered}


def _ask(
    completion: Completion,
    turns: Iterator[str],
    on_table: list[str],
    vocabulary: tuple[str, ...],
    say: Callable[[str], None],
) -> dict[str, str] | None:
    """Ask the completion's question until an answer picks an object (role -> object), at most three times."""
    role = completion.missing
    choices = [c.object for c in completion.candidates]
    question = completion.question
    for _ in range(MAX_TRIES):
        say(f"robot: {question}")
        reply = next(turns, None)
        if reply is None:
            return None
        say(f"you: {reply}")
        stated = {v for r, v in completion.frame.roles if r != role}
        reading = read_answer(reply, choices, [o for o in on_table if o not in stated], vocabulary)
        if reading.choice:
            return {role: reading.choice}
        question = f"{reading.problem} {completion.question}"
    return None
