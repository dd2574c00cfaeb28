"""Facts about the LMCR checkout itself: where it is and which commit it is (paths: `lmcr.workspace`)."""

from __future__ import annotations

import hashlib
import subprocess
from functools import cache
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
SQL_DIR = REPO_ROOT / "sql"  # the migrations, contracts and named queries shipped with the code
LIBRARY = Path(__file__).resolve().parent
LIBRARY_FILES = ("*.py", "*.json", "*.sql")  # code, and the data files it ships (lexicon, household)


def git_commit(root: Path = REPO_ROOT) -> str | None:
    """The checked-out commit (with '+changes' when tracked files differ), or None outside a git checkout
    or without git."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=10)
        if head.returncode != 0:
            return None
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=root,
            capture_output=True,
            text=True,
            timeout=10,
        ).stdout.strip()
        return head.stdout.strip() + ("+changes" if dirty else "")
    except (OSError, subprocess.TimeoutExpired):
        return None


@cache
def library_fingerprint(roots: tuple[Path, ...] = (LIBRARY, SQL_DIR)) -> str:
    """Hash of the library's code and the files it ships (every .py, .json and .sql under `roots`; no
    bytecode): a result kept on disk depends on it as much as on its inputs, so a cache key holds it. A
    scoring change, committed or not, then computes afresh (`git_commit` knows neither an edit in a
    checkout nor an installed copy). Computed once a process: the code does not change under it."""
    digest = hashlib.sha256()
    for root in roots:
        files = sorted(path for pattern in LIBRARY_FILES for path in root.rglob(pattern) if path.is_file())
        for path in files:
            digest.update(str(path.relative_to(root)).encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()
