"""Property tests: generated Meal-Master exports parse back to the recipes that were written."""

from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import example, given, settings
from hypothesis import strategies as st

from lmcr.ingest.mealmaster import parse_mealmaster

word = st.text(alphabet="abcdefghijklmnopqrstuvwxyzéçäñ", min_size=2, max_size=9)
title = st.lists(word, min_size=1, max_size=4).map(lambda w: " ".join(w).title())
ingredient = st.tuples(
    st.sampled_from(["1", "2", "1/2", "1 1/2", "12"]),
    st.sampled_from(["c ", "ts", "tb", "lb", "  "]),
    st.lists(word, min_size=1, max_size=3).map(" ".join),
)
sentence = st.lists(word, min_size=2, max_size=8).map(lambda w: " ".join(w).capitalize() + ".")
recipe = st.tuples(title, st.lists(ingredient, min_size=1, max_size=6), st.lists(sentence, min_size=1, max_size=5))
style = st.sampled_from(
    [
        ("MMMMM----- Recipe via Meal-Master (tm) v8.05", "MMMMM"),
        ("---------- Recipe via Meal-Master (tm) v8.02", "-----"),
        ("@@@@@ Now You're Cooking! Export Format", "END RECIPE"),
    ]
)


def render(recipes, start, end) -> str:
    blocks = []
    for name, ingredients, directions in recipes:
        lines = [start, "", f"      Title: {name}", " Categories: Test", "      Yield: 2 servings", ""]
        lines += [f"{qty:>7} {unit} {text}" for qty, unit, text in ingredients]
        lines += ["", "  " + "  ".join(directions), "", end, ""]
        blocks.append("\n".join(lines))
    return "\n".join(blocks)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(recipe, min_size=1, max_size=5),
    style,
    st.sampled_from(["utf-8", "cp437", "latin-1"]),
    st.sampled_from(["\n", "\r\n"]),
)
# Found by hypothesis: a lone "Ä" once tied cp437 with latin-1; a direction starting "Note" was a comment.
@example(
    [("Äa", [("1", "c ", "aa")], ["Aa aa."])],
    ("MMMMM----- Recipe via Meal-Master (tm) v8.05", "MMMMM"),
    "latin-1",
    "\n",
)
@example(
    [("Aa", [("1", "c ", "aa")], ["Note aa."])],
    ("MMMMM----- Recipe via Meal-Master (tm) v8.05", "MMMMM"),
    "utf-8",
    "\n",
)
def test_generated_exports_round_trip(recipes, markers, encoding, newline):
    text = render(recipes, *markers).replace("\n", newline)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "gen.mmf"
        path.write_bytes(text.encode(encoding))
        parsed = parse_mealmaster(path)
    assert parsed.rejects == []
    assert [d["title"] for d in parsed.documents] == [r[0] for r in recipes]
    for doc, (_, ingredients, directions) in zip(parsed.documents, recipes):
        rows = [s for s in parsed.sentences if s["doc_id"] == doc["doc_id"]]
        assert sum(s["kind"] == "ingredient" for s in rows) == len(ingredients)
        assert " ".join(s["text"] for s in rows if s["kind"] == "instruction") == " ".join(directions)


@settings(max_examples=40, deadline=None)
@given(st.lists(recipe, min_size=2, max_size=4), st.integers(0, 3))
def test_truncated_export_quarantines_exactly_the_cut_recipe(recipes, cut_at):
    cut_at = min(cut_at, len(recipes) - 1)
    text = render(recipes, "MMMMM----- Recipe via Meal-Master (tm) v8.05", "MMMMM")
    blocks = text.split("\nMMMMM\n")
    truncated = "\nMMMMM\n".join(blocks[:cut_at]) + ("\nMMMMM\n" if cut_at else "") + blocks[cut_at]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "cut.mmf"
        path.write_text(truncated, encoding="utf-8")
        parsed = parse_mealmaster(path)
    assert len(parsed.documents) == cut_at
    assert [r["reason"] for r in parsed.rejects] == ["recipe block has no end marker before the end of the file"]
    assert parsed.records_in == cut_at + 1
