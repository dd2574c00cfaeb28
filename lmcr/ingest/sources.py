"""Which adapter reads a path, and how user paths expand into ingestable sources."""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from lmcr.errors import one_line
from lmcr.files import hash_file
from lmcr.ingest.epic_kitchens import narration_files, parse_epic_kitchens
from lmcr.ingest.feeding_america import parse_feeding_america
from lmcr.ingest.mealmaster import START_RE, parse_mealmaster
from lmcr.ingest.recipe_json import parse_recipe_json
from lmcr.ingest.records import IngestError, ParsedFile
from lmcr.ingest.virtualhome import parse_virtualhome
from lmcr.ingest.youcook2 import parse_youcook2
from lmcr.jsonl import InputError
from lmcr.setting import SOURCE_CORPORA as CORPORA
from lmcr.setting import SettingError

FORMATS: dict[str, Callable[..., ParsedFile]] = {
    "youcook2": parse_youcook2,
    "recipe_json": parse_recipe_json,
    "mealmaster": parse_mealmaster,
    "feeding_america": parse_feeding_america,
    "epic_kitchens": parse_epic_kitchens,
    "virtualhome": parse_virtualhome,
}
TEXT_SUFFIXES = (".mmf", ".mm", ".mxp", ".nyc", ".txt")


@dataclass(frozen=True)
class Source:
    """One ingestable input: a file, or a folder of one-JSON-per-recipe files."""

    path: Path
    format: str
    corpus: str
    encoding: str | None = None

    @property
    def key(self) -> str:
        """The identity its rows are stored under (re-ingesting it replaces them)."""
        return str(self.path)

    def sha256(self) -> str:
        """Content hash; for a folder, over the names and contents of the files its adapter reads."""
        digest = hashlib.sha256()
        files = self.files()
        for file in files:
            digest.update(file.relative_to(self.path).as_posix().encode() if self.path.is_dir() else b"")
            try:
                hash_file(digest, file)
            except OSError as exc:
                raise unreadable(file, exc) from exc
        return digest.hexdigest()

    def files(self) -> list[Path]:
        """The files the source's adapter reads."""
        if not self.path.is_dir():
            return [self.path]
        return narration_files(self.path) if self.format == "epic_kitchens" else sorted(self.path.rglob("*.json"))


def unreadable(path: Path, exc: OSError) -> IngestError:
    """An input that the system cannot read (permission, an I/O error) as the error naming the file: a
    read's OSError often carries no file name ("[Errno 5] Input/output error")."""
    return IngestError(str(exc.filename or path), None, f"cannot read: {exc.strerror or one_line(exc)}")


def _sniff(path: Path) -> str:
    try:
        with open(path, "rb") as handle:
            head = handle.read(8192).decode("latin-1")
    except OSError as exc:
        raise unreadable(path, exc) from exc
    if head.lstrip().startswith("[") and "Task:" in head:
        return "virtualhome"
    if '"database"' in head:
        return "youcook2"
    if any(START_RE.match(line) or line.strip().lower().startswith("title:") for line in head.splitlines()):
        return "mealmaster"
    if head.lstrip().startswith("{"):
        return "recipe_json"
    if "<cookbook" in head:
        return "feeding_america"
    raise IngestError(str(path), None, "unrecognised format; pass --format " + "|".join(FORMATS))


def detect_format(path: Path) -> str:
    """The adapter for a path, from its name and, where that is ambiguous, its first bytes."""
    name = path.name.lower()
    if path.is_dir():
        return "recipe_json"
    if name.endswith((".jsonl", ".jsonl.gz", ".ndjson", ".ndjson.gz")):
        return "recipe_json"
    if name.endswith(".csv"):
        return "epic_kitchens"
    if name.endswith(".xml"):
        return "feeding_america"
    if name.endswith(TEXT_SUFFIXES):
        return "mealmaster"
    return _sniff(path)


def expand_inputs(paths: list[Path], corpus: str, fmt: str | None = None, encoding: str | None = None) -> list[Source]:
    """Sources for user paths: a folder of XML or text exports gives one source per file (so they
    parse in parallel); a folder of JSON files is one source; missing paths fail clearly."""
    if corpus not in CORPORA:
        raise SettingError(f"corpus must be one of {CORPORA}, not {corpus!r}")
    if fmt is not None and fmt not in FORMATS:
        raise InputError(f"format must be one of {sorted(FORMATS)}, not {fmt!r}")
    sources: list[Source] = []
    for path in (Path(p).resolve() for p in paths):
        if not path.exists():
            raise IngestError(str(path), None, "no such file or folder")
        sources += _path_sources(path, corpus, fmt, encoding)
    return sources


def _path_sources(path: Path, corpus: str, fmt: str | None, encoding: str | None) -> list[Source]:
    """The sources of one existing user path: a file, or a folder as `expand_inputs` describes."""
    if path.is_dir() and corpus == "household" and fmt is None:
        return _household_sources(path, encoding)
    if path.is_dir() and corpus == "youcook2":
        files = sorted(path.glob("*.json"))
        if not files:
            raise IngestError(str(path), None, "folder holds no YouCook2 .json annotation files")
        return [Source(f, fmt or "youcook2", corpus, encoding) for f in files]
    if path.is_dir() and not any(path.rglob("*.json")):
        files = sorted(p for p in path.iterdir() if p.suffix.lower() in (".xml", *TEXT_SUFFIXES))
        if not files:
            raise IngestError(str(path), None, "folder holds no .json, .xml or recipe text files")
        return [Source(f, fmt or detect_format(f), corpus, encoding) for f in files]
    return [Source(path, fmt or detect_format(path), corpus, encoding)]


def expand_corpora(paths: dict[str, list], fmt: str | None = None, encoding: str | None = None) -> list[Source]:
    """Sources for each corpus's user paths ({"recipes": [...], "household": [...]}), corpus by corpus."""
    unknown = set(paths) - set(CORPORA)
    if unknown:
        raise SettingError(f"corpus must be one of {CORPORA}, not {sorted(unknown)[0]!r}")
    return [
        s
        for corpus in CORPORA
        for s in expand_inputs([Path(p) for p in paths.get(corpus) or []], corpus, fmt, encoding)
    ]


def _household_sources(path: Path, encoding: str | None) -> list[Source]:
    """A household folder: its EPIC-KITCHENS narration CSVs as one source (their overlap is settled
    together), each VirtualHome program file as its own."""
    sources = [Source(path, "epic_kitchens", "household", encoding)] if narration_files(path) else []
    sources += [
        Source(f, "virtualhome", "household", encoding)
        for f in sorted(path.rglob("*.json"))
        if _sniff_or_none(f) == "virtualhome"
    ]
    if not sources:
        raise IngestError(str(path), None, "folder holds no EPIC-KITCHENS narration CSV or VirtualHome program file")
    return sources


def _sniff_or_none(path: Path) -> str | None:
    try:
        return _sniff(path)
    except IngestError:
        return None


def parse_source(source: Source) -> ParsedFile:
    """Run the source's adapter; a file the system cannot read is an IngestError naming it."""
    parser = FORMATS[source.format]
    try:
        if source.format == "mealmaster":
            return parser(source.path, source.corpus, encoding=source.encoding)
        return parser(source.path, source.corpus)
    except OSError as exc:
        raise unreadable(source.path, exc) from exc
