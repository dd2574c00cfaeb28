"""Frame rules on hand-built parses (no spaCy model needed)."""

from __future__ import annotations

from collections import Counter

import pytest

from lmcr.lexicon import load_lexicon
from lmcr.srl.compounds import Compounds
from lmcr.srl.mentions import extract_frames
from lmcr.srl.parser import _object_lost, find_split, needs_reparse
from lmcr.srl.priors import RolePriors
from tests.srl_docs import make_doc

LEX = load_lexicon()


def frames(spec: str, compounds: Compounds | None = None):
    return [(f.predicate, f.roles) for f in extract_frames(make_doc(spec), LEX, compounds)]


def test_dative_is_not_a_role():
    doc = "pour/VB/ROOT/0 me/PRP/dative/0 some/DT/det/3 water/NN/dobj/0"
    assert frames(doc) == [("pour", {"Theme": "water", "Destination": None})]


def test_double_object_misparse_keeps_the_theme():
    doc = "fry/VB/ROOT/0 me/PRP/dative/0 an/DT/det/3 egg/NN/npadvmod/0"
    assert frames(doc) == [("fry", {"Theme": "egg", "Instrument": None})]


def test_with_alternation_gives_the_same_frame():
    with_phrase = "brush/VB/ROOT/0 the/DT/det/2 bread/NN/dobj/0 with/IN/prep/0 oil/NN/pobj/3"
    on_phrase = "brush/VB/ROOT/0 oil/NN/dobj/0 on/IN/prep/0 the/DT/det/4 bread/NN/pobj/2"
    expected = [("brush", {"Theme": "oil", "Destination": "bread"})]
    assert frames(with_phrase) == frames(on_phrase) == expected


def test_fill_and_season_with_phrases():
    assert frames("fill/VB/ROOT/0 the/DT/det/2 glass/NN/dobj/0 with/IN/prep/0 ice/NN/pobj/3") == [
        ("fill", {"Destination": "glass", "Theme": "ice"})
    ]
    assert frames("fill/VB/ROOT/0 water/NN/dobj/0 into/IN/prep/0 the/DT/det/4 pot/NN/pobj/2") == [
        ("fill", {"Destination": "pot", "Theme": "water"})
    ]
    assert frames("season/VB/ROOT/0 with/IN/prep/0 salt/NN/pobj/1") == [
        ("season", {"Theme": None, "Instrument": "salt"})
    ]


def test_particles_are_not_destinations():
    assert frames("pour/VB/ROOT/0 in/IN/prep/0 the/DT/det/3 milk/NN/pobj/1") == [
        ("pour", {"Theme": "milk", "Destination": None})
    ]
    assert frames("dip/VB/ROOT/0 it/PRP/dobj/0 in/RP/prt/0") == [("dip", {"Theme": "it", "Destination": None})]
    # ...but a role preposition the parser called a particle still introduces its role
    assert frames("sprinkle/VB/ROOT/0 over/RP/prt/0 the/DT/det/3 salad/NN/dobj/0") == [
        ("sprinkle", {"Theme": None, "Destination": "salad"})
    ]
    # and an instrument verb's "in" is never a particle
    assert frames("fry/VB/ROOT/0 in/IN/prep/0 a/DT/det/4 hot/JJ/amod/4 skillet/NN/pobj/1") == [
        ("fry", {"Theme": None, "Instrument": "skillet"})
    ]


def test_coordination():
    # "heat and stir the milk": the object-less first verb shares the next verb's object
    assert frames("heat/VB/ROOT/0 and/CC/cc/0 stir/VB/conj/0 the/DT/det/4 milk/NN/dobj/2")[0] == (
        "heat",
        {"Theme": "milk", "Instrument": None},
    )
    # coordinated objects: the first conjunct fills the role
    doc = (
        "pour/VB/ROOT/0 the/DT/det/2 milk/NN/dobj/0 and/CC/cc/2 the/DT/det/5 cream/NN/conj/2 "
        "into/IN/prep/0 the/DT/det/8 pot/NN/pobj/6"
    )
    assert frames(doc) == [("pour", {"Theme": "milk", "Destination": "pot"})]


def test_argument_values():
    doc = (
        "heat/VB/ROOT/0 3/CD/nummod/2 tablespoons/NNS/dobj/0/tablespoon of/IN/prep/2 olive/NN/compound/5 "
        "oil/NN/pobj/3 in/IN/prep/0 a/DT/det/9 large/JJ/amod/9 skillet/NN/pobj/6"
    )
    assert frames(doc) == [("heat", {"Theme": "olive oil", "Instrument": "skillet"})]
    # measure nouns stand alone without an of-phrase, quantity words do not
    assert frames("fill/VB/ROOT/0 each/DT/det/2 cup/NN/dobj/0") == [("fill", {"Destination": "cup", "Theme": None})]
    assert frames("dip/VB/ROOT/0 a/DT/det/2 few/JJ/dobj/0 in/IN/prep/0 the/DT/det/5 chocolate/NN/pobj/3") == [
        ("dip", {"Theme": None, "Destination": "chocolate"})
    ]
    # a number gives way to its of-phrase too, and names nothing alone
    assert frames("sprinkle/VB/ROOT/0 3/CD/dobj/0 of/IN/prep/1 the/DT/det/4 pepper/NN/pobj/2 over/RP/prt/0") == [
        ("sprinkle", {"Theme": "pepper", "Destination": None})
    ]
    assert frames("heat/VB/ROOT/0 350/CD/dobj/0") == [("heat", {"Theme": None, "Instrument": None})]
    # adjectives and determiners go, plurals become singular, noun-tagged modifiers stay
    doc = (
        "pour/VB/ROOT/0 the/DT/det/3 melted/JJ/amod/3 chocolate/NN/dobj/0 into/IN/prep/0 "
        "the/DT/det/7 frying/NN/amod/7 pans/NNS/pobj/4/pan"
    )
    assert frames(doc) == [("pour", {"Theme": "chocolate", "Destination": "frying pan"})]
    assert frames("fry/VB/ROOT/0 them/PRP/dobj/0 in/IN/prep/0 oil/NN/pobj/2") == [
        ("fry", {"Theme": "them", "Instrument": "oil"})
    ]


@pytest.mark.parametrize(
    ("before", "expected"),
    [
        ("2/CD/nummod/2 tablespoons/NNS/compound/3/tablespoon", "oil"),  # counted: a quantity, not a name
        ("1/CD/nummod/2 tablespoon/NN/compound/3", "oil"),
        ("tablespoons/NNS/compound/2/tablespoon", "oil"),  # a plural unit before a noun is counted too
        ("a/DT/det/3 tablespoon/NN/compound/3", "tablespoon oil"),  # uncounted: the parse's compound stands
    ],
)
def test_a_counted_measure_is_no_part_of_a_name(before, expected):
    n = len(before.split())
    doc = f"heat/VB/ROOT/0 {before} oil/NN/dobj/0 in/IN/prep/0 a/DT/det/{n + 4} pan/NN/pobj/{n + 2}"
    assert frames(doc) == [("heat", {"Theme": expected, "Instrument": "pan"})]
    loaf = (
        "pour/VB/ROOT/0 into/IN/prep/0 a/DT/det/7 9/CD/nummod/5 -/HYPH/punct/5 inch/NN/compound/7 "
        "loaf/NN/compound/7 pan/NN/pobj/1"
    )
    assert frames(loaf) == [("pour", {"Theme": None, "Destination": "loaf pan"})]


def test_a_closing_please_is_no_part_of_a_name():
    """The small tagger reads a last 'please' as the noun a compound ends in ("coffee/compound please/pobj")."""
    doc = "pour/VB/ROOT/0 me/PRP/dative/0 a/DT/det/3 mug/NN/dobj/0 of/IN/prep/3 coffee/NN/compound/6 please/NN/pobj/4"
    assert frames(doc) == [("pour", {"Theme": "coffee", "Destination": None})]
    doc = "blend/VB/ROOT/0 the/DT/det/3 soup/NN/compound/3 please/NN/dobj/0"
    assert frames(doc) == [("blend", {"Theme": "soup", "Destination": None})]
    assert frames("heat/VB/ROOT/0 the/DT/det/2 please/NN/dobj/0") == [("heat", {"Theme": None, "Instrument": None})]


def test_passive_subject_is_the_theme():
    doc = (
        "the/DT/det/1 steak/NN/nsubjpass/4 should/MD/aux/4 be/VB/auxpass/4 seasoned/VBN/ROOT/4/season "
        "with/IN/prep/4 salt/NN/pobj/5"
    )
    assert frames(doc) == [("season", {"Theme": "steak", "Instrument": "salt"})]


def test_a_participles_object_stands_elsewhere():
    """Requests said with a participle ("I want the steak seasoned") keep what they are about."""
    small_clause = "I/PRP/nsubj/1 want/VBP/ROOT/1 the/DT/det/3 steak/NN/nsubj/4 seasoned/VBD/ccomp/1/season"
    assert ("season", {"Theme": "steak", "Instrument": None}) in frames(small_clause)
    control = "the/DT/det/1 chicken/NN/nsubj/2 needs/VBZ/ROOT/2/need to/TO/aux/5 be/VB/auxpass/5 fried/VBN/xcomp/2/fry"
    assert ("fry", {"Theme": "chicken", "Instrument": None}) in frames(control)
    described = "serve/VB/ROOT/0 the/DT/det/2 fish/NN/dobj/0 fried/VBN/acl/2/fry in/IN/prep/3 butter/NN/pobj/4"
    assert ("fry", {"Theme": "fish", "Instrument": "butter"}) in frames(described)
    assert ("fry", {"Theme": "it", "Instrument": None}) in frames("get/VB/ROOT/0 it/PRP/nsubj/2 fried/VBN/ccomp/0/fry")
    coordinated = (
        "the/DT/det/1 chicken/NN/nsubjpass/3 is/VBZ/auxpass/3 seasoned/VBN/ROOT/3/season and/CC/cc/3 "
        "fried/VBN/conj/3/fry"
    )
    assert frames(coordinated) == [
        ("season", {"Theme": "chicken", "Instrument": None}),
        ("fry", {"Theme": "chicken", "Instrument": None}),
    ]
    # the participle's preposition right after it is a role's, not a particle, when its object stands elsewhere
    sprinkled = (
        "I/PRP/nsubj/2 'd/MD/aux/2 like/VB/ROOT/2 some/DT/det/4 cheese/NN/nsubj/5 sprinkled/VBD/ccomp/2/sprinkle "
        "on/IN/prep/5 my/PRP$/poss/8 pasta/NN/pobj/6"
    )
    assert ("sprinkle", {"Theme": "cheese", "Destination": "pasta"}) in frames(sprinkled)
    assert frames("pour/VB/ROOT/0 in/IN/prep/0 the/DT/det/3 milk/NN/pobj/1") == [
        ("pour", {"Theme": "milk", "Destination": None})
    ]
    # a person does the frying; a participle with its own object needs nothing from elsewhere
    assert frames("we/PRP/nsubj/2 have/VBP/aux/2 fried/VBN/ROOT/2/fry") == [
        ("fry", {"Theme": None, "Instrument": None})
    ]
    own = "I/PRP/nsubj/2 have/VBP/aux/2 fried/VBN/ROOT/2/fry the/DT/det/4 fish/NN/dobj/2"
    assert frames(own) == [("fry", {"Theme": "fish", "Instrument": None})]


def test_a_gerund_after_a_thing_is_done_to_it():
    """ "the chicken needs frying" means it needs to be fried; a person with a gerund does the frying."""
    needs = "the/DT/det/1 chicken/NN/nsubj/2 needs/VBZ/ROOT/2/need frying/VBG/xcomp/2/fry in/IN/prep/3 oil/NN/pobj/4"
    assert ("fry", {"Theme": "chicken", "Instrument": "oil"}) in frames(needs)
    up = "the/DT/det/1 soup/NN/nsubj/2 needs/VBZ/ROOT/2/need heating/VBG/xcomp/2/heat up/RP/prt/3"
    assert ("heat", {"Theme": "soup", "Instrument": None}) in frames(up)
    person = "I/PRP/nsubj/1 like/VBP/ROOT/1 frying/VBG/xcomp/1/fry"
    assert ("fry", {"Theme": None, "Instrument": None}) in frames(person)
    own = "I/PRP/nsubj/1 keep/VBP/ROOT/1 frying/VBG/xcomp/1/fry the/DT/det/4 fish/NN/dobj/2"
    assert ("fry", {"Theme": "fish", "Instrument": None}) in frames(own)


def test_adjectival_participles_and_nouns_are_not_predicates():
    doc = "add/VB/ROOT/0 the/DT/det/3 fried/VBN/amod/3/fry onions/NNS/dobj/0/onion"
    assert frames(doc) == [("add", {"Theme": "onion"})]
    assert frames("use/VB/ROOT/0 a/DT/det/3 pastry/NN/compound/3 brush/NN/dobj/0") == [
        ("use", {"Theme": "pastry brush"})
    ]


def test_generic_frames_keep_object_and_prepositions():
    doc = "add/VB/ROOT/0 the/DT/det/2 shallots/NNS/dobj/0/shallot to/IN/prep/0 the/DT/det/5 pan/NN/pobj/3"
    assert frames(doc) == [("add", {"Theme": "shallot", "to": "pan"})]


def test_learned_compounds_decide_adjective_tagged_modifiers():
    doc = "sprinkle/VB/ROOT/0 the/DT/det/3 cinnamon/JJ/amod/3 sugar/NN/dobj/0 over/IN/prep/0 toast/NN/pobj/4"
    assert frames(doc)[0][1]["Theme"] == "sugar"
    learned = Compounds(head_rates={"cinnamon": 0.41}, strong_bigrams=frozenset({"olive oil"}))
    assert frames(doc, learned)[0][1]["Theme"] == "cinnamon sugar"
    assert frames("heat/VB/ROOT/0 olive/JJ/amod/2 oil/NN/dobj/0", learned)[0][1]["Theme"] == "olive oil"
    assert frames("heat/VB/ROOT/0 hot/JJ/amod/2 oil/NN/dobj/0", learned)[0][1]["Theme"] == "oil"


def test_a_noun_said_as_a_modifier_in_the_singular_joins_by_its_plurals_head_rate():
    # "the vegetable stock": vegetable seldom heads a phrase, vegetables often ("add the vegetables.")
    doc = "pour/VB/ROOT/0 the/DT/det/3 vegetable/JJ/amod/3 stock/NN/dobj/0 into/IN/prep/0 pot/NN/pobj/4"
    learned = Compounds(head_rates={"vegetables": 0.40, "berries": 0.5, "tomatoes": 0.48, "others": 0.6})
    assert frames(doc)[0][1]["Theme"] == "stock"
    assert frames(doc, learned)[0][1]["Theme"] == "vegetable stock"
    assert learned.joins("berry", "sauce") and learned.joins("tomato", "sauce")  # -ies and -es plurals
    assert not learned.joins("other", "bowl")  # "the others" heads phrases; "other" is a function word
    assert not learned.joins("large", "bowl") and not Compounds(
        predicative=frozenset({"vegetable"}), head_rates={"vegetables": 0.4}
    ).joins("vegetable", "stock")


def test_lone_object_of_alternating_verb_is_resolved_by_priors():
    [frame] = extract_frames(make_doc("rub/VB/ROOT/0 the/DT/det/2 steak/NN/dobj/0"), LEX)
    assert frame.ambiguous_object == "Theme" and frame.roles == {"Theme": "steak", "Destination": None}
    priors = RolePriors(by_verb=Counter({("rub", "steak", "Destination"): 9, ("rub", "steak", "Theme"): 1}))
    resolved = priors.resolve(frame)
    assert resolved.roles == {"Theme": None, "Destination": "steak"}
    # a noun seen only with other alternating verbs backs off to the pooled counts
    pooled = RolePriors(pooled=Counter({("salt", "Theme"): 5}))
    [salt] = extract_frames(make_doc("rub/VB/ROOT/0 the/DT/det/2 salt/NN/dobj/0"), LEX)
    assert pooled.resolve(salt).roles == {"Theme": "salt", "Destination": None}
    assert RolePriors().resolve(frame).roles == frame.roles  # unseen: syntactic default stays
    # a particle settles it syntactically: "rub the salt in"
    [particle] = extract_frames(make_doc("rub/VB/ROOT/0 the/DT/det/2 salt/NN/dobj/0 in/RP/prt/0"), LEX)
    assert particle.ambiguous_object is None


def test_priors_round_trip(tmp_path):
    priors = RolePriors(Counter({("rub", "steak", "Destination"): 3}), Counter({("steak", "Destination"): 3}))
    priors.save(tmp_path / "p.json")
    assert RolePriors.load(tmp_path / "p.json") == priors


def test_imperative_repair_triggers():
    misread = make_doc("Heat/NN/compound/1 oil/NN/ROOT/1 in/IN/prep/1 a/DT/det/4 pan/NN/pobj/2")
    assert needs_reparse(misread[:])
    declarative = make_doc("Chicken/NN/nsubjpass/3 should/MD/aux/3 be/VB/auxpass/3 fried/VBN/ROOT/3")
    assert not needs_reparse(declarative[:])
    verb_first = make_doc("pour/VB/ROOT/0 water/NN/dobj/0")
    assert not needs_reparse(verb_first[:])
    # How the tagger reads a bare "fry the chicken": a preposition heading a sentence with no verb.
    preposition_root = make_doc("fry/IN/ROOT/0 the/DT/det/2 chicken/NN/dobj/0")
    assert needs_reparse(preposition_root[:])
    # "pour milk, I'm making tea": tagged a verb, parsed as a modifier of the noun after it
    modifier = make_doc(
        "pour/VB/compound/1 milk/NN/dep/5 ,/,/punct/5 I/PRP/nsubj/5 'm/VBP/aux/5 making/VBG/ROOT/5 tea/NN/dobj/5"
    )
    assert needs_reparse(modifier[:])
    assert not needs_reparse(make_doc("boiling/VB/amod/1 water/NN/nsubj/2 hisses/VBZ/ROOT/2")[:])  # a subject
    leading_prep = make_doc("In/IN/prep/3 a/DT/det/2 bowl/NN/pobj/0 mix/VB/ROOT/3 flour/NN/dobj/3")
    assert not needs_reparse(leading_prep[:])
    clause = make_doc("brush/VB/ROOT/0 bread/NN/dobj/0 and/CC/cc/1 season/NN/conj/1 with/IN/prep/3 salt/NN/pobj/4")
    assert find_split(clause[:], LEX).text == "season"
    assert find_split(make_doc("add/VB/ROOT/0 salt/NN/dobj/0 and/CC/cc/1 pepper/NN/conj/1")[:], LEX) is None


def test_a_clause_that_says_what_a_thing_is_for_is_not_the_request():
    """ "hand me something to cut the bread with": cut modifies "something" (what it is for); hand is what
    the robot is asked to do."""
    doc = make_doc(
        "hand/VB/ROOT/0 me/PRP/dative/0 something/NN/dobj/0 to/TO/aux/4 cut/VB/relcl/2 the/DT/det/6 "
        "bread/NN/dobj/4 with/IN/prep/4"
    )
    addressed = {f.predicate: f.addressed for f in extract_frames(doc, LEX)}
    assert addressed["cut"] is False


def test_a_thing_asked_for_by_its_purpose_fills_a_role_of_the_purpose_frame():
    """ "hand me something to season the steak with": the thing is season's Instrument (the stranded
    "with"); "get me something to pour into the bowl": pour's object, the Theme; a request that names its
    thing has no purpose frame."""
    from lmcr.srl.context import Purpose, purpose_of

    doc = make_doc(
        "hand/VB/ROOT/0 me/PRP/dative/0 something/NN/dobj/0 to/TO/aux/4 season/VB/relcl/2 the/DT/det/6 "
        "steak/NN/dobj/4 with/IN/prep/4"
    )
    hand = next(f for f in extract_frames(doc, LEX) if f.predicate == "hand")
    assert purpose_of(doc, hand, LEX) == Purpose("season", {"Theme": "steak"}, "Instrument")
    doc = make_doc(
        "get/VB/ROOT/0 me/PRP/dative/0 something/NN/dobj/0 to/TO/aux/4 pour/VB/relcl/2 into/IN/prep/4 "
        "the/DT/det/7 bowl/NN/pobj/5"
    )
    get = next(f for f in extract_frames(doc, LEX) if f.predicate == "get")
    assert purpose_of(doc, get, LEX) == Purpose("pour", {"Destination": "bowl"}, "Theme")
    doc = make_doc("hand/VB/ROOT/0 me/PRP/dative/0 the/DT/det/3 knife/NN/dobj/0")
    assert purpose_of(doc, extract_frames(doc, LEX)[0], LEX) is None
    # the clause states every role the thing could fill: what it is for leaves it none
    doc = make_doc(
        "hand/VB/ROOT/0 me/PRP/dative/0 something/NN/dobj/0 to/TO/aux/4 season/VB/relcl/2 the/DT/det/6 "
        "steak/NN/dobj/4 with/IN/prep/4 salt/NN/pobj/7"
    )
    assert purpose_of(doc, next(f for f in extract_frames(doc, LEX) if f.predicate == "hand"), LEX) is None


def test_an_object_after_a_particle_read_as_an_adverbial_is_the_object():
    """ "fry up some bacon": the parser hangs "some bacon" on fry as an adverbial after the particle; it is
    the object. A span of time stays an adverbial ("fry up every minute")."""
    bacon = make_doc("fry/VB/ROOT/0 up/RP/prt/0 some/DT/det/3 bacon/NN/npadvmod/0")
    assert extract_frames(bacon, LEX)[0].to_json() == {
        "predicate": "fry",
        "roles": {"Theme": "bacon", "Instrument": None},
    }
    minute = make_doc("fry/VB/ROOT/0 up/RP/prt/0 every/DT/det/3 minute/NN/npadvmod/0")
    assert extract_frames(minute, LEX)[0].roles["Theme"] is None


def test_a_learned_verbs_particle_stays_a_particle():
    """ "bring over the salt": over is one of bring's learned Destination prepositions, but the parser read
    it as a particle with "the salt" the object, and so it stays; a paper verb's particle that is its
    role's preposition is that role's ("sprinkle over the salad")."""
    from dataclasses import replace

    from lmcr.lexicon import PredicateSpec

    bring = PredicateSpec(
        name="bring",
        roles=("Theme", "Destination"),
        object_role="Theme",
        with_role=None,
        preps={"Destination": ("over", "into")},
        particles=frozenset(),
        alternating=False,
        sentence="bring {Theme} into the {Destination}",
    )
    lex = replace(LEX, predicates={**LEX.predicates, "bring": bring}, learned=frozenset({"bring"}))
    salt = make_doc("bring/VB/ROOT/0 over/RP/prt/0 the/DT/det/3 salt/NN/dobj/0")
    assert extract_frames(salt, lex)[0].roles == {"Theme": "salt", "Destination": None}
    salad = make_doc("sprinkle/VB/ROOT/0 over/RP/prt/0 the/DT/det/3 salad/NN/dobj/0")
    assert extract_frames(salad, lex)[0].roles == {"Theme": None, "Destination": "salad"}


def test_a_reparse_that_hangs_the_object_as_an_adverbial_loses_it():
    """ "toast the bread": behind "Please" the tagger reads toast as a verb but hangs "the bread" on it as an
    adverbial noun phrase; behind "You should" it is the object. A span of time stays an adverbial."""
    please = make_doc("Please/UH/intj/1 toast/VB/ROOT/1 the/DT/det/3 bread/NN/npadvmod/1")
    should = make_doc("You/PRP/nsubj/2 should/MD/aux/2 toast/VB/ROOT/2 the/DT/det/4 bread/NN/dobj/2")
    assert _object_lost(please, "Please ") and not _object_lost(should, "You should ")
    minutes = make_doc("Please/UH/intj/1 bake/VB/ROOT/1 another/DT/det/4 20/CD/nummod/4 minutes/NNS/npadvmod/1")
    assert not _object_lost(minutes, "Please ")
    later = make_doc("Please/UH/intj/1 stir/VB/ROOT/1 the/DT/det/3 soup/NN/dobj/1 the/DT/det/5 day/NN/npadvmod/1")
    assert not _object_lost(later, "Please ")  # it has its object


def _participles(doc_spec: str, words: set[str]):
    doc = make_doc(doc_spec)
    for token in doc:
        token._.participle = token.lower_ in words  # what LazyLemmas marks with the model's lemmatizer
    return doc


def test_participles_and_predicative_adjectives_are_never_name_parts():
    strong = Compounds(
        strong_bigrams=frozenset({"grated parmesan", "hot sauce", "sesame oil"}), predicative=frozenset({"hot"})
    )
    doc = _participles("sprinkle/VB/ROOT/0 the/DT/det/3 grated/JJ/amod/3 parmesan/NN/dobj/0", {"grated"})
    assert extract_frames(doc, LEX, strong)[0].roles["Theme"] == "parmesan"  # strong bigram, still a participle
    assert frames("pour/VB/ROOT/0 the/DT/det/3 boiled/VBN/amod/3 water/NN/dobj/0", strong)[0][1]["Theme"] == "water"
    assert frames("pour/VB/ROOT/0 hot/JJ/amod/2 sauce/NN/dobj/0", strong)[0][1]["Theme"] == "sauce"
    assert frames("heat/VB/ROOT/0 sesame/JJ/amod/2 oil/NN/dobj/0", strong)[0][1]["Theme"] == "sesame oil"


def test_proper_noun_tagged_modifiers_are_judged_by_the_corpus():
    doc = "heat/VB/ROOT/0 the/DT/det/3 leftover/NNP/compound/3 pizza/NN/dobj/0"
    assert frames(doc)[0][1]["Theme"] == "leftover pizza"  # no statistics: the parser's compound label stands
    assert frames(doc, Compounds())[0][1]["Theme"] == "pizza"
    # a common-noun modifier of a modifier is part of the name too
    doc = "fill/VB/ROOT/0 the/DT/det/4 ice/NN/compound/3 cube/NN/compound/4 tray/NN/dobj/0"
    assert frames(doc)[0][1]["Destination"] == "ice cube tray"


@pytest.mark.parametrize(
    "doc, expected",
    [
        # the quantity read as an adverbial noun phrase is still the object
        (
            "fry/VB/ROOT/0 a/DT/det/2 couple/NN/npadvmod/0 of/IN/prep/2 eggs/NNS/pobj/3/egg in/IN/prep/0 "
            "the/DT/det/7 skillet/NN/pobj/5",
            ("fry", {"Theme": "egg", "Instrument": "skillet"}),
        ),
        # a destination hung on the of-object of a quantity
        (
            "pour/VB/ROOT/0 some/DT/dobj/0 of/IN/prep/1 the/DT/det/4 sauce/NN/pobj/2 over/IN/prep/4 "
            "the/DT/det/7 meatballs/NNS/pobj/5/meatball",
            ("pour", {"Theme": "sauce", "Destination": "meatball"}),
        ),
        # a role phrase hung on the object of a time phrase
        (
            "fry/VB/ROOT/0 the/DT/det/2 onions/NNS/dobj/0/onion for/IN/prep/0 five/CD/nummod/5 "
            "minutes/NNS/pobj/3/minute in/IN/prep/5 the/DT/det/8 butter/NN/pobj/6",
            ("fry", {"Theme": "onion", "Instrument": "butter"}),
        ),
        # two phrases for one role: the more usual preposition names it ("in" before "on" for fry)
        (
            "fry/VB/ROOT/0 the/DT/det/2 fish/NN/dobj/0 on/IN/prep/0 both/DT/det/5 sides/NNS/pobj/3/side "
            "in/IN/prep/5 hot/JJ/amod/8 oil/NN/pobj/6",
            ("fry", {"Theme": "fish", "Instrument": "oil"}),
        ),
    ],
)
def test_quantities_and_phrases_hung_on_other_phrases(doc, expected):
    assert frames(doc) == [expected]


def test_a_negated_request_asks_for_nothing():
    """ "do not pour the milk": the frame is there, said not to be done, so it is no request; a request
    beside it still is ("pour the milk, don't spill it"), and one asking only what not to do is refused
    in one line that says so."""
    from types import SimpleNamespace

    from lmcr.srl.instruction import NothingAskedError, _first_known

    negated = "do/VB/aux/2 not/RB/neg/2 pour/VB/ROOT/2 the/DT/det/4 milk/NN/dobj/2"
    found = extract_frames(make_doc(negated), LEX)
    assert [(f.predicate, f.negated) for f in found] == [("pour", True)]
    with pytest.raises(
        NothingAskedError, match="nothing to do in 'do not pour the milk': it asks the robot not to pour"
    ):
        _first_known(SimpleNamespace(lex=LEX), "do not pour the milk", found)
    both = "pour/VB/ROOT/0 milk/NN/dobj/0 and/CC/cc/0 do/VB/aux/5 not/RB/neg/5 dump/VB/conj/0 water/NN/dobj/5"
    chosen = _first_known(SimpleNamespace(lex=LEX), "", extract_frames(make_doc(both), LEX))
    assert (chosen.predicate, chosen.roles["Theme"], chosen.negated) == ("pour", "milk", False)


@pytest.mark.parametrize(
    "spec",
    [
        "get/VB/auxpass/1 rid/VBN/ROOT/1 of/IN/prep/1 the/DT/det/4 peel/NN/pobj/2",  # get rid of the peel
        "get/VB/ROOT/0 rid/JJ/acomp/0 of/IN/prep/1 the/DT/det/4 peel/NN/pobj/2",
    ],
)
def test_get_rid_of_names_one_generic_frame_whichever_way_it_is_parsed(spec):
    assert frames(spec) == [("get rid", {"of": "peel"})]


def test_a_clause_that_says_what_a_thing_is_for_comes_after_the_request_it_serves():
    """ "get me something to pour the water into": pour describes the thing, so get (a learned verb) is the
    request, though the eleven come first otherwise (pour had been chosen); with get unknown the clause is
    all there is, and is read (a misparse may hang the request there)."""
    from types import SimpleNamespace

    from lmcr.srl.instruction import _first_known

    spec = (
        "get/VB/ROOT/0 me/PRP/dative/0 something/NN/dobj/0 to/TO/aux/4 pour/VB/relcl/2 the/DT/det/6 "
        "water/NN/dobj/4 into/IN/prep/4"
    )
    found = extract_frames(make_doc(spec), LEX)
    assert [(f.predicate, f.describes) for f in found] == [("get", False), ("pour", True)]
    alone = _first_known(SimpleNamespace(lex=LEX), "", found)
    assert (alone.predicate, alone.roles) == ("pour", {"Theme": "water", "Destination": None})
    found[0].known = True  # as where get is learned
    learned = SimpleNamespace(lex=SimpleNamespace(learned={"get"}, predicates=LEX.predicates))
    assert _first_known(learned, "", found).predicate == "get"
