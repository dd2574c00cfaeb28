"""Completion edge cases with the real parser and a stand-in scorer, and the calibration rule."""

from __future__ import annotations

import json
import math

import pytest

from lmcr.complete import CompletionConfig, CompletionError, calibrate, complete, load_config, save_config, softmax
from lmcr.srl.instruction import NoPredicateError, parse_instruction
from lmcr.srl.parser import load_parser

pytestmark = pytest.mark.model
LIKES = {"cup": 3.0, "glass": 2.9, "bowl": 0.0, "scissors": -5.0, "water": 1.0, "milk": 0.5}


def scorer(frames, context=""):
    """Prefers objects by LIKES, summed over roles (a stand-in for an LM)."""
    return [sum(LIKES.get(v, -1.0) for v in roles.values()) for _, roles in frames]


@pytest.fixture(scope="module")
def parser():
    return load_parser()


def test_one_missing_role_is_filled_with_probabilities(parser):
    out = complete(
        parser, scorer, "pour me some water", ["scissors", "cup", "bowl", "water"], CompletionConfig(set_threshold=0.5)
    )
    assert out.frame.to_json() == {"predicate": "pour", "roles": {"Theme": "water", "Destination": "cup"}}
    assert out.missing == "Destination" and [c.object for c in out.candidates] == ["cup", "bowl", "scissors"]
    assert sum(c.probability for c in out.candidates) == pytest.approx(1, abs=1e-3)
    assert out.question is None  # the stated theme is no candidate; cup clearly wins


def test_close_candidates_give_a_question_naming_them(parser):
    out = complete(parser, scorer, "pour me some water", ["glass", "cup", "bowl"], CompletionConfig(set_threshold=0.3))
    assert out.frame.role_map["Destination"] == "cup"
    assert out.question == "Should I pour water into the cup or the glass?"  # not the unlikely bowl
    pair = complete(parser, scorer, "pour it", ["water", "milk", "cup", "glass"], CompletionConfig(set_threshold=0.9))
    assert pair.question == (
        "Should I pour cup into the glass, pour glass into the cup "  # the stand-in's taste
        "or pour water into the cup?"
    )


def test_complete_instruction_comes_back_unchanged(parser):
    out = complete(parser, scorer, "pour the water into the bowl", ["cup"])
    assert out.to_json() == {
        "frame": {"predicate": "pour", "roles": {"Theme": "water", "Destination": "bowl"}},
        "missing": None,
        "missing_roles": [],
        "referred": {},
        "served": {},
        "unresolved": {},
        "unfamiliar_objects": [],
        "ignored_objects": [],
        "candidates": [],
        "question": None,
        "context": "",
        "instances": {"Theme": [], "Destination": []},
        "prediction_set": [],  # nothing was predicted
    }


@pytest.mark.parametrize(
    ("objects", "threshold", "expected_set"),
    [
        (["scissors", "cup", "bowl"], 0.5, ["cup"]),  # one likely object: no question
        (["glass", "cup", "bowl"], 0.3, ["cup", "glass"]),  # two: ask between them
        (["glass", "cup", "bowl"], 0.9, []),  # none sure enough: ask among the best
    ],
)
def test_to_json_keeps_the_contract_keys_and_the_prediction_set_matches_the_question(
    parser, objects, threshold, expected_set
):
    out = complete(parser, scorer, "pour me some water", objects, CompletionConfig(set_threshold=threshold))
    line = out.to_json()
    assert list(line) == [
        *("frame", "missing", "missing_roles", "referred", "served", "unresolved", "unfamiliar_objects"),
        *("ignored_objects", "candidates", "question", "context", "instances", "prediction_set"),
    ]
    assert json.loads(json.dumps(line)) == line  # plain JSON: lists, not tuples or dataclasses
    assert line["frame"] == out.frame.to_json() and line["missing"] == "Destination"
    assert line["candidates"][0] == {
        "object": "cup",
        "objects": {"Destination": "cup"},
        "score": out.candidates[0].score,
        "probability": out.candidates[0].probability,
        "ids": ["cup"],
    }
    assert line["prediction_set"] == expected_set == [c.object for c in out.candidates if c.probability >= threshold]
    assert (line["question"] is not None) == (len(expected_set) != 1)


def test_objects_sharing_a_label_are_one_candidate_listing_their_ids(parser):
    """Three cups and two bowls: one candidate per label (the probabilities are not split between
    copies), each with the ids of its objects, assigned in order as a scene assigns them, or given."""
    out = complete(parser, scorer, "pour me some water", ["cup", "bowl", "water", "cup", "bowl", "cup"])
    assert sorted((c.object, list(c.ids)) for c in out.candidates) == [
        ("bowl", ["bowl", "bowl#2"]),
        ("cup", ["cup", "cup#2", "cup#3"]),
    ]
    assert out.instances["Theme"] == ["water"]
    assert sum(c.probability for c in out.candidates) == pytest.approx(1)
    given = complete(parser, scorer, "pour the water into the cup", ["cup", "water", "cup"], ids=["a", "w", "b"])
    assert given.instances == {"Theme": ["w"], "Destination": ["a", "b"]}


def test_a_stated_word_the_robot_cannot_ground_is_filled_and_confirmed(parser):
    """'side' is neither detected nor in the robot's object vocabulary; 'water' (not detected) is."""
    out = complete(parser, scorer, "fry two sunny side up in the pan", ["pan", "cup", "glass"])
    assert out.unresolved == {"Theme": "side"} and out.missing == "Theme"
    assert out.frame.role_map == {"Theme": "cup", "Instrument": "pan"}
    assert out.question == "I see no side. Should I fry the cup or the glass in the pan?"
    kept = complete(parser, scorer, "pour the water", ["cup", "bowl"])
    assert kept.unresolved == {} and kept.frame.role_map["Theme"] == "water"
    heard = []
    coffee = complete(
        parser,
        lambda frames, context="": heard.append(context) or scorer(frames),
        "pour a little milk in my coffee",
        ["mug", "bowl", "milk"],
    )
    assert coffee.unresolved == {"Destination": "coffee"} and heard == ["in my coffee"]  # what it says of the mug
    assert coffee.context == "in my coffee" and coffee.question.startswith("I see no coffee. ")


def test_a_pronoun_refers_back_to_a_detected_object_named_before_it(parser):
    out = complete(parser, scorer, "I'd love some wine, could you pour it?", ["wine", "water", "cup", "glass"])
    assert out.frame.role_map == {"Theme": "wine", "Destination": "cup"} and out.referred == {"Theme": "wine"}
    assert out.missing_roles == ("Destination",)  # the stand-in likes water better: the speaker said wine
    unseen = complete(parser, scorer, "I'd love some juice, could you pour it?", ["wine", "water", "cup", "glass"])
    assert unseen.referred == {} and unseen.missing_roles == ("Theme", "Destination")  # no juice: the scene decides
    plain = complete(parser, scorer, "pour it into the cup", ["wine", "water", "cup"])
    assert plain.referred == {} and plain.frame.role_map["Theme"] == "water"
    # the parser names the antecedent by its lemma ("carrot"): it is the carrots on the table
    plural = complete(parser, scorer, "These carrots are cooked. Dump them into the bowl.", ["carrots", "bowl", "cup"])
    assert plural.referred == {"Theme": "carrots"} and plural.frame.role_map["Theme"] == "carrots"


def test_the_vessel_a_request_serves_in_is_where_it_goes(parser):
    out = complete(parser, scorer, "could you pour me a glass of water?", ["pot", "bowl", "glass", "water"])
    assert out.served == {"Destination": "glass"} and out.missing is None
    assert out.frame.role_map == {"Theme": "water", "Destination": "glass"} and out.question is None
    unseen = complete(parser, scorer, "pour me a glass of water", ["pot", "bowl", "cup"])  # no glass: the scene decides
    assert unseen.served == {} and unseen.missing == "Destination"
    measured = complete(parser, scorer, "pour me half a cup of milk", ["cup", "bowl", "pot"])  # a quantity
    assert measured.served == {} and measured.missing == "Destination"
    stated = complete(parser, scorer, "pour me a glass of water into the pot", ["pot", "glass"])
    assert stated.served == {} and stated.frame.role_map["Destination"] == "pot"


def test_a_stated_object_that_is_detected_grounds_without_the_robot_vocabulary(parser):
    """The person named the cucumber and the robot sees one: it is no choice of the scorer's, so it stays
    (not 'I see no cucumber') and is no question; an unnamed detection outside the vocabulary is a candidate."""
    out = complete(parser, scorer, "season the sliced cucumbers", ["cucumber", "salt", "kumquat", "cup"])
    assert out.unresolved == {} and out.missing == "Instrument" and out.question is None
    assert out.frame.role_map == {"Theme": "cucumber", "Instrument": "cup"}  # the stand-in likes cups
    assert out.unfamiliar_objects == ("kumquat",) and [c.object for c in out.candidates] == ["cup", "salt", "kumquat"]
    unseen = complete(parser, scorer, "season the sliced cucumbers", ["salt", "cup"])
    assert unseen.unresolved == {"Theme": "cucumber"} and unseen.question.startswith("I see no cucumber.")


def test_two_missing_roles_score_object_pairs(parser):
    out = complete(parser, scorer, "pour it", ["water", "milk", "cup", "scissors"])
    assert out.missing_roles == ("Theme", "Destination")
    assert set(out.frame.role_map.values()) == {"cup", "water"}  # the best-scoring pair
    assert all(c.objects["Theme"] != c.objects["Destination"] for c in out.candidates)
    assert len(out.candidates) == 12
    vague = complete(parser, scorer, "I'm thirsty, pour me something", ["water", "milk", "cup", "scissors"])
    assert vague.missing_roles == ("Theme", "Destination") and vague.unresolved == {}  # no "I see no something"


def test_empty_objects_and_unknown_verbs_are_clear_errors(parser):
    with pytest.raises(CompletionError, match="no usable objects"):
        complete(parser, scorer, "pour me some water", [])
    with pytest.raises(CompletionError, match="no usable objects"):
        complete(parser, scorer, "pour me some water", ["water"])
    with pytest.raises(NoPredicateError, match="no known predicate"):
        complete(parser, scorer, "juggle the oranges", ["cup"])
    with pytest.raises(CompletionError, match="the limit is 5"):
        complete(parser, scorer, "pour it", ["water", "milk", "cup"], CompletionConfig(max_frames=5))


def test_calibration_temperature_and_conformal_threshold(tmp_path):
    confident = [[5.0, 0.0, 0.0]] * 20
    cal = calibrate(confident, alpha=0.1)
    assert cal.temperature <= 0.1 + 1e-9 and cal.set_threshold > 0.99  # sharper is better when always right
    mixed = [[2.0, 0.0, 0.0]] * 8 + [[0.0, 2.0, 0.0]] * 2
    cal = calibrate(mixed, alpha=0.1)
    probs = [softmax(s, cal.temperature)[0] for s in mixed]
    assert sum(p >= cal.set_threshold for p in probs) / len(probs) >= 0.9  # coverage on the calibration data
    assert math.isfinite(cal.temperature)
    save_config(cal, tmp_path / "c.json", "abc")
    assert load_config(tmp_path / "c.json", "abc") == cal and load_config(tmp_path / "c.json", "other") is None


def test_a_scorer_is_one_registry_entry(monkeypatch):
    """A new method is one SCORERS entry: `make_scorer`, sums and calibration fingerprints follow."""
    from lmcr.frame import Frame
    from lmcr.scorers import registry as methods
    from lmcr.scorers.resources import MethodResources

    spec = methods.ScorerSpec(
        lambda res: lambda frames: [float(len(f.predicate)) for f in frames], lambda res: "len-v1"
    )
    monkeypatch.setitem(methods.SCORERS, "verb_length", spec)
    res = MethodResources(checkpoints=__import__("pathlib").Path("/nonexistent"))
    frames = [Frame.of("pour", {"Theme": "water"}), Frame.of("season", {"Theme": "rice"})]
    assert methods.make_scorer("verb_length", res)(frames) == [4.0, 6.0]
    assert methods.make_scorer("verb_length+verb_length", res)(frames) == [8.0, 12.0]
    assert methods.scorer_fingerprint("verb_length+verb_length", res) == "len-v1+len-v1"
    assert methods.scorer_fingerprint("verb_length+random", res) is None  # random is never calibrated


def test_the_learned_verbs_calibration_is_read_beside_the_methods_and_only_with_it(monkeypatch, tmp_path):
    """`lmcr evaluate --requests` saves the learned verbs' calibration beside the method's, under its
    fingerprint: completion reads both; without the method's own, or under another fingerprint, neither."""
    from lmcr.complete import calibration_file, completion_scorer, requests_calibration_file
    from lmcr.scorers import registry as methods
    from lmcr.scorers.resources import MethodResources

    spec = methods.ScorerSpec(lambda res: lambda frames: [0.0] * len(frames), lambda res: "const-v1")
    monkeypatch.setitem(methods.SCORERS, "const", spec)
    res = MethodResources(checkpoints=tmp_path / "none")
    path, fingerprint = calibration_file("const", res, tmp_path)
    learned = CompletionConfig(temperature=9.0, set_threshold=0.1, source="requests")
    save_config(learned, requests_calibration_file(path), fingerprint)
    assert completion_scorer("const", res, tmp_path)[1].learned_temperature is None  # uncalibrated defaults
    save_config(CompletionConfig(temperature=2.0, set_threshold=0.5, source="ratings"), path, fingerprint)
    config = completion_scorer("const", res, tmp_path)[1]
    assert (config.temperature, config.calibrated_for(True).temperature, config.learned_source) == (
        2.0,
        9.0,
        "requests",
    )
    save_config(learned, requests_calibration_file(path), "another scorer")
    assert completion_scorer("const", res, tmp_path)[1].calibrated_for(True).temperature == 2.0


def test_a_modifier_the_parser_kept_does_not_hide_a_detected_object(parser):
    """Without learned compounds the parser keeps "leftover pizza" whole; the robot sees a pizza."""
    assert parse_instruction(parser, "heat the leftover pizza").roles["Theme"] == "leftover pizza"
    out = complete(parser, scorer, "heat the leftover pizza", ["pizza", "microwave", "cup"])
    assert out.unresolved == {} and out.missing == "Instrument"
    assert out.frame.role_map["Theme"] == "pizza" and "pizza" not in [c.object for c in out.candidates]


def test_instruction_accuracy_counts_a_question_by_its_best_guess(parser, tmp_path):
    from lmcr.evaluate.instructions import instruction_accuracy, load_instructions
    from lmcr.jsonl import InputError

    def pour(destination):
        return {"predicate": "pour", "roles": {"Theme": "water", "Destination": destination}}

    lines = [
        {"instruction": "pour me some water", "objects": ["scissors", "cup", "bowl"], "expected": pour("cup")},
        {"instruction": "pour me some water", "objects": ["glass", "cup"], "expected": pour("cup")},  # asks, cup first
        {
            "instruction": "pour me some water",
            "objects": ["glass", "cup"],
            "expected": pour("glass"),
        },  # asks, wrong guess
        {"instruction": "pour me some water", "objects": ["bowl", "scissors"], "expected": pour("scissors")},
        {"instruction": "wash the cup", "objects": ["cup", "sink"], "expected": pour("cup")},
    ]  # no robot verb
    path = tmp_path / "instructions.jsonl"
    path.write_text("".join(json.dumps(line) + "\n" for line in lines), encoding="utf-8")
    done = instruction_accuracy(parser, scorer, CompletionConfig(set_threshold=0.3), load_instructions(path))
    assert (done.total, done.answered_right, done.asked, done.asked_right, done.right) == (5, 1, 2, 1, 2)
    assert done.accuracy == 0.4 and [roles.get("Destination") for _, roles, _ in done.wrong] == ["cup", "bowl", None]
    assert "no known predicate in 'wash the cup'" in done.wrong[-1][1]["error"]  # counted wrong, not a crash
    assert done.summary().splitlines()[0] == (
        "dev instructions: 2/5 = 0.400 right (1 answered right, 2 questions of which 1 guess right)"
    )
    path.write_text(json.dumps(lines[0]) + "\n" + '{"instruction": "pour it"}\n', encoding="utf-8")
    with pytest.raises(InputError, match=r"instructions.jsonl:2"):
        load_instructions(path)


def test_a_stated_thing_grounds_in_the_one_object_its_head_word_names(parser):
    """ "the soda" is the orange soda on the table, "redbull" the red bull; with two kinds of chips "the
    chips" names neither, and the robot asks which (it sees more than one, not none)."""
    soda = complete(parser, scorer, "pour the soda", ["orange soda", "cup", "bowl"])
    assert soda.frame.role_map["Theme"] == "orange soda" and not soda.unresolved
    bull = complete(parser, scorer, "pour the redbull", ["red bull", "cup"])
    assert bull.frame.role_map["Theme"] == "red bull"
    chips = complete(parser, scorer, "pour the chips into the bowl", ["kettle chips", "multigrain chips", "bowl"])
    assert chips.unresolved == {"Theme": "chip"} and chips.question.startswith("I see more than one chip.")


def test_a_thing_said_but_not_grounded_is_no_missing_role_and_is_one_of_the_objects_it_names(parser):
    """ "pour the chips" with two kinds of chips: the Destination is what the request left missing; the
    Theme was said, so the robot picks one of the chips for it (never the cup), and offers the pairs."""
    out = complete(parser, scorer, "pour the chips", ["kettle chips", "multigrain chips", "cup", "bowl"])
    assert out.missing_roles == ("Destination",) and out.unresolved == {"Theme": "chip"}
    assert {c.objects["Theme"] for c in out.candidates} == {"kettle chips", "multigrain chips"}
    assert all(c.object == c.objects["Destination"] for c in out.candidates)  # a candidate names the missing role
    assert out.frame.role_map["Destination"] == "cup"
    assert out.question.startswith("I see more than one chip. Should I pour ")
    unnamed = complete(parser, scorer, "pour the crisps", ["kettle chips", "cup", "bowl"])  # names no object
    assert unnamed.missing_roles == ("Destination",) and {c.objects["Theme"] for c in unnamed.candidates} == {
        "kettle chips",
        "cup",
        "bowl",
    }


def test_a_stated_thing_grounds_in_the_object_named_in_either_number_or_in_full(parser):
    """The parser's lemma "carrot" is the carrots on the table, "dish" the dishes, "patty" the mint
    patties; an object whose whole label the instruction says is what a filler cut short stands for
    ("the tank top": Theme 'tank'), and one it says where the filler ends ("the blue cup": 'cup'); "the
    trash" names the one trash can; a detected object comes before the robot's word for it."""
    from lmcr.grounding import ground_roles, named_by_head, named_by_modifier, said_before, said_in_full, same_noun

    assert same_noun("carrot", "carrots") and same_noun("dishes", "dish") and same_noun("patty", "patties")
    assert not same_noun("cup", "cups of") and not same_noun("pan", "pants")
    assert named_by_head("carrot", ["carrots", "counter"]) == "carrots"
    assert named_by_head("mint patty", ["mint patties", "corner"]) == "mint patties"
    assert named_by_head("plate", ["plates", "plate"]) is None  # two objects: the robot asks
    said = "put the tank top away"
    assert said_in_full("tank", ["tank top", "closet"], said) == "tank top"
    assert said_in_full("steel", ["stainless steel spoon", "steel pan"], "put the stainless steel spoon away") == (
        "stainless steel spoon"
    )
    assert said_in_full("top", ["tank top"], "put the top away") is None  # the label is not said in full
    # "the trash" is the trash can, "the recycling" the recycling bin: a label's first words, one object
    assert named_by_modifier("trash", ["trash can", "banana"]) == "trash can"
    assert named_by_modifier("storage", ["storage box", "storage chest"]) is None  # which: the robot asks
    assert named_by_modifier("can", ["trash can", "canister"]) is None
    # "the blue cup": the parser keeps 'cup', and a blue cup is on the table beside a cup
    assert said_before(len("pour it into the blue cup"), "cup", ["cup", "blue cup"], "pour it into the blue cup") == (
        "blue cup"
    )
    assert said_before(len("pour it into the cup"), "cup", ["cup", "blue cup"], "pour it into the cup") is None
    blue = complete(parser, scorer, "pour the water into the blue cup", ["water", "cup", "blue cup"])
    assert blue.frame.role_map["Destination"] == "blue cup" and blue.missing is None
    said = {"Theme": "shirt", "Destination": "laundry"}
    roles, unresolved = ground_roles(said, ("cup",), ["shirt", "laundry basket"])
    assert roles == {"Theme": "shirt", "Destination": "laundry basket"} and not unresolved
    roles, unresolved = ground_roles({"Theme": "egg", "Destination": None}, ("egg", "bowl"), ["eggs", "bowl"], "")
    assert roles == {"Theme": "eggs", "Destination": None} and not unresolved
    poured = complete(parser, scorer, "pour the carrots into the bowl", ["carrots", "bowl", "cup"])
    assert poured.frame.role_map["Theme"] == "carrots" and not poured.unresolved


def test_a_request_is_scored_on_the_idle_cores_and_the_setting_comes_back(parser, monkeypatch):
    """A completion's kernels on two threads wait for the slower one, and on a busy machine that is one
    the scheduler put aside (`lmcr.lm.threads`): a request runs on the cores the load average leaves idle;
    the process's own setting is back afterwards, also when the scorer fails."""
    import os

    import torch

    from lmcr.lm.threads import idle_cores

    seen = []

    def counting(frames, context=""):
        seen.append(torch.get_num_threads())
        return scorer(frames, context)

    def failing(frames, context=""):
        raise RuntimeError("scorer broke")

    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        for load, threads in ((3.1, 1), (1.6, 1), (1.0, 2), (0.2, 2)):  # two busy cores ... an idle machine
            monkeypatch.setattr(os, "getloadavg", lambda load=load: (load, load, load))
            assert idle_cores() == threads
            seen.clear()
            complete(parser, counting, "pour me some water for my tea", ["cup", "bowl", "water"])
            assert seen and set(seen) == {threads} and torch.get_num_threads() == 2
        monkeypatch.setattr(os, "getloadavg", lambda: (3.1, 3.1, 3.1))
        with pytest.raises(RuntimeError, match="scorer broke"):
            complete(parser, failing, "pour me some water", ["cup", "bowl", "water"])
        assert torch.get_num_threads() == 2

        def unreadable():
            raise OSError("no load average here")

        monkeypatch.setattr(os, "getloadavg", unreadable)
        assert idle_cores() == 1
    finally:
        torch.set_num_threads(before)
