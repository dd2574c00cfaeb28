"""What the terms that rank the fillers of one role share (`ScorerSpec.within_role`: `commonsense`,
`stated_pmi`): a call's frames grouped by the roles they fill, and each group's scores centred on its
mean, so that a term orders the frames of a group and moves no group against another."""

from __future__ import annotations

from collections.abc import Mapping

from lmcr.frame import Frame


def role_sets(frames: list[Frame]) -> list[list[int]]:
    """The frames' indices grouped by (predicate, the roles it fills), in the order first met."""
    groups: dict[tuple, list[int]] = {}
    for i, frame in enumerate(frames):
        groups.setdefault((frame.predicate, tuple(sorted(frame.role_map))), []).append(i)
    return list(groups.values())


def centred(raw: Mapping[int, float], groups: list[list[int]], size: int, weight: float) -> list[float]:
    """`weight` times each frame's raw score less its group's mean, for the `size` frames of a call; 0 for
    a frame in a group not every frame of which has a raw score, or in none of the groups."""
    out = [0.0] * size
    for members in groups:
        if all(i in raw for i in members):
            mean = sum(raw[i] for i in members) / len(members)
            for i in members:
                out[i] = weight * (raw[i] - mean)
    return out
