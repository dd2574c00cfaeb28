"""One evaluation run: score the rated frames with every method and LM setting, sweep, calibrate the
completion of the LM methods, and write the report."""

from __future__ import annotations

import time
from collections.abc import Callable, Collection
from dataclasses import replace
from pathlib import Path

from lmcr.complete import CompletionConfig, calibrate, calibration_file, save_config
from lmcr.errors import LMCRError, one_line
from lmcr.evaluate import provenance
from lmcr.evaluate.paper import read_paper_table
from lmcr.evaluate.protocol import EvalConfig, Results, evaluate, score_rated
from lmcr.evaluate.ratings import RatedFrame
from lmcr.evaluate.report import write_report
from lmcr.evaluate.scenarios import build_scenarios
from lmcr.scorers.lm_checkpoints import lm_experts, lm_version_dir
from lmcr.scorers.mixture import Mixture
from lmcr.scorers.rarity import WEIGHT
from lmcr.scorers.registry import COMPLETION_METHOD, make_scorer
from lmcr.scorers.resources import MethodResources, MethodUnavailable
from lmcr.scorers.similar_verbs import NEIGHBOURS
from lmcr.setting import ALL_SETTINGS, LM_METHODS, Setting

SETTINGS = tuple(s.label for s in ALL_SETTINGS)
DEVIATIONS = [
    "Corpora: the shared web recipes and Feeding America stand in for 'Now You're Cooking!' (not available); "
    "YouCook2 is the real annotation set.",
    "cooccur, word2vec and conceptnet add the verb-first-argument term to the paper's two terms; it is the "
    "same for every candidate of a scenario, so rankings are the paper's whichever role varies.",
    "word2vec: the paper's pretrained GloVe 6B 50-d (400k words) when the `vectors` extra is installed, else "
    "skip-gram word2vec trained with gensim on our corpora (a vector file can be given); a term with no known "
    "word is at distance 1.0 (unrelated).",
    "conceptnet: the API is unreachable offline; relatedness is the cosine of PPMI+SVD embeddings of the "
    "cn100k edge list (Numberbatch's starting point), or of a Numberbatch file. conceptnet_retrofit: the same "
    "word vectors as word2vec retrofitted to the cn100k edges (Faruqui et al. 2015, how Numberbatch is built), "
    "the closest stand-in for the API's relatedness offline.",
    "Corpus mixture: the household narrations (EPIC-KITCHENS, VirtualHome) are about 1% of the text; "
    "'@household=w' makes them count w times in the pooled setting (frame counts weighted, the LMs "
    "interpolated with the household LM at its share of the weighted words), w chosen on the rated frames "
    "(and dev instructions, with the context term's weight) by `lmcr mixture`; a bare method name uses the "
    "chosen mixture (see provenance).",
    "The paper: Chen, Tan, Kuntz, Bansal, Alterovitz, Enabling Robots to Understand Incomplete Natural "
    "Language Instructions Using Commonsense Reasoning, ICRA 2020. Its Table I is read from its LaTeX source "
    "when one is given (--paper or $LMCR_PAPER); its ratings are not ours, so its figures are a reference, "
    "not a like-for-like comparison.",
    "frame_counts is not in the paper: smoothed counts of the SRL frames of the robot predicates, "
    "log P(a2 | v, a1) + log P(a1 | v, a2) (lmcr/scorers/frame_counts.py). "
    "similar_verbs is not in the paper either: the same "
    f"two conditionals from the pair counts of the {NEIGHBOURS} verbs whose fillers are most like the predicate's "
    "(similarity-based smoothing, lmcr/scorers/similar_verbs.py). 'a+b' sums two methods' log-probabilities "
    f"(a product of experts); rarity is the term -{WEIGHT:g} log P(fillers) from the fillers' corpus frequencies "
    "(lmcr/scorers/rarity.py: the score less how common the words are anyway, a PMI); context_pmi is the term "
    "that weighs what an instruction's purpose says of each filler, learned from the sentences that name "
    "both (lmcr/scorers/context_pmi.py), 0 on the rated "
    "frames, which have no context; "
    f"{COMPLETION_METHOD} is what `lmcr complete` uses by default.",
]


def named_method(name: str, res: MethodResources) -> tuple[str, MethodResources]:
    """'sentence_lm/youcook2' -> the method and the resources of that corpus; 'frame_counts@household=30'
    -> under that corpus mixture ('@plain': none); a bare name keeps `res`'s."""
    name, at, mixture = name.partition("@")
    method, _, corpus = name.partition("/")
    named = replace(res, corpus=corpus or res.corpus)
    return method, replace(named, mixture=Mixture.parse(mixture)) if at else named


def build_scorers(
    names: list[str], res: MethodResources, log: Callable[[str], None], optional: Collection[str] = ()
) -> tuple[dict, list[str]]:
    """Scorers by name ('sentence_lm', 'sentence_lm/youcook2', 'cooccur', ...). A name in `optional` (a
    default the user did not ask for) that cannot be built is skipped with a note; any other name that
    cannot be built is a MethodUnavailable error: a requested method is never silently left out."""
    scorers, notes = {}, []
    for name in names:
        try:
            scorers[name] = make_scorer(*named_method(name, res))
        except (LMCRError, ValueError, OSError) as exc:  # LMCR's own errors, a missing or unreadable file
            if name not in optional:
                raise MethodUnavailable(f"method {name}: cannot be built: {one_line(exc)}") from exc
            notes.append(f"{name} not evaluated: {one_line(exc)}")
            log(notes[-1])
    return scorers, notes


def calibrate_completion(
    rated: list[RatedFrame],
    scores: dict,
    methods: list[str],
    res: MethodResources,
    config: EvalConfig,
    out_dir: Path,
    log: Callable[[str], None],
) -> dict[str, tuple[Path, str, CompletionConfig]]:
    """Completion temperature and conformal threshold of each calibrated method (LMs, frame_counts and
    their sums), from the headline scenarios; saved, and returned as method -> (file, fingerprint,
    calibration)."""
    scenarios, _ = build_scenarios(rated, config.lam, config.k, config.per_verb, config.seed)
    saved = {}
    for method in (m for m in methods if m in scores):
        path, fingerprint = calibration_file(method, res, out_dir)
        if fingerprint is None:
            continue
        cal = calibrate([[scores[method][f.key] for f in sc.candidates] for sc in scenarios])
        save_config(cal, path, fingerprint)
        saved[method] = (path, fingerprint, cal)
        log(calibration_note(method, cal))
    return saved


def calibration_note(method: str, cal: CompletionConfig) -> str:
    return (
        f"{method} completion calibration: temperature {cal.temperature:.3g}, prediction-set "
        f"threshold p >= {cal.set_threshold:.3f} ({cal.source})"
    )


def evaluated_checkpoints(names: list[str], res: MethodResources) -> dict[str, Path]:
    """LM setting ('sentence-all') -> the checkpoint version folder each evaluated name uses."""
    found = {}
    for name in names:
        method, named = named_method(name, res)
        for part in (p for p in method.split("+") if p in LM_METHODS):
            for corpus, _ in lm_experts(named):
                found[Setting(LM_METHODS[part], corpus).name] = lm_version_dir(named, LM_METHODS[part], corpus)
    return found


def run_evaluation(
    rated: list[RatedFrame],
    res: MethodResources,
    methods: list[str],
    settings: list[str],
    config: EvalConfig,
    out_dir: Path,
    calibration_dir: Path | None = None,
    log: Callable[[str], None] = print,
    ratings_source: Path | None = None,
    paper: Path | None = None,
    optional: Collection[str] = (),
) -> Results:
    """Score, sweep, calibrate and write the report; `ratings_source` (CSV or store) goes into its
    provenance and `paper` (the paper's LaTeX source) gives its published Table I columns. Methods and
    settings in `optional` (defaults, not asked for) may be skipped with a note; the others must build."""
    started = time.perf_counter()
    published = read_paper_table(paper) if paper else {}  # a bad file fails before the scoring
    scorers, notes = build_scorers(list(dict.fromkeys(methods + settings)), res, log, optional)
    scores = {}
    for name, fn in scorers.items():
        t = time.perf_counter()
        scores.update(score_rated(rated, {name: fn}))
        log(f"scored {len(rated):,} rated frames with {name} in {time.perf_counter() - t:.1f}s")
    results = evaluate(rated, scores, config)
    if calibration_dir is not None:
        saved = calibrate_completion(rated, scores, methods, res, config, calibration_dir, log)
        notes += [calibration_note(method, cal) for method, (_, _, cal) in saved.items()]
    if published:
        notes.append(
            "The paper's Fig. 4 (accuracy against lambda and k) is drawn without its values in the LaTeX "
            "source, so only Table I is set beside ours; our Fig. 4 has no paper series."
        )
    notes += DEVIATIONS + [f"{len(rated):,} rated frames; evaluation took {time.perf_counter() - started:.0f}s."]
    evaluated = [m for m in methods if m in scores], [s for s in settings if s in scores]
    origin = (
        {
            **provenance.collect(ratings_source, res.db, evaluated_checkpoints(evaluated[0] + evaluated[1], res)),
            "mixture": res.mixture.label,
            "context_weight": res.context_weight,
        }
        if ratings_source is not None
        else {}
    )
    write_report(results, *evaluated, out_dir, notes, origin, published)
    return results
