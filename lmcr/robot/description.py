"""Which robot description the simulation loads: the built-in Baxter (`baxter.py`), or the official
`baxter_description` made loadable by pybullet (`official.py`) when one is given."""

from __future__ import annotations

from pathlib import Path

from lmcr.robot.baxter import builtin_urdf
from lmcr.robot.official import RobotModelError, official_urdf


def baxter_urdf(cache_dir: Path, official: Path | None = None) -> Path:
    """Our URDF written (atomically) under `cache_dir`, or the official description at `official`
    (`baxter_common/baxter_description/urdf/baxter.urdf`) made loadable there."""
    if official is None:
        return builtin_urdf(cache_dir)
    if not Path(official).is_file():
        raise RobotModelError(f"{official}: no such robot description")
    return official_urdf(Path(official), cache_dir)
