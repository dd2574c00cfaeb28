"""SRL error classes and the learned lexical statistics (no spaCy model)."""

from __future__ import annotations

import duckdb

from lmcr.srl.compounds import Compounds, learn_compounds
from lmcr.srl.evaluate import classify_errors, instruction_correct


def frame(pred: str, a: str | None, b: str | None, roles=("Theme", "Destination")) -> dict:
    return {"predicate": pred, "roles": dict(zip(roles, (a, b)))}


def test_every_error_has_its_class():
    gold = [
        [frame("pour", "water", "cup")],
        [frame("pour", "peanut butter", "cookie")],
        [frame("dip", "bread", None), frame("pour", "oil", "bowl")],
        [frame("pour", "milk", "glass")],
    ]
    pred = [
        [frame("pour", "cup", "water")],
        [frame("pour", "butter", "cooky")],
        [frame("dip", "bread", "soup"), frame("fry", "egg", None, ("Theme", "Instrument"))],
        [frame("pour", "leftover milk", None)],
    ]
    errors = classify_errors(gold, pred, {"pour", "dip", "fry"})
    assert errors[0] == [("role", "pour.Theme"), ("role", "pour.Destination")]
    assert errors[1] == [("boundary", "pour.Theme"), ("lemma", "pour.Destination")]
    assert errors[2] == [("extra role", "dip.Destination"), ("extra predicate", "fry"), ("missed predicate", "pour")]
    assert errors[3] == [("boundary", "pour.Theme"), ("missed role", "pour.Destination")]


def test_an_instruction_parse_is_right_with_the_open_role_open_and_a_pronoun_for_a_role():
    expected = {"predicate": "pour", "roles": {"Theme": "wine", "Destination": "glass"}}
    pronouns = frozenset({"it", "them"})
    assert instruction_correct(frame("pour", "wine", None), expected, "Destination")
    assert not instruction_correct(frame("pour", "wine", "glass"), expected, "Destination")  # not left open
    assert not instruction_correct(frame("pour", "water", None), expected, "Destination")
    assert instruction_correct(frame("pour", "it", None), expected, "Destination", pronouns)  # "could you pour it?"
    assert not instruction_correct(frame("pour", "it", None), expected, "Destination")  # not a pronoun it knows
    assert not instruction_correct(frame("pour", "wine", "it"), expected, "Destination", pronouns)  # the open role
    assert not instruction_correct(frame("heat", "it", None), expected, "Destination", pronouns)


def test_lexical_statistics_are_learned_from_sentences():
    con = duckdb.connect()
    con.execute("create table sentences (text varchar, kind varchar, corpus varchar)")
    rows = (
        ["heat the sesame oil in a large bowl."] * 30
        + ["add sesame seeds to a large pan."] * 20
        + ["add a large egg."] * 60
        + ["cook until hot."] * 30
        + ["pour hot oil over a cookie."] * 40
        + ["serve with a spring roll."] * 10
        + ["Serve with French toast and Dijon mustard."] * 20
        + ["Dijon is best."] * 5
    )
    con.executemany("insert into sentences values (?, 'instruction', 'recipes')", [[r] for r in rows])
    learned = learn_compounds(con)
    assert "sesame oil" in learned.strong_bigrams  # sesame comes with oil 60% of the time
    assert "large bowl" not in learned.strong_bigrams  # large comes with many heads
    assert "hot" in learned.predicative and "sesame" not in learned.predicative
    assert learned.singular_counts["cookie"] == 40 and "cookies" not in learned.singular_counts
    assert not learned.joins("hot", "oil") and learned.joins("sesame", "oil")
    # written capitalised inside sentences: a proper adjective, part of a name (not at a sentence's start)
    assert learned.proper == frozenset({"french", "dijon"}) and learned.joins("french", "fries")


def test_saved_statistics_do_not_depend_on_the_order_they_came_in(tmp_path):
    """The frames stage is skipped when the compounds file's hash is unchanged."""
    a = Compounds({"olive": 0.2, "cream": 0.3}, frozenset({"b c", "a b"}), singular_counts={"x": 3, "y": 4})
    b = Compounds({"cream": 0.3, "olive": 0.2}, frozenset({"a b", "b c"}), singular_counts={"y": 4, "x": 3})
    a.save(tmp_path / "a.json")
    b.save(tmp_path / "b.json")
    assert (tmp_path / "a.json").read_bytes() == (tmp_path / "b.json").read_bytes()
