"""Shared fixtures: the embedded sample corpus, throwaway stores, the optional ../shared data and a simulator."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

# The planning search of every test (and of the commands it starts) stops at its IK count alone: a wall
# clock would end it earlier on a busy machine, and a test would find another plan or none. The tests of
# the clock give their own budget.
os.environ.setdefault("LMCR_PLAN_SECONDS", "3600")

from lmcr.checkout import REPO_ROOT
from lmcr.store import connect
from lmcr.workspace import Workspace

SAMPLE = REPO_ROOT / "data" / "sample"


@pytest.fixture
def sample_dir() -> Path:
    return SAMPLE


@pytest.fixture
def paths(tmp_path: Path) -> Workspace:
    """A private data dir and store for one test."""
    return Workspace.from_env(data_dir=tmp_path / "data")


@pytest.fixture
def con(paths: Workspace):
    connection = connect(paths.db, paths.sql_dir)
    yield connection
    connection.close()


@pytest.fixture
def shared_dir() -> Path:
    """The read-only shared data (`LMCR_SHARED_DIR`, else ../shared); tests using it skip without it."""
    root = Path(os.environ.get("LMCR_SHARED_DIR") or REPO_ROOT.parent / "shared")
    if not (root / "data").is_dir():
        pytest.skip(f"shared data not found at {root}")
    return root


@pytest.fixture(scope="module")
def prefect_api(tmp_path_factory):
    """One local Prefect server for a test module (the pipeline's own, `flows.server`), its database in a
    throwaway Prefect home: the server process reads the variable when it starts."""
    from flows.server import local_server

    home = os.environ.get("PREFECT_HOME")
    os.environ["PREFECT_HOME"] = str(tmp_path_factory.mktemp("prefect-home"))
    try:
        with local_server():
            yield
    finally:
        if home is None:
            os.environ.pop("PREFECT_HOME")
        else:
            os.environ["PREFECT_HOME"] = home


@pytest.fixture(scope="module")
def sim():
    """A DIRECT pybullet simulator for a test module's robot tests."""
    import pybullet as p

    client = p.connect(p.DIRECT)
    yield client
    p.disconnect(client)
