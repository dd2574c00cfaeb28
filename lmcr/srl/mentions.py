"""Verb frames from a dependency parse: the 11 robot predicates with their two roles, generic frames
(object and prepositional arguments) for every other verb."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from spacy.tokens import Doc, Span, Token

from lmcr.lexicon import Lexicon, PredicateSpec
from lmcr.srl.arguments import argument_value, misread_name_end, noun_gerund, resolve_head
from lmcr.srl.compounds import Compounds
from lmcr.srl.lemmas import lemma as lemma_of

OBJECT_DEPS = frozenset({"dobj", "obj", "nsubjpass"})
NOT_PREDICATE_DEPS = frozenset({"amod", "compound", "aux", "auxpass", "nmod"})
# determiners that open a thing's noun phrase ("the bread", "some bread"); not "another", "every", "each",
# which open spans of time ("bake another 10 minutes")
THING_DETERMINERS = frozenset({"the", "a", "an", "some", "this", "that", "these", "those"})
NOUN_CLAUSE_DEPS = frozenset({"relcl", "acl"})  # a clause that modifies a noun ("something to drink from")
SKIPPED_LEMMAS = frozenset({"be", "have", "do", "let", "go", "will", "would", "can", "could", "should"})
# forms of "be" the lemmatiser leaves as they are when the tagger misreads them
BE_FORMS = frozenset({"is", "are", "was", "were", "am", "been", "being"})
PREP_DEPS = frozenset({"prep", "advmod", "prt", "agent", "dative"})
# Adverbs that complete a phrasal verb where the parser calls them adverbs ("put the milk away"); the
# parser's own particles (dep prt) count whatever the word. English's closed class, not a verb list.
ADVERB_PARTICLES = frozenset({"away", "back", "aside", "out", "up", "down", "off"})
# Prepositions English also uses as particles ("stir in the sugar", "put on the lid"); "into" never is.
PREP_PARTICLES = frozenset({"in", "on", "over", "off", "through", "around", "along", "about"})
# English idioms of a light verb and a participle that take their object through a preposition ("get rid
# of the peel"): the participle -> its verb. The pair names the predicate ("get rid", as "dispose" is named
# without its "of") and the participle's phrases are its roles. The parser reads the participle as the
# root with the verb its passive auxiliary ("get/auxpass rid/ROOT of it") or as the verb's adjectival
# complement ("get/ROOT rid/acomp of it"); either way the verb alone is no frame ("get" the milk).
LIGHT_VERB_IDIOMS = {"rid": "get"}
IDIOM_DEPS = frozenset({"acomp", "oprd", "xcomp", "ccomp", "dobj"})
# Where only a noun can stand: a word tagged as a verb there is a noun the tagger misread.
NOUN_DEPS = frozenset({"dobj", "pobj", "nsubjpass", "attr", "appos"})
# Tags of a noun phrase's words (POS: the possessive 's), and those a particle is tagged with; tags, since
# the parser's pipeline leaves out the coarse parts of speech.
NOMINAL_TAGS = frozenset({"DT", "PDT", "JJ", "JJR", "JJS", "NN", "NNS", "NNP", "NNPS", "CD", "POS", "PRP", "PRP$"})
PARTICLE_TAGS = frozenset({"RB", "RP", "IN"})


@dataclass
class FrameMention:
    """One predicate occurrence: roles map to values (None when not expressed), spans to char offsets."""

    predicate: str
    roles: dict[str, str | None]
    known: bool
    start: int
    end: int
    spans: dict[str, tuple[int, int]] = field(default_factory=dict)
    # Set when a lone object of an alternating verb got its role by default ("rub the steak").
    ambiguous_object: str | None = None
    # Said to the robot: an imperative or "can you ...", not "I drank it" or "the one was eaten".
    addressed: bool = True
    # "stir in the sugar": the same words read as a learned phrasal verb and its object ("stir in", Theme
    # sugar) instead of the verb and a phrase ("stir", Destination sugar); the corpus decides which
    # (`RolePriors.resolve`), and without its counts the phrase stands.
    particle_reading: FrameMention | None = None
    # Said not to be done: "don't pour the milk", "never put the knife in the dishwasher".
    negated: bool = False
    # A clause that says what a thing is or is for ("something to pour the water into": pour), no request.
    describes: bool = False

    def missing(self) -> list[str]:
        return [role for role, value in self.roles.items() if value is None]

    def to_json(self) -> dict:
        return {"predicate": self.predicate, "roles": dict(self.roles)}

    def shifted(self, offset: int) -> FrameMention:
        """The same frame with character offsets moved (for text that was re-parsed with a prefix)."""
        spans = {r: (s + offset, e + offset) for r, (s, e) in self.spans.items()}
        reading = self.particle_reading.shifted(offset) if self.particle_reading else None
        return replace(self, start=self.start + offset, end=self.end + offset, spans=spans, particle_reading=reading)


@dataclass
class _Args:
    objects: list[Token]
    preps: list[tuple[str, Token]]
    particles: list[str]


def idiom_verb(token: Token) -> Token | None:
    """The light verb of an idiom whose participle `token` is ("rid" in "get rid of it": the "get"), or None."""
    verb = LIGHT_VERB_IDIOMS.get(token.lower_)
    if verb is None:
        return None
    paired = [c for c in token.children if c.dep_ in ("auxpass", "aux") and c.i < token.i]
    if token.dep_ in IDIOM_DEPS and token.head.i < token.i:
        paired.append(token.head)
    return next((t for t in paired if lemma_of(t) == verb or t.lower_ == verb), None)


def _idiom_participle(token: Token) -> Token | None:
    """The idiom participle `token` is the light verb of ("get" in "get rid of it"), or None."""
    return next(
        (c for c in token.children if c.i > token.i and (v := idiom_verb(c)) is not None and v.i == token.i), None
    )


def predicate_lemma(token: Token, lex: Lexicon) -> str | None:
    """The predicate a verb token evokes, or None if it is no predicate (aux, adjective, noun, copula). An
    idiom's participle evokes the idiom ("rid" in "get rid of it": "get rid"), its light verb none."""
    if (verb := idiom_verb(token)) is not None:
        return f"{lemma_of(verb) or verb.lower_} {token.lower_}"
    if _idiom_participle(token) is not None:
        return None
    if not token.tag_.startswith("VB") or token.dep_ in NOT_PREDICATE_DEPS or not token.is_alpha:
        return None
    if _misread_noun(token):
        return None
    lemma = lemma_of(token)
    if lemma not in lex.predicates and token.lower_ in lex.predicates:
        lemma = token.lower_  # the lemmatiser follows the tagger, which mis-tags imperatives
    return None if lemma in SKIPPED_LEMMAS or lemma in BE_FORMS else lemma


def _is_particle(token: Token) -> bool:
    return token.dep_ == "prt" or token.dep_ == "advmod" and token.lower_ in ADVERB_PARTICLES


def _misread_noun(token: Token) -> bool:
    """A word tagged as a verb where only a noun can stand: an argument ("put the dish rack/VB/dobj away")
    or the gerund that ends a name ("the steak seasoning")."""
    return token.tag_.startswith("VB") and (token.dep_ in NOUN_DEPS or noun_gerund(token))


def _particle(verb: Token) -> str | None:
    """The particle of a phrasal verb: the parser's (dep prt) or an adverb of the closed class after the
    verb ("put the milk away"); also one the parser hung on a noun it read as a verb inside the object
    ("put the steak seasoning away", "put the dish rack away")."""
    for child in verb.children:
        if child.i > verb.i and _is_particle(child):
            return child.lower_
    for obj in (c for c in verb.children if c.dep_ in OBJECT_DEPS):
        for token in obj.subtree:
            if token.head.i != verb.i and _misread_noun(token.head) and _is_particle(token):
                return token.lower_
    return _after_object(verb)


def _after_object(verb: Token) -> str | None:
    """A closed-class particle right after the noun phrase that follows the verb, wherever the parser hung
    it: "put the teddy bear away" with bear read as a verb of its own clause, "put the bay leaves away"
    with put the subject of leaves. Inside the phrase a word tagged as a verb counts as a noun when a noun
    or the particle follows it (the head noun misread, "the granite cutting board")."""
    doc, i = verb.doc, verb.i + 1
    while i < len(doc) and (
        doc[i].tag_ in NOMINAL_TAGS
        or i > verb.i + 1
        and doc[i].tag_.startswith("VB")
        and i + 1 < len(doc)
        and (doc[i + 1].tag_.startswith("NN") or doc[i + 1].lower_ in ADVERB_PARTICLES)
    ):
        i += 1
    if i > verb.i + 1 and i < len(doc) and doc[i].lower_ in ADVERB_PARTICLES and doc[i].tag_ in PARTICLE_TAGS:
        return doc[i].lower_
    return None


def predicate_name(verb: Token, lemma: str, lex: Lexicon) -> tuple[str, PredicateSpec | None]:
    """The predicate a verb names with its particle ("put away") and its spec: a hand-written predicate
    ignores particles (its own are part of its spec); a phrasal verb the lexicon lacks falls back to its
    verb's spec ("whisk in the sugar": whisk; "clean up", seen in 15 frames: clean), unless the corpora
    refused it for what its frames say ("pick up", 5,493 frames that state no place or tool, is no picking
    to be placed somewhere: it is refused by name); a verb with no spec keeps its phrasal name (a generic
    frame of the corpus)."""
    if lemma in lex.predicates and lemma not in lex.learned:
        return lemma, lex.predicates[lemma]
    particle = _particle(verb)
    name = f"{lemma} {particle}" if particle else lemma
    if particle and lex.refused.get(name, 0) >= max(lex.min_frames, 1) and name not in lex.predicates:
        return name, None
    spec = lex.predicates.get(name) or lex.predicates.get(lemma)
    return (spec.name if spec else name), spec


def _pobj(prep: Token) -> Token | None:
    """The object of a preposition; a bare gerund counts ("with frosting"), a clause does not."""
    for child in prep.children:
        if child.dep_ == "pobj" or child.dep_ == "pcomp" and not any(g.dep_ in OBJECT_DEPS for g in child.children):
            return child
    return None


def _measured(token: Token, lex: Lexicon) -> bool:
    """A quantity or measure noun with an of-phrase ("a couple of eggs"), whatever the parser called it."""
    return (lemma_of(token) in lex.quantity_nouns or lemma_of(token) in lex.measure_nouns) and any(
        c.dep_ == "prep" and c.lower_ == "of" for c in token.children
    )


def _object_after_particle(verb: Token) -> list[Token]:
    """The noun phrase right after the verb's particle, when the parser hung it on the verb as an adverbial
    and it opens as a thing's does ("fry up some bacon", "top off my glass"; not "stir up every minute")."""
    prt = next((c for c in verb.children if c.dep_ == "prt"), None)
    if prt is None:
        return []
    return [
        c
        for c in verb.children
        if c.dep_ == "npadvmod"
        and c.left_edge.i == prt.i + 1
        and (c.left_edge.lower_ in THING_DETERMINERS or c.left_edge.tag_ == "PRP$")
    ][:1]


def _attached_preps(token: Token, skip: frozenset[str]) -> list[tuple[str, Token]]:
    """PPs the parser hung on `token` rather than on the verb, other than `skip` ("of" of a measure)."""
    return [
        (c.lower_, p)
        for c in token.children
        if c.dep_ == "prep" and c.lower_ not in skip and (p := _pobj(c)) is not None
    ]


def _collect(verb: Token, lex: Lexicon, spec: PredicateSpec | None) -> _Args:  # noqa: C901 - one rule per way the parser attaches arguments
    # an idiom's passive-looking subject is its subject ("I got rid of the peel"): its object is the of-phrase
    objects = [c for c in verb.children if c.dep_ in OBJECT_DEPS and not (c.dep_ == "nsubjpass" and idiom_verb(verb))]
    if not objects and any(c.dep_ == "dative" for c in verb.children):
        objects = [c for c in verb.children if c.dep_ == "npadvmod" and c.i > verb.i]  # "fry me an egg"
    if not objects:  # "fry a couple of eggs": the quantity read as an adverbial noun phrase
        objects = [c for c in verb.children if c.dep_ == "npadvmod" and c.i > verb.i and _measured(c, lex)][:1]
    if not objects:  # "fry up some bacon", "top off my glass": the object read as an adverbial after the particle
        objects = _object_after_particle(verb)
    if len(objects) > 1:  # "fry me an egg" parsed as two objects: the recipient is not the theme
        objects = [o for o in objects if o.lower_ not in lex.recipient_pronouns] or objects[:1]
    preps: list[tuple[str, Token]] = []
    particles: list[str] = []
    for child in verb.children:
        if child.dep_ not in PREP_DEPS or child.dep_ == "dative" and child.tag_ == "PRP":
            continue
        obj = _pobj(child) if child.dep_ != "prt" else None
        if obj is not None:
            preps.append((child.lower_, obj))
        elif child.dep_ == "prt" or child.lower_ in (spec.particles if spec else ()):
            particles.append(child.lower_)
    # "sprinkle over the salad": the parser's particle is this verb's role preposition, not a particle; a
    # learned verb's particle stays one ("bring over the salt": its Destination prepositions are many)
    if spec and objects and particles and spec.name not in lex.learned:
        prt = next((c for c in verb.children if c.dep_ == "prt"), None)
        if (
            prt is not None
            and prt.lower_ not in spec.particles
            and spec.prep_role(prt.lower_)
            and prt.i == verb.i + 1
            and objects[0].i > prt.i
        ):
            preps.insert(0, (prt.lower_, objects.pop(0)))
            particles.remove(prt.lower_)
    # "I want the steak seasoned": a participle's object may stand elsewhere.
    understood = _understood_object(verb, lex) if not objects else []
    # "pour in the milk": a particle right after the verb whose "object" is really the verb's object;
    # not when the object stands elsewhere ("some cheese sprinkled on my pasta": a role's preposition).
    if spec and not objects and not understood and preps:
        prep, obj = preps[0]
        if prep in spec.particles and obj.head.i == verb.i + 1:
            objects, preps, particles = [obj], preps[1:], particles + [prep]
    # PPs the parser hung on the object ("heat some oil in the wok", "pour some of the sauce over the
    # meatballs": on the of-object) still belong to the verb.
    for obj in objects:
        head = resolve_head(obj, lex) or obj
        if head.i == obj.i:
            preps += _attached_preps(obj, frozenset())
        else:  # a measure's "of" leads to the head, whose own PPs count too
            preps += _attached_preps(obj, frozenset({"of"})) + _attached_preps(head, frozenset())
    objects = objects or understood
    # A PP hung on the object of another PP ("for five minutes in the butter", "with a ladle over the
    # pasta", "on both sides in hot oil") belongs to the verb too; which one names a role is decided
    # by how usual its preposition is (`_known_frame`).
    if spec:
        preps += [more for _, obj in list(preps) for more in _attached_preps(obj, frozenset({"of"}))]
    return _Args(objects, preps, particles)


def _is_person(token: Token, lex: Lexicon) -> bool:
    return token.tag_ == "PRP" and token.lower_ not in lex.object_pronouns


def _understood_object(verb: Token, lex: Lexicon) -> list[Token]:
    """The object of a participle that has none after it, where the syntax puts it elsewhere:
    - the subject of a participle clause ("I want the steak seasoned", "get the chicken fried", "once
      the oil has heated"): a past participle's subject undergoes it, unless it is a person ("I have
      fried", "we fried");
    - the noun a participle describes ("the steak seasoned with salt", "the fish fried in butter");
    - the subject that controls a subjectless passive ("the chicken needs to be fried") or, when there
      is one, the object ("I want the chicken to be fried" read as want + chicken + to be fried);
    - the object of the participle it is coordinated with ("the chicken is seasoned and fried",
      "2 potatoes, peeled and chopped").
    - the subject of the verb a gerund complements ("the chicken needs frying", "the soup wants
      heating up"): an object-less gerund after a thing is done to it, as a passive would be.
    The small tagger reads a participle after its subject as a past tense ("want the steak seasoned/VBD"),
    so a past tense in a complement clause counts too."""
    if any(c.dep_ in OBJECT_DEPS or c.dep_ == "expl" for c in verb.children):
        return []
    if verb.tag_ == "VBG" and verb.dep_ == "xcomp":
        subject = next((c for c in verb.head.children if c.dep_ == "nsubj"), None)
        return [] if subject is None or _is_person(subject, lex) else [subject]
    if not (verb.tag_ == "VBN" or verb.tag_ == "VBD" and verb.dep_ in ("ccomp", "xcomp", "oprd")):
        return []
    subject = next((c for c in verb.children if c.dep_ == "nsubj"), None)
    if subject is not None:
        return [] if _is_person(subject, lex) else [subject]
    if verb.dep_ == "conj" and verb.head.tag_ == "VBN":  # the first participle's object is shared
        return [c for c in verb.head.children if c.dep_ in OBJECT_DEPS][:1] or _understood_object(verb.head, lex)
    if verb.dep_ == "acl" and verb.head.i < verb.i and verb.head.tag_.startswith("NN"):
        return [verb.head]
    if verb.dep_ == "xcomp" and any(c.dep_ == "auxpass" for c in verb.children):
        controller = next((c for dep in ("dobj", "nsubj") for c in verb.head.children if c.dep_ == dep), None)
        return [] if controller is None or _is_person(controller, lex) else [controller]
    return []


def _right_node_object(verb: Token) -> list[Token]:
    """'heat and stir the milk': an object-less verb shares the object of the verb coordinated right after it."""
    for conj in verb.children:
        if conj.dep_ == "conj" and conj.i == verb.i + 2 and verb.doc[verb.i + 1].dep_ == "cc":
            return [c for c in conj.children if c.dep_ in OBJECT_DEPS]
    return []


def _known_frame(
    verb: Token, spec: PredicateSpec, args: _Args, lex: Lexicon, compounds: Compounds | None
) -> FrameMention:
    roles = spec.roles_for(prep for prep, _ in args.preps)  # "cut the bread with a knife": its Instrument
    frame = FrameMention(spec.name, {role: None for role in roles}, True, verb.idx, verb.idx + len(verb))

    def fill(role: str, token: Token) -> bool:
        found = argument_value(token, lex, compounds)
        if found is None or frame.roles[role] is not None:
            return False
        frame.roles[role], frame.spans[role] = found[0], found[1:]
        return True

    # Two phrases for one role: the more usual preposition names it, then the first in the text.
    for prep, obj in sorted(args.preps, key=lambda p: (spec.prep_rank(p[0]), p[1].i)):
        role = spec.prep_role(prep)
        if role in frame.roles:
            fill(role, obj)
    if args.objects:
        obj = args.objects[0]
        other = {roles[0]: roles[1], roles[1]: roles[0]}  # the frame's roles: an alternative's may differ
        role = spec.object_role if frame.roles[spec.object_role] is None else other[spec.object_role]
        if fill(role, obj) and spec.alternating and not args.particles and frame.roles[other[role]] is None:
            frame.ambiguous_object = role
    return frame


def _generic_frame(verb: Token, lemma: str, args: _Args, lex: Lexicon, compounds: Compounds | None) -> FrameMention:
    frame = FrameMention(lemma, {}, False, verb.idx, verb.idx + len(verb))
    for role, token in ([("Theme", args.objects[0])] if args.objects else []) + args.preps:
        found = argument_value(token, lex, compounds)
        if found and role not in frame.roles:
            frame.roles[role], frame.spans[role] = found[0], found[1:]
    return frame


def _addressed(verb: Token) -> bool:
    """Whether the verb is said to the robot: no subject of its own (an imperative, or one coordinated
    with it) or "you" ("can you dispose of it"), not "I drank it" or "the crispy one was eaten"; nor a
    clause that says what a thing is for ("hand me something to cut the bread with": cut)."""
    if verb.dep_ in NOUN_CLAUSE_DEPS:
        return False
    light = idiom_verb(verb)
    if light is not None and light.i == verb.head.i:  # "I got rid of it": the light verb's subject
        verb = light
    subjects = [c for c in verb.children if c.dep_ in ("nsubj", "nsubjpass")]
    return all(c.lower_ == "you" for c in subjects)


def is_negated(verb: Token) -> bool:
    """Whether the verb (or an idiom's light verb: "don't get rid of it") is negated: "don't", "do not",
    "never"."""
    return any(c.dep_ == "neg" for v in (verb, idiom_verb(verb)) if v is not None for c in v.children)


def extract_frames(doc: Doc | Span, lex: Lexicon, compounds: Compounds | None = None) -> list[FrameMention]:
    """Every predicate occurrence in `doc`, in text order; `compounds` (learned) decides adjective-tagged
    modifiers, without it only noun-tagged modifiers join a name."""
    frames = []
    for token in doc:
        lemma = predicate_lemma(token, lex)
        if lemma is None or misread_name_end(token, compounds):
            continue
        name, spec = predicate_name(token, lemma, lex)
        args = _collect(token, lex, spec)
        if not args.objects and not args.preps:
            args.objects = _right_node_object(token)
        frame = (
            _known_frame(token, spec, args, lex, compounds)
            if spec
            else _generic_frame(token, name, args, lex, compounds)
        )
        frame.addressed = _addressed(token)
        frame.negated = is_negated(token)
        frame.describes = token.dep_ in NOUN_CLAUSE_DEPS
        if (reading := _particle_reading(token, lemma, name, args, lex)) is not None:
            frame.particle_reading = replace(_known_frame(token, *reading, lex, compounds), addressed=frame.addressed)
        frames.append(frame)
    return sorted(frames, key=lambda f: f.start)


def _particle_reading(verb: Token, lemma: str, name: str, args: _Args, lex: Lexicon) -> tuple | None:
    """The predicate and arguments a learned verb with no object may be read as when its first phrase
    follows it at once, its preposition a particle and its noun the object ("stir in the sugar": "stir in",
    the sugar its object, as "pour in the milk"; "whisk in the eggs": whisk, the phrasal verb not learned);
    None for any other verb."""
    if name not in lex.learned or args.objects or not args.preps:
        return None
    prep, obj = args.preps[0]
    if obj.head.i != verb.i + 1 or prep not in PREP_PARTICLES:
        return None
    phrasal = lex.predicates.get(f"{lemma} {prep}")
    spec = phrasal if phrasal is not None and phrasal.name in lex.learned else lex.predicates[name]
    return spec, _Args([obj], args.preps[1:], [*args.particles, prep])
