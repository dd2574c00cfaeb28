-- What every verb that is not a robot predicate does with two fillers at once: its object (Theme) and
-- the object of one of its prepositions ("transfer the rice into a bowl": transfer, rice, into, bowl),
-- counted per verb, object, preposition and value ($corpus: a corpus name or 'all'). The similar-verbs
-- model (lmcr/scorers/similar_verbs.py) pools them over the verbs most like each robot predicate.
select f.predicate as verb, o.value as theme, p.role as prep, p.value, count(*) as n
from frames f
join frame_roles o using (corpus, doc_id, sent_id, frame_no)
join frame_roles p using (corpus, doc_id, sent_id, frame_no)
where not f.known
  and ($corpus = 'all' or f.corpus = $corpus)
  and o.role = 'Theme' and o.value is not null
  and p.role <> 'Theme' and p.value is not null
group by all
order by all
