"""Feeding America cookbook XML: `<cookbook>` books whose `<recipe>` elements mix tagged and free text.

`<purpose>` is the recipe's title, `<list>/<item>` lines are ingredients, the running text of the
recipe's paragraphs is instructions, and notes/attributions are comments.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

from lmcr.ingest.records import IngestError, ParsedFile

KIND_OF_TAG = {"purpose": "title", "item": "ingredient", "attribution": "comment", "note": "comment"}
SKIPPED_TAGS = frozenset({"pb", "ednote", "illustration", "gap", "figure"})
# These end a run of text, so the next text starts a new part even of the same kind.
BLOCK_TAGS = frozenset({"p", "item", "purpose", "list", "recipe", "table", "row", "lb"})
RECIPE_START = re.compile(rb"<recipe[\s>/]")


def _emit(parts: list[list], kind: str, text: str | None) -> None:
    if not text:
        return
    if parts and parts[-1][0] == kind and parts[-1][2]:
        parts[-1][1] += text  # whitespace too: it separates inline tags ("onion.</ingredient> <ingredient>")
    elif text.strip():
        parts.append([kind, text, True])


def _collect(elem: ET.Element, kind: str, parts: list[list]) -> None:
    """Gather (kind, text, open) parts from an element, its children and their tails, in order."""
    own = KIND_OF_TAG.get(elem.tag, kind)
    _emit(parts, own, elem.text)
    for child in elem:
        if child.tag not in SKIPPED_TAGS:
            _collect(child, own, parts)
        _emit(parts, own, child.tail)
    if elem.tag in BLOCK_TAGS and parts:
        parts[-1][2] = False


def _recipe_lines(raw: bytes) -> list[int]:
    """1-based line of each `<recipe` start tag, in document order (ElementTree keeps no line numbers)."""
    return [raw.count(b"\n", 0, m.start()) + 1 for m in RECIPE_START.finditer(raw)]


def parse_feeding_america(path: Path, corpus: str = "recipes") -> ParsedFile:
    """Read one cookbook; a recipe with no text is quarantined, a malformed book fails with its line."""
    parsed = ParsedFile(str(path), "feeding_america", corpus)
    try:
        raw = path.read_bytes()
        root = ET.fromstring(raw)
    except ET.ParseError as exc:
        raise IngestError(str(path), exc.position[0], f"malformed XML: {exc}") from exc
    if root.tag != "cookbook":
        raise IngestError(str(path), 1, f"root element is <{root.tag}>, not <cookbook>")
    book = path.stem
    recipes = list(root.iter("recipe"))
    lines = _recipe_lines(raw)
    if len(lines) != len(recipes):
        lines = [0] * len(recipes)
    for ordinal, (recipe, line) in enumerate(zip(recipes, lines), start=1):
        parts: list[list] = []
        _collect(recipe, "instruction", parts)
        titles = [text for kind, text, _ in parts if kind == "title"]
        parsed.add_document(
            f"{book}:{ordinal}",
            f"feeding_america:{book}",
            line or ordinal,
            [(kind, text) for kind, text, _ in parts],
            title=" ".join(titles) or None,
            category=recipe.get("class1"),
        )
    return parsed
