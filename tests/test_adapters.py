"""Every ingest adapter on the sample fixtures (good and malformed records) and on hand-made edge cases."""

from __future__ import annotations

import gzip
import json

import pytest

from lmcr.ingest import IngestError, detect_format, expand_inputs
from lmcr.ingest.feeding_america import parse_feeding_america
from lmcr.ingest.mealmaster import parse_mealmaster
from lmcr.ingest.recipe_json import parse_recipe_json
from lmcr.ingest.youcook2 import parse_youcook2


def reasons(parsed):
    return sorted((r["position"], r["reason"]) for r in parsed.rejects)


def assert_balanced(parsed):
    assert parsed.records_in == parsed.records_loaded + len(parsed.rejects)


def test_youcook2_sample(sample_dir):
    parsed = parse_youcook2(sample_dir / "youcook2" / "youcook2_sample.json")
    assert_balanced(parsed)
    assert (parsed.records_in, parsed.records_loaded, len(parsed.documents)) == (59, 56, 11)
    assert [r[1] for r in reasons(parsed)] == [
        "video smp_broken11: no annotations list",
        "video smp_defects12 annotation 1: bad segment [30, 12] (want [start, end] seconds, start <= end)",
        "video smp_defects12 annotation 2: annotation has no sentence",
    ]
    first = parsed.sentences[0]
    assert (first["doc_id"], first["kind"], first["seg_start"], first["seg_end"]) == (
        "smp_pancakes01",
        "instruction",
        10.0,
        25.0,
    )
    assert parsed.documents[0]["subset"] == "training" and parsed.documents[0]["category"] == "201"


def test_youcook2_not_youcook2(tmp_path):
    bad = tmp_path / "x.json"
    bad.write_text('{"videos": {}}')
    with pytest.raises(IngestError, match="not a YouCook2 file"):
        parse_youcook2(bad)
    bad.write_text('{"database": {\n"a": [}')
    with pytest.raises(IngestError, match=r"x.json:2: not valid JSON"):
        parse_youcook2(bad)


def test_recipe_jsonl_sample(sample_dir):
    parsed = parse_recipe_json(sample_dir / "recipes_json" / "recipes_sample.jsonl")
    assert_balanced(parsed)
    assert (parsed.records_in, parsed.records_loaded) == (11, 8)
    assert reasons(parsed) == [
        (4, "not valid JSON: Expecting ',' delimiter at column 1"),
        (7, "'directions' is not a list of strings"),
        (9, "no ingredients and no directions"),
    ]
    kinds = {s["kind"] for s in parsed.sentences}
    assert kinds == {"title", "ingredient", "instruction"}
    assert parsed.documents[0]["source"] == "web:sample-kitchen.example"


def test_recipe_json_gz_and_folder(tmp_path, sample_dir):
    gz = tmp_path / "r.jsonl.gz"
    with gzip.open(gz, "wt", encoding="utf-8") as f:
        f.write(json.dumps({"title": "T", "ingredients": ["1 cup milk"], "directions": ["Pour it."]}) + "\n")
    parsed = parse_recipe_json(gz)
    assert [s["text"] for s in parsed.sentences] == ["T", "1 cup milk", "Pour it."]
    assert parsed.documents[0]["doc_id"] == "r:1"
    folder = parse_recipe_json(sample_dir / "recipes_json" / "folder")
    assert_balanced(folder)
    assert (folder.records_loaded, reasons(folder)) == (3, [(4, "record is not a JSON object")])
    assert folder.documents[0]["doc_id"] == "folder:fried_eggs"


def test_recipe_jsonl_unreadable(tmp_path):
    bad = tmp_path / "bad.jsonl.gz"
    bad.write_bytes(b"not gzip at all")
    with pytest.raises(IngestError, match="bad.jsonl.gz: cannot read"):
        parse_recipe_json(bad)


def test_feeding_america_sample(sample_dir):
    parsed = parse_feeding_america(sample_dir / "feeding_america" / "sample_book.xml")
    assert_balanced(parsed)
    assert (parsed.records_in, parsed.records_loaded) == (6, 5)
    assert reasons(parsed) == [(31, "document 'sample_book:5' has no text")]
    soup = [s for s in parsed.sentences if s["doc_id"] == "sample_book:1"]
    assert soup[0] == {**soup[0], "kind": "title", "text": "POTATO SOUP.", "position": 10}
    assert [s["text"] for s in soup if s["kind"] == "ingredient"] == ["6 potatoes.", "1 quart of milk.", "1 onion."]
    text = " ".join(s["text"] for s in soup if s["kind"] == "instruction")
    assert "onion, pour it over" in text  # inline tags joined with their spacing
    assert "Illegible" not in text  # editorial notes are not recipe text
    tomato = [s for s in parsed.sentences if s["doc_id"] == "sample_book:2"]
    assert tomato[-1]["kind"] == "comment" and tomato[-1]["text"] == "MRS. J. B. SAMPLE."


def test_feeding_america_malformed(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text("<cookbook>\n<recipe>\n<p>Stir</recipe>\n</cookbook>")
    with pytest.raises(IngestError, match=r"bad.xml:3: malformed XML"):
        parse_feeding_america(bad)
    bad.write_text("<book><recipe/></book>")
    with pytest.raises(IngestError, match="not <cookbook>"):
        parse_feeding_america(bad)


def test_mealmaster_cp437_sample(sample_dir):
    parsed = parse_mealmaster(sample_dir / "nyc" / "mealmaster_sample_cp437.mmf")
    assert_balanced(parsed)
    assert [d["title"] for d in parsed.documents] == ["Café Vinaigrette Salad", "Pan-Fried Fish", "Oven Fries Crème"]
    assert reasons(parsed) == [
        (1, "text outside any recipe block"),
        (47, "recipe block has no Title: line"),
        (74, "recipe block has no end marker before the end of the file"),
    ]
    salad = [s for s in parsed.sentences if s["doc_id"] == "mealmaster_sample_cp437:1"]
    # two-column ingredient lists come out one ingredient per row
    assert [s["text"] for s in salad if s["kind"] == "ingredient"] == [
        "1 lg Tomato, chopped",
        "2 tb Red wine vinegar",
        "1 Bell pepper, sliced",
        "6 tb Olive oil",
        "1/2 ts Salt",
        "1 pn Black pepper",
    ]
    assert salad[-1] == {**salad[-1], "kind": "comment", "text": "Source: Sample Kitchen Notes, 1994"}
    fries = " ".join(s["text"] for s in parsed.sentences if s["doc_id"] == "mealmaster_sample_cp437:4")
    assert "220°C" in fries and "Bake 1/2 hour" in fries
    assert parsed.documents[0]["category"] == "Salads, Vegetables"


def test_nyc_latin1_sample(sample_dir):
    parsed = parse_mealmaster(sample_dir / "nyc" / "nyc_sample_latin1.txt")
    assert_balanced(parsed)
    assert [d["title"] for d in parsed.documents] == ["Crêpes Suzette", "Garlic Bread", "Iced Tea"]
    assert reasons(parsed) == [(19, "text outside any recipe block")]


def test_mealmaster_forced_encoding(tmp_path):
    path = tmp_path / "one.mmf"
    path.write_bytes("Title: Crème\n\n  Stir.\nMMMMM\n".encode("latin-1"))
    assert parse_mealmaster(path, encoding="latin-1").documents[0]["title"] == "Crème"
    with pytest.raises(IngestError, match="cannot decode as utf-8"):
        parse_mealmaster(path, encoding="utf-8")


def test_detect_and_expand(sample_dir, tmp_path):
    assert detect_format(sample_dir / "youcook2" / "youcook2_sample.json") == "youcook2"
    assert detect_format(sample_dir / "nyc" / "nyc_sample_latin1.txt") == "mealmaster"
    assert detect_format(sample_dir / "feeding_america" / "sample_book.xml") == "feeding_america"
    sources = expand_inputs([sample_dir / "nyc", sample_dir / "recipes_json" / "folder"], "recipes")
    assert [(s.path.name, s.format) for s in sources] == [
        ("mealmaster_sample_cp437.mmf", "mealmaster"),
        ("nyc_sample_latin1.txt", "mealmaster"),
        ("folder", "recipe_json"),
    ]
    with pytest.raises(IngestError, match="no such file"):
        expand_inputs([tmp_path / "missing.jsonl"], "recipes")
    with pytest.raises(ValueError, match="corpus must be one of"):
        expand_inputs([], "nyc")
    odd = tmp_path / "notes.dat"
    odd.write_text("hello")
    with pytest.raises(IngestError, match="unrecognised format"):
        detect_format(odd)


# --- household: EPIC-KITCHENS narrations and VirtualHome programs ---------------------------------


def test_epic_kitchens_sample_folder(sample_dir):
    from lmcr.ingest.epic_kitchens import parse_epic_kitchens

    parsed = parse_epic_kitchens(sample_dir / "household" / "epic_kitchens")
    assert_balanced(parsed)
    # 43 narrations in the EPIC-100-style file (5 listed twice), 7 more only in the EPIC-55-style file,
    # its 4 P90_01 rows the same narrations in older words; the class list is skipped.
    assert (parsed.records_in, parsed.records_loaded) == (52, 50)
    assert [r[1] for r in reasons(parsed)] == [
        "EPIC_sample_100.csv:50: bad narration_id 'not-an-id' (want P01_01_0)",
        "EPIC_sample_100.csv:51: empty narration",
    ]
    docs = {d["doc_id"]: d for d in parsed.documents}
    assert sorted(docs) == ["epic:P90_01", "epic:P90_02", "epic:P91_01", "epic:P92_03"]
    assert (docs["epic:P92_03"]["subset"], docs["epic:P90_01"]["category"]) == ("epic-55", "P90")
    first = [s["text"] for s in parsed.sentences if s["doc_id"] == "epic:P90_01"][:2]
    assert first == ["open cupboard", "take glass"]  # the EPIC-100 file's words win over "pick up glass"


def test_epic_kitchens_ids_from_video_order_and_bad_lines(tmp_path):
    from lmcr.ingest.epic_kitchens import parse_epic_kitchens

    path = tmp_path / "narrations.csv"
    path.write_bytes(
        b"participant_id,video_id,start_timestamp,stop_timestamp,narration\n"
        b"P01,P01_01,0,1,open door\nP01,P01_01,1,2,pour water into glass\n"
        b"P01,bad,2,3,take cup\nP01,P01_01,3,4,too,many\nP01,P01_01,4,5,caf\xe9\n\n"
    )
    parsed = parse_epic_kitchens(path)
    assert_balanced(parsed)
    assert [(s["doc_id"], s["sent_id"], s["text"]) for s in parsed.sentences] == [
        ("epic:P01_01", 0, "open door"),
        ("epic:P01_01", 1, "pour water into glass"),
    ]
    assert [(p, r.split(": ", 1)[1][:18]) for p, r in reasons(parsed)] == [
        (4, "no narration_id an"),
        (5, "6 fields, the head"),
        (6, "not UTF-8 (byte 0x"),
    ]
    not_narrations = tmp_path / "classes.csv"
    not_narrations.write_text("id,key\n0,take\n")
    with pytest.raises(IngestError, match="classes.csv:1: no 'narration' column"):
        parse_epic_kitchens(not_narrations)
    with pytest.raises(IngestError, match="no EPIC-KITCHENS narration CSV"):
        parse_epic_kitchens(_folder_with(tmp_path / "empty", not_narrations))


def _folder_with(folder, file):
    folder.mkdir()
    (folder / file.name).write_bytes(file.read_bytes())
    return folder


def test_virtualhome_sample(sample_dir):
    from lmcr.ingest.virtualhome import parse_virtualhome

    parsed = parse_virtualhome(sample_dir / "household" / "virtualhome" / "programs_sample.json")
    assert_balanced(parsed)
    assert (parsed.records_in, len(parsed.documents)) == (8, 5)  # two repeats are the same records
    assert [r for _, r in reasons(parsed)] == [
        "entry 8: not a program string",
        "entry 9: does not start with 'Task: <title>'",
        "entry 10: has no steps",
    ]
    serve = next(d for d in parsed.documents if d["title"] == "Serve milk")
    texts = [(s["kind"], s["text"]) for s in parsed.sentences if s["doc_id"] == serve["doc_id"]]
    assert texts[0] == ("title", "Serve milk") and ("instruction", "Pour milk into cup") in texts


def test_virtualhome_not_a_program_list(tmp_path):
    from lmcr.ingest.virtualhome import parse_virtualhome

    path = tmp_path / "p.json"
    for body, message in (
        (b'{"Task": 1}', "a JSON dict, not a list"),
        (b"[1,", "not valid JSON"),
        (b'["Task: x\xff"]', "not UTF-8"),
    ):
        path.write_bytes(body)
        with pytest.raises(IngestError, match=message):
            parse_virtualhome(path)


def test_household_folder_expands_to_both_adapters(sample_dir):
    sources = expand_inputs([sample_dir / "household"], "household")
    assert [(s.format, s.path.name) for s in sources] == [
        ("epic_kitchens", "household"),
        ("virtualhome", "programs_sample.json"),
    ]
    assert detect_format(sample_dir / "household" / "epic_kitchens" / "EPIC_sample_55.csv") == "epic_kitchens"
    assert detect_format(sample_dir / "household" / "virtualhome" / "programs_sample.json") == "virtualhome"
    # The folder source's hash covers its narration files, so an edit to one is noticed.
    assert sources[0].files() == sorted(sources[0].files(), key=lambda f: "55" in f.name)
