-- sentence keys are present and unique, kinds are from the fixed set, and each sentence has a document
with keyed as (
    select corpus, doc_id, sent_id, kind, text, count(*) over (partition by doc_id, sent_id) as n
    from sentences
)
select k.doc_id, k.sent_id, 'bad key or kind' as problem
from keyed k
where k.n > 1 or k.kind not in ('instruction', 'ingredient', 'title', 'comment')
   or k.text = '' or k.corpus not in ('youcook2', 'recipes', 'household')
union all
select s.doc_id, s.sent_id, 'no document' as problem
from sentences s anti join documents d using (doc_id)
