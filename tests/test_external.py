"""The external request sets' measures (lmcr/evaluate/external.py) on hand-made items and completions, the
reading of a malformed set, and bench/bench_external.py end to end on a three-item set."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pytest

from lmcr.checkout import REPO_ROOT
from lmcr.evaluate.external import (
    ExternalItem,
    cross_calibrated,
    error_reason,
    percentile,
    read_items,
    read_sets,
    right_first,
    right_predicate,
    score,
    summarize,
)
from lmcr.jsonl import InputError
from tests.test_serve import trained  # noqa: F401  (the fixture: a small workspace trained on the sample)

PUT_AWAY = ExternalItem(
    id="t-1",
    instruction="put the orange away",
    objects=("orange", "storage box", "coffee table"),
    verb="put away",
    missing="Destination",
    missing_roles=("Destination",),
    expected_any=("coffee table",),
)
DISPOSE_IT = ExternalItem(
    id="i-1",
    instruction="It is rotten. Can you dispose of it?",
    objects=("apple", "landfill bin", "compost bin"),
    verb="dispose of",
    missing="Destination",
    missing_roles=("Theme", "Destination"),
    expected_any=("compost bin",),
)


def completion(predicate: str, roles: dict, missing: list[str], ranked: list[dict], in_set: int, question=None) -> dict:
    """A completion line as `Completion.to_json` writes it: `ranked` the candidates' fillings, best first,
    the first `in_set` of them the prediction set."""
    candidates = [
        {"object": f[missing[0]], "objects": f, "score": -k, "probability": 0.5 / (k + 1), "ids": []}
        for k, f in enumerate(ranked)
    ]
    return {
        "frame": {"predicate": predicate, "roles": {**roles, **ranked[0]}},
        "missing": missing[0] if missing else None,
        "missing_roles": missing,
        "candidates": candidates,
        "question": question,
        "prediction_set": [c["object"] for c in candidates[:in_set]],
    }


def test_a_phrasal_predicate_is_right_only_with_its_particle():
    assert right_predicate("put away", "put away") and right_predicate("Put  Away", "put away")
    assert not right_predicate("put", "put away") and not right_predicate("season", "put away")
    # "of" introduces the Theme: the name may leave it off; a particle may not be left off
    assert right_predicate("dispose", "dispose of") and right_predicate("dispose of", "dispose of")
    assert not right_predicate("throw", "throw away") and not right_predicate(None, "put")


def test_a_right_completion_without_a_question():
    line = completion(
        "put away",
        {"Theme": "orange"},
        ["Destination"],
        [{"Destination": "coffee table"}, {"Destination": "storage box"}],
        1,
    )
    out = score(PUT_AWAY, line, ms=3.0)
    assert out.right_predicate and out.right_role and out.top_right and out.covered
    assert (out.asked, out.set_size, out.chosen, out.error, out.ms) == (False, 1, "coffee table", None, 3.0)


def test_a_wrong_predicate_and_a_wrong_guess_covered_by_a_question():
    ranked = [{"Instrument": "storage box"}, {"Instrument": "coffee table"}]
    line = completion("season", {"Theme": "orange"}, ["Instrument"], ranked, 2, question="Should I ...?")
    out = score(PUT_AWAY, line)
    # the item's Destination was not left open: no guess for it, no set that covers it
    assert not (out.right_predicate or out.right_role or out.top_right or out.covered)
    assert out.asked and out.set_size == 2
    line = completion(
        "put away",
        {"Theme": "orange"},
        ["Destination"],
        [{"Destination": "storage box"}, {"Destination": "coffee table"}],
        2,
        "Which?",
    )
    out = score(PUT_AWAY, line)
    assert out.right_predicate and out.right_role and not out.top_right and out.covered and out.asked


def test_the_set_covers_only_with_a_right_object_in_it():
    ranked = [{"Destination": "storage box"}, {"Destination": "coffee table"}]
    out = score(PUT_AWAY, completion("put away", {"Theme": "orange"}, ["Destination"], ranked, 1))
    assert not out.covered and out.set_size == 1
    out = score(PUT_AWAY, completion("put away", {"Theme": "orange"}, ["Destination"], ranked, 0, "Which?"))
    assert not out.covered and out.set_size == 0


def test_missing_roles_left_open_by_a_pronoun():
    both = [{"Theme": "apple", "Destination": "compost bin"}, {"Theme": "apple", "Destination": "landfill bin"}]
    out = score(DISPOSE_IT, completion("dispose", {}, ["Theme", "Destination"], both, 1))
    # two roles open, both allowed; the set's filler of the scored role (Destination) is what counts
    assert out.right_predicate and out.right_role and out.top_right and out.covered
    # "it" resolved to the apple: only the Destination open, still right
    out = score(
        DISPOSE_IT, completion("dispose of", {"Theme": "apple"}, ["Destination"], [{"Destination": "compost bin"}], 1)
    )
    assert out.right_role and out.top_right
    # a role the item states reported open is wrong
    line = completion(
        "put away", {}, ["Theme", "Destination"], [{"Theme": "storage box", "Destination": "coffee table"}], 1
    )
    assert not score(PUT_AWAY, line).right_role


def test_right_first_puts_the_best_right_candidate_first_and_leaves_the_other_right_ones_out():
    ranked = [{"Destination": "storage box"}, {"Destination": "coffee table"}, {"Destination": "sofa"}]
    line = completion("put away", {"Theme": "orange"}, ["Destination"], ranked, 1)  # scores 0, -1, -2
    assert right_first(PUT_AWAY, line) == [-1, 0, -2]
    two = ExternalItem(**{**PUT_AWAY.__dict__, "expected_any": ("coffee table", "sofa")})
    assert right_first(two, line) == [-1, 0]
    # nothing to calibrate on: a wrong predicate, no right candidate, an error
    assert right_first(PUT_AWAY, completion("season", {"Theme": "orange"}, ["Destination"], ranked, 1)) is None
    assert right_first(PUT_AWAY, completion("put away", {"Theme": "orange"}, ["Destination"], ranked[:1], 1)) is None
    assert right_first(PUT_AWAY, {"error": "no known predicate"}) is None


def test_each_sets_prediction_sets_are_calibrated_on_the_other_sets():
    """A set whose right object is always second, calibrated on one where it is always first, keeps a set of
    one that never holds it; the other way round, the sets widen and hold it. A line of the eleven keeps
    its own set, and a set with nothing to calibrate on has no figures."""
    first = [{"Destination": "coffee table"}, {"Destination": "storage box"}]
    second = first[::-1]
    items = {"easy": [PUT_AWAY] * 10, "hard": [PUT_AWAY] * 10}
    easy = completion("put away", {"Theme": "orange"}, ["Destination"], first, 1)
    easy["candidates"][1]["score"] = -0.5  # closer than the hard set's, whose calibration then holds both
    lines = {
        "easy": [easy] * 10,
        "hard": [completion("put away", {"Theme": "orange"}, ["Destination"], second, 1)] * 10,
    }
    rows = cross_calibrated(items, lines, frozenset({"put away"}))
    assert rows["hard"]["set holds a right object"] == 0.0 and rows["hard"]["mean set size"] == 1.0
    assert rows["easy"]["set holds a right object"] == 1.0 and rows["easy"]["mean set size"] == 2.0
    eleven = cross_calibrated(items, lines, frozenset())
    assert eleven["easy"]["set holds a right object"] is None and eleven["easy"]["mean set size"] is None
    pour = completion("pour", {"Theme": "water"}, ["Destination"], [{"Destination": "coffee table"}], 0)
    mixed = cross_calibrated({**items, "eleven": [PUT_AWAY]}, {**lines, "eleven": [pour]}, frozenset({"put away"}))
    assert mixed["eleven"]["mean set size"] == 0.0  # its own (empty) set


def test_an_error_is_right_at_nothing_and_its_reason_is_counted():
    out = score(PUT_AWAY, {"id": "t-1", "error": "no known predicate in 'put the orange away': the robot can pour"})
    assert out.error and not (out.right_predicate or out.top_right or out.covered or out.asked)
    assert error_reason(out.error) == "no known predicate"
    assert error_reason("cannot fill Destination of 'pour': no usable objects besides ['water']") == (
        "cannot fill Destination of …"
    )


def test_a_summary_counts_over_all_items_and_sizes_over_the_completed():
    right = score(
        PUT_AWAY,
        completion(
            "put away",
            {"Theme": "orange"},
            ["Destination"],
            [{"Destination": "coffee table"}, {"Destination": "storage box"}],
            2,
            "Which?",
        ),
        4.0,
    )
    wrong = score(
        DISPOSE_IT, completion("season", {"Theme": "apple"}, ["Instrument"], [{"Instrument": "compost bin"}], 1), 2.0
    )
    error = score(PUT_AWAY, {"error": "no known predicate in 'x': the robot can pour"}, 1.0)
    s = summarize([PUT_AWAY, DISPOSE_IT], [right, wrong, error])
    assert s["items"] == 3 and s["completed"] == 2 and s["mean set size"] == 1.5
    assert s["right predicate and missing role"] == round(1 / 3, 3) and s["top guess right"] == round(1 / 3, 3)
    assert s["questions asked"] == round(1 / 3, 3) and s["set holds a right object"] == round(1 / 3, 3)
    assert s["errors"] == round(1 / 3, 3) and s["error reasons"] == {"no known predicate": 1}
    assert s["wrong predicates"] == {"dispose of -> season": 1}
    assert (s["p50 ms"], s["p90 ms"]) == (2.0, 4.0) and percentile([5.0], 0.9) == 5.0


GOOD = {
    "id": "g",
    "instruction": "put the cup away",
    "objects": ["cup", "shelf"],
    "missing": "Destination",
    "expected_any": ["shelf"],
    "verb": "put away",
}


@pytest.mark.parametrize(
    "line, reason",
    [
        ("{not json", "not valid JSON"),
        (json.dumps({**GOOD, "id": "b", "expected_any": None}), "'expected_any' missing or not list"),
        (json.dumps({**GOOD, "id": "b", "objects": ["cup", 3]}), "'objects' must be a non-empty list"),
        (json.dumps({**GOOD, "id": "b", "expected_any": []}), "'expected_any' must be a non-empty list"),
        (json.dumps({**GOOD, "id": "b", "missing_roles": ["Theme"]}), "'missing_roles' must be a list of roles"),
        (json.dumps({**GOOD, "id": "b", "verb": " "}), "'verb' and 'missing' must not be empty"),
        (json.dumps(GOOD), "id 'g' repeats line 1"),
    ],
)
def test_a_malformed_item_is_one_line_naming_file_and_line(tmp_path, line, reason):
    path = tmp_path / "set.jsonl"
    path.write_text(json.dumps(GOOD) + "\n\n" + line + "\n", encoding="utf-8")
    with pytest.raises(InputError, match=rf"^{re.escape(str(path))}:3: .*{re.escape(reason)}") as caught:
        read_items(path)
    assert "\n" not in str(caught.value)


def test_a_folder_without_sets(tmp_path):
    with pytest.raises(InputError, match="no request sets"):
        read_sets(tmp_path)
    with pytest.raises(InputError, match="not a folder of request sets"):
        read_sets(tmp_path / "none")


ITEMS = [
    {"id": "pour", "instruction": "pour the water", "objects": ["water", "cup", "plate"], "missing": "Destination",
     "expected_any": ["cup"], "verb": "pour"},
    {"id": "fry", "instruction": "fry an egg", "objects": ["egg", "pan", "bowl"], "missing": "Instrument",
     "expected_any": ["pan"], "verb": "fry"},
    {"id": "away", "instruction": "put the orange away", "objects": ["orange", "storage box", "coffee table"],
     "missing": "Destination", "expected_any": ["coffee table"], "verb": "put away"},
]  # fmt: skip


def test_the_benchmark_end_to_end(trained, tmp_path):  # noqa: F811
    sets = tmp_path / "sets"
    sets.mkdir()
    (sets / "tiny.jsonl").write_text("".join(json.dumps(item) + "\n" for item in ITEMS), encoding="utf-8")
    out, lines = tmp_path / "bench.json", tmp_path / "items.jsonl"
    argv = ["--sets", str(sets), "--data-dir", str(trained.data_dir), "--json", str(out), "--out-jsonl", str(lines)]
    done = subprocess.run(
        [sys.executable, str(REPO_ROOT / "bench" / "bench_external.py"), *argv], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert "tiny" in done.stdout and "no known predicate 1" in done.stdout
    record = json.loads(out.read_text(encoding="utf-8"))
    figures = record["figures"]
    assert record["benchmark"] == "bench_external" and figures["sets"] == "tiny"
    assert figures["tiny: items"] == 3 and figures["tiny: errors (count)"] == 1 and figures["tiny: completed"] == 2
    assert figures["tiny: error 'no known predicate'"] == 1 and figures["tiny: right predicate (count)"] == 2
    assert figures["tiny: p50 ms"] > 0 and figures["tiny: mean set size"] is not None
    written = [json.loads(line) for line in lines.read_text(encoding="utf-8").splitlines()]
    assert [w["id"] for w in written] == ["pour", "fry", "away"] and {w["set"] for w in written} == {"tiny"}
    assert "prediction_set" in written[0] and written[0]["outcome"]["right_predicate"]
    assert written[2]["error"].startswith("no known predicate") and not written[2]["outcome"]["right_predicate"]
    assert all(w["outcome"]["ms"] > 0 for w in written)


def test_the_benchmark_refuses_a_missing_folder_in_one_line(tmp_path):
    done = subprocess.run(
        [
            sys.executable,
            str(REPO_ROOT / "bench" / "bench_external.py"),
            "--sets",
            str(tmp_path / "none"),
            "--json",
            "",
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 1 and done.stderr.strip() == f"error: {tmp_path / 'none'}: not a folder of request sets"
