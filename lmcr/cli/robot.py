"""Commands of the robot: the recogniser's `speech-lm`, `listen` to speech, `execute` an instruction in
simulation, talk to the `robot`, and `serve` a page to try it."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from lmcr.cli.common import SPACY_MODEL_HELP, CorpusSetting, app, console, fail, note, one_or_batch, write_batch
from lmcr.robot.budget import (
    IK_CALLS,
    IK_CALLS_RANGE,
    PLAN_SECONDS,
    PLAN_SECONDS_ENV,
    PLAN_SECONDS_RANGE,
    Budget,
    default_plan_seconds,
)
from lmcr.scorers.registry import COMPLETION_METHOD, METHODS
from lmcr.speech.domain_lm import SpeechLMConfig
from lmcr.workspace import Workspace

SPEECH_MODEL_HELP = "sphinx: domain model folder (default $LMCR_DATA_DIR/speech/en-us)."
ASR_HELP = "Speech recogniser: whisper (default; $LMCR_ASR) or sphinx (pocketsphinx with the `lmcr speech-lm` model)."
METHOD_HELP = "Scorer that completes the instructions."
CORPUS_HELP = "Corpus setting of the LM checkpoints and frame counts."
EXECUTE_USAGE = (
    'give "INSTRUCTION" (or --audio FILE.wav) and --scene SCENE.json, or --input IN.jsonl and '
    "--output OUT.jsonl (no instruction, --scene, --render or --video)"
)
PLAN_SECONDS_HELP = "Planning search's time budget per instruction (seconds of wall clock); then it refuses."
IK_BUDGET_HELP = "Planning search's budget of inverse-kinematics solves per instruction; then it refuses."


def plan_seconds_option():
    return typer.Option(
        PLAN_SECONDS, "--plan-seconds", envvar=PLAN_SECONDS_ENV, **PLAN_SECONDS_RANGE, help=PLAN_SECONDS_HELP
    )


def ik_budget_option():
    return typer.Option(IK_CALLS, "--ik-budget", **IK_CALLS_RANGE, help=IK_BUDGET_HELP)


@app.command("speech-lm")
def speech_lm(
    max_sentences: int = typer.Option(
        SpeechLMConfig.max_sentences, min=1, help="Corpus instruction sentences sampled."
    ),
    request_share: float = typer.Option(
        SpeechLMConfig.request_share, min=0.0, max=0.99, help="Share of tokens from lexicon request forms."
    ),
    max_vocab: int = typer.Option(
        SpeechLMConfig.max_vocab, min=1, help="Most words in the model (lexicon words always in)."
    ),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Build and publish the recogniser's domain language model from the corpora and the lexicon."""
    from lmcr.lexicon import load_lexicon
    from lmcr.speech.domain_lm import build_speech_lm
    from lmcr.speech.recognize import cmudict_path

    ws = Workspace.from_env(db=db)
    with ws.read() as con:
        build_speech_lm(
            con,
            load_lexicon(),
            cmudict_path(),
            ws.speech,
            SpeechLMConfig(max_sentences=max_sentences, request_share=request_share, max_vocab=max_vocab),
            log=lambda m: console.print(m, highlight=False),
        )


@app.command()
def listen(
    audio: Path | None = typer.Argument(None, help="One WAV file: prints the transcript and its frames."),
    input: Path | None = typer.Option(None, "--input", help="JSONL of {id, audio} (paths relative to its folder)."),
    output: Path | None = typer.Option(None, "--output", help="JSONL of {id, audio, text, frames, ...}."),
    speech_model: Path | None = typer.Option(None, help=SPEECH_MODEL_HELP),
    asr: str | None = typer.Option(None, help=ASR_HELP),
    model: str | None = typer.Option(None, help=SPACY_MODEL_HELP),
) -> None:
    """Speech in, offline: transcribe 16-bit PCM WAV (any rate, mono) and parse it into frames."""
    from lmcr.speech.listen import listen as listen_one
    from lmcr.speech.listen import listen_batch, read_listen_input

    batch = one_or_batch(audio, input, output, "give either AUDIO.wav or both --input IN.jsonl and --output OUT.jsonl")
    ws = Workspace.from_env()
    if batch:
        records = read_listen_input(input)  # bad input fails before the models load
        recognizer, parser = ws.recognizer(speech_model, asr), ws.parser(model)
        tally = write_batch(
            output, input, records, lambda rest: listen_batch(rest, input.parent, recognizer, parser), "listening"
        )
        console.print(f"{tally['lines']:,} recordings -> {output} ({tally['error']} could not be decoded)")
        return
    result = listen_one(ws.recognizer(speech_model, asr), ws.parser(model), audio)
    how = result.get("reason") or f"confidence {result['confidence']:.2f}"
    note(f"heard: {result['text'] or '(nothing)'} ({how})")
    if result["question"]:
        note(result["question"])
    print(json.dumps(result))


@app.command()
def execute(
    instruction: str | None = typer.Argument(None, help='The spoken instruction, e.g. "pour me some water".'),
    scene: Path | None = typer.Option(None, help="Scene JSON: objects with labels and table positions."),
    input: Path | None = typer.Option(None, "--input", help="Batch JSONL: {id, instruction, scene | scene_file}."),
    output: Path | None = typer.Option(None, "--output", help="Batch JSONL: {id, ...result} or {id, error}."),
    checkpoint: Path | None = typer.Option(None, help="Checkpoint root or folder (sentence LM)."),
    method: str = typer.Option(COMPLETION_METHOD, help="Scorer that completes the instruction."),
    corpus: CorpusSetting = typer.Option("all", help=CORPUS_HELP),
    json_out: bool = typer.Option(False, "--json", help="Print the result as one JSON line (last line)."),
    render: list[Path] = typer.Option(
        [],
        help="Save the execution: out.gif (a 3/4 view per waypoint) or out.png (a "
        "contact sheet with waypoint captions); may be given twice.",
    ),
    model: str | None = typer.Option(None, help="spaCy model (default $LMCR_SPACY_MODEL)."),
    audio: Path | None = typer.Option(None, help="The instruction spoken, as a WAV file (instead of INSTRUCTION)."),
    speech_model: Path | None = typer.Option(None, help=SPEECH_MODEL_HELP),
    asr: str | None = typer.Option(None, help=ASR_HELP),
    urdf: Path | None = typer.Option(
        None,
        help="Official Baxter URDF (baxter_common/baxter_description/urdf/"
        "baxter.urdf; default $LMCR_BAXTER_URDF, else the built-in model).",
    ),
    video: Path | None = typer.Option(None, help="Save an animation of the run: out.gif (the motions as they go)."),
    plan_seconds: float = plan_seconds_option(),
    ik_budget: int = ik_budget_option(),
) -> None:
    """Detect, complete, plan and execute an instruction with a simulated Baxter (pybullet, headless);
    with --audio, the instruction is heard first; with --input/--output, a batch of instructions and
    scenes with the models loaded once."""
    from lmcr.jsonl import check_text

    ws = Workspace.from_env()
    if audio is not None and (instruction is not None or input is not None or output is not None):
        fail("--audio replaces INSTRUCTION (and is not a batch option)")
    batch = one_or_batch(instruction if audio is None else audio, input, output, EXECUTE_USAGE)
    if (batch and (scene is not None or render or video is not None)) or (not batch and scene is None):
        fail(EXECUTE_USAGE)
    _check_render(render, video)  # before the simulation, so a bad path does not cost its result
    if batch:
        from lmcr.robot.execute import read_batch

        lines = read_batch(input)  # an unreadable input fails before the models load
    else:
        from lmcr.robot.scene import load_scene  # pybullet: after the argument checks

        layout = load_scene(scene)
        if instruction is not None:
            check_text(instruction, "instruction")
    # after the checks: completion's import (the models' libraries) takes seconds, a bad scene fails at once
    from lmcr.robot.request import Executor, execute_request

    scorer, config = ws.completion_scorer(method, ws.resources(checkpoint, corpus))
    budget = Budget(plan_seconds, ik_budget)
    executor = Executor(ws.parser(model), scorer, config, ws.robot, urdf or ws.baxter_urdf, budget)
    if batch:
        tally = write_batch(output, input, lines, lambda rest: executor.run_batch(input, rest), "executing")
        console.print(f"{tally['lines']:,} lines -> {output}: {tally['success']} succeeded, {tally['error']} errors")
        return
    recognizer = ws.recognizer(speech_model, asr) if audio is not None else None
    _show_execution(execute_request(executor, layout, instruction, audio, recognizer, render, video), json_out)


def _check_render(paths: list[Path], video: Path | None) -> None:
    from lmcr.files import OutputError, check_output_file

    for path in paths:
        check_output_file(path)
        if path.suffix.lower() not in (".png", ".gif"):
            raise OutputError(f"{path}: --render takes a .png or .gif file name")
    if video is not None:
        check_output_file(video)
        if video.suffix.lower() != ".gif":
            raise OutputError(f"{video}: --video takes a .gif file name (an animated GIF)")


def _show_execution(result: dict, json_out: bool) -> None:
    """What `execute` did, on stderr (unless `json_out`), then its JSON as the last line on stdout."""
    if "waypoints" not in result:  # heard, but unsure what was said: the robot asked and did not act
        note(f"heard: {result['text']}. {result['question']}")
    elif not json_out:
        for w in result["waypoints"]:
            console.print(f"  {w['name']}: {1000 * w['error_m']:.1f} mm", highlight=False)
        if result["feasible"]:
            outcome = "success" if result["success"] else "FAILED"
            note(f"{result['reply']} ({result['arm']} arm, {outcome}: {json.dumps(result['checks'])})")
        else:  # planned, found infeasible: the robot did not move
            note(f"{result['reply']} (the robot did not move: {result['reason']})")
    print(json.dumps(result))


@app.command()
def robot(
    scene: Path = typer.Option(..., help="Scene JSON: the objects on the table."),
    turns: Path | None = typer.Option(None, help="Scripted turns, one per line (default: type them; empty line ends)."),
    audio_dir: Path | None = typer.Option(None, help="Spoken turns: the folder's WAV files in name order."),
    method: str = typer.Option(COMPLETION_METHOD, help=METHOD_HELP),
    corpus: CorpusSetting = typer.Option("all", help=CORPUS_HELP),
    checkpoint: Path | None = typer.Option(None, help="Checkpoint root or folder."),
    json_out: bool = typer.Option(False, "--json", help="Print each outcome as one JSON line."),
    asr: str | None = typer.Option(
        None, help="Speech recogniser for --audio-dir: whisper (default; $LMCR_ASR) or sphinx."
    ),
    plan_seconds: float = plan_seconds_option(),
    ik_budget: int = ik_budget_option(),
) -> None:
    """Talk to the robot: instructions and answers to its questions, typed, scripted or spoken."""
    from lmcr.jsonl import read_lines
    from lmcr.robot.scene import load_scene

    if turns is not None and audio_dir is not None:
        fail("give --turns or --audio-dir, not both")
    ws = Workspace.from_env()
    layout = load_scene(scene)
    from lmcr.robot.dialogue import converse  # after the scene's checks: it loads the models' libraries (seconds)

    parser = ws.parser()
    if turns is not None:
        said = iter([t.strip() for t in read_lines(turns) if t.strip()])
    elif audio_dir is not None:
        said = _heard_turns(ws.recognizer(asr=asr), parser, audio_dir, [o.label for o in layout.objects])
    else:
        said = _typed_turns()
    scorer, config = ws.completion_scorer(method, ws.resources(checkpoint, corpus))
    outcomes = converse(
        said, layout, parser, scorer, config, ws.robot, say=note, budget=Budget(plan_seconds, ik_budget)
    )
    if json_out:
        for outcome in outcomes:
            print(json.dumps({k: v for k, v in outcome.items() if k not in ("waypoints", "detections")}))


def _typed_turns():
    """Lines typed at the prompt until an empty line or the end of input."""
    while True:
        try:
            line = input("> ").strip()
        except EOFError:
            return
        if not line:
            return
        yield line


def _heard_turns(recognizer, parser, folder: Path, on_table: list[str]):
    """What `lmcr listen` hears in each of a folder's WAV files, in name order (a file that cannot be
    heard is skipped with its reason)."""
    from lmcr.speech.audio import AudioError
    from lmcr.speech.listen import listen

    wavs = sorted(folder.glob("*.wav")) if folder.is_dir() else []
    if not wavs:
        fail(f"{folder}: no .wav files")
    for wav in wavs:
        try:
            heard = listen(recognizer, parser, wav, on_table)
        except AudioError as exc:
            note(f"{exc}")
            continue
        if heard["text"]:
            yield heard["text"]
        else:
            note(f"{wav}: {heard['reason']}")


@app.command()
def serve(
    host: str = typer.Option("127.0.0.1", help="Address to listen on (the default serves this machine only)."),
    port: int = typer.Option(
        8000, min=0, max=65535, help="Port to listen on (0: any free port; the address is printed)."
    ),
    data_dir: Path | None = typer.Option(
        None,
        "--data-dir",
        help="Data folder with the trained checkpoints (default: lmcr --data-dir, $LMCR_DATA_DIR or data).",
    ),
    method: str = typer.Option(COMPLETION_METHOD, help=METHOD_HELP),
    corpus: CorpusSetting = typer.Option("all", help=CORPUS_HELP),
) -> None:
    """A local web page to try the robot: objects and an instruction (typed or recorded) in; the frame, the
    completion, the robot's question and the simulated execution out. Models load on the first request."""
    from lmcr.serve.app import serve as serve_page

    unknown = [m for m in method.split("+") if m not in METHODS]
    if unknown:  # checked now: the models load on the first request
        fail(f"--method: unknown {unknown[0]!r}; available: {', '.join(METHODS)} (a+b sums two)")
    default_plan_seconds()  # each request plans under it: a bad $LMCR_PLAN_SECONDS is said now, once
    ws = Workspace.from_env(data_dir=data_dir)
    if not ws.data_dir.is_dir():
        fail(f"{ws.data_dir}: no such data folder (run `make demo`, or give --data-dir)")
    serve_page(ws, host, port, method, corpus, say=lambda line: note(line, soft_wrap=True))
