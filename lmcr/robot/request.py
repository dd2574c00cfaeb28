"""`lmcr execute` as library calls: an instruction typed or heard from a WAV file, executed in a scene with
the pictures saved; or a batch of instructions and scenes. The models are loaded once, into an `Executor`."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from lmcr.complete import CompletionConfig
from lmcr.robot.budget import Budget
from lmcr.robot.execute import execute, execute_batch
from lmcr.robot.render import VIDEO_EVERY, Recorder
from lmcr.robot.scene import Scene
from lmcr.scorers.registry import Scorer
from lmcr.speech.audio import AudioError
from lmcr.speech.listen import listen
from lmcr.srl.parser import FrameParser


@dataclass(frozen=True)
class Executor:
    """What executing instructions needs, loaded once: the parser, the completion scorer and its
    calibration, the robot's cache folder, the official Baxter URDF to use instead of ours (or None), and
    the planning search's budget per instruction."""

    parser: FrameParser
    scorer: Scorer
    config: CompletionConfig
    cache_dir: Path
    urdf: Path | None = None
    budget: Budget = field(default_factory=Budget)

    def run(self, instruction: str, scene: Scene, recorder: Recorder | None = None) -> dict:
        """One instruction executed in `scene`: the CLI contract's result (see `execute`)."""
        return execute(
            instruction,
            scene,
            self.parser,
            self.scorer,
            self.config,
            self.cache_dir,
            recorder,
            urdf=self.urdf,
            budget=self.budget,
        )

    def run_batch(self, path: Path, lines: Sequence[tuple] | None = None) -> Iterator[dict]:
        """The batch of the JSONL file `path` (or those of its `lines` that `read_batch` read), one result
        per line as each is done (see `execute_batch`)."""
        return execute_batch(path, self.run, lines)


def execute_request(
    executor: Executor,
    scene: Scene,
    instruction: str | None = None,
    audio: Path | None = None,
    recognizer=None,
    render: Sequence[Path] = (),
    video: Path | None = None,
) -> dict:
    """One instruction executed in `scene`, typed (`instruction`) or heard from `audio` by `recognizer`
    (the result adds the `text` heard). When the recogniser is unsure what was said, nothing moves: the
    result is {text, question, executed: False, success: False}; when it heard nothing, AudioError. With
    `render` (.gif or .png paths), the execution's pictures are saved there and listed in `render` (none
    when the plan was infeasible: the robot did not move); with `video` (a .gif path), the run's animation
    is saved there and named in `video` (none when the robot did not move)."""
    heard = None
    if audio is not None:
        heard = listen(recognizer, executor.parser, audio, [o.label for o in scene.objects])
        if not heard["text"]:
            raise AudioError(f"{audio}: {heard.get('reason', 'nothing recognised')}")
        if heard["question"]:  # unsure what was said: ask, do not act
            return {"text": heard["text"], "question": heard["question"], "executed": False, "success": False}
        instruction = heard["text"]
    recorder = Recorder(scene, every=VIDEO_EVERY if video else 0) if render or video else None
    result = executor.run(instruction, scene, recorder)
    if recorder is not None and recorder.pictures:
        result["render"] = [str(recorder.save(path)) for path in render]
        if video is not None:
            result["video"] = str(recorder.save_video(video))
    return result if heard is None else {"text": heard["text"], **result}
