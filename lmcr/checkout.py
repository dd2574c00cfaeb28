"""Facts about the LMCR checkout itself: where it is and which commit it is (paths: `lmcr.workspace`)."""

from __future__ import annotations

import subprocess
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
SQL_DIR = REPO_ROOT / "sql"  # the migrations, contracts and named queries shipped with the code


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
