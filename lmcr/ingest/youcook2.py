"""YouCook2 annotations (`youcookii_annotations_trainval.json`): one document per video, one record per step."""

from __future__ import annotations

import json
from pathlib import Path

from lmcr.ingest.records import IngestError, ParsedFile
from lmcr.jsonl import has_surrogates


def _text(value: object) -> str | None:
    """A metadata field as text (the file may hold numbers there), None when absent or empty."""
    return str(value) if value not in (None, "") and not isinstance(value, (dict, list)) else None


def _segment(annotation: dict) -> tuple[float, float] | None:
    seg = annotation.get("segment")
    if not (isinstance(seg, list) and len(seg) == 2 and all(isinstance(x, (int, float)) for x in seg)):
        return None
    return (float(seg[0]), float(seg[1])) if 0 <= seg[0] <= seg[1] < float("inf") else None


def _annotation_problem(annotation: object) -> str | None:
    if not isinstance(annotation, dict):
        return "annotation is not an object"
    if not isinstance(annotation.get("sentence"), str) or not annotation["sentence"].strip():
        return "annotation has no sentence"
    if has_surrogates(annotation):
        return "text has an unpaired surrogate"
    if _segment(annotation) is None:
        return f"bad segment {annotation.get('segment')!r} (want [start, end] seconds, start <= end)"
    return None


def parse_youcook2(path: Path, corpus: str = "youcook2") -> ParsedFile:  # noqa: C901 - the annotation schema: a check per field that can be malformed
    """Read the annotations file; a malformed annotation is quarantined, its video's other steps kept."""
    parsed = ParsedFile(str(path), "youcook2", corpus)
    try:
        database = json.loads(path.read_text(encoding="utf-8"))["database"]
    except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as exc:
        raise IngestError(str(path), getattr(exc, "lineno", None), f"not valid JSON: {exc}") from exc
    except (KeyError, TypeError) as exc:
        raise IngestError(str(path), None, 'no top-level "database" object: not a YouCook2 file') from exc
    except OSError as exc:
        raise IngestError(str(path), None, f"cannot read: {exc.strerror}") from exc
    if not isinstance(database, dict):
        raise IngestError(str(path), None, f'"database" is a {type(database).__name__}, not an object of videos')
    for ordinal, (video_id, video) in enumerate(database.items(), start=1):
        annotations = video.get("annotations") if isinstance(video, dict) else None
        if has_surrogates(
            [video_id, {k: v for k, v in video.items() if k != "annotations"}] if isinstance(video, dict) else video_id
        ):
            parsed.reject(ordinal, "video id or metadata has an unpaired surrogate", video_id)
            continue
        if not isinstance(annotations, list) or not annotations:
            parsed.reject(ordinal, f"video {video_id}: no annotations list", video)
            continue
        parts = []
        for index, annotation in enumerate(annotations):
            problem = _annotation_problem(annotation)
            if problem:
                parsed.reject(ordinal, f"video {video_id} annotation {index}: {problem}", annotation)
                continue
            start, end = _segment(annotation)
            parts.append(("instruction", annotation["sentence"], {"seg_start": start, "seg_end": end}))
        if parts:
            parsed.add_document(
                video_id,
                "youcook2",
                ordinal,
                parts,
                category=_text(video.get("recipe_type")),
                subset=_text(video.get("subset")),
                url=_text(video.get("video_url")),
                records=len(parts),
            )
    return parsed
