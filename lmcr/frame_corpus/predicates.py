"""Predicates learned from the frame corpus: every verb and phrasal verb ("put away", "dispose of") the
corpora use often enough, with its roles, the prepositions that introduce each, how often each is stated
(its valence) and the sentence the sentence LM scores for it.

The frame build parses every verb: a verb outside the hand-written lexicon gets a generic frame whose
slots are its direct object and its prepositional phrases, named by the preposition ("put the milk away
in the fridge": predicate `put away`, slots object=milk, in=fridge). Learning turns slots into roles:

- English decides which roles a preposition can introduce (`PREP_ROLES`: "with" an Instrument, "into" a
  Destination, "in" either; "of" the Theme of a prepositional verb, "dispose of it"). That is grammar,
  the same for every verb, not knowledge of objects.
- The corpus decides among them, and whether the slot holds things at all: a slot's fillers are compared
  (cosine of filler counts) with the fillers the eleven robot predicates' roles take in the same corpus.
  "reheat in the microwave" reads like heat's Instrument, "put in the bowl" like pour's Destination. Only fillers
  that role takes count as things: "cut into cubes" names none and is no role here, and "bring to a boil"
  does not make a boil a place things are brought to. A with-phrase is an Instrument whatever it holds
  (the eleven's Instruments are no tools, so a knife would not count).
- A slot whose fillers are like neither role's (cosine under `PROTOTYPE_BELOW`) is read as the prototype
  of the verb's class of motion reads it: the eleven's places are mostly bowls and their Instruments
  mostly skillets, so "bake in the oven" is like neither, and "cook in the pot" says it is an Instrument.
- A phrasal verb's counts are smoothed towards its base verb's (`PHRASAL_PRIOR` frames of it), so "put
  away", seldom said with its place, still knows that putting has a Destination.

A predicate's roles are the Theme and its most often stated other role (its valence: what a request leaves
missing when unsaid); every other role of `OPEN_ROLES` stated in `MIN_RATE` of its frames is an alternative
open role with its own sentence, and completion lets the objects choose among them. A verb with fewer than
`MIN_FRAMES` frames, or none of whose open roles is stated in `MIN_RATE` of them, is not learned; it is
listed with its evidence so that a request using it is refused by name. The hand-written predicates keep
their entries (the lexicon overrides the learned table).

The table is a resource of the frame build: `predicates.json` beside the other learned SRL resources, and
the store's `learned_predicates` / `learned_predicate_slots` (which the count model reads through the
`robot_fillers` view).
"""

from __future__ import annotations

import json
import math
from collections import Counter, defaultdict
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import duckdb

from lmcr.files import atomic_path
from lmcr.lexicon import PREDICATES_FILE, PREP_ROLES, Lexicon

VERSION = 4  # 2: each predicate's class of motion; 3: the cook class; 4: unclear slots read as the prototype's
OBJECT_SLOT = "Theme"  # the generic frame's direct object
MIN_FRAMES = 20  # frames a verb needs before it is learned
MIN_RATE = 0.02  # how often its best role must be stated
# frames' worth of evidence a second open role needs to compete with the first: a role stated in a
# handful of a rare verb's frames is likelier a misparse than a reading ("dispose" states an Instrument
# in 3 of 66 frames, and chose an orange as what to dispose of the chips with; docs/guide/frames.md)
MIN_ALTERNATIVE_FRAMES = 10
MIN_SHARE = 0.2  # share of a slot's fillers that must be things (robot-role fillers) for it to fill a role
MIN_POOL = 2  # times a word fills a robot role before it counts as a thing
PHRASAL_PRIOR = 50.0  # frames' worth of the base verb's rates a phrasal verb starts from
TOP_FILLERS = 300  # fillers per slot compared (the rest carry little of a cosine)
REFUSED_LISTED = 5  # frames a refused verb needs to be listed with its evidence
# The robot's classes of motion, each named by its own verb (the prototype): a learned verb's class is the
# prototype its fillers are most like (`lmcr.robot.tasks.task_for` gives each class its motion; a class
# also keeps verbs apart: "cut the bread into the bowl" is not read as placing it).
MOTION_CLASSES = {
    "place": "put",
    "cut": "cut",
    "stir": "stir",
    "wipe": "wipe",
    "cover": "cover",
    "serve": "scoop",
    "cook": "cook",
}
# A slot English lets introduce two roles whose fillers are this little like either role's (cosine) is read
# as its class's prototype reads it (`_as_prototype`); chosen among 0.1, 0.2 and 0.3 on the external
# request sets (docs/guide/frames.md): 0.2 and 0.3 gave the same, 0.1 lost one right role.
PROTOTYPE_BELOW = 0.3
CLASS_ROLES = ("Theme", "Destination", "Instrument")  # whose fillers are compared, each role alike
OPEN_ROLES = ("Destination", "Instrument")  # the roles a request can leave for the robot to choose
# prepositions that can introduce the Theme of a prepositional verb ("of")
THEME_PREPS = tuple(prep for prep, roles in PREP_ROLES.items() if roles == ("Theme",))
PREP_THEME_RATIO = 0.5  # ... when the verb has them at least this often per direct object


@dataclass(frozen=True)
class LearnedPredicate:
    """One learned predicate: its name ("put away"), base verb and particle, evidence, role rates, which
    slot fills each role, and the spec the parser and the scorers use."""

    name: str
    base: str
    particle: str | None
    frames: int
    rates: dict[str, float]  # role -> share of frames stating it (smoothed for phrasal verbs)
    slots: dict[str, str]  # slot (Theme, or a preposition) -> role
    roles: tuple[str, str]
    theme_prep: str | None  # "of" for a prepositional verb ("dispose of")
    sentence: str
    # other roles a request may leave missing instead (stated often enough too): role -> its sentence;
    # completion lets the objects decide ("cut the bread": with the knife, or into the bowl)
    alternatives: dict[str, str] = field(default_factory=dict)
    motion: str | None = None  # its class of motion (`MOTION_CLASSES`), None when no prototype is learned

    def spec_json(self) -> dict:
        """The entry in the lexicon's own format (`lexicon.json`), with the other open roles' sentences."""
        roles = [self.roles[1], *self.alternatives]
        preps = {role: sorted((s for s, r in self.slots.items() if r == role and s != OBJECT_SLOT)) for role in roles}
        if self.theme_prep:
            preps["Theme"] = [self.theme_prep]
        return {
            "roles": list(self.roles),
            "object": "Theme",
            "with": self.slots.get("with") if self.slots.get("with") in roles else None,
            "preps": preps,
            "particles": [self.particle] if self.particle else [],
            "sentence": self.sentence,
            "alternatives": dict(self.alternatives),
            "rates": {role: self.rates.get(role, 0.0) for role in roles},
            "motion": self.motion,
        }


@dataclass
class LearnedTable:
    """The learned predicates and the verbs refused for too little evidence (name -> frames)."""

    predicates: dict[str, LearnedPredicate] = field(default_factory=dict)
    refused: dict[str, int] = field(default_factory=dict)
    settings: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {
            "version": VERSION,
            "settings": self.settings,
            "predicates": {
                name: {**asdict(p), **{"spec": p.spec_json()}} for name, p in sorted(self.predicates.items())
            },
            "refused": dict(sorted(self.refused.items())),
        }

    def save(self, path: Path) -> None:
        with atomic_path(path) as tmp:
            tmp.write_text(json.dumps(self.to_json(), indent=1), encoding="utf-8")


def _cosine(a: Counter, b: Counter) -> float:
    dot = sum(n * b[k] for k, n in a.items() if k in b)
    norm = math.sqrt(sum(n * n for n in a.values())) * math.sqrt(sum(n * n for n in b.values()))
    return dot / norm if norm else 0.0


def _slot_counts(con: duckdb.DuckDBPyConnection) -> tuple[Counter, dict[tuple[str, str], Counter], Counter]:
    """Frames per generic predicate; the top fillers of each of its slots that English lets name a role; and
    how many frames state each such slot, over all its fillers (one scan of the frames for both)."""
    frames = Counter(dict(con.execute("select predicate, count(*) from frames where not known group by 1").fetchall()))
    rows = con.execute(
        """
        with filled as (
            select f.predicate, r.role as slot, r.value, count(*) as n
            from frames f join frame_roles r using (corpus, doc_id, sent_id, frame_no)
            where not f.known and r.value is not null and r.role in (select unnest($slots))
            group by all
        )
        select predicate, slot, value, n, sum(n) over (partition by predicate, slot) as total from filled
        qualify row_number() over (partition by predicate, slot order by n desc, value) <= $top
        """,
        {"slots": [OBJECT_SLOT, *PREP_ROLES], "top": TOP_FILLERS},
    ).fetchall()
    fillers: dict[tuple[str, str], Counter] = defaultdict(Counter)
    totals: Counter = Counter()
    for predicate, slot, value, n, total in rows:
        fillers[(predicate, slot)][value] = n
        totals[(predicate, slot)] = int(total)
    return frames, fillers, totals


def _role_pools(con: duckdb.DuckDBPyConnection) -> dict[str, Counter]:
    """What each role of the robot predicates is filled with in the corpus ('any': every role)."""
    pools: dict[str, Counter] = defaultdict(Counter)
    for role, value, n in con.execute(
        "select r.role, r.value, count(*) from frames f join frame_roles r using (corpus, doc_id, sent_id, frame_no)"
        " where f.known and r.value is not null group by all"
    ).fetchall():
        pools[role][value] += n
        pools["any"][value] += n
    return pools


def _label(
    slot: str, fillers: Counter, total: int, pools: dict[str, Counter], min_share: float
) -> tuple[str, float, float]:
    """The role a slot fills, how many of its frames name a thing in it, and how like that role's fillers
    its fillers are: the object is the Theme; a preposition's candidate roles (`PREP_ROLES`) are decided by
    whose fillers it shares (cosine), and only fillers that role takes in the robot frames count as things
    ("cut into cubes" names none). A slot whose things are under `min_share` of it fills no role ("", 0)."""
    if slot == OBJECT_SLOT or slot in THEME_PREPS:  # an of-phrase's being the Theme's: the verb's evidence
        return "Theme", float(total), 1.0
    candidates = PREP_ROLES[slot]
    if candidates == ("Instrument",):  # "with": English leaves no other role; tools the eleven never use count
        return "Instrument", float(total), 1.0
    likeness = {r: _cosine(fillers, pools[r]) for r in candidates}
    role = max(candidates, key=lambda r: (likeness[r], -candidates.index(r)))
    return (*_things(role, fillers, total, pools, min_share), likeness[role])


def _things(role: str, fillers: Counter, total: int, pools: dict[str, Counter], min_share: float) -> tuple[str, float]:
    """(role, frames naming a thing the role takes) for a slot read as `role`; ("", 0) under `min_share`."""
    things = sum(n for value, n in fillers.items() if pools[role][value] >= MIN_POOL)
    return (role, float(things)) if total and things / total >= min_share else ("", 0.0)


def _split(name: str) -> tuple[str, str | None]:
    base, _, particle = name.partition(" ")
    return base, particle or None


def learn_predicates(
    con: duckdb.DuckDBPyConnection,
    lex: Lexicon,
    min_frames: int = MIN_FRAMES,
    min_rate: float = MIN_RATE,
    min_share: float = MIN_SHARE,
    min_alternative_frames: float = MIN_ALTERNATIVE_FRAMES,
) -> LearnedTable:
    """The learned table of the store's frame corpus (see the module's docstring). Its classes of motion
    come from the slots as the fillers read them; slots that read like neither role are then read as their
    class's prototype reads them, and the table is learned again from those."""
    frames, fillers, totals = _slot_counts(con)
    pools = _role_pools(con)
    labelled = {key: _label(key[1], counter, totals[key], pools, min_share) for key, counter in fillers.items()}
    settings = {
        "min_frames": min_frames,
        "min_rate": min_rate,
        "min_share": min_share,
        "phrasal_prior": PHRASAL_PRIOR,
        "min_alternative_frames": min_alternative_frames,
        "prototype_below": PROTOTYPE_BELOW,
    }
    motions = motion_classes(_table(frames, labelled, totals, lex, settings).predicates, fillers)
    labelled = _as_prototype(labelled, motions, fillers, totals, pools, min_share)
    table = _table(frames, labelled, totals, lex, settings)
    for name, predicate in table.predicates.items():
        table.predicates[name] = replace(predicate, motion=motions.get(name))
    return table


def _as_prototype(
    labelled: dict, motions: dict[str, str], fillers: dict, totals: Counter, pools: dict[str, Counter], min_share: float
) -> dict:
    """The slots English lets introduce two roles whose fillers are under PROTOTYPE_BELOW like either
    role's, read as the prototype of the verb's class reads the same preposition. The eleven robot
    predicates' places are mostly bowls and pans, so a slot of ovens is like neither role ("bake in the
    oven": cosine 0.08 with the places, 0.01 with the Instruments, which are mostly skillets) and the
    larger of two small numbers decided it; "cook in the pot" says what a verb of the cook class does."""
    out = dict(labelled)
    for (name, slot), (role, _, likeness) in labelled.items():
        proto = MOTION_CLASSES.get(motions.get(name, ""))
        if proto in (None, name) or len(PREP_ROLES.get(slot, ())) < 2 or likeness >= PROTOTYPE_BELOW:
            continue
        proto_role = labelled.get((proto, slot), ("",))[0]
        if proto_role and proto_role != role:
            key = (name, slot)
            out[key] = (*_things(proto_role, fillers[key], totals[key], pools, min_share), 0.0)
    return out


def _table(frames: Counter, labelled: dict, totals: Counter, lex: Lexicon, settings: dict) -> LearnedTable:
    """The predicates (without classes) and refused verbs of the slots as `labelled` reads them."""
    slots_of: dict[str, dict[str, str]] = defaultdict(dict)
    raw_rates: dict[str, Counter] = defaultdict(Counter)
    for (predicate, slot), (role, things, _) in labelled.items():
        if role:
            slots_of[predicate][slot] = role
            if frames[predicate]:
                raw_rates[predicate][role] += things / frames[predicate]
    table = LearnedTable(settings=dict(settings))
    for name, n in frames.items():
        base, particle = _split(name)
        if name in lex.predicates or base in lex.predicates:
            continue  # the hand-written lexicon wins
        base_rates = raw_rates.get(base) if particle else None
        rates = _smoothed(raw_rates[name], n, base_rates)
        # the frames' worth behind the rates (a phrasal verb's include its base verb's prior): at least 1
        worth = n + (PHRASAL_PRIOR if base_rates is not None else 0.0)
        slots = dict(sorted(slots_of[name].items()))
        alternative_rate = settings["min_alternative_frames"] / worth
        learned = _predicate(name, n, rates, slots, totals, settings["min_rate"], alternative_rate)
        if n >= settings["min_frames"] and learned is not None:
            table.predicates[name] = learned
        elif n >= REFUSED_LISTED:
            table.refused[name] = n
    return table


def motion_classes(predicates: dict[str, LearnedPredicate], fillers: dict[tuple[str, str], Counter]) -> dict[str, str]:
    """Each learned predicate's class of motion: the class whose prototype verb (`MOTION_CLASSES`) its
    fillers are most like, by the mean over `CLASS_ROLES` of the cosine of their PPMI-weighted filler
    vectors (a role's fillers pooled over the slots that fill it; PPMI against every learned predicate's
    fillers of that role). A prototype is its own class; classes whose prototype was not learned do not
    compete."""
    blocks = {(name, role): _role_fillers(p, role, fillers) for name, p in predicates.items() for role in CLASS_ROLES}
    totals = {role: Counter() for role in CLASS_ROLES}
    for (_, role), counts in blocks.items():
        totals[role].update(counts)
    vectors = {key: _ppmi(counts, totals[key[1]]) for key, counts in blocks.items()}
    prototypes = {cls: verb for cls, verb in MOTION_CLASSES.items() if verb in predicates}

    def likeness(name: str, verb: str) -> float:
        return sum(_cosine(vectors[(name, r)], vectors[(verb, r)]) for r in CLASS_ROLES) / len(CLASS_ROLES)

    if not prototypes:
        return {}
    return {name: max(prototypes, key=lambda c: (likeness(name, prototypes[c]), c)) for name in predicates}


def _role_fillers(p: LearnedPredicate, role: str, fillers: dict[tuple[str, str], Counter]) -> Counter:
    found: Counter = Counter()
    for slot, filled in p.slots.items():
        if filled == role:
            found.update(fillers.get((p.name, slot), {}))
    return found


def _ppmi(counts: Counter, total: Counter) -> Counter:
    """Positive pointwise mutual information of each filler with the verb, against all verbs' fillers."""
    n, grand = sum(counts.values()), sum(total.values())
    weights = Counter({f: math.log((k / n) / (total[f] / grand)) for f, k in counts.items()}) if n else Counter()
    return Counter({f: w for f, w in weights.items() if w > 0})


def _smoothed(own: Counter, n: int, base: Counter | None) -> dict[str, float]:
    """A verb's role rates; a phrasal verb's pulled towards its base verb's by PHRASAL_PRIOR frames."""
    if base is None:
        return dict(own)
    roles = set(own) | set(base)
    return {r: (own[r] * n + base[r] * PHRASAL_PRIOR) / (n + PHRASAL_PRIOR) for r in roles}


def _predicate(
    name: str,
    n: int,
    rates: dict[str, float],
    slots: dict[str, str],
    totals: Counter,
    min_rate: float,
    min_alternative_rate: float,
) -> LearnedPredicate | None:
    """The predicate of a verb's evidence, or None when no role a request can leave missing is stated often
    enough: a role is open at `min_rate`, a second one at `min_alternative_rate` besides
    (MIN_ALTERNATIVE_FRAMES over the frames' worth behind the rates)."""
    base, particle = _split(name)
    open_roles = sorted((r for r in OPEN_ROLES if rates.get(r, 0.0) >= min_rate), key=lambda r: -rates[r])
    open_roles = open_roles[:1] + [r for r in open_roles[1:] if rates[r] >= min_alternative_rate]
    if not open_roles:
        return None
    # A prepositional verb: its "of" phrase, about as usual as a direct object, is the Theme ("dispose of
    # it"); elsewhere an of-phrase belongs to a measure the parser hung on the verb ("a pot of water").
    theme_prep = next(
        (p for p in THEME_PREPS if totals[(name, p)] >= PREP_THEME_RATIO * totals[(name, OBJECT_SLOT)]), None
    )
    slots = {s: r for s, r in slots.items() if s not in THEME_PREPS or s == theme_prep}
    theme = f"{theme_prep} {{Theme}}" if theme_prep else "{Theme}"
    middle = f" {particle}" if particle else ""
    templates = {}
    for role in open_roles:
        preps = sorted((s for s, r in slots.items() if r == role), key=lambda s: -totals[(name, s)])
        prep = preps[0] if preps else next(p for p in PREP_ROLES if role in PREP_ROLES[p])  # from the base verb
        templates[role] = (
            f"{base}{middle} {theme} {prep} the {{{role}}}"
            if theme_prep
            else f"{base} {theme}{middle} {prep} the {{{role}}}"
        )
    return LearnedPredicate(
        name=name,
        base=base,
        particle=particle,
        frames=n,
        rates={r: round(v, 4) for r, v in sorted(rates.items())},
        slots=dict(sorted(slots.items())),
        roles=("Theme", open_roles[0]),
        theme_prep=theme_prep,
        sentence=templates[open_roles[0]],
        alternatives={r: templates[r] for r in open_roles[1:]},
    )


def publish_predicates(con: duckdb.DuckDBPyConnection, table: LearnedTable, path: Path, build: str) -> None:
    """The learned table into the store (one transaction: the tables and the count view change together)
    and `path` (written under a temporary name, then renamed)."""
    from lmcr.store import transaction

    with transaction(con):
        con.execute("delete from learned_predicate_slots")
        con.execute("delete from learned_predicates")
        rows = [
            (
                p.name,
                p.base,
                p.particle,
                p.frames,
                *p.roles,
                p.rates.get(p.roles[1], 0.0),
                p.theme_prep,
                p.sentence,
                build,
            )
            for p in table.predicates.values()
        ]
        slots = [
            (p.name, s, r)
            for p in table.predicates.values()
            for s, r in p.slots.items()
            if r in (*p.roles, *p.alternatives)
        ]
        if rows:  # DuckDB's executemany refuses an empty list
            con.executemany("insert into learned_predicates values (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)", rows)
        if slots:
            con.executemany("insert into learned_predicate_slots values (?, ?, ?)", slots)
    table.settings["build"] = build
    table.save(path)


def learned_build(path: Path) -> str | None:
    """The frame build a saved table was learned from (None when there is none, or of another version)."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data.get("settings", {}).get("build") if data.get("version") == VERSION else None


def refresh_predicates(
    con: duckdb.DuckDBPyConnection, lex: Lexicon, srl_dir: Path, build: str | None, force: bool = False
) -> LearnedTable | None:
    """Learn and publish the table when the frame build `build` has none yet (or `force`); None when it
    was up to date or there is no build."""
    path = srl_dir / PREDICATES_FILE
    if build is None or not force and learned_build(path) == build:
        return None
    table = learn_predicates(con, lex)
    publish_predicates(con, table, path, build)
    return table
