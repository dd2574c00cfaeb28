"""Completion: an incomplete instruction plus the detected objects -> the completed frame.

Parse the instruction into a frame of a robot predicate; for the missing role(s), build one complete
frame per detected object (per ordered pair of objects when two roles are missing), score them all in
one batch, and turn scores into probabilities with a softmax at a temperature calibrated on the dev
ratings. When the calibrated prediction set (split conformal, see `calibrate`) holds more than one
object, or none, the result carries a clarifying `question` naming the top choices instead of a
silent guess. A complete instruction comes back unchanged. The result is a `Completion`; its `to_json`
is the CLI contract's output line.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

from lmcr.errors import LMCRError
from lmcr.files import atomic_path
from lmcr.frame import Frame
from lmcr.grounding import (
    conjoined,
    ground_roles,
    grounded,
    objects_named,
    referents,
    served_vessel,
    speaker_destination,
)
from lmcr.instances import assign_ids, ids_by_label
from lmcr.lexicon import is_object_name
from lmcr.lm.threads import request_threads
from lmcr.scorers.registry import Scorer, make_scorer, scorer_fingerprint
from lmcr.srl.context import Purpose, purpose_of, utterance_context
from lmcr.srl.instruction import read_instruction
from lmcr.srl.parser import FrameParser


class CompletionError(LMCRError, ValueError):
    """The instruction cannot be completed: no objects, or too many combinations. `frame` is the frame read
    from it ({"predicate", "roles"}, None for a role not filled) when there is one."""

    def __init__(self, message: str, frame: dict | None = None):
        super().__init__(message)
        self.frame = frame


@dataclass(frozen=True)
class CompletionConfig:
    temperature: float = 1.0
    # A candidate is in the prediction set when its probability is at least this; calibrated as
    # 1 - q, q the conformal quantile of 1 - p(right object) on dev scenarios.
    set_threshold: float = 0.5
    max_choices: int = 3  # objects a question names at most
    max_frames: int = 20_000  # ordered pairs scored when two roles are missing
    max_listed: int = 20  # candidates listed for two missing roles
    # Score the rest of the instruction with the frame ("for my tea"); chosen on the dev instructions
    # against scoring the frame alone (README, Completion).
    context: bool = True
    source: str = "default"  # where the numbers came from
    # The learned verbs' own temperature and threshold, calibrated on household requests (`lmcr evaluate
    # --requests`): the dev ratings are recipe steps of the eleven, whose calibration holds the right object
    # of a household request a quarter of the time. None: the eleven's serve for them too.
    learned_temperature: float | None = None
    learned_set_threshold: float | None = None
    learned_source: str = ""

    def to_json(self) -> dict:
        return asdict(self)

    def calibrated_for(self, learned: bool) -> CompletionConfig:
        """The temperature and threshold that hold for a predicate: a learned one's own where they were
        calibrated, else this config's."""
        if not learned or self.learned_temperature is None or self.learned_set_threshold is None:
            return self
        return replace(
            self,
            temperature=self.learned_temperature,
            set_threshold=self.learned_set_threshold,
            source=self.learned_source,
        )

    def with_learned(self, learned: CompletionConfig) -> CompletionConfig:
        """This config with `learned`'s temperature and threshold as the learned verbs' own."""
        return replace(
            self,
            learned_temperature=learned.temperature,
            learned_set_threshold=learned.set_threshold,
            learned_source=learned.source,
        )


@dataclass(frozen=True)
class Candidate:
    """One filling of the missing roles: `objects` role -> label (`object` the first missing role's), its
    score, its probability (softmax at the calibrated temperature) and the ids of the objects `object` names."""

    object: str
    objects: dict[str, str]
    score: float
    probability: float
    ids: tuple[str, ...]

    def to_json(self) -> dict:
        return {
            "object": self.object,
            "objects": dict(self.objects),
            "score": self.score,
            "probability": self.probability,
            "ids": list(self.ids),
        }


@dataclass(frozen=True)
class Completion:
    """An instruction completed: `frame` the completed frame (the chosen objects filled in), the roles that
    were missing, the roles filled from what the instruction said (`referred` pronouns, `served` vessels),
    stated words the robot could not ground (`unresolved`), detections outside the vocabulary
    (`unfamiliar_objects` scored, `ignored_objects` not), the candidates best first, the clarifying
    `question` (None when the choice is clear), the `context` scored with the frame, the ids each role's
    label stands for (`instances`) and the calibrated prediction set (`prediction_set`: one candidate's
    `object` per candidate in the set, best first; empty when nothing was missing)."""

    frame: Frame
    missing_roles: tuple[str, ...] = ()
    referred: dict[str, str] = field(default_factory=dict)
    served: dict[str, str] = field(default_factory=dict)
    unresolved: dict[str, str] = field(default_factory=dict)
    unfamiliar_objects: tuple[str, ...] = ()
    ignored_objects: tuple[str, ...] = ()
    candidates: tuple[Candidate, ...] = ()
    question: str | None = None
    context: str = ""
    instances: dict[str, list[str]] = field(default_factory=dict)
    prediction_set: tuple[str, ...] = ()

    @property
    def missing(self) -> str | None:
        """The (first) role that was missing, None for a complete instruction."""
        return self.missing_roles[0] if self.missing_roles else None

    def to_json(self) -> dict:
        """The CLI contract's output line (without the id)."""
        return {
            "frame": self.frame.to_json(),
            "missing": self.missing,
            "missing_roles": list(self.missing_roles),
            "referred": dict(self.referred),
            "served": dict(self.served),
            "unresolved": dict(self.unresolved),
            "unfamiliar_objects": list(self.unfamiliar_objects),
            "ignored_objects": list(self.ignored_objects),
            "candidates": [c.to_json() for c in self.candidates],
            "question": self.question,
            "context": self.context,
            "instances": {role: list(ids) for role, ids in self.instances.items()},
            "prediction_set": list(self.prediction_set),
        }


def softmax(scores: list[float], temperature: float) -> list[float]:
    top = max(scores)
    weights = [math.exp((s - top) / temperature) for s in scores]
    total = sum(weights)
    return [w / total for w in weights]


def _candidate_frames(
    missing: list[str], objects: list[str], open_roles: tuple[str, ...], named: dict[str, list[str]]
) -> list[dict[str, str]]:
    """One filling per object (or ordered object pair) for the missing roles; one missing role that may be
    any of `open_roles` (`_open_roles`) gets a filling per role and object. A role whose stated word names
    several objects (`named`: "the chips" with two bags) is filled with one of those."""

    def choices(role: str) -> list[str]:
        return [o for o in objects if o in named[role]] if named.get(role) else objects

    if len(missing) == 1:
        return [{role: o} for role in open_roles for o in choices(role)]
    return [{missing[0]: a, missing[1]: b} for a in choices(missing[0]) for b in choices(missing[1]) if a != b]


def _question(spec, roles: dict[str, str | None], missing: list[str], choices: list[Candidate]) -> str:
    """'Should I pour milk into the bowl, the glass or the plate?': the predicate's sentence template with
    the choices in the missing slot (one missing role, the same for every choice), or one filled template
    per choice (two roles, or choices that fill different roles: "cut bread with the knife or cut bread
    into the bowl")."""

    def either(items: list[str]) -> str:
        return ", ".join(items[:-1]) + f" or {items[-1]}" if len(items) > 1 else items[0]

    filled = [_filled(roles, c.objects) for c in choices]
    if len(missing) == 1 and all(missing[0] in c.objects for c in choices):
        role, template = missing[0], spec.template(filled[0])
        slot = template.replace(f"the {{{role}}}", f"{{{role}}}")  # each choice brings its own "the"
        return "Should I " + slot.format(**{**roles, role: either([f"the {c.objects[role]}" for c in choices])}) + "?"
    return "Should I " + either([spec.template(f).format(**f) for f in filled]) + "?"


def complete(
    parser: FrameParser,
    scorer: Scorer,
    instruction: str,
    objects: list[str],
    config: CompletionConfig = CompletionConfig(),
    ids: list[str] | None = None,
    held: tuple[str, ...] = (),
) -> Completion:
    """The completion of one instruction (`Completion.to_json` is the CLI contract's output line without the
    id); the scorer also reads the rest of the instruction (`context`: "for my tea") when the config says so.
    `held`: the labels of what the robot holds, which a stated word grounds in ("stir the batter with the
    whisk" in the hand) but which never fill a missing role.

    Objects are scored by label: several objects with one label (three cups) are one candidate, whose
    `ids` list them (`ids`: the objects' ids, in order; assigned as a scene assigns them when not given),
    and `instances` lists the ids each role's label stands for; which one to act on is the executor's choice."""
    frame, doc = read_instruction(parser, instruction)
    labels = [" ".join(o.split()).lower() for o in objects]
    kept = [k for k, o in enumerate(objects) if o and o.strip()]
    every_id = ids or assign_ids(labels)  # once: per object it made a completion quadratic in the objects
    ids_of = ids_by_label([labels[k] for k in kept], [every_id[k] for k in kept])
    detected = list(ids_of)
    pronouns = parser.lex.object_pronouns
    # "I'd love some wine, could you pour it?": the wine; "bring me the soap": to the person who asks
    referred = referents(parser, doc, frame, detected) | speaker_destination(parser, doc, frame, detected)
    # "pour me a glass of water": the person asked for the glass as well as the water
    served = served_vessel(parser, doc, frame, detected, referred)
    # "pour it": who knows what, unless "it" points back to an object named before ("some wine")
    roles = {r: referred.get(r) or served.get(r) or (None if v in pronouns else v) for r, v in frame.roles.items()}
    # A stated word grounds in any detection: the person named it ("season the cucumbers" with a
    # cucumber seen), so it is no choice of ours even when the robot has no vocabulary for it.
    vocabulary = (*parser.lex.objects, *held) if parser.lex.objects else ()
    roles, unresolved = ground_roles(roles, vocabulary, detected, instruction, frame.spans)
    # A stated word the robot cannot ground still says what is meant ("pour milk in my coffee", no coffee
    # seen: the mug): its phrase is read as context, as the rest of the utterance is.
    context = utterance_context(doc, frame, said=frozenset(unresolved)) if config.context else ""
    stated = {v for v in roles.values() if v}
    # A detection outside the robot's object vocabulary ("salsa" typed to `lmcr complete`) is scored like
    # any other, as the corpora know it (a word they never saw scores low), but never chosen silently;
    # one that names nothing (emoji, digits, a paragraph, only function words) is ignored.
    outside = [o for o in detected if parser.lex.objects and o not in parser.lex.objects and o not in stated]
    ignored = [o for o in outside if not is_object_name(o)]
    read = Completion(
        Frame.of(frame.predicate, {}),
        referred=referred,
        served=served,
        unresolved=unresolved,
        unfamiliar_objects=tuple(o for o in outside if o not in ignored),
        ignored_objects=tuple(ignored),
        context=context,
    )
    # The roles nothing was said for come first: a stated word the robot could not ground ("dispose of the
    # empty bottle") still says the role, so the robot picks what it names but the role was not missing.
    missing = sorted((r for r, v in roles.items() if v is None), key=lambda r: r in unresolved)
    if not missing:
        return replace(read, frame=Frame.of(frame.predicate, roles), instances=_instances(roles, ids_of))
    spec = parser.lex.predicates[frame.predicate]
    config = config.calibrated_for(frame.predicate in parser.lex.learned)
    # "hand me something to cut the bread with": the thing is also scored as what it is for (cut bread with
    # it), and what the purpose states (the bread) is not the thing, as what the request states is not
    purpose = purpose_of(doc, frame, parser.lex, parser.compounds) if "Theme" in missing else None
    for_purpose = {grounded(v, set(detected)) for v in purpose.roles.values()} if purpose else set()
    # "mix the flour and sugar": the sugar is mixed too, not what it is mixed with
    free = [o for o in detected if o not in stated | for_purpose | conjoined(doc, frame, detected)]
    # "can I have the cup?" with nobody and nothing else seen: the error says who is not there
    unseen = _unseen({r: w for r, w in unresolved.items() if r in missing}, {}, parser.lex.person_words)
    pool = _pool(frame.predicate, roles, missing, free, ignored, config, unseen)
    named = {r: objects_named(word, pool) for r, word in unresolved.items()}
    fillings = _candidate_frames(missing, pool, _open_roles(spec, missing, unresolved), named)
    scores = _scores(scorer, [Frame.of(frame.predicate, _filled(roles, f)) for f in fillings], fillings, context)
    if len(missing) == 1 and spec.alternatives:  # which role was left open: as often as it is stated
        scores = [s + spec.open_role_prior(next(iter(f))) for s, f in zip(scores, fillings)]
    if purpose is not None and all("Theme" in f for f in fillings):
        scores = [s + p for s, p in zip(scores, _purpose_scores(scorer, purpose, fillings))]
    probs = softmax(scores, config.temperature)
    ranked = sorted(zip(fillings, scores, probs), key=lambda x: -x[1])
    candidates = tuple(
        Candidate(_first(f), f, round(s, 4), round(p, 4), tuple(ids_of[_first(f)]))
        for f, s, p in ranked[: len(ranked) if len(missing) == 1 else config.max_listed]
    )
    chosen = _filled(roles, candidates[0].objects)
    in_set = [c for c in candidates if c.probability >= config.set_threshold]
    # the roles the objects chose, nothing said for them first (`missing`'s order), unless words were said for all
    missing = [r for r in candidates[0].objects if r not in unresolved] or list(candidates[0].objects)
    return replace(
        read,
        frame=Frame.of(frame.predicate, chosen),
        missing_roles=tuple(missing),
        candidates=candidates,
        question=_ask(
            spec,
            roles,
            list(candidates[0].objects),
            read,
            candidates,
            in_set,
            config.max_choices,
            named,
            parser.lex.person_words,  # "bring it to her" with no one seen
        ),
        instances=_instances(chosen, ids_of),
        prediction_set=tuple(c.object for c in in_set),
    )


@request_threads()  # one request's few texts: on the idle cores only (`lmcr.lm.threads`)
def _purpose_scores(scorer: Scorer, purpose: Purpose, fillings: list[dict[str, str]]) -> list[float]:
    """Each filling's Theme scored as the thing its purpose frame needs ("cut bread with the knife"); the
    purpose is that frame, so it is no context of it."""
    frames = [Frame.of(purpose.predicate, {**purpose.roles, purpose.gap: f["Theme"]}) for f in fillings]
    return list(scorer(frames, ""))


@request_threads()  # one request's few texts: on the idle cores only (`lmcr.lm.threads`)
def _scores(scorer: Scorer, frames: list[Frame], fillings: list[dict[str, str]], context: str) -> list[float]:
    """The frames' scores. Where the fillings span several open roles and the scorer has terms that only
    rank fillers within a role (`SummedScorer.with_roles`), each role's best scores as it does without
    them and its fillers keep their order with them: the roles compete as without the terms."""
    by_role = [next(iter(f)) for f in fillings]
    if not getattr(scorer, "has_within_role", False) or len(set(by_role)) < 2:
        return scorer(frames, context)
    full, without = scorer.with_roles(frames, context)
    best: dict[str, float] = {}
    best_without: dict[str, float] = {}
    for role, score, rest in zip(by_role, full, without):
        best[role] = max(best.get(role, -math.inf), score)
        best_without[role] = max(best_without.get(role, -math.inf), rest)
    return [score - best[role] + best_without[role] for role, score in zip(by_role, full)]


def _open_roles(spec, missing: list[str], unresolved: dict[str, str]) -> tuple[str, ...]:
    """The roles one missing role may be: a learned predicate's open roles when its second role is the
    missing one ("cut the bread": into the bowl, or with the knife), else just that role; also just that
    role when a word was said for it that grounds in no one object ("put the cup in the drawer" with two
    drawers: a drawer, not something to put it with)."""
    if len(missing) == 1 and spec.alternatives and missing[0] == spec.roles[1] and missing[0] not in unresolved:
        return spec.open_roles
    return tuple(missing)


def _filled(roles: dict[str, str | None], filling: dict[str, str]) -> dict[str, str]:
    """The roles with a filling, in the frame's order: an alternative open role stands in the place of the
    missing role it replaces ("cut the bread": Theme, then Instrument instead of Destination)."""
    rest, out = dict(filling), {}
    for role, value in roles.items():
        if value is not None:
            out[role] = value
        elif rest:
            chosen = role if role in rest else next(iter(rest))
            out[chosen] = rest.pop(chosen)
    return out


def _first(filling: dict[str, str]) -> str:
    return next(iter(filling.values()))


def _pool(
    predicate: str,
    roles: dict[str, str | None],
    missing: list[str],
    unstated: list[str],
    ignored: list[str],
    config: CompletionConfig,
    unseen: str = "",
) -> list[str]:
    """The objects the missing roles may be filled with (the unstated detections that name an object), or
    CompletionError when there are too few of them (saying first what was named but not seen: `unseen`,
    "I see no one here.") or they give too many combinations to score."""
    pool = [o for o in unstated if o not in ignored]
    if len(pool) < len(missing):
        stated = sorted({v for v in roles.values() if v})
        shown = [repr(o if len(o) <= 30 else o[:27] + "...") for o in ignored[:3]]  # the error stays one short line
        unnamed = f" ({', '.join(shown)}{', ...' if len(ignored) > 3 else ''}: no object name)" if ignored else ""
        raise CompletionError(
            f"cannot fill {', '.join(missing)} of {predicate!r}: {unseen.rstrip('.') + '; ' if unseen else ''}"
            f"{'no usable objects' if not pool else 'too few usable objects'} besides "
            f"{stated or 'none'}{unnamed}",
            {"predicate": predicate, "roles": roles},
        )
    combinations = len(pool) if len(missing) == 1 else len(pool) * (len(pool) - 1)
    if combinations > config.max_frames:
        raise CompletionError(
            f"{len(pool)} objects give {combinations:,} combinations for {missing}; the limit is {config.max_frames:,}",
            {"predicate": predicate, "roles": roles},
        )
    return pool


def _ask(
    spec,
    roles: dict[str, str | None],
    missing: list[str],
    read: Completion,
    candidates: tuple[Candidate, ...],
    in_set: list[Candidate],
    max_choices: int,
    named: dict[str, list[str]],
    people: frozenset[str] = frozenset(),
) -> str | None:
    """The clarifying question, or None when the choice is clear: asked when the prediction set `in_set`
    holds more or fewer than one candidate (and there was a choice), and always when the best candidate
    stands for a word the robot could not ground (`read.unresolved`) or names an object outside its
    vocabulary, however likely."""
    confirm = read.unresolved or any(o in read.unfamiliar_objects for o in candidates[0].objects.values())
    if not (len(in_set) != 1 and len(candidates) > 1 or confirm):
        return None
    # One likely object is confirmed alone, unless it stands for a word we replaced: then offer others.
    one = len(in_set) == 1 and not read.unresolved
    choices = (in_set if len(in_set) > 1 or one else list(candidates))[: max(max_choices, 2)]
    question = _question(spec, roles, missing, choices)
    if read.unresolved:
        return f"{_unseen(read.unresolved, named, people)} {question}"
    return question


def _unseen(unresolved: dict[str, str], named: dict[str, list[str]], people: frozenset[str] = frozenset()) -> str:
    """What the robot says of the words it could not ground: "I see no side.", "I see no one here." for a
    word that names a person (`people`: "bring it to her" with nobody in the scene), or, for a word whose
    head names several of the objects (`named`: "the chips" with two bags), "I see more than one chip." """
    several = [w for r, w in unresolved.items() if named.get(r)]
    unseen = [w for r, w in unresolved.items() if not named.get(r) and w not in people]
    said = [f"I see no {' or '.join(unseen)}."] if unseen else []
    said += ["I see no one here."] if any(w in people for w in unresolved.values()) else []
    return " ".join(said + ([f"I see more than one {' or '.join(several)}."] if several else []))


def _instances(roles: dict[str, str | None], ids_of: dict[str, list[str]]) -> dict[str, list[str]]:
    """role -> the ids of the objects its label stands for (empty for one not among the objects)."""
    return {role: ids_of.get(value, []) if value else [] for role, value in roles.items()}


def calibrate(
    positive_first: list[list[float]], alpha: float = 0.1, source: str = "", what: str = "dev scenarios"
) -> CompletionConfig:
    """Temperature and prediction-set threshold from dev scenarios, each a list of scores with the
    right (positive) candidate first.

    The temperature minimises the mean negative log-likelihood of the right candidate (grid over
    0.01..100, log-spaced). The threshold is split-conformal: with nonconformity 1 - p(right), q is
    the ceil((n + 1)(1 - alpha))/n empirical quantile, so the set {p >= 1 - q} holds the right object
    with probability >= 1 - alpha on exchangeable data."""
    if not positive_first:
        raise CompletionError("calibration needs at least one scenario (the ratings give none)")
    grid = [10 ** (e / 20) for e in range(-40, 41)]

    def nll(t: float) -> float:
        return -sum(math.log(max(softmax(s, t)[0], 1e-300)) for s in positive_first) / len(positive_first)

    temperature = min(grid, key=nll)
    scores = sorted(1 - softmax(s, temperature)[0] for s in positive_first)
    n = len(scores)
    rank = min(n, math.ceil((n + 1) * (1 - alpha)))
    q = scores[rank - 1]
    return CompletionConfig(
        temperature=temperature,
        set_threshold=max(1 - q, 1e-6),
        source=source or f"calibrated on {n} {what} (alpha={alpha:g}, NLL {nll(temperature):.3f})",
    )


def save_config(config: CompletionConfig, path: Path, fingerprint: str | None) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps({**config.to_json(), "fingerprint": fingerprint}, indent=2), encoding="utf-8")


def load_config(path: Path, fingerprint: str | None) -> CompletionConfig | None:
    """The saved calibration when it was made for this fingerprint (the scorer's checkpoints and
    corpus, see `scorers.registry.scorer_fingerprint`), else None."""
    if not Path(path).exists():
        return None
    data = json.loads(Path(path).read_text(encoding="utf-8"))
    if data.pop("fingerprint", None) != fingerprint:
        return None
    return CompletionConfig(**data)


def calibration_file(method: str, res, calibration_dir: Path) -> tuple[Path, str | None]:
    """Where a method's completion calibration lives (what `lmcr evaluate` writes and `lmcr complete`
    reads), and the fingerprint it must carry; None for a method that is not calibrated."""
    # Named by the fingerprint too, so the calibration of a retrain candidate can be written before it
    # is promoted without disturbing the one the current checkpoint uses.
    fingerprint = scorer_fingerprint(method, res)
    tag = hashlib.sha256(fingerprint.encode()).hexdigest()[:12] if fingerprint else "none"
    return calibration_dir / f"{method}-{res.corpus}-{tag}.json", fingerprint


def requests_calibration_file(path: Path) -> Path:
    """Where the learned verbs' calibration on household requests lives beside a method's (`calibration_file`)."""
    return path.with_name(f"{path.stem}-requests{path.suffix}")


def completion_scorer(method: str, res, calibration_dir: Path) -> tuple[Scorer, CompletionConfig]:
    """The scorer of `method` and the completion settings `lmcr evaluate` calibrated for exactly what it
    is built from (its fingerprint), with the learned verbs' own when it calibrated them on requests too;
    uncalibrated defaults when there are none."""
    scorer = make_scorer(method, res)
    path, fingerprint = calibration_file(method, res, calibration_dir)
    config = load_config(path, fingerprint) if fingerprint else None
    if config is None:
        return scorer, CompletionConfig(source="uncalibrated defaults (run `lmcr evaluate`)")
    learned = load_config(requests_calibration_file(path), fingerprint)
    return scorer, config.with_learned(learned) if learned else config
