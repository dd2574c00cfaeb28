"""Predicates learned from the frame corpus: roles from prepositions and fillers, valence, phrasal verbs,
prepositional verbs, refusal for too little evidence, the published table, and the parser and the count
model using it. A tiny store built by hand; no spaCy model needed except where a test says so."""

from __future__ import annotations

import json

import pytest

from lmcr.frame import Frame
from lmcr.frame_corpus.predicates import (
    MIN_ALTERNATIVE_FRAMES,
    MIN_FRAMES,
    MIN_RATE,
    learn_predicates,
    publish_predicates,
    refresh_predicates,
)
from lmcr.lexicon import PREDICATES_FILE, load_lexicon
from lmcr.scorers.frame_counts import FrameCountScorer
from lmcr.store import connect
from lmcr.workspace import Workspace

SQL = Workspace.from_env().sql_dir
HAND = load_lexicon(learned=False)


def _frame(rows: list, roles: list, predicate: str, slots: dict[str, str], known: bool = False) -> None:
    key = ("household", f"d{len(rows)}", 0, 0)
    rows.append((*key, predicate, known))
    roles += [(*key, slot, value) for slot, value in slots.items()]


def _store(tmp_path, frames: list[tuple[str, dict, bool]]):
    con = connect(tmp_path / "lmcr.duckdb", SQL)
    rows, roles = [], []
    for predicate, slots, known in frames:
        _frame(rows, roles, predicate, slots, known)
    con.executemany(
        "insert into frames (corpus, doc_id, sent_id, frame_no, predicate, known, pred_start, pred_end) "
        "values (?, ?, ?, ?, ?, ?, 0, 1)",
        rows,
    )
    con.executemany(
        "insert into frame_roles (corpus, doc_id, sent_id, frame_no, role, value) values (?, ?, ?, ?, ?, ?)", roles
    )
    return con


def _kitchen() -> list[tuple[str, dict, bool]]:
    """Robot frames that say what containers and appliances are, and generic frames of four verbs."""
    robot = [("pour", {"Theme": "milk", "Destination": "bowl"}, True)] * 30
    robot += [("pour", {"Theme": "water", "Destination": "glass"}, True)] * 20
    robot += [("heat", {"Theme": "soup", "Instrument": "microwave"}, True)] * 20
    robot += [("heat", {"Theme": "oil", "Instrument": "oven"}, True)] * 20
    generic = [("put", {"Theme": "milk", "in": "bowl"}, False)] * 25
    generic += [("put", {"Theme": "cup", "in": "glass"}, False)] * 5
    generic += [("put away", {"Theme": "milk"}, False)] * 30  # seldom says where: the base verb does
    generic += [("bake", {"Theme": "cake", "in": "oven"}, False)] * 20
    generic += [("bake", {"Theme": "bread", "in": "microwave"}, False)] * 5
    generic += [("cut", {"Theme": "bread", "into": "cube"}, False)] * 30  # no thing: no role
    generic += [("dispose", {"of": "milk", "in": "bowl"}, False)] * 25
    generic += [("juggle", {"Theme": "egg", "in": "bowl"}, False)] * 3  # too little evidence
    # warmed in the microwave mostly, sometimes into a bowl: two open roles
    generic += [("warm", {"Theme": "soup", "in": "microwave"}, False)] * 20
    generic += [("warm", {"Theme": "milk", "into": "glass"}, False)] * 10
    return robot + generic


def test_roles_come_from_prepositions_and_the_robot_roles_fillers(tmp_path):
    table = learn_predicates(_store(tmp_path, _kitchen()), HAND)
    put, bake = table.predicates["put"], table.predicates["bake"]
    # "put in the bowl" reads like pour's Destination, "bake in the oven" like heat's Instrument
    assert put.roles == ("Theme", "Destination") and put.slots == {"Theme": "Theme", "in": "Destination"}
    assert bake.roles == ("Theme", "Instrument") and bake.sentence == "bake {Theme} in the {Instrument}"
    assert put.sentence == "put {Theme} in the {Destination}"
    # "cut into cubes": no thing fills it, so cut states no role but its Theme and is not learned
    assert "cut" not in table.predicates and table.refused["cut"] == 30
    assert "juggle" not in table.refused and "juggle" not in table.predicates  # under 5 frames: not listed


def test_a_phrasal_verb_takes_its_base_verbs_valence_and_a_prepositional_verb_its_theme(tmp_path):
    table = learn_predicates(_store(tmp_path, _kitchen()), HAND)
    away = table.predicates["put away"]
    assert (away.base, away.particle, away.roles) == ("put", "away", ("Theme", "Destination"))
    assert 0 < away.rates["Destination"] < table.predicates["put"].rates["Destination"]
    assert away.sentence == "put {Theme} away into the {Destination}"
    dispose = table.predicates["dispose"]
    assert dispose.theme_prep == "of" and dispose.sentence == "dispose of {Theme} in the {Destination}"
    assert dispose.spec_json()["preps"] == {"Destination": ["in"], "Theme": ["of"]}


def test_a_verb_with_two_open_roles_keeps_both_with_their_sentences(tmp_path):
    warm = learn_predicates(_store(tmp_path, _kitchen()), HAND).predicates["warm"]
    assert warm.roles == ("Theme", "Instrument") and warm.alternatives == {
        "Destination": "warm {Theme} into the {Destination}"
    }
    spec = warm.spec_json()
    assert spec["preps"] == {"Instrument": ["in"], "Destination": ["into"]}
    assert warm.rates == {"Theme": 1.0, "Instrument": 0.6667, "Destination": 0.3333}


def test_a_second_role_stated_in_too_few_frames_is_no_reading(tmp_path):
    """ "dispose" states its Instrument in 3 of its frames (a misparse more likely than a reading): not an
    open role beside its Destination; with a lower bound, or a verb that states it more often, it is."""
    frames = [("dispose", {"of": "milk", "in": "bowl"}, False)] * 25 + [("dispose", {"of": "milk"}, False)] * 12
    frames += [("dispose", {"of": "milk", "with": "microwave"}, False)] * 3 + _kitchen()
    con = _store(tmp_path, frames)
    dispose = learn_predicates(con, HAND).predicates["dispose"]
    assert dispose.rates["Instrument"] >= MIN_RATE and 3 < MIN_ALTERNATIVE_FRAMES
    assert dispose.roles == ("Theme", "Destination") and dispose.alternatives == {}
    loose = learn_predicates(con, HAND, min_alternative_frames=3).predicates["dispose"]
    assert loose.alternatives == {"Instrument": "dispose of {Theme} with the {Instrument}"}


def test_the_hand_written_eleven_are_never_learned_and_evidence_bounds_what_is(tmp_path):
    con = _store(tmp_path, _kitchen() + [("pour", {"Theme": "milk", "in": "bowl"}, False)] * 40)
    table = learn_predicates(con, HAND)
    assert not set(table.predicates) & set(HAND.predicates)
    assert MIN_FRAMES > 3 and "juggle" not in table.predicates
    strict = learn_predicates(con, HAND, min_frames=26)
    assert "put" in strict.predicates and "bake" not in strict.predicates and strict.refused["bake"] == 25


def test_the_published_table_merges_into_the_lexicon_and_the_count_model(tmp_path):
    con = _store(tmp_path, _kitchen())
    srl = tmp_path / "srl"
    srl.mkdir()
    assert refresh_predicates(con, HAND, srl, "build-1") is not None
    assert refresh_predicates(con, HAND, srl, "build-1") is None  # up to date: not learned again
    assert refresh_predicates(con, HAND, srl, "build-2") is not None
    lex = load_lexicon(learned=srl / PREDICATES_FILE)
    assert lex.learned == {"put", "put away", "bake", "dispose", "warm"}
    assert lex.hand_written == sorted(HAND.predicates) and lex.predicates["pour"] == HAND.predicates["pour"]
    assert lex.predicates["put away"].particles == {"away"} and lex.refused == {"cut": 30}
    rows = con.execute("select predicate, role2, build from learned_predicates order by 1").fetchall()
    assert rows[0] == ("bake", "Instrument", "build-2")
    con.close()
    counts = FrameCountScorer.from_store(tmp_path / "lmcr.duckdb", SQL)
    # the learned predicate's "in" slot is counted as its Destination, beside the eleven's roles
    assert counts.filler[("put", "Destination", "bowl")] == 25 and counts.filler[("pour", "Destination", "bowl")] == 30
    # an alternative open role is counted too: warm's Destination beside its Instrument
    assert (
        counts.filler[("warm", "Destination", "glass")] == 10
        and counts.filler[("warm", "Instrument", "microwave")] == 20
    )
    bowl, glass = (Frame.of("put", {"Theme": "milk", "Destination": d}) for d in ("bowl", "glass"))
    assert counts.score_frame(bowl) > counts.score_frame(glass)


def test_the_frame_counts_follow_a_table_learned_again_from_the_same_frames(tmp_path):
    """The learned table decides what the count model counts (its slots) and how its verbs back off (their
    classes): a table learned again from unchanged frames (other settings) changes the method's
    fingerprint, so a calibration made under the old table is not reused, and its kept counts."""
    from lmcr.scorers.registry import make_scorer, scorer_fingerprint
    from lmcr.scorers.resources import MethodResources

    con = _store(tmp_path, _kitchen())
    path = tmp_path / PREDICATES_FILE
    publish_predicates(con, learn_predicates(con, HAND), path, "b1")
    res = MethodResources(tmp_path / "ckpt", db=tmp_path / "lmcr.duckdb", sql_dir=SQL, predicates=path)
    put = [Frame.of("put", {"Theme": "milk", "Destination": "bowl"})]
    before, learned_score = scorer_fingerprint("frame_counts", res), make_scorer("frame_counts", res)(put)
    publish_predicates(con, learn_predicates(con, HAND, min_frames=10_000), path, "b1")  # the same build
    con.close()
    assert scorer_fingerprint("frame_counts", res) != before
    assert scorer_fingerprint("verb_fillers", res) == scorer_fingerprint("frame_counts", res)
    assert make_scorer("frame_counts", res)(put) < learned_score  # put's frames no longer counted
    # the counts kept under the old table are gone: nothing names them again
    kept = sorted(p.name for p in (tmp_path / "baselines").glob("frame-counts-*"))
    assert len(kept) == 2 and len({name.split("-")[-2] for name in kept}) == 1, kept


def test_a_republished_table_replaces_the_old_one_whole(tmp_path):
    con = _store(tmp_path, _kitchen())
    path = tmp_path / PREDICATES_FILE
    publish_predicates(con, learn_predicates(con, HAND), path, "b1")
    publish_predicates(con, learn_predicates(con, HAND, min_frames=10_000), path, "b2")
    assert con.execute("select count(*) from learned_predicates").fetchone() == (0,)
    assert con.execute("select count(*) from learned_predicate_slots").fetchone() == (0,)
    saved = json.loads(path.read_text())
    assert saved["predicates"] == {} and saved["settings"]["build"] == "b2"


def test_a_broken_table_is_one_line_naming_it(tmp_path):
    from lmcr.errors import LMCRError

    path = tmp_path / PREDICATES_FILE
    path.write_text(json.dumps({"predicates": {"put": {"spec": {"roles": ["Theme"]}}}}))
    with pytest.raises(LMCRError, match=f"{path}: cannot read the learned predicate table"):
        load_lexicon(learned=path)


@pytest.mark.parametrize("settings", [[], {"min_frames": "many"}, {"min_frames": -1}, {"min_frames": True}])
def test_a_table_whose_settings_give_no_frame_count_is_one_line_naming_it(tmp_path, settings):
    from lmcr.errors import LMCRError

    path = tmp_path / PREDICATES_FILE
    path.write_text(json.dumps({"predicates": {}, "settings": settings}))
    with pytest.raises(LMCRError, match=f"{path}: cannot read the learned predicate table.*'min_frames'"):
        load_lexicon(learned=path)


@pytest.fixture(scope="module")
def learned_parser(tmp_path_factory):
    """The real parser with the table learned from `_kitchen` (put, put away, bake, dispose; cut refused)."""
    from lmcr.srl.parser import FrameParser, load_nlp

    tmp = tmp_path_factory.mktemp("learned")
    con = _store(tmp, _kitchen())
    publish_predicates(con, learn_predicates(con, HAND), tmp / PREDICATES_FILE, "b")
    con.close()
    return FrameParser(load_nlp(), load_lexicon(learned=tmp / PREDICATES_FILE))


def _prefer(*order: str):
    return lambda frames, context="": [
        -min(order.index(v) if v in order else 99 for v in r.values()) for _, r in frames
    ]


@pytest.mark.model
@pytest.mark.parametrize(
    "instruction, predicate, roles",
    [
        ("put the milk away", "put away", {"Theme": "milk", "Destination": None}),
        ("could you put away the milk?", "put away", {"Theme": "milk", "Destination": None}),
        ("please put the steak seasoning away", "put away", {"Theme": "steak seasoning", "Destination": None}),
        ("put the milk in the bowl", "put", {"Theme": "milk", "Destination": "bowl"}),
        # the corpus put things "in" only; English gives "into" a place alone, and the request says it
        ("put the milk into the glass", "put", {"Theme": "milk", "Destination": "glass"}),
        ("dispose of it in the bowl", "dispose", {"Theme": "it", "Destination": "bowl"}),
        ("bake the cake", "bake", {"Theme": "cake", "Instrument": None}),
        ("pour me some water", "pour", {"Theme": "water", "Destination": None}),  # the eleven unchanged
        ("warm the milk into a glass", "warm", {"Theme": "milk", "Destination": "glass"}),  # the stated role
        ("warm the soup", "warm", {"Theme": "soup", "Instrument": None}),
        # what is said to the robot, not what the speaker did
        ("I put the milk away already. Can you bake the cake?", "bake", {"Theme": "cake", "Instrument": None}),
        # two requests leave a role open: the one whose verb states it more often (bake: always; put away:
        # about half the time) is what is left to do
        ("put the milk away and bake the cake", "bake", {"Theme": "cake", "Instrument": None}),
    ],
)
def test_requests_with_learned_verbs_parse_into_their_frames(learned_parser, instruction, predicate, roles):
    from lmcr.srl.instruction import parse_instruction

    frame = parse_instruction(learned_parser, instruction)
    assert (frame.predicate, frame.roles) == (predicate, roles)


def test_a_frame_that_states_nothing_gives_way_to_one_that_does(learned_parser):
    """ "can you help me put the milk away?": help is said to the robot and states nothing; put away, whose
    subject is "me" in the parse, states the milk. The task is putting the milk away (help had been read,
    with both its roles to fill). The paper's predicates still come first, stating something or not."""
    from lmcr.srl.instruction import _first_known
    from lmcr.srl.mentions import FrameMention

    helps = FrameMention("bake", {"Theme": None, "Instrument": None}, True, 8, 12, addressed=True)
    puts = FrameMention("put away", {"Theme": "milk", "Destination": None}, True, 16, 19, addressed=False)
    assert _first_known(learned_parser, "can you help me put the milk away?", [helps, puts]) is puts
    assert _first_known(learned_parser, "can you help?", [helps]) is helps  # alone it is still read
    # the robot's own predicates still come first: "I like my coffee with milk, pour some in"
    likes = FrameMention("put", {"Theme": "coffee", "Destination": "milk"}, True, 2, 6, addressed=False)
    pours = FrameMention("pour", {"Theme": None, "Destination": None}, True, 30, 34, addressed=True)
    assert _first_known(learned_parser, "I like my coffee with milk, pour some in", [likes, pours]) is pours


@pytest.mark.model
@pytest.mark.parametrize(
    "instruction, predicate, roles",
    [
        ("stir in the sugar", "stir in", {"Theme": "sugar", "Destination": None}),  # the sugar is stirred in
        ("stir in the bowl", "stir", {"Theme": None, "Destination": "bowl"}),  # the bowl is where
        ("stir in the flour", "stir", {"Theme": None, "Destination": "flour"}),  # unseen: the phrase stands
        ("whisk in the sugar", "whisk", {"Theme": "sugar", "Destination": None}),  # "whisk in" not learned
        ("stir the milk in the bowl", "stir", {"Theme": "milk", "Destination": "bowl"}),  # an object: no question
    ],
)
def test_a_learned_verbs_preposition_is_a_particle_when_the_corpus_takes_its_noun_for_a_theme(
    tmp_path, instruction, predicate, roles
):
    from collections import Counter

    from lmcr.srl.instruction import parse_instruction
    from lmcr.srl.parser import FrameParser, load_nlp
    from lmcr.srl.priors import RolePriors

    frames = _kitchen()
    frames += [("stir", {"Theme": "milk", "in": "bowl"}, False)] * 25 + [("stir in", {"Theme": "sugar"}, False)] * 25
    frames += [("whisk", {"Theme": "egg", "in": "bowl"}, False)] * 25
    con = _store(tmp_path, frames)
    publish_predicates(con, learn_predicates(con, HAND), tmp_path / PREDICATES_FILE, "b")
    con.close()
    pooled = Counter({("sugar", "Theme"): 9, ("sugar", "Destination"): 1, ("bowl", "Destination"): 9})
    lex = load_lexicon(learned=tmp_path / PREDICATES_FILE)
    assert {"stir", "stir in", "whisk"} <= lex.learned and "whisk in" not in lex.predicates
    parser = FrameParser(load_nlp(), lex, priors=RolePriors(Counter(), pooled))
    frame = parse_instruction(parser, instruction)
    assert (frame.predicate, frame.roles) == (predicate, roles)


@pytest.mark.model
def test_a_refused_phrasal_verb_is_refused_by_name_not_read_as_its_verb(tmp_path):
    """ "bake off" names only what it bakes in 3,000 frames (the base verb's rates, 50 frames' worth, do
    not lift its Instrument to the minimum rate): refused, so "bake off the cake" is refused naming it,
    never read as *bake* with an oven to choose. "bake up", refused for its 8 frames alone (under the 20 a
    verb needs), still falls back to bake."""
    from lmcr.srl.instruction import NoPredicateError, parse_instruction
    from lmcr.srl.parser import FrameParser, load_nlp

    frames = _kitchen() + [("bake off", {"Theme": "cake"}, False)] * 3000 + [("bake up", {"Theme": "cake"}, False)] * 8
    con = _store(tmp_path, frames)
    publish_predicates(con, learn_predicates(con, HAND), tmp_path / PREDICATES_FILE, "b")
    con.close()
    lex = load_lexicon(learned=tmp_path / PREDICATES_FILE)
    assert "bake" in lex.learned and lex.refused == {"cut": 30, "bake off": 3000, "bake up": 8}
    parser = FrameParser(load_nlp(), lex)
    with pytest.raises(NoPredicateError, match=r"the corpora's 3,000 frames of 'bake off' seldom say where it puts"):
        parse_instruction(parser, "bake off the cake")
    assert parse_instruction(parser, "bake the cake").predicate == "bake"
    assert parse_instruction(parser, "bake up the cake").predicate == "bake"  # refused for its 8 frames alone


@pytest.mark.model
@pytest.mark.parametrize(
    "instruction", ["put the teddy bear away", "put the bay leaves away", "put the granite cutting board away"]
)
def test_a_particle_after_an_object_the_parser_misread_still_names_the_phrasal_verb(learned_parser, instruction):
    """The tagger reads "bear", "leaves", "cutting" as verbs and hangs "away" on them: the particle that
    follows the object's noun phrase is still the verb's."""
    from lmcr.srl.instruction import parse_instruction

    assert parse_instruction(learned_parser, instruction).predicate == "put away"


@pytest.mark.model
@pytest.mark.parametrize(
    "instruction, theme",
    [
        ("put the bay leaves away", "bay leaves"),
        ("put the vanilla extract away", "vanilla extract"),
        ("put the ranch dressing away", "ranch dressing"),
    ],
)
def test_a_word_misread_as_a_verb_that_ends_a_name_the_corpus_knows_starts_no_frame(learned_parser, instruction, theme):
    """The tagger reads "leaves", "extract", "dressing" as verbs; the corpus says "bay leaves" is a name,
    so the word ends the Theme and evokes nothing (never "leave", "extract" or "dress" the robot is asked
    to do). Without the learned compounds the name stays cut short."""
    from lmcr.srl.compounds import Compounds
    from lmcr.srl.parser import FrameParser

    names = frozenset({"bay leaves", "vanilla extract", "ranch dressing"})
    parser = FrameParser(learned_parser.nlp, learned_parser.lex, compounds=Compounds(strong_bigrams=names))
    frames = parser.parse(instruction)
    assert [(f.predicate, f.roles) for f in frames] == [("put away", {"Theme": theme, "Destination": None})]
    assert len(learned_parser.parse(instruction)) == 2  # the misread verb's frame, with nothing learned


@pytest.mark.model
def test_a_learned_verb_is_completed_and_asked_about_like_the_eleven(learned_parser):
    from lmcr.complete import CompletionConfig, complete

    out = complete(learned_parser, _prefer("fridge", "bowl"), "put the milk away", ["milk", "bowl", "fridge", "oven"])
    assert out.frame.to_json() == {"predicate": "put away", "roles": {"Theme": "milk", "Destination": "fridge"}}
    assert out.missing_roles == ("Destination",) and out.prediction_set == ("fridge",)
    close = complete(
        learned_parser,
        lambda f, c="": [0.0] * len(f),
        "bake the cake",
        ["cake", "oven", "microwave"],
        CompletionConfig(),
    )
    assert close.question == "Should I bake cake in the oven or the microwave?"
    # a pronoun Theme and the Destination both open: pairs are scored, as for "pour it"
    both = complete(learned_parser, _prefer("peel", "bowl"), "dispose of it", ["peel", "bowl"])
    assert both.missing_roles == ("Theme", "Destination") and both.frame.role_map == {
        "Theme": "peel",
        "Destination": "bowl",
    }


@pytest.mark.model
def test_a_learned_verb_uses_its_own_calibration_where_requests_calibrated_one(learned_parser):
    """The eleven's threshold puts the likelier of two close objects alone in the set; the learned verbs'
    own (calibrated on household requests) keeps both, and the eleven keep theirs."""
    from lmcr.complete import CompletionConfig, complete

    close = _prefer("fridge", "bowl")  # scores 0 and -1
    eleven = CompletionConfig(temperature=1.0, set_threshold=0.6)
    both = eleven.with_learned(CompletionConfig(temperature=10.0, set_threshold=0.3, source="requests"))
    assert both.calibrated_for(True).set_threshold == 0.3 and both.calibrated_for(False) == both
    objects = ["milk", "bowl", "fridge"]
    assert complete(learned_parser, close, "put the milk away", objects, eleven).prediction_set == ("fridge",)
    assert complete(learned_parser, close, "put the milk away", objects, both).prediction_set == ("fridge", "bowl")
    pour = complete(learned_parser, _prefer("bowl", "fridge"), "pour the milk", objects, both)
    assert pour.prediction_set == ("bowl",)  # one of the eleven: its own threshold


@pytest.mark.model
def test_requests_calibrate_the_learned_verbs_and_leave_the_eleven_out(learned_parser):
    from lmcr.complete import CompletionConfig, CompletionError
    from lmcr.evaluate.external import ExternalItem, calibrate_requests

    def item(instruction: str, verb: str, right: str) -> ExternalItem:
        objects = ("milk", "bowl", "fridge")
        return ExternalItem(instruction, instruction, objects, verb, "Destination", ("Destination",), (right,))

    away = [item("put the milk away", "put away", "fridge")] * 9 + [item("put the milk away", "put away", "bowl")]
    pour = item("pour the milk", "pour", "bowl")
    cal = calibrate_requests(learned_parser, _prefer("fridge", "bowl"), CompletionConfig(), [*away, pour])
    assert cal.source.startswith("calibrated on 10 of 11 household requests (alpha=0.1")  # pour left out
    assert 0 < cal.set_threshold < 1  # one right object in ten is the second: the set must widen for it
    with pytest.raises(CompletionError, match="none of 1 requests"):
        calibrate_requests(learned_parser, _prefer("fridge", "bowl"), CompletionConfig(), [pour])


@pytest.mark.model
def test_the_objects_choose_which_open_role_a_request_left_missing(learned_parser):
    from lmcr.complete import CompletionConfig, complete

    likes = {("Destination", "glass"): 2.0, ("Instrument", "microwave"): 1.0}  # a stand-in that reads roles

    def by_role(frames, context=""):
        return [sum(likes.get(pair, 0.0) for pair in f.roles) for f in frames]

    into = complete(learned_parser, by_role, "warm the soup", ["soup", "microwave", "glass"])
    assert into.frame.to_json() == {"predicate": "warm", "roles": {"Theme": "soup", "Destination": "glass"}}
    assert into.missing_roles == ("Destination",)
    assert [(c.object, c.objects) for c in into.candidates[:2]] == [
        ("glass", {"Destination": "glass"}),
        ("microwave", {"Instrument": "microwave"}),
    ]
    # a scorer with no opinion: the role stated twice as often with "warm" is twice as likely left open
    even = complete(learned_parser, lambda f, c="": [0.0] * len(f), "warm the soup", ["soup", "microwave"])
    assert [(c.objects, c.probability) for c in even.candidates] == [
        ({"Instrument": "microwave"}, pytest.approx(2 / 3, abs=1e-3)),
        ({"Destination": "microwave"}, pytest.approx(1 / 3, abs=1e-3)),
    ]
    assert even.to_json()["frame"]["roles"] == {"Theme": "soup", "Instrument": "microwave"} and even.question is None
    unsure = complete(
        learned_parser,
        lambda f, c="": [0.0] * len(f),
        "warm the soup",
        ["soup", "microwave"],
        CompletionConfig(set_threshold=0.3),
    )
    assert unsure.question == "Should I warm soup in the microwave or warm soup into the microwave?"


@pytest.mark.model
def test_a_role_a_word_was_said_for_is_not_open_to_the_others():
    """ "put the cup in the drawer" with a top and a bottom drawer: the word names no one object, so the
    role is filled from the objects it names, but it is the Destination that was said: the verb's other
    open role (something to put it with) is no reading of it (a bowl had won as the Instrument)."""
    from lmcr.complete import _open_roles
    from lmcr.lexicon import PredicateSpec

    put = PredicateSpec(
        "put", ("Theme", "Destination"), "Theme", None, {}, frozenset(), False, "put {Theme} in the {Destination}",
        alternatives={"Instrument": "put {Theme} with the {Instrument}"},
    )  # fmt: skip
    assert _open_roles(put, ["Destination"], {}) == ("Destination", "Instrument")
    assert _open_roles(put, ["Destination"], {"Destination": "drawer"}) == ("Destination",)


def test_a_within_role_term_ranks_fillers_but_leaves_the_open_role_to_the_rest(learned_parser):
    from lmcr.complete import complete
    from lmcr.scorers.registry import SummedScorer

    rest = {("Destination", "glass"): 2.0, ("Instrument", "microwave"): 1.0, ("Instrument", "oven"): 0.5}
    term = {("Instrument", "oven"): 5.0, ("Destination", "glass"): -1.0}  # would turn the role to Instrument

    def reading(likes):
        return lambda frames, context="": [sum(likes.get(pair, 0.0) for pair in f.roles) for f in frames]

    objects = ["soup", "microwave", "oven", "glass"]
    summed = complete(
        learned_parser, SummedScorer([(reading(rest), False), (reading(term), False)]), "warm the soup", objects
    )
    assert summed.frame.role_map == {"Theme": "soup", "Instrument": "oven"}  # a plain sum: the term chose the role
    split = complete(
        learned_parser, SummedScorer([(reading(rest), False), (reading(term), True)]), "warm the soup", objects
    )
    assert split.frame.role_map == {"Theme": "soup", "Destination": "glass"}  # the role as the rest chose it
    ranked = [(c.objects, c.score) for c in split.candidates]
    instruments = [objects for objects, _ in ranked if "Instrument" in objects]
    assert instruments[0] == {"Instrument": "oven"}  # within the role the term still ranks: oven over microwave
    # each role's best scores as without the term (and its open-role prior): the roles compete as before
    alone = complete(learned_parser, reading(rest), "warm the soup", objects)
    best = {next(iter(c.objects)): c.score for c in reversed(alone.candidates)}
    assert {next(iter(o)): s for o, s in reversed(ranked)} == pytest.approx(best, abs=1e-3)


@pytest.mark.model
def test_a_verb_with_too_little_evidence_is_refused_by_name(learned_parser):
    from lmcr.srl.instruction import NoPredicateError, parse_instruction

    with pytest.raises(NoPredicateError, match=r"the corpora's 30 frames of 'cut' seldom say where it puts things"):
        parse_instruction(learned_parser, "cut the bread")
    with pytest.raises(NoPredicateError, match="none of the 16 verbs the robot learned"):
        parse_instruction(learned_parser, "sing a song")


def test_the_predicates_command_reports_coverage_and_one_predicate(tmp_path, monkeypatch):
    from typer.testing import CliRunner

    from lmcr.cli import app

    monkeypatch.setenv("LMCR_DATA_DIR", str(tmp_path))
    con = _store(tmp_path, _kitchen())
    con.execute(
        "insert into frame_builds (fingerprint, kinds, shards, sentences, words, frames, known_frames, reparsed, "
        "reparse_kept, wall_s, words_per_s) values ('b1', 'instruction', 1, 1, 1, 1, 1, 0, 0, 1.0, 1.0)"
    )
    con.close()
    runner = CliRunner()
    listed = runner.invoke(app, ["predicates"])
    assert listed.exit_code == 0, listed.output
    assert "5 learned, 1 verbs refused (too few frames, or no place" in " ".join(listed.output.split())
    assert "put away" in listed.output
    assert (tmp_path / "srl" / PREDICATES_FILE).exists()
    one = runner.invoke(app, ["predicates", "Put  Away"])
    assert one.exit_code == 0 and "put {Theme} away into the {Destination}" in one.output
    said = " ".join(runner.invoke(app, ["predicates", "cut"]).output.split())
    assert "'cut': refused: the corpora's 30 frames of 'cut' seldom say where it puts things or with what" in said
    unknown = runner.invoke(app, ["predicates", "juggle"])
    assert unknown.exit_code == 1 and "error: no predicate 'juggle'" in unknown.output
    empty = tmp_path / "empty"
    monkeypatch.setenv("LMCR_DATA_DIR", str(empty))
    assert "no store yet" in runner.invoke(app, ["predicates"]).output and not empty.exists()


def test_rating_tasks_can_ask_about_a_learned_predicate(tmp_path, monkeypatch):
    from lmcr.annotate.tasks import HitBatchError, corpus_frames, protocol_frames, render

    monkeypatch.setenv("LMCR_DATA_DIR", str(tmp_path))
    con = _store(tmp_path, _kitchen())
    refresh_predicates(con, HAND, tmp_path / "srl", "b1")
    frames = protocol_frames(0, 1, ("put away",))
    assert frames and {f.predicate for f in frames} == {"put away"}
    assert {tuple(r for r, _ in f.roles) for f in frames} == {("Theme", "Destination"), ("Destination", "Theme")}
    assert render(frames[0]).startswith("Put the ") and " away into the " in render(frames[0])
    # from the corpus: the learned predicate's frames with both roles stated, its slots named by role
    found = sorted(corpus_frames(con, 10, 0, ("put",)), key=lambda f: f.roles)
    assert found == [
        Frame("put", (("Destination", "bowl"), ("Theme", "milk"))),
        Frame("put", (("Destination", "glass"), ("Theme", "cup"))),
    ]
    assert {f.predicate for f in protocol_frames(0, 1)} == set(HAND.predicates)  # default: the eleven
    with pytest.raises(HitBatchError, match="unknown predicate 'juggle'"):
        protocol_frames(0, 1, ("juggle",))


@pytest.mark.model
def test_the_robot_refuses_a_learned_verb_it_has_no_motion_for_in_one_line(learned_parser, tmp_path):
    import pybullet as p

    from lmcr.complete import CompletionConfig
    from lmcr.robot.execute import NoMotionError, execute
    from lmcr.robot.reply import error_outcome, say
    from lmcr.robot.scene import scene_from_json

    # baking is said with an Instrument (in the oven), and learned here as a placing verb: the robot puts
    # the Theme in a tool that cooks (an oven, a pot, a cup), but a knife or an apple cooks nothing
    scene = scene_from_json({"objects": [{"label": "cake"}, {"label": "knife"}, {"label": "apple"}]}, "scene")
    try:
        with pytest.raises(
            NoMotionError, match=r"no motion for 'bake' with the objects it sees \(it can blend, brush, "
        ):
            execute("bake the cake", scene, learned_parser, _prefer("knife"), CompletionConfig(), tmp_path)
    finally:
        p.disconnect()
    reply = say(error_outcome(NoMotionError("bake")), learned_parser.lex)
    can = "I can blend, brush, dip, dump, fill, fry, heat, pour, rub, season or sprinkle things"
    learned = (
        "put things away, throw them out, hand them over, cook them in a pan or an oven, stir, wipe, cut, cover or "
        "serve with a tool"
    )
    assert reply == f"Sorry, I don't know how to bake. {can}, and {learned}."


def test_each_learned_verb_gets_the_class_of_motion_its_fillers_are_most_like(tmp_path):
    """The classes are named by their prototype verbs (put: place, stir: stir, ...); whisking takes what
    stirring takes (batter, with a spoon or a whisk), transferring what putting takes (milk into a glass)."""
    from lmcr.frame_corpus.predicates import MOTION_CLASSES

    frames = _kitchen()
    frames += [("stir", {"Theme": "batter", "with": "spoon", "in": "bowl"}, False)] * 25
    frames += [("stir", {"Theme": "egg", "with": "whisk"}, False)] * 10
    frames += [("whisk", {"Theme": "egg", "with": "whisk", "in": "bowl"}, False)] * 20
    frames += [("whisk", {"Theme": "batter"}, False)] * 10
    frames += [("transfer", {"Theme": "milk", "into": "glass"}, False)] * 20
    frames += [("transfer", {"Theme": "cup", "in": "glass"}, False)] * 5
    frames += [("cook", {"Theme": "soup", "in": "microwave"}, False)] * 20
    frames += [("cook", {"Theme": "cake", "in": "oven"}, False)] * 10
    table = learn_predicates(_store(tmp_path, frames), HAND)
    motions = {name: p.motion for name, p in table.predicates.items()}
    assert MOTION_CLASSES["place"] == "put" and MOTION_CLASSES["stir"] == "stir"
    assert motions["put"] == "place" and motions["stir"] == "stir"  # a prototype is its own class
    assert motions["whisk"] == "stir" and motions["transfer"] == "place" and motions["put away"] == "place"
    assert motions["cook"] == "cook" and motions["bake"] == "cook" and motions["warm"] == "cook"  # in ovens
    assert table.to_json()["predicates"]["whisk"]["spec"]["motion"] == "stir"


def test_a_learned_verbs_pairs_back_off_to_what_its_class_does(tmp_path):
    """'stash' never says where a cup goes and stashes most things in bowls; the verbs of its class (put,
    transfer) put cups in glasses: the class decides, as the count model reads the published table."""
    frames = _kitchen()
    frames += [("put", {"Theme": "cup", "in": "glass"}, False)] * 5
    frames += [("transfer", {"Theme": "milk", "into": "glass"}, False)] * 20
    frames += [("transfer", {"Theme": "cup", "in": "glass"}, False)] * 5
    frames += [("stash", {"Theme": "milk", "in": "bowl"}, False)] * 20 + [("stash", {"Theme": "cup"}, False)] * 5
    con = _store(tmp_path, frames)
    srl = tmp_path / "srl"
    srl.mkdir()
    refresh_predicates(con, HAND, srl, "build-1")
    con.close()
    classes = load_lexicon(learned=srl / PREDICATES_FILE).motion_classes
    assert classes["stash"] == classes["put"] == classes["transfer"] == "place" and "pour" not in classes
    glass, bowl = (Frame.of("stash", {"Theme": "cup", "Destination": d}) for d in ("glass", "bowl"))
    flat = FrameCountScorer.from_store(tmp_path / "lmcr.duckdb", SQL)
    assert flat.score_frame(bowl) > flat.score_frame(glass)
    counts = FrameCountScorer.from_store(tmp_path / "lmcr.duckdb", SQL, classes=classes)
    assert counts.score_frame(glass) > counts.score_frame(bowl)


def test_a_slot_like_neither_role_is_read_as_its_class_prototype_reads_it(tmp_path, monkeypatch):
    """The robot's places are bowls and glasses, its Instruments microwaves and ovens. 'roast in' holds
    trays mostly and a few bowls, ovens and microwaves: little like either role (cosine under
    PROTOTYPE_BELOW), and the bowls would make it a place. Roasting is cooking by its fillers, and 'cook
    in' an Instrument: so 'roast in' is one. 'put in', read clearly as a place, stays one."""
    from lmcr.frame_corpus import predicates

    frames = _kitchen()
    frames += [("cook", {"Theme": "chicken", "in": "microwave"}, False)] * 20
    frames += [("cook", {"Theme": "beef", "in": "oven"}, False)] * 10
    frames += [("roast", {"Theme": "beef", "in": "bowl"}, False)] * 14
    frames += [("roast", {"Theme": "chicken", "in": "oven"}, False)] * 8
    frames += [("roast", {"Theme": "chicken", "in": "microwave"}, False)] * 7
    frames += [("roast", {"Theme": "beef", "in": "tray"}, False)] * 40
    con = _store(tmp_path, frames)
    table = learn_predicates(con, HAND)
    roast = table.predicates["roast"]
    assert roast.motion == "cook" and roast.roles == ("Theme", "Instrument") and roast.slots["in"] == "Instrument"
    assert roast.sentence == "roast {Theme} in the {Instrument}"
    assert table.predicates["put"].slots["in"] == "Destination" and table.settings["prototype_below"] > 0
    monkeypatch.setattr(predicates, "PROTOTYPE_BELOW", 0.0)  # the fillers alone
    assert learn_predicates(con, HAND).predicates["roast"].roles == ("Theme", "Destination")


def test_without_a_prototype_no_class_is_guessed(tmp_path):
    frames = [f for f in _kitchen() if f[0] != "put"]
    table = learn_predicates(_store(tmp_path, frames), HAND)
    assert table.predicates and all(p.motion is None for p in table.predicates.values())


@pytest.mark.model
@pytest.mark.parametrize(
    "instruction, predicate, roles",
    [
        ("get rid of the peel", "get rid", {"Theme": "peel", "Destination": None}),  # get/auxpass rid/ROOT
        ("the milk has gone sour, get rid of it", "get rid", {"Theme": "it", "Destination": None}),  # rid/acomp
        ("could you get rid of it in the bowl?", "get rid", {"Theme": "it", "Destination": "bowl"}),
        ("I got rid of the peel. Can you bake the cake?", "bake", {"Theme": "cake", "Instrument": None}),
        ("get the milk", "get", {"Theme": "milk"}),  # the light verb alone is itself
    ],
)
def test_get_rid_of_is_one_prepositional_verb_whatever_the_parse(tmp_path, instruction, predicate, roles):
    """ "get rid of it": the parser reads "rid" as the root with "get" its passive auxiliary, or as get's
    adjectival complement; either way the pair names the predicate, learned as dispose is (its Theme the
    of-phrase), and "get" makes no frame of its own (it had read "get rid of it" as get, Theme milk, into
    the fridge). Without the verb learned, the request is no "get" frame either."""
    from lmcr.srl.instruction import parse_instruction
    from lmcr.srl.parser import FrameParser, load_nlp

    frames = _kitchen() + [("get rid", {"of": "peel", "in": "bowl"}, False)] * 25
    con = _store(tmp_path, frames)
    table = learn_predicates(con, HAND)
    assert table.predicates["get rid"].sentence == "get rid of {Theme} in the {Destination}"
    publish_predicates(con, table, tmp_path / PREDICATES_FILE, "b")
    con.close()
    nlp = load_nlp()
    parser = FrameParser(nlp, load_lexicon(learned=tmp_path / PREDICATES_FILE))
    if predicate == "get":  # not learned from this corpus: a generic frame
        assert [(m.predicate, m.roles) for m in parser.parse(instruction)] == [(predicate, roles)]
        return
    frame = parse_instruction(parser, instruction)
    assert (frame.predicate, frame.roles) == (predicate, roles)
    plain = FrameParser(nlp, HAND).parse(instruction)
    assert "get" not in [m.predicate for m in plain]
