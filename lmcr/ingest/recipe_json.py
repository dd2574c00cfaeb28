"""Recipe JSON: JSON Lines (optionally gzipped) or a folder of one-JSON-per-recipe files.

Fields: `title`, `ingredients[]`, `directions[]`, `source`, `url` (others are ignored).
"""

from __future__ import annotations

import gzip
import json
import zlib
from collections.abc import Iterator
from pathlib import Path

from lmcr.errors import one_line
from lmcr.ingest.records import IngestError, ParsedFile
from lmcr.jsonl import InputError, decode_utf8, has_surrogates


def _recipe_problem(recipe: object) -> str | None:
    if not isinstance(recipe, dict):
        return "record is not a JSON object"
    if has_surrogates(recipe):
        return "text has an unpaired surrogate"
    for key in ("ingredients", "directions"):
        value = recipe.get(key, [])
        if not isinstance(value, list) or not all(isinstance(x, str) for x in value):
            return f"{key!r} is not a list of strings"
    if not recipe.get("directions") and not recipe.get("ingredients"):
        return "no ingredients and no directions"
    for key in ("title", "url", "source"):
        if recipe.get(key) is not None and not isinstance(recipe[key], str):
            return f"{key!r} is not a string"
    return None


def _lines(path: Path) -> Iterator[tuple[int, bytes]]:
    opener = gzip.open if path.suffix == ".gz" else open
    try:
        with opener(path, "rb") as handle:
            yield from enumerate(handle, start=1)
    except (OSError, EOFError, zlib.error) as exc:
        raise IngestError(str(path), None, f"cannot read: {one_line(exc)}") from exc


def _records(path: Path) -> Iterator[tuple[int, str, bytes]]:
    """(position, doc key, raw bytes) for each record of a JSONL file or a folder of JSON files."""
    if path.is_dir():
        for position, file in enumerate(sorted(path.rglob("*.json")), start=1):
            yield position, file.relative_to(path).with_suffix("").as_posix(), file.read_bytes()
        return
    for line_no, line in _lines(path):
        if line.strip():
            yield line_no, str(line_no), line


def _stem(path: Path) -> str:
    name = path.name
    for suffix in (".gz", ".jsonl", ".json"):
        name = name.removesuffix(suffix)
    return name


def parse_recipe_json(path: Path, corpus: str = "recipes") -> ParsedFile:
    """Read recipes; a line that is not JSON or not a recipe is quarantined with its line number."""
    parsed = ParsedFile(str(path), "recipe_json", corpus)
    stem = _stem(path)
    for position, key, data in _records(path):
        try:
            raw = decode_utf8(data, f"record {position}")
        except InputError as exc:
            parsed.reject(position, str(exc), "")
            continue
        try:
            recipe = json.loads(raw)
        except json.JSONDecodeError as exc:
            parsed.reject(position, f"not valid JSON: {exc.msg} at column {exc.colno}", raw)
            continue
        except RecursionError:
            parsed.reject(position, "JSON nested too deeply", raw[:200])
            continue
        problem = _recipe_problem(recipe)
        if problem:
            parsed.reject(position, problem, raw)
            continue
        title = recipe.get("title")
        parts = [("title", title)] if title else []
        parts += [("ingredient", x) for x in recipe.get("ingredients", [])]
        parts += [("instruction", x) for x in recipe.get("directions", [])]
        source = f"web:{recipe['source']}" if recipe.get("source") else f"json:{stem}"
        parsed.add_document(f"{stem}:{key}", source, position, parts, title=title, url=recipe.get("url"))
    return parsed
