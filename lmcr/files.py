"""File helpers shared by every stage: atomic writes, content hashes and reading the learned resources."""

from __future__ import annotations

import errno
import hashlib
import json
import os
import shutil
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
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
        raise ResourceError(f"{path}: cannot read the {what} ({one_line(exc, 200)}); run `lmcr frames` again") from exc


def output_target(path: Path) -> Path:
    """Where an output named `path` is written. The rule for every output path, file or folder, of every
    command: a symbolic link is followed (its target is written and the link stays a link); missing
    parent folders are created; a path that cannot be written there (a read-only folder, a parent that is
    a file) is a one-line OutputError naming `path` as the user gave it, never a temporary name; an
    existing file is replaced whole (atomically), an existing folder only when it is empty or an LMCR
    output holding only LMCR's files (`check_output_dir`)."""
    try:
        return Path(os.path.realpath(path, strict=True))
    except (FileNotFoundError, NotADirectoryError):  # not there yet (a link to it may be), or under a file
        return Path(os.path.realpath(path))
    except OSError as exc:  # a loop of links, a component that is a file, ...
        raise OutputError(f"{path}: {exc.strerror or one_line(exc)}") from exc


def _check_writable(path: Path, target: Path) -> None:
    """Refuse `path` (written at `target`) when its nearest existing folder cannot take a new file: the
    permission bits do not tell (root, read-only mounts), so a probe file is created and removed."""
    folder = next((p for p in target.parents if p.exists()), Path(target.anchor))
    if not folder.is_dir():
        raise OutputError(f"{path}: {folder} is a file, not a folder")
    try:
        handle, probe = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".probe", dir=folder)
        os.close(handle)
        os.unlink(probe)
    except OSError as exc:
        raise OutputError(f"{path}: cannot write there ({exc.strerror or one_line(exc)})") from exc


# Errors only a write raises, without a file name (a write or a flush): in an output block, the output's.
WRITE_ERRNOS = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS)


def output_error(path: Path, exc: OSError, *ours: Path) -> OutputError | None:
    """An OSError of writing the output `path` (about one of `ours`, the temporary names and the target,
    or a write error with no file name) as the one line naming `path`; None for any other OSError."""
    names = [str(n) for n in (exc.filename, exc.filename2) if n is not None]
    if names and not any(n == str(p) or n.startswith(f"{p}{os.sep}") for n in names for p in ours):
        return None
    if not names and exc.errno not in WRITE_ERRNOS:
        return None
    return OutputError(f"{path}: cannot write: {exc.strerror or one_line(exc)}")


def _make_parents(path: Path, target: Path) -> None:
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{path}: cannot create its folder ({exc.strerror or one_line(exc)})") from exc


@contextmanager
def atomic_path(path: Path) -> Iterator[Path]:
    """A temporary path beside `path` to write to; renamed onto `path` when the block succeeds and
    removed when it fails, so readers never see a partial file. `path` follows `output_target`'s rule."""
    path = Path(path)
    check_output_file(path)
    target = output_target(path)
    _make_parents(path, target)
    tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    try:
        yield tmp
        os.replace(tmp, target)
    except OSError as exc:
        error = output_error(path, exc, tmp, target)
        if error is None:
            raise
        raise error from exc
    finally:
        with suppress(OSError):
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
    """Refuse an output file path that is a folder, lies under a file, cannot be written there, or is the
    file the command `reads` (the result would replace the user's input): checked before the work, so a
    bad `--out` does not cost the result. The rule of `output_target` applies."""
    path = Path(path)
    target = output_target(path)
    if target.is_dir():
        raise OutputError(f"{path}: is a folder; give a file name")
    if reads is not None and target.exists() and Path(reads).exists() and target.samefile(reads):
        raise OutputError(f"{path}: is the input file; give the output another name")
    _check_writable(path, target)


def check_output_dir(path: Path) -> None:
    """Refuse to replace `path` unless it is absent, empty, or an LMCR output folder that holds only the
    files LMCR wrote there (its marker lists them), and refuse it where it cannot be written; the rule of
    `output_target` applies, and every error names `path`."""
    path = Path(path)
    target = output_target(path)
    if target.exists() and not target.is_dir():
        raise OutputError(f"{path}: exists and is not a folder")
    _check_writable(path, target)
    files = [p for p in target.rglob("*") if not p.is_dir()] if target.exists() else []
    present = {p.relative_to(target).as_posix() for p in files}
    if not present:
        return
    marker = target / OUTPUT_MARKER
    if not marker.is_file():
        raise OutputError(
            f"{path}: folder is not empty and is not an LMCR output (no {OUTPUT_MARKER}); choose a new or empty folder"
        )
    try:
        ours = set(json.loads(marker.read_text(encoding="utf-8"))["files"]) | {OUTPUT_MARKER}
    except (ValueError, KeyError, TypeError, OSError) as exc:
        raise OutputError(f"{path}: unreadable output marker {OUTPUT_MARKER}; choose a new or empty folder") from exc
    foreign = sorted(present - ours)
    if foreign:
        raise OutputError(
            f"{path}: holds files LMCR did not write ({', '.join(foreign[:3])}"
            f"{', ...' if len(foreign) > 3 else ''}); move them or choose another folder"
        )


@contextmanager
def atomic_dir(path: Path) -> Iterator[Path]:
    """A temporary folder beside `path` to fill; when the block succeeds it replaces `path` whole, and
    when it fails it is removed. The folder gets a marker listing its files; an existing `path` is
    replaced only if `check_output_dir` allows it (checked before and again just before the swap).
    `path` follows `output_target`'s rule: a link to a folder stays a link, to the new folder."""
    path = Path(path)
    check_output_dir(path)
    target = output_target(path)
    _make_parents(path, target)
    tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    old = target.with_name(f".{target.name}.{os.getpid()}.old")
    try:
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir()
        yield tmp
        files = sorted(p.relative_to(tmp).as_posix() for p in tmp.rglob("*") if not p.is_dir())
        (tmp / OUTPUT_MARKER).write_text(json.dumps({"files": files}, indent=1), encoding="utf-8")
        check_output_dir(path)
        if target.exists():
            shutil.rmtree(old, ignore_errors=True)
            target.rename(old)
            try:
                tmp.rename(target)
            except OSError:
                old.rename(target)  # put the previous output back
                raise
            shutil.rmtree(old, ignore_errors=True)
        else:
            tmp.rename(target)
    except OSError as exc:
        error = output_error(path, exc, tmp, old, target)
        if error is None:
            raise
        raise error from exc
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
