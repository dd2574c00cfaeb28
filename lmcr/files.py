"""File helpers shared by every stage: atomic writes, content hashes and reading the learned resources."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TypeVar

from lmcr.errors import LMCRError, one_line

T = TypeVar("T")
# What reading a JSON file LMCR wrote can raise when the file is missing, not JSON, or not shaped as its
# reader expects (a reader indexes into the value and converts it freely).
UNREADABLE_JSON = (OSError, ValueError, KeyError, TypeError, AttributeError, IndexError)

# Written into every folder LMCR publishes, listing the files it wrote: a folder is replaced only when
# everything in it is LMCR's own, so a user's files are never deleted.
OUTPUT_MARKER = ".lmcr-output.json"


class OutputError(LMCRError, ValueError):
    """An output path LMCR must not write to (a user's folder, a folder where a file is expected)."""


class ResourceError(LMCRError, RuntimeError):
    """A learned resource (compounds, role priors, first words) that cannot be read."""


def read_resource(path: Path, what: str, build: Callable[[object], T]) -> T:
    """`build` of the JSON a stage wrote at `path`. A file that cannot be read, is not JSON or is not
    shaped as `build` expects (it indexes into the value and converts it freely: a wrong shape raises a
    KeyError, TypeError or ValueError there) is a one-line ResourceError naming the file."""
    try:
        return build(json.loads(Path(path).read_text(encoding="utf-8")))
    except UNREADABLE_JSON as exc:
        raise ResourceError(f"{path}: cannot read the {what} ({one_line(exc, 200)}); "
                            "run `lmcr frames` again") from exc


@contextmanager
def atomic_path(path: Path) -> Iterator[Path]:
    """A temporary path beside `path` to write to; renamed onto `path` when the block succeeds and
    removed when it fails, so readers never see a partial file."""
    path = Path(path)
    check_output_file(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def cached_json(path: Path, usable: Callable[[object], bool], make: Callable[[], object]) -> object:
    """What `make()` returns, kept as JSON at `path`: the saved value when `usable` accepts it, else made
    afresh and saved there (atomically). A file that is missing, not JSON, or not shaped as `usable`
    expects (it may index into the value freely) is made again."""
    try:
        saved = json.loads(Path(path).read_text(encoding="utf-8"))
        if usable(saved):
            return saved
    except UNREADABLE_JSON:
        pass  # no cache yet, or not one of ours
    made = make()
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(made), encoding="utf-8")
    return made


def check_output_file(path: Path, reads: Path | None = None) -> None:
    """Refuse an output file path that is a folder, lies under a file, or is the file the command
    `reads` (the result would replace the user's input): checked before the work, so a bad `--out` does
    not cost the result."""
    path = Path(path)
    if path.is_dir():
        raise OutputError(f"{path}: is a folder; give a file name")
    if reads is not None and path.exists() and Path(reads).exists() and path.samefile(reads):
        raise OutputError(f"{path}: is the input file; give the output another name")
    parent = next((p for p in path.parents if p.exists()), None)
    if parent is not None and not parent.is_dir():
        raise OutputError(f"{path}: {parent} is a file, not a folder")


def check_output_dir(path: Path) -> None:
    """Refuse to replace `path` unless it is absent, empty, or an LMCR output folder that holds only the
    files LMCR wrote there (its marker lists them)."""
    path = Path(path)
    if not path.exists():
        return
    if not path.is_dir():
        raise OutputError(f"{path}: exists and is not a folder")
    present = {p.relative_to(path).as_posix() for p in path.rglob("*") if not p.is_dir()}
    if not present:
        return
    marker = path / OUTPUT_MARKER
    if not marker.is_file():
        raise OutputError(f"{path}: folder is not empty and is not an LMCR output (no {OUTPUT_MARKER}); "
                          "choose a new or empty folder")
    try:
        ours = set(json.loads(marker.read_text(encoding="utf-8"))["files"]) | {OUTPUT_MARKER}
    except (ValueError, KeyError, TypeError, OSError) as exc:
        raise OutputError(f"{marker}: unreadable output marker; choose a new or empty folder") from exc
    foreign = sorted(present - ours)
    if foreign:
        raise OutputError(f"{path}: holds files LMCR did not write ({', '.join(foreign[:3])}"
                          f"{', ...' if len(foreign) > 3 else ''}); move them or choose another folder")


@contextmanager
def atomic_dir(path: Path) -> Iterator[Path]:
    """A temporary folder beside `path` to fill; when the block succeeds it replaces `path` whole, and
    when it fails it is removed. The folder gets a marker listing its files; an existing `path` is
    replaced only if `check_output_dir` allows it (checked before and again just before the swap)."""
    path = Path(path)
    check_output_dir(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    try:
        yield tmp
        files = sorted(p.relative_to(tmp).as_posix() for p in tmp.rglob("*") if not p.is_dir())
        (tmp / OUTPUT_MARKER).write_text(json.dumps({"files": files}, indent=1), encoding="utf-8")
        check_output_dir(path)
        if path.exists():
            old = path.with_name(f".{path.name}.{os.getpid()}.old")
            shutil.rmtree(old, ignore_errors=True)
            path.rename(old)
            tmp.rename(path)
            shutil.rmtree(old)
        else:
            tmp.rename(path)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def hash_file(digest: hashlib._Hash, path: Path) -> None:
    """Feed a file's bytes into `digest` in 1 MiB chunks."""
    with open(path, "rb") as handle:
        for chunk in iter(lambda: handle.read(1 << 20), b""):
            digest.update(chunk)


def file_sha256(path: Path) -> str:
    digest = hashlib.sha256()
    hash_file(digest, path)
    return digest.hexdigest()
