"""The one frame type: frozen, hashable, stable id, the rating tables' key, JSON, unpacking."""

from __future__ import annotations

import dataclasses

import pytest

from lmcr.frame import Frame


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
