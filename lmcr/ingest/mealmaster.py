"""Meal-Master and "Now You're Cooking!" text exports: several recipes per file in marked blocks.

A block starts at a start marker (`MMMMM----- Recipe via Meal-Master`, `---------- Recipe via
Meal-Master`, `@@@@@ Now You're Cooking!`, `BEGIN RECIPE`) or a bare `Title:` line, carries header
fields (`Title:`, `Categories:`, `Servings:`/`Yield:`), ingredient lines in Meal-Master's columns
(possibly two side by side), sub-section rules, then direction paragraphs, and ends at an end marker
(`MMMMM`, `-----`, `END RECIPE`, `** Exported from ... **`). Files are cp437 (DOS), latin-1/cp1252 or
UTF-8; the encoding is detected unless given.
"""

from __future__ import annotations

import re
import unicodedata
from dataclasses import dataclass, field
from pathlib import Path

from lmcr.ingest.records import IngestError, ParsedFile

START_RE = re.compile(
    r"^\s*(?:(?:MMMMM|-{5})-{5}\s*Recipe via Meal-Master|@{5}\s*Now You're Cooking|BEGIN RECIPE)", re.I
)
END_RE = re.compile(r"^\s*(?:MMMMM|-{5}|END RECIPE|\*\*\s*Exported from .*\*\*)\s*$", re.I)
SECTION_RE = re.compile(r"^\s*(?:MMMMM|-{5})-*\s*([A-Za-z][^-]*?)?\s*-{3,}\s*$")
HEADER_RE = re.compile(r"^\s*(Title|Categories|Servings|Yield)\s*:\s*(.*)$", re.I)
# Comment paragraphs start with a label ("Notes:", "Source:") or a byline ("Posted by", "Typed to").
COMMENT_RE = re.compile(
    r"^\s*(?:(?:Source|From|Notes?|Per serving|Date|Nutrition|Exchanges?|Contributor|Comments?)\s*:"
    r"|(?:Posted|Typed|Formatted|Shared|Entered|Converted|Recipe)\s+(?:by|to|in|for)\b|Copyright|MC formatted)",
    re.I,
)
# Meal-Master ingredient columns: quantity right-aligned in 7, unit in 2, then the text; lines
# without a quantity are indented to the text column.
QUANTITY = r"(?:\d+(?:[ -]\d+/\d+|/\d+|\.\d+)?|\.\d+)"
INGREDIENT_RE = re.compile(rf"^ {{0,8}}{QUANTITY}(?:-{QUANTITY})?\s+\S|^ {{5,}}\S")
TWO_COLUMN_AT = 41


def _plausibility(ch: str) -> int:
    """How a non-ASCII character argues for a decoding of recipe text: accented Latin letters, fractions,
    degrees and typographic quotes for; box drawing, C1 controls, Greek and maths symbols (what cp437
    bytes look like through the wrong codec, and vice versa) against."""
    code = ord(ch)
    if code < 0x80:
        return 0
    if 0x80 <= code < 0xA0 or 0x2500 <= code <= 0x25FF or 0x0370 <= code <= 0x03FF or 0x2200 <= code <= 0x22FF:
        return -3
    name = unicodedata.name(ch, "")
    return 1 if "LATIN" in name or "FRACTION" in name or "QUOTATION" in name or ch in "°–—" else 0


def decode(raw: bytes, path: str, encoding: str | None = None) -> str:
    """Decode with the given codec, else UTF-8, else the likelier of cp437 and cp1252/latin-1."""
    if encoding:
        try:
            return raw.decode(encoding)
        except (UnicodeDecodeError, LookupError) as exc:
            raise IngestError(path, None, f"cannot decode as {encoding}: {exc}") from exc
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        pass

    def score(text: str) -> int:
        return sum(_plausibility(ch) for ch in text)

    candidates = [raw.decode("cp437"), raw.decode("cp1252", errors="replace"), raw.decode("latin-1")]
    return max(candidates, key=score)


@dataclass
class _Block:
    line: int
    header: dict[str, str] = field(default_factory=dict)
    ingredients: list[str] = field(default_factory=list)
    paragraphs: list[list[str]] = field(default_factory=list)
    in_directions: bool = False

    def add(self, line: str) -> None:
        header = HEADER_RE.match(line)
        if header and not self.in_directions:
            self.header[header.group(1).lower()] = header.group(2).strip()
        elif SECTION_RE.match(line) and not END_RE.match(line):
            self.paragraphs.append([])  # a sub-section rule ("MMMMM----FILLING----") separates text
        elif not line.strip():
            self.paragraphs.append([])
        elif not self.in_directions and INGREDIENT_RE.match(line):
            self.ingredients.extend(_split_columns(line))
        else:
            self.in_directions = True
            if not self.paragraphs:
                self.paragraphs.append([])
            self.paragraphs[-1].append(line.strip())

    def parts(self) -> list[tuple[str, str]]:
        parts = [("title", self.header["title"])] if self.header.get("title") else []
        parts += [("ingredient", x) for x in self.ingredients]
        for paragraph in filter(None, self.paragraphs):
            text = " ".join(paragraph)
            parts.append(("comment" if COMMENT_RE.match(text) else "instruction", text))
        return parts


def _split_columns(line: str) -> list[str]:
    """One or two ingredients: Meal-Master prints short ingredient lists in two columns."""
    left, right = line[:TWO_COLUMN_AT], line[TWO_COLUMN_AT:]
    if right.strip() and INGREDIENT_RE.match(right) and left.endswith(" "):
        return [x for x in (_ingredient(left), _ingredient(right)) if x]
    return [x for x in (_ingredient(line),) if x]


def _ingredient(column: str) -> str:
    return " ".join(column.split())


def parse_mealmaster(path: Path, corpus: str = "recipes", encoding: str | None = None) -> ParsedFile:  # noqa: C901 - the format's grammar: a branch per kind of line
    """Read every recipe block; untitled or unterminated blocks and stray text are quarantined."""
    try:
        text = decode(path.read_bytes(), str(path), encoding)
    except OSError as exc:
        raise IngestError(str(path), None, f"cannot read: {exc}") from exc
    parsed = ParsedFile(str(path), "mealmaster", corpus)
    stem, block, stray, ordinal = path.stem, None, [], 0

    def flush_stray() -> None:
        if stray:
            parsed.reject(stray[0][0], "text outside any recipe block", "\n".join(t for _, t in stray))
            stray.clear()

    def close(b: _Block, reason: str | None) -> None:
        nonlocal ordinal
        ordinal += 1
        if reason:
            parsed.reject(b.line, reason, b.header.get("title", ""))
        elif not b.header.get("title"):
            parsed.reject(b.line, "recipe block has no Title: line", "")
        else:
            parsed.add_document(
                f"{stem}:{ordinal}",
                f"mealmaster:{stem}",
                b.line,
                b.parts(),
                title=b.header["title"],
                category=b.header.get("categories"),
            )

    for line_no, line in enumerate(text.splitlines(), start=1):
        starts = START_RE.match(line) or (
            block is None and HEADER_RE.match(line) and HEADER_RE.match(line).group(1).lower() == "title"
        )
        if starts:
            if block is not None:
                close(block, f"recipe block has no end marker before the next recipe at line {line_no}")
            flush_stray()
            block = _Block(line_no)
            if not START_RE.match(line):
                block.add(line)
        elif block is not None and END_RE.match(line):
            close(block, None)
            block = None
        elif block is not None:
            block.add(line)
        elif line.strip():
            stray.append((line_no, line))
        else:
            flush_stray()
    if block is not None:
        close(block, "recipe block has no end marker before the end of the file")
    flush_stray()
    return parsed
