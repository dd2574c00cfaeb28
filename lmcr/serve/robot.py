"""What the page asks of the robot: a scene from typed labels, an instruction completed, a person's answer
read, the instruction executed and recorded, a recording heard. Models load once, on first use, and one
request at a time drives them (pybullet's simulator is one per process).

The page holds the conversation: when the robot asks, its question comes back with a `Pending` (what was
asked: the role, the choices, how many times) that the page returns with the person's answer, so the
server keeps no state between requests besides the models and the last few animations.
"""

from __future__ import annotations

import tempfile
import threading
import uuid
from collections import OrderedDict
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from lmcr.errors import LMCRError, one_line
from lmcr.jsonl import check_text
from lmcr.lexicon import load_lexicon
from lmcr.robot.reply import LEAVE_IT, say
from lmcr.scorers.registry import COMPLETION_METHOD
from lmcr.workspace import Workspace

MAX_OBJECTS = 10  # a person picks a handful; the 1.2 m x 0.7 m table holds about this many
MAX_AUDIO_BYTES = 8 * 2**20  # a minute of 16-bit mono at 48 kHz is 5.5 MiB
KEPT_ANIMATIONS = 16  # the GIFs of the last runs stay served; older ones are dropped


class RequestError(LMCRError, ValueError):
    """A request that cannot be served: an empty instruction, an unknown or repeated label, too many
    objects, an answer that names no role of the instruction, a recording too large."""


class ModelsUnavailable(LMCRError, RuntimeError):
    """The data folder lacks what completing needs (checkpoints, frame counts, SRL resources)."""


@dataclass(frozen=True)
class Pending:
    """What the robot asked and waits for an answer to: `choose` among the completion's `choices` for
    `role` (asked at most MAX_TRIES times), or take the feasible `offer` (choices[0])."""

    kind: str  # "choose" or "offer"
    role: str
    choices: list[str]
    allowed: list[str]  # the objects an answer may name
    question: str
    tries: int = 1


def check_instruction(text: str) -> str:
    """The instruction with its spaces tidied; empty or over-long text is a RequestError."""
    text = " ".join(text.split())
    if not text:
        raise RequestError("the instruction is empty: type what the robot should do")
    return check_text(text, "instruction")


def check_labels(objects: list[str]) -> list[str]:
    """The scene's labels (lowercase, single spaces): known to the robot, each once, at most MAX_OBJECTS."""
    labels = [" ".join(o.lower().split()) for o in objects]
    labels = [label for label in labels if label]
    if not labels:
        raise RequestError("no objects: put at least one object on the table")
    if len(labels) > MAX_OBJECTS:
        raise RequestError(f"{len(labels)} objects; the table holds at most {MAX_OBJECTS}")
    known = set(load_lexicon().objects)
    for label in labels:
        if label not in known:
            raise RequestError(
                f"unknown object {label[:40]!r}: the robot knows {len(known)} objects (the page lists "
                "them; GET /api/vocabulary)"
            )
    repeated = next((label for label in labels if labels.count(label) > 1), None)
    if repeated:
        raise RequestError(f"the {repeated} is on the list twice; the robot tells objects apart by name")
    return labels


def make_layout(labels: list[str], seed: int):
    """The scene: the labelled objects placed at random (seeded) where they fit on the table."""
    from lmcr.robot.scene import make_scene

    return make_scene([(label, None) for label in labels], seed, "scene")


def read_reply(reply: str, pending: Pending) -> dict:
    """A person's answer to `pending`: {"answer": {role: object}} to act on, {"pending", "said"} to ask
    again, or {"left": True, "said"} when the robot gives up (a refused offer, MAX_TRIES unusable answers)."""
    from lmcr.robot.dialogue import (  # here: it imports the parser (seconds), the page need not wait
        MAX_TRIES,
        read_answer,
    )

    reading = read_answer(reply, pending.choices, pending.allowed, load_lexicon().objects)
    if pending.kind == "offer":  # only the offered object is taken, as in `lmcr robot`
        if reading.choice == pending.choices[0]:
            return {"answer": {pending.role: reading.choice}}
        return {"left": True, "said": LEAVE_IT}
    if reading.choice:
        return {"answer": {pending.role: reading.choice}}
    if pending.tries >= MAX_TRIES:
        return {"left": True, "said": LEAVE_IT}
    again = replace(pending, tries=pending.tries + 1)
    return {"pending": asdict(again), "said": f"{reading.problem} {pending.question}"}


class ServedRobot:
    """The parser, scorer, calibration and recogniser of one server process, each loaded on first use,
    and the animations of its last runs."""

    def __init__(self, ws: Workspace, method: str = COMPLETION_METHOD, corpus: str = "all"):
        self.ws, self.method, self.corpus = ws, method, corpus
        self.lock = threading.Lock()  # the models and the simulator serve one request at a time
        self._models = None
        self._recognizer = None
        self.animations: OrderedDict[str, bytes] = OrderedDict()

    def models(self):
        """(parser, scorer, completion config), loaded once; a failure is retried on the next request."""
        if self._models is None:
            try:
                parser = self.ws.parser()
                scorer, config = self.ws.completion_scorer(self.method, self.ws.resources(corpus=self.corpus))
            except (LMCRError, OSError, ValueError, RuntimeError, KeyError) as exc:
                raise ModelsUnavailable(
                    f"cannot load the models from {self.ws.data_dir} ({one_line(exc, 300)}); "
                    "run `make demo` or the pipeline for this data folder first"
                ) from exc
            self._models = parser, scorer, config
        return self._models

    def complete(self, instruction: str, objects: list[str], seed: int = 0) -> dict:
        """The instruction's frame as said, its completion with the candidates' probabilities, and the
        question with what it asks (`pending`) when the robot is unsure."""
        from lmcr.complete import complete

        text, labels = check_instruction(instruction), check_labels(objects)
        layout = make_layout(labels, seed)  # a scene that does not fit the table fails here, before the models
        with self.lock:
            parser, scorer, config = self.models()
            completion = complete(parser, scorer, text, labels, config)
        missing = completion.missing_roles
        said = {r: (None if r in missing else completion.unresolved.get(r, v)) for r, v in completion.frame.roles}
        pending = None
        if completion.question and missing:
            stated = {v for r, v in completion.frame.roles if r != missing[0]}
            choices = list(dict.fromkeys(c.object for c in completion.candidates))
            pending = asdict(
                Pending("choose", missing[0], choices, [o for o in labels if o not in stated], completion.question)
            )
        return {
            "instruction": text,
            "scene": [{"label": o.label, "xy": list(o.xy)} for o in layout.objects],
            "said": {"predicate": completion.frame.predicate, "roles": said},
            **completion.to_json(),
            "calibration": config.source,
            "pending": pending,
        }

    def execute(
        self, instruction: str, objects: list[str], seed: int = 0, answer: dict[str, str] | None = None
    ) -> dict:
        """Execute the instruction in simulation (with a person's `answer`, role -> object, when given) and
        record it: the result, the animation's id, what the robot says, and its offer when the choice was
        out of reach but another object is not."""
        from lmcr.robot.execute import execute
        from lmcr.robot.render import Recorder
        from lmcr.srl.instruction import read_instruction

        text, labels = check_instruction(instruction), check_labels(objects)
        layout = make_layout(labels, seed)
        with self.lock:
            parser, scorer, config = self.models()
            if answer:
                _check_answer(answer, read_instruction(parser, text)[0].roles, labels)
            recorder = Recorder(layout)
            result = execute(
                text, layout, parser, scorer, config, self.ws.robot, recorder, answer=answer, urdf=self.ws.baxter_urdf
            )
            animation = self._keep(recorder) if recorder.pictures else None
        pending = None
        if not result["feasible"] and result.get("suggestion"):
            role, offered = next(iter(result["suggestion"].items()))
            pending = asdict(Pending("offer", role, [offered, result["chosen_object"]], labels, say(result)))
        shown = {k: v for k, v in result.items() if k != "detections"}
        return {
            **shown,
            "animation": animation,
            "captions": recorder.captions,
            "reply": say(result),
            "pending": pending,
        }

    def _keep(self, recorder) -> str:
        """Keep the run's GIF (the last KEPT_ANIMATIONS are served) and return its id."""
        with tempfile.TemporaryDirectory(prefix="lmcr-serve-") as tmp:
            data = recorder.save(Path(tmp) / "run.gif").read_bytes()
        key = uuid.uuid4().hex
        self.animations[key] = data
        while len(self.animations) > KEPT_ANIMATIONS:
            self.animations.popitem(last=False)
        return key

    def listen(self, audio: bytes, objects: list[str]) -> dict:
        """A recording (16-bit PCM WAV, mono) heard: its text, and the question when the recogniser was
        unsure what was said (`lmcr listen`'s result)."""
        from lmcr.speech.audio import AudioError, read_wav
        from lmcr.speech.listen import listen

        if len(audio) > MAX_AUDIO_BYTES:
            raise RequestError(
                f"the recording is {len(audio) / 2**20:.1f} MiB; the limit is {MAX_AUDIO_BYTES / 2**20:.0f} MiB"
            )
        labels = check_labels(objects) if objects else None
        with tempfile.TemporaryDirectory(prefix="lmcr-serve-") as tmp:
            path = Path(tmp) / "recording.wav"
            path.write_bytes(audio)
            try:
                read_wav(path)  # bad audio is refused before the models load
            except AudioError as exc:  # it names our temporary file: the person knows it as the recording
                raise RequestError(str(exc).replace(str(path), "the recording")) from exc
            with self.lock:
                parser = self.models()[0]
                if self._recognizer is None:
                    self._recognizer = self.ws.recognizer()
                heard = listen(self._recognizer, parser, path, labels)
        return {k: heard.get(k) for k in ("text", "question", "confidence", "reason", "heard")}


def _check_answer(answer: dict[str, str], roles: dict, labels: list[str]) -> None:
    for role, obj in answer.items():
        if role not in roles:
            raise RequestError(
                f"the answer fills {role[:40]!r}, which is no role of this instruction ({', '.join(roles)})"
            )
        if obj not in labels:
            raise RequestError(f"the answer names {obj[:40]!r}, which is not on the table")
