"""From audio to frames: transcribe, pick the reading the robot understands, and ask when unsure.

The recogniser's best text is not always the one the robot can act on ("a few in the chocolate" when
an alternative is "dip a few in the chocolate"); among the best text and its n-best alternatives, the
first whose robot frame names only objects on the table is taken (without a scene: only objects the
robot knows), else the first that parses to a robot predicate. When close alternatives put a
different predicate or object word in the same place, the robot asks instead of acting.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from lmcr.jsonl import InputError, read_jsonl
from lmcr.speech.audio import AudioError, read_wav
from lmcr.speech.recognize import Recognizer, Transcript
from lmcr.srl.parser import FrameParser


def understood_reading(parser: FrameParser, heard: Transcript, objects: list[str] | None = None) -> str:
    """The first of the best text and its n-best alternatives whose robot frame names only objects on the
    table (`objects`, when the scene is known; else objects the robot knows, the lexicon's), else the
    first with a robot predicate, else the best."""
    readings = [(text, [f for f in parser.parse(text) if f.known]) for text in (heard.text, *heard.alternatives)]
    on_table = set(parser.lex.objects if objects is None else objects)
    for text, frames in readings:
        stated = [v for v in frames[0].roles.values() if v] if frames else []
        if stated and set(stated) <= on_table:
            return text
    return next((text for text, frames in readings if frames), heard.text)


def clarifying_question(heard: Transcript) -> str | None:
    """'Did you say pour or fill?' for the first word the close alternatives disagree on, else None."""
    if not heard.doubts:
        return None
    options = heard.doubts[0]
    return f"Did you say {', '.join(options[:-1])} or {options[-1]}?"


def listen(recognizer: Recognizer, parser: FrameParser, audio: Path, objects: list[str] | None = None) -> dict:
    """One WAV file -> {text, frames, confidence, alternatives, question, [reason]} (frames as `lmcr srl`);
    with the scene's `objects`, a reading naming what is on the table is preferred."""
    heard = recognizer.transcribe(read_wav(audio))
    text = understood_reading(parser, heard, objects) if heard.text else ""
    frames = [f.to_json() for f in parser.parse(text) if f.known] if text else []
    out = {**heard.to_json(), "text": text, "frames": frames, "question": clarifying_question(heard)}
    if text != heard.text:
        out["heard"] = heard.text
    return out


LISTEN_FIELDS = {"id": (str, int), "audio": str}  # a `lmcr listen --input` line (CLI contract)


def read_listen_input(path: Path) -> list[tuple[int, dict]]:
    """The (line, record) pairs of a listen batch; malformed JSONL raises InputError naming file and line."""
    return list(read_jsonl(path, required=LISTEN_FIELDS))


def listen_batch(
    records: list[tuple[int, dict]], base: Path, recognizer: Recognizer, parser: FrameParser
) -> Iterator[dict]:
    """Each record {id, audio} (audio relative to `base` or absolute) heard and parsed, in order, as soon as
    each is done; a line whose audio cannot be decoded gets an `error` and the batch goes on."""
    for line, rec in records:
        audio = Path(rec["audio"]) if Path(rec["audio"]).is_absolute() else base / rec["audio"]
        try:
            yield {"id": rec["id"], "audio": rec["audio"], **listen(recognizer, parser, audio)}
        except (AudioError, InputError) as exc:
            yield {"id": rec["id"], "audio": rec["audio"], "error": f"line {line}: {exc}"}
