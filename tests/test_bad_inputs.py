"""Property-based bad input, through the command line as a user meets it: for every batch input format,
generated malformed files end with exit status 1 and exactly one line on stderr naming the file (and
the line where there is one) and the reason; never a traceback, never an output file, never a changed
store. Ingest formats may instead quarantine the bad records: then counts balance.

`LMCR_FUZZ_EXAMPLES` sets how many files each format's test generates (default 25); each test prints
how many it ran.
"""

from __future__ import annotations

import gzip
import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

import duckdb
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from lmcr.cli import app

EXAMPLES = int(os.environ.get("LMCR_FUZZ_EXAMPLES", "25"))
FUZZ = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
runner = CliRunner()
COUNTS: dict[str, int] = {}

# JSON values of every type, for fields that must have one particular type.
ANY_JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=4), inner, max_size=3),
    max_leaves=6,
)


def _count(name: str) -> None:
    COUNTS[name] = COUNTS.get(name, 0) + 1


@pytest.fixture(scope="module", autouse=True)
def report_counts():
    yield
    for name, n in sorted(COUNTS.items()):
        print(f"\nmalformed {name} inputs: {n}, tracebacks: 0")


def invoke(args: list[str], workdir: Path):
    env = {"LMCR_DATA_DIR": str(workdir / "data"), "LMCR_DEBUG": ""}
    return runner.invoke(app, args, env=env)


def assert_one_line_error(result, path: Path, line: int | None = None) -> str:
    """Exit status 1, one stderr line naming the file (and line), no traceback; returns the line."""
    assert result.exit_code == 1, (result.exit_code, result.output)
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    assert "Traceback" not in result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    where = f"{path}:{line}:" if line else str(path)
    assert where in lines[0], (where, lines[0])
    return lines[0]


def store_snapshot(db: Path) -> dict:
    """Row counts of every table holding data, migrations aside (empty when there is no store yet)."""
    if not db.exists():
        return {}
    con = duckdb.connect(str(db))  # the CLI ran in this process: same configuration as its connection
    try:
        tables = [
            t
            for (t,) in con.execute(
                "select table_name from information_schema.tables where table_type = 'BASE TABLE'"
            ).fetchall()
        ]
        counts = {t: con.execute(f'select count(*) from "{t}"').fetchone()[0] for t in tables}
        return {t: n for t, n in counts.items() if n and t != "schema_migrations"}
    finally:
        con.close()


# --- JSON Lines of the batch commands ------------------------------------------------------------


def _jsonl_case(fields: dict[str, object], text_field: str, list_field: str | None):
    """(lines, bad line number, mutation) with exactly one malformed line among valid ones."""
    valid = [json.dumps({**fields, "id": f"r{k}"}) for k in range(3)]
    required = list(fields)
    mutations = st.one_of(
        st.tuples(st.just("undecodable"), st.binary(min_size=1, max_size=6).map(lambda b: b"\xff" + b)),
        st.tuples(st.just("not json"), st.text(max_size=12).map(lambda t: '{"id": "x", ' + t.replace("\n", " "))),
        st.tuples(st.just("not an object"), ANY_JSON.filter(lambda v: not isinstance(v, dict)).map(json.dumps)),
        st.tuples(st.just("missing field"), st.sampled_from(required)),
        st.tuples(st.just("wrong type"), st.tuples(st.sampled_from(required), ANY_JSON)),
        st.tuples(st.just("surrogate"), st.integers(0xD800, 0xDFFF)),
    )
    if list_field:
        mutations |= st.tuples(
            st.just("list of non-strings"), st.lists(st.integers() | st.none() | st.booleans(), min_size=1, max_size=3)
        )
    return st.tuples(st.just(valid), st.integers(1, 4), mutations)


def _mutated_line(fields: dict, text_field: str, list_field: str | None, kind: str, arg) -> bytes | None:
    record = {**fields, "id": "bad"}
    if kind == "undecodable":
        return b'{"id": "' + arg + b'"}'
    if kind in ("not json", "not an object"):
        return arg.encode("utf-8", "surrogatepass")
    if kind == "missing field":
        del record[arg]
    elif kind == "wrong type":
        name, value = arg
        expected = type(fields[name])
        if name == "id" and isinstance(value, (str, int)) and not isinstance(value, bool):
            return None  # a valid id
        if isinstance(value, expected) and not isinstance(value, bool):
            if name != list_field or all(isinstance(v, str) for v in value):
                return None  # the right type after all
        record[name] = value
    elif kind == "surrogate":
        return json.dumps({**record, text_field: "a"}).replace('"a"', f'"a\\u{arg:04x}"').encode()
    elif kind == "list of non-strings":
        record[list_field] = arg
    return json.dumps(record).encode()


def _write_jsonl(path: Path, valid: list[str], at: int, bad: bytes) -> None:
    lines = [v.encode() for v in valid]
    lines.insert(at - 1, bad)
    path.write_bytes(b"\n".join(lines) + b"\n")


SRL_FIELDS = {"id": "a", "text": "pour the water into the cup"}
COMPLETE_FIELDS = {"id": "a", "instruction": "pour me some water", "objects": ["cup", "plate"]}
LISTEN_FIELDS = {"id": "a", "audio": "said.wav"}
INSTRUCTION_FIELDS = {
    "instruction": "pour me some water",
    "objects": ["cup", "plate"],  # no id: it is not read
    "expected": {"predicate": "pour", "roles": {"Theme": "water", "Destination": "cup"}},
}
SAMPLE_RATINGS = Path(__file__).resolve().parents[1] / "data" / "sample" / "ratings" / "sample_ratings_mturk.csv"


def _check_rejected(
    command: str,
    fields: dict,
    text_field: str,
    list_field: str | None,
    case,
    argv: Callable[[Path, Path], list[str]] | None = None,
    made: str = "out.jsonl",
) -> bool:
    """Run `lmcr COMMAND --input --output` (or `argv(input, folder)`) on one generated case; the file
    `made` (in the folder) must not appear. False when the mutation was valid."""
    valid, at, (kind, arg) = case
    bad = _mutated_line(fields, text_field, list_field, kind, arg)
    if bad is None:
        return False
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        _write_jsonl(tmp / "in.jsonl", valid, at, bad)
        args = (
            argv(tmp / "in.jsonl", tmp)
            if argv
            else [command, "--input", str(tmp / "in.jsonl"), "--output", str(tmp / made)]
        )
        result = invoke(args, tmp)
        assert_one_line_error(result, tmp / "in.jsonl", at)
        assert not (tmp / made).exists()
    return True


@FUZZ
@given(case=_jsonl_case(SRL_FIELDS, "text", None))
def test_srl_batch_rejects_malformed_jsonl(case):
    if _check_rejected("srl", SRL_FIELDS, "text", None, case):
        _count("srl JSONL")


@FUZZ
@given(case=_jsonl_case(COMPLETE_FIELDS, "instruction", "objects"))
def test_complete_batch_rejects_malformed_jsonl(case):
    if _check_rejected("complete", COMPLETE_FIELDS, "instruction", "objects", case):
        _count("complete JSONL")


@FUZZ
@given(case=_jsonl_case(INSTRUCTION_FIELDS, "instruction", "objects"))
def test_mixture_rejects_malformed_instructions(case):
    """`lmcr mixture --instructions`: the dev instructions a corpus weight is chosen on; nothing is saved."""

    def argv(instructions: Path, folder: Path) -> list[str]:
        return ["mixture", "--ratings", str(SAMPLE_RATINGS), "--instructions", str(instructions)]

    if _check_rejected("mixture", INSTRUCTION_FIELDS, "instruction", "objects", case, argv, "data/mixture.json"):
        _count("instructions JSONL")


@FUZZ
@given(case=_jsonl_case(LISTEN_FIELDS, "audio", None))
def test_listen_batch_rejects_malformed_jsonl(case):
    if _check_rejected("listen", LISTEN_FIELDS, "audio", None, case):
        _count("listen JSONL")


SRL_INSTRUCTION_FIELDS = {key: value for key, value in INSTRUCTION_FIELDS.items() if key != "objects"}  # no scene read
GOLD_FIELDS = {
    "text": "pour the water into the cup",
    "frames": [{"predicate": "pour", "roles": {"Theme": "water", "Destination": None}}],
}


def _srl_eval_argv(gold: Path | None = None) -> Callable[[Path, Path], list[str]]:
    """srl-eval on the generated file as its gold (or, with `gold`, as its instructions)."""

    def argv(path: Path, folder: Path) -> list[str]:
        if gold is None:
            return ["srl-eval", "--gold", str(path)]
        (folder / "gold.jsonl").write_text(json.dumps(GOLD_FIELDS) + "\n")
        return ["srl-eval", "--gold", str(folder / "gold.jsonl"), "--instructions", str(path)]

    return argv


def _is_gold_frame(value) -> bool:
    return (
        isinstance(value, dict)
        and isinstance(value.get("predicate"), str)
        and isinstance(value.get("roles"), dict)
        and all(v is None or isinstance(v, str) for v in value["roles"].values())
    )


@FUZZ
@given(
    case=_jsonl_case(GOLD_FIELDS, "text", None),
    frame=st.one_of(
        ANY_JSON,
        st.fixed_dictionaries({"predicate": ANY_JSON, "roles": ANY_JSON}),
        st.fixed_dictionaries(
            {"predicate": st.just("pour"), "roles": st.dictionaries(st.text(max_size=5), ANY_JSON, max_size=2)}
        ),
    ),
)
def test_srl_eval_rejects_malformed_gold(case, frame):
    """`lmcr srl-eval --gold`: the line's fields, or one of its frames not shaped as a frame."""
    if _check_rejected("srl-eval", GOLD_FIELDS, "text", None, case, _srl_eval_argv()):
        _count("SRL gold JSONL")
    if not _is_gold_frame(frame):
        valid, at, _ = case
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            _write_jsonl(tmp / "gold.jsonl", valid, at, json.dumps({**GOLD_FIELDS, "frames": [frame]}).encode())
            assert "field 'frames'" in assert_one_line_error(
                invoke(["srl-eval", "--gold", str(tmp / "gold.jsonl")], tmp), tmp / "gold.jsonl", at
            )
        _count("SRL gold frames")


@FUZZ
@given(
    case=_jsonl_case(SRL_INSTRUCTION_FIELDS, "instruction", None),
    missing=st.one_of(ANY_JSON, st.sampled_from(["Theme", "Tool"])),
)
def test_srl_eval_rejects_malformed_instructions(case, missing):
    """`lmcr srl-eval --instructions`: the line's fields, or a `missing` that is no expected role."""
    if _check_rejected("srl-eval", SRL_INSTRUCTION_FIELDS, "instruction", None, case, _srl_eval_argv(Path("gold"))):
        _count("SRL instructions JSONL")
    if missing is not None and not (isinstance(missing, str) and missing in INSTRUCTION_FIELDS["expected"]["roles"]):
        valid, at, _ = case
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            _write_jsonl(
                tmp / "in.jsonl", valid, at, json.dumps({**SRL_INSTRUCTION_FIELDS, "missing": missing}).encode()
            )
            line = assert_one_line_error(
                invoke(_srl_eval_argv(Path("gold"))(tmp / "in.jsonl", tmp), tmp), tmp / "in.jsonl", at
            )
            assert "field 'missing'" in line
        _count("SRL instructions missing")


def test_srl_batch_text_over_the_length_cap_is_one_line(tmp_path):
    path = tmp_path / "in.jsonl"
    path.write_text(json.dumps({"id": 1, "text": "pour water " + "🥛" * 5000}) + "\n", encoding="utf-8")
    result = invoke(["srl", "--input", str(path), "--output", str(tmp_path / "out.jsonl")], tmp_path)
    assert "the limit is 1,000" in assert_one_line_error(result, path, 1)


# --- frames CSV (lmcr score) ----------------------------------------------------------------------

FRAMES_HEADER = "verb,role1,arg1,role2,arg2,note"
FRAMES_ROW = "pour,Theme,water,Destination,cup,x"


def score_one_frame(tmp: Path, *method_args: str):
    """`lmcr score` of `tmp/frames.csv` into `tmp/scores.csv` with the given method options."""
    return invoke(["score", "--frames", str(tmp / "frames.csv"), "--out", str(tmp / "scores.csv"), *method_args], tmp)


FRAME_DEFECTS = st.sampled_from(
    [
        ("bad header", "verb,role1,arg1,arg2", 1),
        ("method column", "verb,role1,arg1,role2,arg2,sentence_lm", 1),
        ("unknown verb", "juggle,Theme,water,Destination,cup,x", None),
        ("wrong roles", "pour,Theme,water,Source,cup,x", None),
        ("empty argument", "pour,Theme,,Destination,cup,x", None),
        ("extra field", "pour,Theme,water,Destination,cup,x,y", None),
        ("undecodable", b"pour,Theme,wat\xe9r,Destination,cup,x", None),
    ]
)


@FUZZ
@given(defect=FRAME_DEFECTS, before=st.integers(0, 3), after=st.integers(0, 3))
def test_score_rejects_malformed_frames_csv(defect, before, after):
    name, bad, line = defect
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "frames.csv"
        if line == 1:
            rows = [bad.encode()] + [FRAMES_ROW.encode()] * (before + after)
        else:
            line = 2 + before
            rows = (
                [FRAMES_HEADER.encode()]
                + [FRAMES_ROW.encode()] * before
                + [bad if isinstance(bad, bytes) else bad.encode()]
                + [FRAMES_ROW.encode()] * after
            )
        path.write_bytes(b"\n".join(rows) + b"\n")
        result = invoke(["score", "--frames", str(path), "--out", str(tmp / "scores.csv"), "--methods", "random"], tmp)
        assert_one_line_error(result, path, line)
        assert not (tmp / "scores.csv").exists()
    _count("frames CSV")


# --- word vectors (score/evaluate/complete --vectors) ---------------------------------------------

VECTOR_LINES = ["water 1 0", "cup 0.5 -0.5", "2 2"]
VECTOR_DEFECTS = st.one_of(
    st.sampled_from(["milk 1", "milk 1 0 2", "milk nan 0", "milk 1 inf", "milk 1 x", "milk", "milk\t1\t2\t3"]),
    st.lists(st.text(alphabet="ab1.e-+ ", max_size=4), min_size=1, max_size=4).map(lambda p: "milk " + " ".join(p)),
)


@FUZZ
@given(
    before=st.lists(st.sampled_from(VECTOR_LINES[:2]), max_size=3),
    defect=VECTOR_DEFECTS,
    header=st.booleans(),
    garbage=st.sampled_from([b"", b"\xff"]),
)
def test_a_malformed_vector_file_is_one_line_naming_its_line(before, defect, header, garbage):
    lines = ([VECTOR_LINES[2]] if header else []) + ["pour 0 1", *before, defect]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "frames.csv").write_text(f"{FRAMES_HEADER}\n{FRAMES_ROW}\n")
        (tmp / "v.txt").write_bytes("\n".join(lines).encode() + b"\n" + garbage)
        result = score_one_frame(tmp, "--methods", "word2vec", "--vectors", str(tmp / "v.txt"))
        if result.exit_code == 0:  # the defect made a valid line after all ("milk 1 2")
            assert not garbage and len(defect.split()) == 3
        else:
            assert_one_line_error(result, tmp / "v.txt", None if garbage else len(lines))
            assert not (tmp / "scores.csv").exists()
    _count("vector text")


EDGE_LINES = [
    "RelatedTo\tcup\tmug",
    "/a/[x]\t/r/AtLocation\t/c/en/milk\t/c/en/fridge\t{}",
    "RelatedTo\t/c/fr/tasse\t/c/fr/bol",
]


@FUZZ
@given(
    before=st.lists(st.sampled_from(EDGE_LINES), max_size=3),
    defect=st.one_of(
        st.text(alphabet="ab\t /", max_size=6).filter(lambda t: t.count("\t") < 2 and t.strip()), st.just("\udcff")
    ),
    gz=st.sampled_from(["plain", "gzip", "corrupt gzip"]),
)
def test_a_malformed_conceptnet_edge_file_is_one_line(before, defect, gz):
    lines = [EDGE_LINES[0], *before, defect]
    raw = "\n".join(lines).encode("utf-8", "surrogateescape") + b"\n"
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / ("edges.txt.gz" if gz != "plain" else "edges.txt")
        path.write_bytes(gzip.compress(raw) if gz == "gzip" else raw if gz == "plain" else b"\x1f\x8b" + raw)
        (tmp / "frames.csv").write_text(f"{FRAMES_HEADER}\n{FRAMES_ROW}\n")
        result = score_one_frame(tmp, "--methods", "conceptnet", "--conceptnet", str(path))
        named_line = gz != "corrupt gzip" and defect != "\udcff"
        assert "edge" in assert_one_line_error(result, path, len(lines) if named_line else None)
        assert not (tmp / "scores.csv").exists()
    _count("ConceptNet edges")


# --- MTurk results CSV (lmcr annotate ingest) ------------------------------------------------------

MTURK_META = ["HITId", "AssignmentId", "WorkerId", "AssignmentStatus", "WorkTimeInSeconds"]
ANSWERS = st.sampled_from(["1", "5", "0", "6", "٣", "²", "3.0", " 4", "", "x", "１"])


@FUZZ
@given(
    answers=st.lists(st.lists(ANSWERS, min_size=2, max_size=2), min_size=1, max_size=4),
    extra=st.lists(st.booleans(), min_size=4, max_size=4),
    work=st.sampled_from(["60", "²", "", "-1"]),
)
def test_mturk_results_quarantine_defects_and_balance(answers, extra, work):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        header = MTURK_META + [
            f"{f}_{k}"
            for k in (1, 2)
            for f in ("Input.verb", "Input.role1", "Input.arg1", "Input.role2", "Input.arg2", "Answer.rating")
        ]
        lines = [",".join(header)]
        for n, pair in enumerate(answers):
            cells = [f"H{n}", f"A{n}", f"W{n}", "Submitted", work]
            for k, answer in enumerate(pair):
                cells += ["pour", "Theme", "water", "Destination", ["cup", "glass"][k], answer]
            lines.append(",".join(cells) + (",surplus" if extra[n] else ""))
        path = tmp / "results.csv"
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
        result = invoke(["annotate", "ingest", str(path)], tmp)
        assert result.exit_code == 0, result.output
        con = duckdb.connect(str(tmp / "data" / "lmcr.duckdb"))
        ratings = [r for (r,) in con.execute("select rating from ratings").fetchall()]
        items_in, loaded, quarantined = con.execute(
            "select items_in, items_loaded, items_quarantined from rating_files"
        ).fetchone()
        con.close()
        assert set(ratings) <= {1, 2, 3, 4, 5} and items_in == loaded + quarantined
        good = sum(
            a.strip() in ("1", "2", "3", "4", "5") for n, pair in enumerate(answers) if not extra[n] for a in pair
        )
        assert len(ratings) == good
    _count("MTurk CSV")


def test_mturk_file_that_is_not_results_is_one_line(tmp_path):
    path = tmp_path / "r.csv"
    path.write_bytes(b"HITId,WorkerId\n\xff\xfe,1\n")
    assert_one_line_error(invoke(["annotate", "ingest", str(path)], tmp_path), path)
    assert store_snapshot(tmp_path / "data" / "lmcr.duckdb") == {}


# --- scene JSON (lmcr execute --scene) ------------------------------------------------------------

BAD_XY = st.one_of(
    st.just([float("nan"), 0.0]),
    st.just([0.0, float("inf")]),
    st.just(["0.1", 0.2]),
    st.just([0.1]),
    st.just([True, 0.0]),
    st.just({"x": 0}),
    st.just("0.1,0.2"),
    st.just([0.9, 0.0]),
)
BAD_SCENES = st.one_of(
    st.tuples(st.just("objects"), ANY_JSON.filter(lambda v: not isinstance(v, list))),
    st.tuples(st.just("object"), ANY_JSON.filter(lambda v: not isinstance(v, dict))),
    st.tuples(st.just("label"), ANY_JSON.filter(lambda v: v not in ("cup", "water"))),
    st.tuples(st.just("xy"), BAD_XY),
    st.tuples(st.just("seed"), st.one_of(st.floats(), st.text(max_size=3), st.booleans(), st.lists(st.integers()))),
    st.tuples(st.just("bytes"), st.binary(min_size=1, max_size=8).map(lambda b: b"\xc3\x28" + b)),
)


@FUZZ
@given(bad=BAD_SCENES)
def test_execute_rejects_malformed_scenes(bad):
    kind, value = bad
    scene: object = {"objects": [{"label": "cup", "xy": [0.1, 0.2]}, {"label": "water"}]}
    if kind == "objects":
        scene = {"objects": value}
    elif kind == "object":
        scene["objects"][1] = value
    elif kind == "label":
        scene["objects"][1]["label"] = value
    elif kind == "xy":
        scene["objects"][1]["xy"] = value
    elif kind == "seed":
        scene["seed"] = value
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "scene.json"
        path.write_bytes(value if kind == "bytes" else json.dumps(scene).encode())
        result = invoke(["execute", "pour me some water", "--scene", str(path), "--json"], tmp)
        assert_one_line_error(result, path)
        assert not result.stdout.strip()
    _count("scene JSON")


# --- corpus ingestion: every adapter ------------------------------------------------------------


def _ingest_and_check(tmp: Path, path: Path, flag: str, extra: list[str] = ()) -> None:
    db = tmp / "data" / "lmcr.duckdb"
    before = store_snapshot(db)
    result = invoke(["ingest", flag, str(path), "--workers", "1", *extra], tmp)
    assert "Traceback" not in result.output
    if result.exit_code == 0:
        con = duckdb.connect(str(db))
        unbalanced = con.execute(
            "select count(*) from ingested_files where records_in <> records_loaded + records_quarantined"
        ).fetchone()[0]
        con.close()
        assert unbalanced == 0
    else:
        assert_one_line_error(result, path)
        assert store_snapshot(db) == before


YOUCOOK_VALUES = st.one_of(
    ANY_JSON,
    st.just({"v1": {"annotations": [{"segment": [1, 2], "sentence": "fry the egg"}]}}),
    st.just(
        {"v1": {"annotations": [{"segment": [float("nan"), 2], "sentence": "x"}], "subset": 3, "video_url": ["u"]}}
    ),
)


@FUZZ
@given(database=YOUCOOK_VALUES, wrap=st.booleans(), garbage=st.binary(max_size=4))
def test_ingest_youcook2_never_tracebacks(database, wrap, garbage):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "yc.json"
        body = json.dumps({"database": database} if wrap else database).encode()
        path.write_bytes(body + garbage)
        _ingest_and_check(tmp, path, "--youcook2")
    _count("YouCook2 JSON")


RECIPE_LINES = st.lists(
    st.one_of(
        ANY_JSON.map(json.dumps),
        st.fixed_dictionaries({"title": ANY_JSON, "directions": ANY_JSON, "url": ANY_JSON}).map(json.dumps),
        st.just('{"title": "a\\ud800", "directions": ["fry it"]}'),
        st.text(max_size=10),
    ),
    min_size=1,
    max_size=5,
)


@FUZZ
@given(lines=RECIPE_LINES, gz=st.sampled_from(["plain", "gzip", "corrupt gzip"]))
def test_ingest_recipe_jsonl_never_tracebacks(lines, gz):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        data = ("\n".join(lines) + "\n").encode("utf-8", "surrogatepass")
        path = tmp / ("r.jsonl.gz" if gz != "plain" else "r.jsonl")
        packed = gzip.compress(data) if gz != "plain" else data
        if gz == "corrupt gzip":
            packed = packed[:12] + bytes(b ^ 0x5A for b in packed[12:30]) + packed[30:]
        path.write_bytes(packed)
        _ingest_and_check(tmp, path, "--recipes")
    _count("recipe JSONL")


@FUZZ
@given(
    body=st.binary(max_size=200),
    header=st.sampled_from([b"", b"MMMMM----- Recipe via Meal-Master\n", b"Title: Soup\n"]),
)
def test_ingest_mealmaster_never_tracebacks(body, header):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "r.mmf"
        path.write_bytes(header + body)
        _ingest_and_check(tmp, path, "--recipes")
        _ingest_and_check(tmp, path, "--recipes", ["--encoding", "no-such-codec"])
    _count("Meal-Master text")


@FUZZ
@given(inner=st.text(max_size=40), tag=st.sampled_from(["cookbook", "book", "recipe"]), garbage=st.binary(max_size=4))
def test_ingest_feeding_america_never_tracebacks(inner, tag, garbage):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "book.xml"
        path.write_bytes(
            f"<{tag}><recipe><p>".encode()
            + inner.encode("utf-8", "surrogatepass")
            + garbage
            + f"</p></recipe></{tag}>".encode()
        )
        _ingest_and_check(tmp, path, "--recipes")
    _count("Feeding America XML")


EPIC_FIELDS = st.lists(
    st.one_of(
        st.sampled_from(["P01", "P01_01", "P01_01_3", "pour water into glass", "", '"', ","]), st.text(max_size=6)
    ),
    min_size=1,
    max_size=6,
)


@FUZZ
@given(
    header=st.sampled_from(
        [b"narration_id,video_id,narration\n", b"participant_id,video_id,start_timestamp,narration\n", b"id,key\n", b""]
    ),
    rows=st.lists(EPIC_FIELDS, max_size=4),
    garbage=st.binary(max_size=4),
)
def test_ingest_epic_kitchens_never_tracebacks(header, rows, garbage):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "narrations.csv"
        body = "".join(",".join(row) + "\n" for row in rows).encode("utf-8", "surrogatepass")
        path.write_bytes(header + body + garbage)
        _ingest_and_check(tmp, path, "--household")
    _count("EPIC-KITCHENS CSV")


@FUZZ
@given(
    programs=st.one_of(
        ANY_JSON,
        st.lists(
            st.one_of(
                ANY_JSON,
                st.just("Task: Serve milk\nStep 1: Pour milk into cup"),
                st.just("Task: x\nStep 1: a\ud800"),
                st.text(max_size=20).map(lambda t: "Task: " + t),
            ),
            max_size=4,
        ),
    ),
    garbage=st.binary(max_size=3),
)
def test_ingest_virtualhome_never_tracebacks(programs, garbage):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "programs.json"
        path.write_bytes(json.dumps(programs).encode() + garbage)
        _ingest_and_check(tmp, path, "--household", ["--format", "virtualhome"])
    _count("VirtualHome JSON")


# --- the learned SRL resources the frames stage publishes, damaged -----------------------------

RESOURCE_KEYS = {
    "compounds.json": ("head_rates", "strong_bigrams", "predicative", "proper", "singular_counts"),
    "role_priors.json": ("by_verb", "pooled"),
    "first_words.json": ("heat", "pour"),
}


@FUZZ
@given(name=st.sampled_from(sorted(RESOURCE_KEYS)), data=st.data(), garbage=st.binary(max_size=3))
def test_a_damaged_srl_resource_is_one_line_naming_it(name, data, garbage):
    shaped = st.fixed_dictionaries({k: ANY_JSON for k in RESOURCE_KEYS[name]})  # the right keys, any values
    value = data.draw(st.one_of(ANY_JSON, shaped), label="content")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "srl" / name
        path.parent.mkdir()
        path.write_bytes(json.dumps(value).encode() + garbage)
        result = invoke(["srl", "pour the milk", "--resources", str(path.parent)], tmp)
        if result.exit_code != 0:  # what reads as a resource of its kind ({} for first words) may be used
            assert "cannot read the" in assert_one_line_error(result, path)
    _count(f"SRL resource {name}")


# --- batch execute: a bad line is reported in its output line, the run goes on ------------------

BAD_EXECUTE_LINES = st.one_of(
    st.binary(min_size=1, max_size=8).map(lambda b: b'{"id": "x\xff' + b.replace(b"\n", b"")),
    st.text(max_size=10).map(lambda t: ('{"id": ' + t.replace("\n", "")).encode("utf-8", "surrogatepass")),
    ANY_JSON.filter(lambda v: not isinstance(v, dict)).map(lambda v: json.dumps(v).encode()),
    st.fixed_dictionaries(
        {
            "id": st.just("s"),
            "instruction": st.just("pour me some water"),
            "scene": ANY_JSON.filter(lambda v: not isinstance(v, dict) or "objects" not in v),
        }
    ).map(lambda r: json.dumps(r).encode()),
    st.fixed_dictionaries(
        {
            "id": st.just("f"),
            "instruction": st.just("pour me some water"),
            "scene_file": st.sampled_from(["missing.json", ".", "in.jsonl"]),
        }
    ).map(lambda r: json.dumps(r).encode()),
    st.fixed_dictionaries(
        {
            "id": st.just("i"),
            "instruction": ANY_JSON.filter(lambda v: not isinstance(v, str)),
            "scene": st.just({"objects": []}),
        }
    ).map(lambda r: json.dumps(r).encode()),
)


@FUZZ
@given(lines=st.lists(BAD_EXECUTE_LINES, min_size=1, max_size=4))
def test_batch_execute_reports_every_bad_line(lines, monkeypatch):
    from lmcr.workspace import Workspace

    monkeypatch.setattr(Workspace, "completion_scorer", lambda *a: (None, None))
    monkeypatch.setattr(Workspace, "parser", lambda *a: None)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "in.jsonl").write_bytes(b"\n".join(lines) + b"\n")
        result = invoke(["execute", "--input", str(tmp / "in.jsonl"), "--output", str(tmp / "out.jsonl")], tmp)
        assert result.exit_code == 0 and "Traceback" not in result.output, result.output
        out = [json.loads(line) for line in (tmp / "out.jsonl").read_text().splitlines()]
        assert len(out) == sum(1 for line in lines if line.strip()) and all("error" in r for r in out)
    _count("execute JSONL")


def test_batch_execute_with_an_unreadable_input_is_one_line(tmp_path):
    result = invoke(["execute", "--input", str(tmp_path), "--output", str(tmp_path / "o.jsonl")], tmp_path)
    assert_one_line_error(result, tmp_path)
    assert not (tmp_path / "o.jsonl").exists()


def test_robot_turns_that_are_not_utf8_are_one_line(tmp_path):
    (tmp_path / "scene.json").write_text('{"objects": [{"label": "water", "xy": [0, 0]}]}')
    (tmp_path / "turns.txt").write_bytes(b"pour me some water\n\xff\xfe the cup\n")
    result = invoke(
        ["robot", "--scene", str(tmp_path / "scene.json"), "--turns", str(tmp_path / "turns.txt")], tmp_path
    )
    assert_one_line_error(result, tmp_path / "turns.txt")


@pytest.mark.parametrize(
    "command, flags",
    [
        ("complete", ("--input", "--output")),
        ("srl", ("--input", "--output")),
        ("execute", ("--input", "--output")),
        ("listen", ("--input", "--output")),
        ("score", ("--frames", "--out")),
    ],
)
def test_an_output_that_is_the_input_file_is_refused_and_the_input_kept(tmp_path, command, flags):
    """`--output IN.jsonl` would replace what the user gave with the result: refused before any work."""
    given = tmp_path / "in.jsonl"
    given.write_text('{"id": "a", "instruction": "pour me some water", "objects": ["cup"]}\n')
    before = given.read_bytes()
    result = invoke([command, flags[0], str(given), flags[1], str(tmp_path / "." / "in.jsonl")], tmp_path)
    assert "is the input file" in assert_one_line_error(result, given)
    assert given.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["in.jsonl"]
