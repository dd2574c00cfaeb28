"""The one frame type: frozen, hashable, stable id, the rating tables' key, JSON, unpacking; the frames CSV."""

from __future__ import annotations

import dataclasses
import re

import pytest

from lmcr.frame import FRAME_COLUMNS, Frame, read_frames_csv, write_scores_csv
from lmcr.jsonl import InputError
from lmcr.scorers.registry import is_method_name


def test_frame_is_a_value():
    a = Frame.of("pour", {"Theme": "water", "Destination": "cup"})
    b = Frame("pour", (("Theme", "water"), ("Destination", "cup")))
    assert a == b and hash(a) == hash(b) and len({a, b}) == 1
    assert a.key == ("pour", "Theme", "water", "Destination", "cup")
    assert a.to_json() == {"predicate": "pour", "roles": {"Theme": "water", "Destination": "cup"}}
    verb, roles = a
    assert (verb, roles) == ("pour", {"Theme": "water", "Destination": "cup"})
    swapped = Frame.of("pour", {"Destination": "cup", "Theme": "water"})
    assert swapped != a and swapped.id == a.id and a.id.startswith("f-") and len(a.id) == 14
    assert Frame.of("pour", {"Theme": "water", "Destination": "glass"}).id != a.id
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.predicate = "fill"


def test_the_frames_csv_reads_frames_keeps_other_columns_and_writes_scores_beside_them(tmp_path):
    given, out = tmp_path / "f.csv", tmp_path / "o.csv"
    given.write_text(",".join(FRAME_COLUMNS) + ",note\npour,Destination,Cup,Theme,water,x\n")
    columns, rows = read_frames_csv(given, reserved=is_method_name)
    assert columns == [*FRAME_COLUMNS, "note"] and rows[0].line == 2 and rows[0].raw["note"] == "x"
    assert rows[0].frame == Frame.of("pour", {"Destination": "cup", "Theme": "water"})
    write_scores_csv(out, columns, rows, {"random": [0.25]})
    assert out.read_text().splitlines() == [
        ",".join([*FRAME_COLUMNS, "note", "random"]),
        "pour,Destination,Cup,Theme,water,x,0.250000",
    ]


@pytest.mark.parametrize("column", ["random", "sentence_lm+rarity"])
def test_a_frames_csv_column_named_like_a_method_is_refused(tmp_path, column):
    given = tmp_path / "f.csv"
    given.write_text(",".join([*FRAME_COLUMNS, column]) + "\npour,Theme,water,Destination,cup,1\n")
    with pytest.raises(InputError, match=re.escape(f"f.csv:1: column '{column}' is named like a method")):
        read_frames_csv(given, reserved=is_method_name)
